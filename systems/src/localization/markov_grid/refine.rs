//! Sub-cell refinement of the grid's estimate: the histogram knows the pose to a cell (0.25 m,
//! 10°), the scan knows it far better. Around the most probable cell, a coarse-to-fine pattern
//! search (three rounds of 5 × 5 × 5 poses, the step halving each round) maximises the scan's
//! log-likelihood under the laser's own σ_hit on the map's distance field — the likelihood
//! field of Probabilistic Robotics §6.4 evaluated by the same kernel MCL weighs particles with.
//! Given a prior (the tracked estimate moved by the odometry), it maximises the posterior
//! instead: where one scan says little, as along a corridor, the prior decides.

use crate::core::{Pose2, wrap_angle};
use crate::localization::map::LocalizationMap;
use crate::localization::mcl::{LaserModelParams, sensor_model};

/// A Gaussian belief about the pose before the scan: the refinement maximises the posterior
/// (scan log-likelihood plus the prior's log-density) instead of the scan's likelihood alone.
#[derive(Clone, Copy, Debug)]
pub struct Prior {
    pub pose: Pose2,
    pub sigma_xy: f64,
    pub sigma_theta: f64,
}

impl Prior {
    /// The prior's log-density at `(x, y, theta)` up to a constant.
    fn log_density(&self, x: f64, y: f64, theta: f64) -> f64 {
        let (dx, dy) = (x - self.pose.x, y - self.pose.y);
        let dt = wrap_angle(theta - self.pose.theta);
        -0.5 * ((dx * dx + dy * dy) / (self.sigma_xy * self.sigma_xy)
            + dt * dt / (self.sigma_theta * self.sigma_theta))
    }
}

/// The pose near `start` (within about `half_xy` m and `half_theta` rad) where the endpoints
/// `points` (base frame) fit the map best, weighed by `prior` when there is one.
#[allow(clippy::too_many_arguments)]
pub fn refine_pose(
    map: &LocalizationMap,
    laser: &LaserModelParams,
    points: &[[f32; 2]],
    range_max: f32,
    start: Pose2,
    half_xy: f64,
    half_theta: f64,
    prior: Option<Prior>,
) -> Pose2 {
    if points.is_empty() {
        return start;
    }
    let rand = laser.z_rand / (range_max as f64).max(1e-6);
    let denom = 2.0 * laser.sigma_hit * laser.sigma_hit;
    let table = map.field.table(|d| {
        let d = d.min(laser.max_dist);
        ((laser.z_hit * (-d * d / denom).exp() + rand).max(1e-30)).ln() as f32
    });
    let mut best = start;
    let (mut sxy, mut sth) = (half_xy / 2.0, half_theta / 2.0);
    let (mut xs, mut ys, mut ths) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..3 {
        xs.clear();
        ys.clear();
        ths.clear();
        for a in -2..=2 {
            for b in -2..=2 {
                for c in -2..=2 {
                    xs.push(best.x + a as f64 * sxy);
                    ys.push(best.y + b as f64 * sxy);
                    ths.push(best.theta + c as f64 * sth);
                }
            }
        }
        // the kernel multiplies w by (1 + Σ table): with w = 1 that is 1 + Σ ln pz
        let mut w = vec![1.0; xs.len()];
        sensor_model::weigh_likelihood_field(&map.field, &table, points, &xs, &ys, &ths, &mut w);
        if let Some(prior) = prior {
            for (k, w) in w.iter_mut().enumerate() {
                *w += prior.log_density(xs[k], ys[k], ths[k]);
            }
        }
        // ties: the first (most negative offsets); the centre (index 62) wins ties against
        // nothing in particular, which is fine for a maximiser
        let k = (0..w.len())
            .max_by(|&i, &j| w[i].total_cmp(&w[j]).then(j.cmp(&i)))
            .unwrap_or(62);
        best = Pose2::new(xs[k], ys[k], wrap_angle(ths[k]));
        sxy /= 2.0;
        sth /= 2.0;
    }
    best
}
