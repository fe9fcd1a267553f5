//! The scan matcher's DE as the alternative matcher of scan-to-map SLAM: differential evolution
//! ([Storn 1997]; [Hospital thesis §5.1], [`crate::matching::de::minimize`]) searches a window
//! around the odometry prediction for the pose minimising Hector SLAM's objective
//! Σ (1 − M(Tₚ(sᵢ)))² (Kohlbrecher et al., SSRR 2011, eq. 6; M the map's bilinearly interpolated
//! occupancy, [`crate::matching::map_pyramid`]) plus the odometry prior's quadratic term — the
//! objective Gauss-Newton descends, searched globally within the window instead of by gradient, as
//! the thesis proposes for its maze drift (match each scan against the map built so far).

use crate::core::moments::weighted_scatter;
use crate::core::{Pose2, SimRng, wrap_angle};
use crate::matching::gauss_newton::OdometryPrior;
use crate::matching::map_pyramid::MapPyramid;
use crate::matching::{Bounds, DeParams, StallStop, Vector, de};

/// The search.
#[derive(Clone, Debug, PartialEq)]
pub struct DeMapMatcher {
    pub params: DeParams,
    /// Half-widths of the window around the prediction: x, y (m) and θ (rad).
    pub window_xy: f64,
    pub window_theta: f64,
}

impl Default for DeMapMatcher {
    /// The thesis's final-experiment DE (population 20, F 0.5, CR 0.9, rand/1, binomial) with a
    /// budget of 80 generations, stopping early once the best cost stalls for 15 generations.
    fn default() -> Self {
        DeMapMatcher {
            params: DeParams {
                generations: 80,
                stall: Some(StallStop {
                    generations: 15,
                    tolerance: 1e-6,
                }),
                parallel: false,
                ..DeParams::thesis_final_experiment()
            },
            window_xy: 0.2,
            window_theta: 0.1,
        }
    }
}

/// The cost of `pose`: Hector's objective on level 0 (points off the map count as M = 0) plus
/// the prior's whitened squared distance.
fn cost(
    pyramid: &MapPyramid,
    points: &[[f32; 2]],
    pose: &Pose2,
    prior: Option<&OdometryPrior>,
) -> f64 {
    let level = pyramid.level(0);
    let (s, c) = pose.theta.sin_cos();
    let mut sum = 0.0;
    for p in points {
        let (px, py) = (p[0] as f64, p[1] as f64);
        let m = level
            .sample(pose.x + c * px - s * py, pose.y + s * px + c * py)
            .map_or(0.0, |m| m.value);
        sum += (1.0 - m) * (1.0 - m);
    }
    if let Some(q) = prior {
        let d = [
            pose.x - q.pose.x,
            pose.y - q.pose.y,
            wrap_angle(pose.theta - q.pose.theta),
        ];
        sum += (0..3).map(|k| q.information[k] * d[k] * d[k]).sum::<f64>();
    }
    sum
}

/// The pose DE finds for `points` (base frame) around `predicted`, and the covariance of its
/// last generation; None when the search could not run.
pub fn match_de(
    pyramid: &MapPyramid,
    points: &[[f32; 2]],
    predicted: Pose2,
    prior: Option<&OdometryPrior>,
    matcher: &DeMapMatcher,
    rng: &mut SimRng,
) -> Option<(Pose2, [[f64; 3]; 3])> {
    let (w, a) = (matcher.window_xy, matcher.window_theta);
    let bounds = Bounds {
        lo: [predicted.x - w, predicted.y - w, predicted.theta - a],
        hi: [predicted.x + w, predicted.y + w, predicted.theta + a],
    };
    let f = |v: &Vector| cost(pyramid, points, &Pose2::new(v[0], v[1], v[2]), prior);
    let seed: Vector = [predicted.x, predicted.y, predicted.theta];
    let out = de::minimize(&f, &bounds, &matcher.params, &[seed], rng).ok()?;
    let n = out.population.len() as f64;
    let mean: Vec<f64> = (0..3)
        .map(|k| out.population.iter().map(|v| v[k]).sum::<f64>() / n)
        .collect();
    let cov = weighted_scatter(
        out.population
            .iter()
            .map(|v| ([v[0] - mean[0], v[1] - mean[1], v[2] - mean[2]], 1.0)),
    );
    let b = out.best;
    Some((Pose2::new(b[0], b[1], wrap_angle(b[2])), cov))
}

#[cfg(test)]
mod tests {
    use crate::core::{Pose2, stream_rng};
    use crate::localization::fixtures::{CORRIDOR, hospital, recorded_drive};
    use crate::mapping::{ScanToMapConfig, ScanToMapSlam};

    #[test]
    fn scan_to_map_with_the_de_matcher_follows_the_corridor_where_odometry_drifts() {
        let world = hospital();
        let steps = recorded_drive(&world, &CORRIDOR, 0.0, 3);
        let config = ScanToMapConfig {
            init_pose: steps[0].truth,
            de_matcher: Some(super::DeMapMatcher::default()),
            ..ScanToMapConfig::default()
        };
        let mut slam = ScanToMapSlam::new(config).with_rng(stream_rng(1, "t", "de-map"));
        let (mut sq, mut sq_odom) = (0.0, 0.0);
        for s in &steps {
            slam.step(&s.scan, &Pose2::default(), &s.odom);
            let odom = steps[0].truth.compose(&steps[0].odom.between(&s.odom));
            sq += slam.pose().distance(&s.truth).powi(2);
            sq_odom += odom.distance(&s.truth).powi(2);
        }
        let n = steps.len() as f64;
        let (ate, ate_odom) = ((sq / n).sqrt(), (sq_odom / n).sqrt());
        eprintln!("DE scan-to-map: ATE {ate:.3} m, odometry {ate_odom:.3} m");
        assert!(ate < 0.06 && ate < ate_odom / 4.0, "{ate} vs {ate_odom}");
        assert!(
            slam.matches > 400 && slam.unconverged == 0,
            "{}",
            slam.matches
        );
    }
}
