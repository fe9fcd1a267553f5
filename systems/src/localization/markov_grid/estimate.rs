//! The pose estimate: the most probable cell, refined over its neighbourhood
//! ([`MarkovGrid::estimate_pose`]), then moved to where the scan fits the map best
//! ([`super::refine`]), from the last estimate moved by the odometry while the histogram agrees
//! with it.

use super::{MarkovGrid, belief_ops, refine};
use crate::core::{Pose2, wrap_angle};
use crate::localization::map::LocalizationMap;
use crate::localization::mcl::PoseEstimate;

/// How far (cells, and θ bins) the histogram's estimate may lie from the last estimate moved by
/// the odometry for the refinement to start from the latter. Along a corridor the scan says
/// little about the position along it, and the most probable cell alternated between two
/// neighbours from one update to the next: the refinement, started from each, kept the estimate
/// a quarter of a metre ahead of the robot every other update (sim/docs/benchmarks.md,
/// "Localization that holds"). Started from the tracked pose instead, it follows the robot; a
/// histogram that moves elsewhere (a kidnapped robot, a look-alike place winning) is followed
/// as before.
const TRACKING_CELLS: f64 = 2.0;

/// The tracked refinement's prior, in cells and heading bins (5 cm and 2° at the default
/// 0.25 m and 10°): the refinement maximises the scan's likelihood times a Gaussian around the
/// last estimate moved by the odometry, so a corridor's flat likelihood along its length leaves
/// the estimate where the odometry puts it instead of where one scan's noise peaks. Without it
/// the estimate slid ahead along the hospital's corridors on single scans.
const PRIOR_CELLS: f64 = 0.2;

/// A cell centre `(x, y, heading offset, belief)` in the estimate's neighbourhood.
type WeightedCell = (f64, f64, f64, f64);

impl MarkovGrid {
    /// The estimate after a correction, from the histogram's most probable cell (`best`, if
    /// the correction found it): tracking, the last estimate moved by the odometry where the
    /// histogram agrees with it, searched within half a cell; otherwise the histogram's own
    /// estimate within a cell. `points` are the scan's reachable endpoints.
    pub(super) fn tracked_estimate(
        &self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
        best: Option<usize>,
    ) -> Option<PoseEstimate> {
        let carried = self.carried_estimate();
        let l = &self.layout;
        let histogram = match best {
            Some(i) => self.estimate_at(i),
            None => self.estimate_pose(),
        };
        histogram.map(|mut e| {
            let (start, reach, prior) = match carried {
                Some(prior)
                    if prior.pose.distance(&e.pose) < TRACKING_CELLS * l.resolution
                        && wrap_angle(prior.pose.theta - e.pose.theta).abs()
                            < TRACKING_CELLS * l.theta_step() =>
                {
                    (prior.pose, 0.5, Some(prior))
                }
                _ => (e.pose, 1.0, None),
            };
            e.pose = refine::refine_pose(
                map,
                &self.config.laser,
                points,
                range_max,
                start,
                reach * l.resolution,
                reach * l.theta_step(),
                prior,
            );
            e
        })
    }

    /// The last estimate moved by the odometry since the scan it was refined on, with the
    /// spread the tracked refinement allows around it: [`PRIOR_CELLS`] of a cell and of a
    /// heading bin, widened by the motion model's noise for that motion.
    fn carried_estimate(&self) -> Option<refine::Prior> {
        let (e, from, to) = (self.estimate?, self.estimate_odom?, self.last_odom?);
        let [sd_xy, sd_theta] = self.config.motion.delta(&from, &to).end_sd();
        let l = &self.layout;
        Some(refine::Prior {
            pose: e.pose.compose(&from.between(&to)),
            sigma_xy: (PRIOR_CELLS * l.resolution).hypot(sd_xy),
            sigma_theta: (PRIOR_CELLS * l.theta_step()).hypot(sd_theta),
        })
    }

    /// The most probable cell, refined over its 3 × 3 × 3 neighbourhood.
    pub fn estimate_pose(&self) -> Option<PoseEstimate> {
        self.estimate_at(belief_ops::argmax(&self.belief)?.0)
    }

    /// Cell `best` refined over its 3 × 3 × 3 neighbourhood, if it holds mass.
    pub(super) fn estimate_at(&self, best: usize) -> Option<PoseEstimate> {
        let l = &self.layout;
        if self.belief[best] <= 0.0 {
            return None;
        }
        let layer = l.layer();
        let (k0, rest) = (best / layer, best % layer);
        let (j0, i0) = (rest / l.nx, rest % l.nx);
        let mut cells = Vec::with_capacity(27);
        for dk in -1..=1isize {
            let k = (k0 as isize + dk).rem_euclid(l.n_theta as isize) as usize;
            for dj in -1..=1isize {
                for di in -1..=1isize {
                    let (i, j) = (i0 as isize + di, j0 as isize + dj);
                    if i < 0 || j < 0 || i >= l.nx as isize || j >= l.ny as isize {
                        continue;
                    }
                    let (i, j) = (i as usize, j as usize);
                    let w = self.belief[k * layer + j * l.nx + i] as f64;
                    if w > 0.0 {
                        let (x, y) = self.sub_cell.position(l, k, i, j);
                        // heading relative to the best cell's, so the mean does not wrap
                        cells.push((x, y, dk as f64 * l.theta_step(), w));
                    }
                }
            }
        }
        let total: f64 = cells.iter().map(|c| c.3).sum();
        let mean = |f: &dyn Fn(&WeightedCell) -> f64| {
            cells.iter().map(|c| c.3 * f(c)).sum::<f64>() / total
        };
        let (mx, my, mt) = (mean(&|c| c.0), mean(&|c| c.1), mean(&|c| c.2));
        let d = |c: &WeightedCell| [c.0 - mx, c.1 - my, c.2 - mt];
        let mut cov = [[0.0; 3]; 3];
        for (a, row) in cov.iter_mut().enumerate() {
            for (b, v) in row.iter_mut().enumerate() {
                *v = mean(&|c| d(c)[a] * d(c)[b]);
            }
        }
        cov[0][0] += l.resolution * l.resolution / 12.0;
        cov[1][1] += l.resolution * l.resolution / 12.0;
        cov[2][2] += l.theta_step() * l.theta_step() / 12.0;
        Some(PoseEstimate {
            pose: Pose2::new(mx, my, wrap_angle(self.sub_cell.heading(l, k0) + mt)),
            covariance: cov,
            weight: total,
        })
    }

    /// Probability mass within `radius` (m) and `angle` (rad) of a pose.
    pub fn mass_near(&self, pose: &Pose2, radius: f64, angle: f64) -> f64 {
        let l = &self.layout;
        let mut m = 0.0;
        for k in 0..l.n_theta {
            if wrap_angle(self.sub_cell.heading(l, k) - pose.theta).abs() > angle {
                continue;
            }
            for s in &l.spans {
                for i in s.i0..s.i0 + s.len {
                    let (x, y) = self.sub_cell.position(l, k, i as usize, s.j as usize);
                    if (x - pose.x).hypot(y - pose.y) <= radius {
                        m += self.belief[k * l.layer() + s.j as usize * l.nx + i as usize] as f64;
                    }
                }
            }
        }
        m
    }
}
