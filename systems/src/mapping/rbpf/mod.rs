//! Rao-Blackwellized particle filter SLAM in the spirit of GMapping (G. Grisetti, C. Stachniss,
//! W. Burgard, "Improved Techniques for Grid Mapping with Rao-Blackwellized Particle Filters",
//! IEEE T-RO 23(1), 2007 ([Grisetti 2007]); [SLAM thesis §3.1, §5.1]), with the parameters
//! that thesis studies under their GMapping names (`particles`, `linearUpdate`, `angularUpdate`,
//! `llsamplerange`, `llsamplestep`, `lasamplerange`, `lasamplestep`) and its defaults.
//!
//! Each particle carries a pose, a weight and its own occupancy map ([`tile_map`], tiles shared
//! between particles until written). A scan is processed once the odometry moved
//! `linear_update` or turned `angular_update` since the last processed one; then, per particle:
//!
//! 1. the pose is moved by the odometry motion with noise drawn from the odometry motion model
//!    (Probabilistic Robotics §5.4; GMapping's srr/srt/str/stt as its α's);
//! 2. the scan is matched against the particle's map from there ([`scan_match::optimize`],
//!    climbing the proposal's target τ below);
//! 3. the improved proposal is fitted around the match ([`proposal::fit`]): τ(x) = p(z|m,x)^(1/ogain)
//!    · p(x | x', u), the new pose drawn from it, the weight multiplied by η (§IV); a match that
//!    explains fewer than `min_matched` of the beams is distrusted: the particle keeps the
//!    motion sample and is weighted by the scan's likelihood there (GMapping's minimumScore).
//!
//! Then the particles are resampled (low-variance) when N_eff = 1 / Σ w̃² falls below
//! `resample_threshold` · N (§V, adaptive resampling), and the scan is inserted into every
//! particle's map at its pose. Between processed scans the published pose is the best particle's
//! carried by the odometry. The trajectory of the run is the best particle's path: its poses at
//! the processed scans, the scans between them placed by odometry.

pub mod proposal;
pub mod scan_match;
#[cfg(test)]
mod tests;
pub mod tile_map;

use super::insert::{Beam, LogOddsModel};
use super::inverse_model::{OccupancyParams, log_odds};
use super::matched_map::base_points;
use crate::core::moments::weighted_scatter;
use crate::core::{Pose2, SimRng, wrap_angle};
use crate::localization::mcl::resample::low_variance_indices;
use crate::localization::motion_model::{OdometryMotionModel, moved_enough};
use crate::localization::{PoseEstimate, ScanEstimator};
use crate::matching::ProbGrid;
use crate::sensors::LaserScan;
use proposal::SampleGrid;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use scan_match::{ClimbParams, ObservationModel, ScanPoints};
use std::any::Any;
use tile_map::TileMap;

#[derive(Clone, Debug, PartialEq)]
pub struct RbpfConfig {
    /// Number of particles (GMapping `particles`).
    pub particles: usize,
    /// Process a scan once the robot moved this far (m) / turned this much (rad) since the last
    /// processed one (GMapping `linearUpdate`, `angularUpdate`).
    pub linear_update: f64,
    pub angular_update: f64,
    /// The proposal's sampling grid (`llsamplerange`, `llsamplestep`, `lasamplerange`,
    /// `lasamplestep`).
    pub sample: SampleGrid,
    /// Map cell size (m).
    pub resolution: f64,
    pub occupancy: OccupancyParams,
    pub motion: OdometryMotionModel,
    pub observation: ObservationModel,
    /// The scan's likelihood enters the proposal and the weights to the power 1/ogain (GMapping
    /// `ogain`): the beams are not independent, and without it one scan decides everything.
    /// GMapping's 3 is for its likelihood; with this one (half the beams of an LMS100 at
    /// sigma 0.3) weights that sharp left N_eff near 1 after a few updates, and the
    /// resampling kept whichever particle a corridor's ambiguity favoured (corridor test drive,
    /// 30 particles: ATE 0.64 m with 3, 0.036 m with 30).
    pub ogain: f64,
    pub climb: ClimbParams,
    /// Use every n-th beam for matching and weighting (GMapping `lskip` + 1).
    pub beam_stride: usize,
    /// Resample when N_eff < this × particles (GMapping `resampleThreshold`).
    pub resample_threshold: f64,
    /// A match explaining fewer than this fraction of the beams is not trusted.
    pub min_matched: f64,
    /// The map frame's pose of the robot at its first scan.
    pub init_pose: Pose2,
}

