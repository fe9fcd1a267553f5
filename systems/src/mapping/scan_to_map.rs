//! Scan-to-map SLAM in the spirit of Hector SLAM (Kohlbrecher et al., SSRR 2011, §IV): every scan
//! is matched by Gauss-Newton against the map built so far (a multi-resolution pyramid), and
//! inserted into it once the robot has moved far enough. This is the fix the [Hospital thesis]
//! proposes for its scan-to-scan drift (§6.2, §8: match each scan against the map built so far).
//!
//! Unlike Hector, which has no odometry, the wheel odometry predicts each match's starting guess
//! and (optionally) pulls the result towards it with a prior whose spread grows with the motion
//! since the last scan, so a featureless corridor — where Hector gets lost ([SLAM thesis §4.3.3],
//! MIT corridor) — leaves the estimate on the odometry along the corridor axis instead of
//! sliding. The map frame is the world frame: the SLAM starts at the robot's known start pose.

use super::de_map_match::{DeMapMatcher, match_de};
use super::inverse_model::OccupancyParams;
use super::matched_map::{MatchedMap, base_points};
use crate::core::{Pose2, SimRng, wrap_angle};
use crate::localization::{PoseEstimate, ScanEstimator};
use crate::matching::ProbGrid;
use crate::matching::gauss_newton::{GaussNewtonParams, OdometryPrior};
use crate::sensors::LaserScan;
use std::any::Any;

#[derive(Clone, Debug, PartialEq)]
pub struct ScanToMapConfig {
    /// Map cell size (m).
    pub resolution: f64,
    /// Pyramid levels (each half the resolution of the one below).
    pub levels: usize,
    pub occupancy: OccupancyParams,
    pub matcher: GaussNewtonParams,
    /// Insert a scan into the map once the robot moved this far (m) or turned this much (rad)
    /// since the last insertion (Hector's map_update_distance_thresh / angle_thresh).
    pub map_update_min_d: f64,
    pub map_update_min_a: f64,
    /// Use every n-th beam for matching.
    pub beam_stride: usize,
    /// Odometry prior: standard deviations [x, y (m), θ (rad)] at zero motion and their growth
    /// per metre and per radian of motion; None matches without a prior (Hector proper).
    pub prior: Option<OdometryPriorModel>,
    /// The map frame's pose of the robot at its first scan.
    pub init_pose: Pose2,
    /// Match by differential evolution instead of Gauss-Newton ([`super::de_map_match`]; the
    /// filter's random stream must be given with [`ScanToMapSlam::with_rng`]).
    pub de_matcher: Option<DeMapMatcher>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometryPriorModel {
    pub base_std: [f64; 3],
    /// Extra σ per metre travelled (position and heading) and per radian turned (heading).
    pub per_metre: f64,
    pub per_radian: f64,
}

impl Default for OdometryPriorModel {
    fn default() -> Self {
        OdometryPriorModel {
            base_std: [0.05, 0.05, 0.02],
            per_metre: 0.2,
            per_radian: 0.2,
        }
    }
}

impl Default for ScanToMapConfig {
    fn default() -> Self {
        ScanToMapConfig {
            resolution: 0.05,
            levels: 3,
            occupancy: OccupancyParams::slam(),
            matcher: GaussNewtonParams::default(),
            map_update_min_d: 0.2,
            map_update_min_a: 0.15,
            beam_stride: 2,
            prior: Some(OdometryPriorModel::default()),
            init_pose: Pose2::default(),
            de_matcher: None,
        }
    }
}

impl OdometryPriorModel {
    /// The prior on `predicted` after odometry moved by `delta`.
    pub fn prior(&self, predicted: Pose2, delta: &Pose2) -> OdometryPrior {
        OdometryPrior::from_std(predicted, self.std(delta))
    }

    /// The standard deviations [x, y, θ] after a motion `delta`.
    pub fn std(&self, delta: &Pose2) -> [f64; 3] {
        let d = delta.x.hypot(delta.y);
        let a = delta.theta.abs();
        let s = self.base_std;
        [
            s[0] + self.per_metre * d,
            s[1] + self.per_metre * d,
            s[2] + self.per_metre * d + self.per_radian * a,
        ]
    }
}

#[derive(Clone, Debug)]
pub struct ScanToMapSlam {
    pub config: ScanToMapConfig,
    pub map: MatchedMap,
    pose: Pose2,
    last_odom: Option<Pose2>,
    last_insert: Option<Pose2>,
    pub estimate: Option<PoseEstimate>,
    /// Every scan's (stamp, pose).
    pub path: Vec<(f64, Pose2)>,
    /// Matches run, and those that did not converge.
    pub matches: usize,
    pub unconverged: usize,
    /// The DE matcher's random stream.
    rng: Option<SimRng>,
}

impl ScanToMapSlam {
    pub fn new(config: ScanToMapConfig) -> Self {
        let map = MatchedMap::new(config.resolution, config.occupancy.clone(), config.levels);
        ScanToMapSlam {
            pose: config.init_pose,
            config,
            map,
            last_odom: None,
            last_insert: None,
            estimate: None,
            path: Vec::new(),
            matches: 0,
            unconverged: 0,
            rng: None,
        }
    }

