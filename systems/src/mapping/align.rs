//! The transform from an estimated map's frame to the truth map's frame, for
//! [`super::quality::map_quality`]. SLAM maps are usually expressed in the frame of the robot's
//! start pose, so the true start pose gives the transform ([`start_pose_alignment`]); when it is
//! known only roughly, [`refine_alignment`] polishes it by chamfer matching of the estimated
//! walls against the true map's distance transform.

use super::quality::occupied_centres;
use crate::core::Pose2;
use crate::world::OccupancyGrid;
use crate::world::distance_field::squared_distances;

/// The estimated-to-truth transform when both maps saw the robot's start pose: `start_in_truth`
/// (the true start pose) and `start_in_est` (where the estimated map puts it; the identity when
/// the map frame is the start pose, as SLAM maps usually are).
pub fn start_pose_alignment(start_in_truth: &Pose2, start_in_est: &Pose2) -> Pose2 {
    start_in_truth.compose(&start_in_est.inverse())
}

/// Refines an estimated-to-truth transform from `initial` by a pattern search (Hooke & Jeeves
/// 1961) minimising the mean distance, truncated at `max_dist` metres, from the estimated
/// occupied cell centres to the nearest true occupied cell centre, read bilinearly from the
/// truth map's exact Euclidean distance transform (chamfer matching, Barrow et al. 1977). For
/// when the start pose is known only roughly; it converges to the nearest local minimum, so
/// `initial` should be within about `max_dist` and a few degrees.
pub fn refine_alignment(
    est: &OccupancyGrid,
    truth: &OccupancyGrid,
    initial: &Pose2,
    max_dist: f64,
) -> Pose2 {
    let (w, h, res) = (truth.width, truth.height, truth.resolution);
    let cap = (max_dist / res).max(1.0);
    let dist: Vec<f64> = squared_distances(w, h, |c, r| truth.is_obstacle(c, r))
        .into_iter()
        .map(|d2| d2.sqrt().min(cap))
        .collect();
    let points: Vec<[f64; 2]> = occupied_centres(est).collect();
    if points.is_empty() || w == 0 || h == 0 {
        return *initial;
    }
    // bilinear between cell centres; outside the grid reads the cap
    let at = |c: i64, r: i64| {
        if c < 0 || r < 0 || c >= w as i64 || r >= h as i64 {
            cap
        } else {
            dist[r as usize * w + c as usize]
        }
    };
    let cost = |t: &Pose2| -> f64 {
        let sum: f64 = points
            .iter()
            .map(|&p| {
                let q = t.transform_point(p);
                let gx = (q[0] - truth.origin[0]) / res - 0.5;
                let gy = (q[1] - truth.origin[1]) / res - 0.5;
                let (c, r) = (gx.floor(), gy.floor());
                let (fx, fy) = (gx - c, gy - r);
                let (c, r) = (c as i64, r as i64);
                let bottom = at(c, r) * (1.0 - fx) + at(c + 1, r) * fx;
                let top = at(c, r + 1) * (1.0 - fx) + at(c + 1, r + 1) * fx;
                bottom * (1.0 - fy) + top * fy
            })
            .sum();
        sum / points.len() as f64
    };
    // search a correction applied in the estimated frame, rotating about the points' centroid
    // so that turning does not also shift the map
    let n = points.len() as f64;
    let centroid = points
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
    let correction = |d: [f64; 3]| {
        let (s, c) = d[2].sin_cos();
        let rc = [
            c * centroid[0] - s * centroid[1],
            s * centroid[0] + c * centroid[1],
        ];
        initial.compose(&Pose2::new(
            centroid[0] - rc[0] + d[0],
            centroid[1] - rc[1] + d[1],
            d[2],
        ))
    };
    let mut best = [0.0; 3];
    let mut best_cost = cost(&correction(best));
    let (mut step_xy, mut step_th) = (2.0 * res, 1f64.to_radians());
    while step_xy > res / 16.0 {
        let mut improved = false;
        for (axis, step) in [(0, step_xy), (1, step_xy), (2, step_th)] {
            for sign in [1.0, -1.0] {
                let mut d = best;
                d[axis] += sign * step;
                let c = cost(&correction(d));
                if c < best_cost {
                    (best, best_cost, improved) = (d, c, true);
                }
            }
        }
        if !improved {
            step_xy /= 2.0;
            step_th /= 2.0;
        }
    }
    correction(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_pose_alignment_maps_the_start_onto_itself() {
        let truth_start = Pose2::new(3.0, 4.0, 1.0);
        let est_start = Pose2::new(0.5, -0.2, 0.3);
        let t = start_pose_alignment(&truth_start, &est_start);
        let p = t.compose(&est_start);
        assert!(p.distance(&truth_start) < 1e-12 && (p.theta - 1.0).abs() < 1e-12);
        assert_eq!(
            start_pose_alignment(&truth_start, &Pose2::IDENTITY),
            truth_start
        );
    }
}