impl Default for RbpfConfig {
    /// The values [SLAM thesis §5.1] lists (GMapping's ROS defaults) where it lists them.
    fn default() -> Self {
        RbpfConfig {
            particles: 30,
            linear_update: 1.0,
            angular_update: 0.5,
            sample: SampleGrid {
                llsamplerange: 0.01,
                llsamplestep: 0.01,
                lasamplerange: 0.005,
                lasamplestep: 0.005,
            },
            resolution: 0.05,
            occupancy: OccupancyParams::slam(),
            // σ of 10 % of a rotation, 4.5 % of a translation, 0.045 rad per metre driven. The
            // ROS defaults of GMapping (srr 0.1, srt 0.2, str 0.1, stt 0.2, as σ per unit of
            // motion: α = 0.01, 0.04, 0.01, 0.04) let the particles slide along featureless
            // corridors (corridor test drive: ATE 0.70 m against 0.036 m with these)
            motion: OdometryMotionModel {
                alpha1: 0.01,
                alpha2: 0.002,
                alpha3: 0.002,
                alpha4: 0.002,
            },
            observation: ObservationModel {
                sigma: 0.3,
                l_max: log_odds(OccupancyParams::slam().p_max),
            },
            ogain: 30.0,
            climb: ClimbParams {
                linear_delta: 0.05,
                angular_delta: 0.05,
                refinements: 5,
            },
            beam_stride: 2,
            resample_threshold: 0.5,
            min_matched: 0.3,
            init_pose: Pose2::default(),
        }
    }
}

#[derive(Clone, Debug)]
struct Particle {
    pose: Pose2,
    /// log weight (normalised so the largest is 0 after each update).
    log_w: f64,
    map: TileMap,
    /// The pose at every processed scan.
    path: Vec<Pose2>,
}

/// Counters of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RbpfStats {
    /// Scans processed (after the first).
    pub updates: usize,
    pub resamples: usize,
    /// Particle matches that explained too few beams.
    pub weak_matches: usize,
    /// N_eff after the latest update.
    pub n_eff: f64,
}

#[derive(Clone, Debug)]
pub struct RbpfSlam {
    pub config: RbpfConfig,
    model: LogOddsModel,
    particles: Vec<Particle>,
    rng: SimRng,
    /// Odometry at every processed scan.
    update_odom: Vec<Pose2>,
    /// Every scan: stamp, odometry, index of the processed scan at or before it.
    scans: Vec<(f64, Pose2, usize)>,
    best: usize,
    estimate: Option<PoseEstimate>,
    pub stats: RbpfStats,
}

impl RbpfSlam {
    pub fn new(config: RbpfConfig, rng: SimRng) -> Self {
        let n = config.particles.max(1);
        let map = TileMap::new(config.resolution);
        RbpfSlam {
            model: LogOddsModel::new(&config.occupancy),
            particles: vec![
                Particle {
                    pose: config.init_pose,
                    log_w: 0.0,
                    map,
                    path: Vec::new(),
                };
                n
            ],
            config,
            rng,
            update_odom: Vec::new(),
            scans: Vec::new(),
            best: 0,
            estimate: None,
            stats: RbpfStats::default(),
        }
    }

    /// The best particle's map.
    pub fn best_map(&self) -> &TileMap {
        &self.particles[self.best].map
    }

    /// Every particle's current pose.
    pub fn poses(&self) -> Vec<Pose2> {
        self.particles.iter().map(|p| p.pose).collect()
    }

    /// One scan taken at odometry pose `odom`.
    pub fn step(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) {
        match self.update_odom.last().copied() {
            None => self.first_scan(scan, mount, odom),
            Some(last)
                if moved_enough(
                    &last,
                    odom,
                    self.config.linear_update,
                    self.config.angular_update,
                ) =>
            {
                self.process(scan, mount, &last, odom)
            }
            Some(last) => {
                let pose = self.particles[self.best].pose.compose(&last.between(odom));
                self.publish(pose);
            }
        }
        self.scans
            .push((scan.stamp, *odom, self.update_odom.len() - 1));
    }

    fn first_scan(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) {
        let mut beams = Vec::new();
        let first = &mut self.particles[0];
        first.path.push(first.pose);
        let sensor = first.pose.compose(mount);
        first.map.insert(
            &sensor,
            scan,
            &self.config.occupancy,
            &self.model,
            &mut beams,
        );
        // every particle starts from the same map: shared tiles
        let first = first.clone();
        self.particles.iter_mut().for_each(|p| *p = first.clone());
        self.update_odom.push(*odom);
        self.publish(self.particles[0].pose);
    }

    fn process(&mut self, scan: &LaserScan, mount: &Pose2, last: &Pose2, odom: &Pose2) {
        let c = &self.config;
        let delta = c.motion.delta(last, odom);
        // draws in particle order from the filter's one stream: the result does not depend on
        // how the particles are spread over threads
        let draws: Vec<(Pose2, [f64; 3])> = self
            .particles
            .iter()
            .map(|p| {
                let moved = c.motion.sample(&delta, &p.pose, &mut self.rng);
                let z = [(); 3].map(|_| StandardNormal.sample(&mut self.rng));
                (moved, z)
            })
            .collect();
        let points = base_points(scan, mount, c.beam_stride);
        let view = ScanPoints { points: &points };
        let min_matched = (c.min_matched * points.len() as f64).ceil() as usize;
        let weak: usize = self
            .particles
            .par_iter_mut()
            .zip(draws.par_iter())
            .map(|(p, (moved, z))| {
                let (weak, pose, log_eta) = propose(p, moved, z, &view, last, odom, min_matched, c);
                p.pose = pose;
                p.log_w += log_eta;
                p.path.push(pose);
                weak as usize
            })
            .sum();
        self.stats.weak_matches += weak;
        self.stats.updates += 1;
        self.reweight_and_resample();
        let (params, model) = (&self.config.occupancy, &self.model);
        self.particles
            .par_iter_mut()
            .for_each_init(Vec::<Beam>::new, |beams, p| {
                p.map
                    .insert(&p.pose.compose(mount), scan, params, model, beams);
            });
        self.update_odom.push(*odom);
        self.publish(self.particles[self.best].pose);
    }

