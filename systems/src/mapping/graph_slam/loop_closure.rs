//! Loop-closure constraints between a node and a finished submap (Hess et al., "Real-Time Loop
//! Closure in 2D LIDAR SLAM", ICRA 2016 ([Hess 2016, §V]); [SLAM thesis §3.3.2]: Cartographer's
//! loop closure by branch-and-bound scan matching over a search window with a minimum score).
//!
//! The node's scan is searched for by [`match_bnb`] over a window around its current global
//! estimate (expressed in the submap's local coordinates); a match that reaches `min_score` is
//! refined by Gauss-Newton on the submap's own pyramid (sub-cell precision, as Cartographer's
//! Ceres refinement after the correlative search) and becomes an edge to the node from the
//! submap's node nearest to the match, whose measurement is the node's pose in that node's
//! local frame. (Cartographer ties the constraint to the submap's pose; tying it to the
//! nearest node instead keeps a large submap's internal drift out of the constraint: the map
//! near that node was built from scans taken near it.)

use super::submap::Submap;
use crate::core::Pose2;
use crate::matching::gauss_newton::GaussNewtonParams;
use crate::matching::{BnbWindow, match_bnb};

#[derive(Clone, Debug, PartialEq)]
pub struct LoopClosureConfig {
    /// Search constraints for every n-th node (Cartographer's sampling ratio, inverted).
    pub every_n_nodes: usize,
    /// A submap is searched when the node's estimate is within this distance (m) of one of the
    /// submap's own nodes (so the scans overlap).
    pub max_distance: f64,
    /// Half-widths of the search window around the node's estimate.
    pub window: BnbWindow,
    /// Minimum mean likelihood of the scan points for a match to count.
    pub min_score: f64,
    /// Branch-and-bound tree depth (precomputed grids per submap).
    pub depth: usize,
    /// Blur of the submap's walls for the search (m).
    pub sigma: f64,
    /// Use every n-th beam for the search.
    pub beam_stride: usize,
    /// The refinement may move the match this far (m) from the search's pose, else the match is
    /// dropped as ambiguous.
    pub max_refine_shift: f64,
    /// Floor of a constraint's standard deviations [x, y (m), θ (rad)], added to the match's
    /// own covariance (on hospital_loop, 0.03 m / 0.01 rad made the closures pull the graph
    /// off by their few-centimetre biases: final ATE 0.095 m at 5 cm cells, 0.040 m at 4 cm,
    /// against 0.081 / 0.021 with these; measured before the SLAM lattice was offset by half a
    /// cell, [`crate::mapping::matched_map::slam_anchor`]).
    pub std: [f64; 3],
    /// Huber δ of a loop-closure constraint, in whitened units.
    pub huber: f64,
}

impl Default for LoopClosureConfig {
    fn default() -> Self {
        LoopClosureConfig {
            every_n_nodes: 3,
            max_distance: 3.0,
            window: BnbWindow {
                x: 1.5,
                y: 1.5,
                theta: 20f64.to_radians(),
            },
            min_score: 0.55,
            depth: 6,
            sigma: 0.05,
            beam_stride: 4,
            max_refine_shift: 0.15,
            std: [0.1, 0.1, 0.03],
            huber: 1.0,
        }
    }
}

/// A constraint found: the node's pose in the frame of the reference node (local frames), and
/// its information matrix in that frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    pub measurement: Pose2,
    pub information: [[f64; 3]; 3],
    pub score: f64,
}

/// Searches node `points` (end points in the base frame) in `submap` around `guess_local` (the
/// node's estimate in the submap's local coordinates): branch-and-bound over the window, then
/// Gauss-Newton; the measurement is the match relative to `reference`, the local pose of the
/// submap's node nearest to it. With `local` (a submap just finished, which the node's own recent scans built)
/// the guess is already good to a few centimetres and only Gauss-Newton runs.
pub fn search(
    submap: &Submap,
    reference: &Pose2,
    guess_local: Pose2,
    points: &[[f32; 2]],
    local: bool,
    config: &LoopClosureConfig,
    refine: &GaussNewtonParams,
) -> Option<Found> {
    let grids = submap.search.as_ref()?;
    let start = if local {
        guess_local
    } else {
        match_bnb(grids, points, guess_local, &config.window, config.min_score)?.pose
    };
    let fine = submap.map.match_points(points, start, None, refine)?;
    let p = fine.pose;
    if !(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite())
        || p.distance(&start) > config.max_refine_shift
        || (local && fine.score < config.min_score)
    {
        return None;
    }
    Some(Found {
        measurement: reference.between(&p),
        information: information(&fine.covariance, reference.theta, &config.std),
        score: fine.score,
    })
}

/// The constraint's information in the anchor's frame: the match covariance (map axes) rotated
/// by −`anchor_theta`, plus `floor`² per axis so no constraint claims more precision than
/// that. Along a featureless corridor the match covariance is huge, so the constraint holds
/// the pose across the corridor and leaves it free along it — the corridor aliasing that makes
/// Hector slide ([SLAM thesis §4.3.3]) cannot drag the graph.
fn information(cov: &[[f64; 3]; 3], anchor_theta: f64, floor: &[f64; 3]) -> [[f64; 3]; 3] {
    let (s, c) = anchor_theta.sin_cos();
    let j = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
    let mut r = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            r[a][b] = (0..3)
                .map(|k| (0..3).map(|l| j[a][k] * cov[k][l] * j[b][l]).sum::<f64>())
                .sum();
        }
        r[a][a] += floor[a] * floor[a];
    }
    inverse3(&r)
}

/// The inverse of a symmetric positive definite 3 × 3 matrix (cofactors).
fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = c(j, i) / det;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse3_inverts() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let inv = inverse3(&m);
        let product =
            m.map(|row| [0, 1, 2].map(|j| (0..3).map(|k| row[k] * inv[k][j]).sum::<f64>()));
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for (p, e) in product.iter().flatten().zip(identity.iter().flatten()) {
            assert!((p - e).abs() < 1e-12, "{product:?}");
        }
    }

    #[test]
    fn a_corridor_match_constrains_across_the_corridor_not_along_it() {
        // a corridor along the map's x axis: the match knows y and θ, not x
        let cov = [[400.0, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-6]];
        let floor = [0.1, 0.1, 0.03];
        let along_x = information(&cov, 0.0, &floor);
        assert!(along_x[0][0] < 0.01, "{along_x:?}");
        assert!(along_x[1][1] > 90.0, "{along_x:?}");
        // seen from a reference node facing +y, the corridor runs along its own y axis
        let turned = information(&cov, std::f64::consts::FRAC_PI_2, &floor);
        assert!(turned[1][1] < 0.01 && turned[0][0] > 90.0, "{turned:?}");
    }
}