    /// Gives the random stream the DE matcher draws from.
    pub fn with_rng(mut self, rng: SimRng) -> Self {
        self.rng = Some(rng);
        self
    }

    /// The robot's pose in the map frame.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// The map as P(occupied) per cell.
    pub fn prob_map(&self) -> &ProbGrid {
        self.map.prob()
    }

    /// One scan: predict by odometry, match against the map, insert if the robot moved enough.
    pub fn step(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) {
        let delta = match self.last_odom {
            Some(prev) => prev.between(odom),
            None => Pose2::default(),
        };
        self.last_odom = Some(*odom);
        let points = base_points(scan, mount, self.config.beam_stride);
        let t = match (&self.config.de_matcher, self.rng.as_mut()) {
            (Some(de), Some(rng)) => {
                track_de(&self.map, &self.config, de, rng, self.pose, &delta, &points)
            }
            _ => track(&self.map, &self.config, self.pose, &delta, &points),
        };
        if let Some(converged) = t.converged {
            self.matches += 1;
            if !converged {
                self.unconverged += 1;
            }
        }
        self.pose = t.pose;
        if insertion_due(self.last_insert, &self.pose, &self.config) {
            self.map.insert(&self.pose.compose(mount), scan);
            self.last_insert = Some(self.pose);
        }
        self.estimate = Some(PoseEstimate {
            pose: self.pose,
            covariance: t.covariance,
            weight: 1.0,
        });
        self.path.push((scan.stamp, self.pose));
    }
}

/// The outcome of [`track`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Tracked {
    pub pose: Pose2,
    pub covariance: [[f64; 3]; 3],
    /// None when no match ran (empty map or too few points), else whether it converged.
    pub converged: Option<bool>,
}

/// The local tracking step scan-to-map and graph SLAM share: predict `pose` by the odometry
/// motion `delta`, then refine it by Gauss-Newton against `map` (with the odometry prior of
/// `config`); a non-finite result keeps the prediction.
pub(super) fn track(
    map: &MatchedMap,
    config: &ScanToMapConfig,
    pose: Pose2,
    delta: &Pose2,
    points: &[[f32; 2]],
) -> Tracked {
    let predicted = pose.compose(delta);
    let mut out = Tracked {
        pose: predicted,
        covariance: [[0.0; 3]; 3],
        converged: None,
    };
    if points.len() < 3 {
        return out;
    }
    let prior = config.prior.map(|m| m.prior(predicted, delta));
    if let Some(r) = map.match_points(points, predicted, prior, &config.matcher) {
        out.converged = Some(r.converged);
        if r.pose.x.is_finite() && r.pose.y.is_finite() && r.pose.theta.is_finite() {
            out.pose = r.pose;
            out.covariance = r.covariance;
        }
    }
    out
}

/// [`track`] with the DE matcher: the prediction when the map is empty, else DE's pose.
fn track_de(
    map: &MatchedMap,
    config: &ScanToMapConfig,
    de: &DeMapMatcher,
    rng: &mut SimRng,
    pose: Pose2,
    delta: &Pose2,
    points: &[[f32; 2]],
) -> Tracked {
    let predicted = pose.compose(delta);
    let prior = config.prior.map(|m| m.prior(predicted, delta));
    match map.pyramid() {
        Some(pyr) if points.len() >= 3 => {
            match match_de(pyr, points, predicted, prior.as_ref(), de, rng) {
                Some((pose, covariance)) => Tracked {
                    pose,
                    covariance,
                    converged: Some(true),
                },
                None => Tracked {
                    pose: predicted,
                    covariance: [[0.0; 3]; 3],
                    converged: Some(false),
                },
            }
        }
        _ => Tracked {
            pose: predicted,
            covariance: [[0.0; 3]; 3],
            converged: None,
        },
    }
}

/// Whether the robot at `pose` moved far enough from `last` (the pose of the last insertion) for
/// a new one (always true for the first).
pub(super) fn insertion_due(last: Option<Pose2>, pose: &Pose2, config: &ScanToMapConfig) -> bool {
    match last {
        None => true,
        Some(p) => {
            p.distance(pose) >= config.map_update_min_d
                || wrap_angle(p.theta - pose.theta).abs() >= config.map_update_min_a
        }
    }
}

impl ScanEstimator for ScanToMapSlam {
    fn kind(&self) -> &'static str {
        "scan_to_map"
    }

    fn update(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) -> bool {
        self.step(scan, mount, odom);
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn map(&self) -> Option<ProbGrid> {
        (self.map.scans > 0).then(|| self.map.prob().clone())
    }

    fn trajectory(&self) -> Vec<(f64, Pose2)> {
        self.path.clone()
    }

    fn box_clone(&self) -> Box<dyn ScanEstimator> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