    /// Normalises the weights, picks the best particle, resamples when N_eff is low.
    fn reweight_and_resample(&mut self) {
        let w = self.relative_weights();
        let (sum, sum2) = (w.iter().sum::<f64>(), w.iter().map(|x| x * x).sum::<f64>());
        self.stats.n_eff = sum * sum / sum2;
        self.best = (0..w.len()).fold(0, |b, i| if w[i] > w[b] { i } else { b });
        let n = self.particles.len();
        if self.stats.n_eff < self.config.resample_threshold * n as f64 {
            let idx = low_variance_indices(&w, n, self.rng.random::<f64>());
            let old = std::mem::take(&mut self.particles);
            self.particles = idx.iter().map(|&i| old[i].clone()).collect();
            self.particles.iter_mut().for_each(|p| p.log_w = 0.0);
            // the best particle has weight ≥ total / n, so it survives
            self.best = idx.iter().position(|&i| i == self.best).unwrap_or(0);
            self.stats.resamples += 1;
        } else {
            for (p, wi) in self.particles.iter_mut().zip(&w) {
                p.log_w = wi.ln();
            }
        }
    }

    /// Publishes `pose` with the spread of the particles (weighted) as its covariance.
    fn publish(&mut self, pose: Pose2) {
        let best = self.particles[self.best].pose;
        let spread = self
            .particles
            .iter()
            .zip(self.relative_weights())
            .map(|(p, w)| {
                let d = p.pose;
                (
                    [d.x - best.x, d.y - best.y, wrap_angle(d.theta - best.theta)],
                    w,
                )
            });
        self.estimate = Some(PoseEstimate {
            pose,
            covariance: weighted_scatter(spread),
            weight: 1.0,
        });
    }

    /// The weights relative to the largest (all 1 when every particle is impossible: the
    /// filter starts over evenly).
    fn relative_weights(&self) -> Vec<f64> {
        let top = self
            .particles
            .iter()
            .map(|p| p.log_w)
            .fold(f64::NEG_INFINITY, f64::max);
        if !top.is_finite() {
            return vec![1.0; self.particles.len()];
        }
        self.particles
            .iter()
            .map(|p| (p.log_w - top).exp())
            .collect()
    }
}

/// One particle's move: match from the motion sample, fit the proposal, draw from it. Returns
/// (weak match, new pose, log weight factor).
#[allow(clippy::too_many_arguments)]
fn propose(
    p: &Particle,
    moved: &Pose2,
    z: &[f64; 3],
    scan: &ScanPoints,
    odom0: &Pose2,
    odom1: &Pose2,
    min_matched: usize,
    c: &RbpfConfig,
) -> (bool, Pose2, f64) {
    let obs = &c.observation;
    // the motion term's spread is floored so a short motion does not make it a Dirac
    let floor = (
        c.sample.llsamplestep.max(0.005),
        c.sample.lasamplestep.max(0.002),
    );
    let log_tau = |x: &Pose2| {
        let obs_ll = scan_match::evaluate(&p.map, x, scan, obs).log_likelihood / c.ogain;
        let motion = c.motion.probability(odom0, odom1, &p.pose, x, floor);
        obs_ll + motion.max(1e-300).ln()
    };
    let (matched, _) = scan_match::optimize(moved, &c.climb, log_tau);
    if scan_match::evaluate(&p.map, &matched, scan, obs).matched < min_matched {
        return (true, *moved, log_tau(moved));
    }
    let fitted = proposal::fit(&matched, &c.sample, log_tau);
    (false, fitted.sample(*z), fitted.log_eta)
}

impl ScanEstimator for RbpfSlam {
    fn kind(&self) -> &'static str {
        "rbpf"
    }

    fn update(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) -> bool {
        self.step(scan, mount, odom);
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn map(&self) -> Option<ProbGrid> {
        (!self.update_odom.is_empty()).then(|| self.best_map().to_prob_grid())
    }

    /// The best particle's path, scans between processed ones placed by odometry.
    fn trajectory(&self) -> Vec<(f64, Pose2)> {
        let path = &self.particles[self.best].path;
        self.scans
            .iter()
            .map(|&(t, odom, k)| (t, path[k].compose(&self.update_odom[k].between(&odom))))
            .collect()
    }

    fn box_clone(&self) -> Box<dyn ScanEstimator> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
