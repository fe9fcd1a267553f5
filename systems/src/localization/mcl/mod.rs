//! Monte Carlo localization at the level of ROS AMCL (Fox, Burgard, Dellaert & Thrun 1999;
//! Probabilistic Robotics Table 8.2 with the refinements of Tables 8.3 and 8.4):
//!
//! - particles as contiguous arrays (x, y, θ, weight);
//! - prediction by the odometry motion model ([`super::motion_model`]), applied only once the
//!   odometry has moved `update_min_d` or turned `update_min_a` since the last update;
//! - correction by the likelihood field (default) or the beam model on `max_beams` beams
//!   ([`sensor_model`]), weighed in parallel;
//! - resampling only when N_eff = 1/Σw² < N/2 (Doucet et al. 2000; GMapping's adaptive
//!   resampling) or when random particles are due; low-variance, KLD-adaptive count between a
//!   minimum and a maximum ([`resample`]);
//! - random-particle injection from short- and long-term averages of the measurement likelihood
//!   (Augmented MCL), so a kidnapped robot is found again; injected particles, and a share of
//!   the particles at every update while a globally started filter has not settled, are drawn
//!   from poses that explain the scan (the dual proposal of Mixture MCL, [`injection`]);
//! - global initialisation uniformly over free space, or a Gaussian around a given pose;
//! - estimate: weighted mean and covariance of the dominant cluster ([`cluster`]).

pub mod cluster;
pub mod field_kernel;
pub mod injection;
pub mod resample;
pub mod sensor_model;

pub use cluster::PoseEstimate;
pub use resample::{BinSize, CountLimits, kld_bound, normal_quantile};
pub use sensor_model::{BeamSubset, LaserModelParams};

use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::motion_model::{OdometryMotionModel, moved_enough};
use crate::core::{Pose2, SimRng, wrap_angle};
use rand::{Rng, RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Which laser model weighs the particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaserModel {
    LikelihoodField,
    Beam,
}

/// How the particles start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialBelief {
    /// Uniform over the free cells of the map, uniform heading.
    Global,
    /// Gaussian around a pose with standard deviations (m, m, rad).
    Gaussian { pose: Pose2, sd: [f64; 3] },
}

/// Parameters, named after AMCL's where there is one.
#[derive(Clone, Debug, PartialEq)]
pub struct MclConfig {
    pub min_particles: usize,
    pub max_particles: usize,
    /// KLD-sampling on (count between min and max) or off (always max).
    pub kld: bool,
    pub kld_err: f64,
    /// Probability δ's complement (AMCL `kld_z` 0.99: the upper 1 % quantile).
    pub kld_z: f64,
    pub update_min_d: f64,
    pub update_min_a: f64,
    /// Resample every this many updates (AMCL's `resample_interval`), or, with 0, only when
    /// the weights have degenerated (N_eff < N/2). AMCL's weights, 1 + Σ pz³, are flat, so
    /// N_eff rarely falls below N/2: gated resampling keeps the cloud (and the KLD count) as
    /// wide as motion noise makes it, resampling every update or two lets it shrink.
    pub resample_interval: u64,
    pub max_beams: usize,
    pub model: LaserModel,
    pub laser: LaserModelParams,
    pub motion: OdometryMotionModel,
    /// Augmented MCL averages (0 disables injection).
    pub recovery_alpha_slow: f64,
    pub recovery_alpha_fast: f64,
    /// Injection starts once w_fast / w_slow falls below this ratio: the probability is
    /// max(0, 1 − (w_fast / w_slow) / ratio). 1 is Table 8.3's rule, which also injects on the
    /// ordinary ups and downs of the scan fit while tracking; below 1 only a real drop counts.
    pub recovery_ratio: f64,
    /// Where injected particles come from: 0 draws them uniformly over free space (AMCL);
    /// n > 0 draws them from poses that explain the current scan, found by a search with n
    /// candidates per round ([`injection`]), so a kidnapped robot is found in a large building
    /// within seconds.
    pub injection_candidates: usize,
    /// Every this many updates (0: never) the scan proposal challenges the filter: when its best
    /// pose explains the scan `challenge_ratio` times better than the filter's best particle,
    /// `challenge_fraction` of the particles are drawn from the proposal at the next
    /// resampling. A filter that converged to a look-alike place is pulled out of it this way:
    /// the weight averages cannot see a wrong place that fits the scans almost as well. A
    /// filter started globally draws from the proposal at every update until it settles (the
    /// dual proposal of Mixture MCL, poses explaining the scan better than its own): until its
    /// dominant cluster is tight and holds most of the weight.
    pub challenge_every: u64,
    pub challenge_ratio: f64,
    pub challenge_fraction: f64,
    pub init: InitialBelief,
    pub bins: BinSize,
}

impl Default for MclConfig {
    fn default() -> Self {
        MclConfig {
            min_particles: 500,
            max_particles: 5000,
            kld: true,
            kld_err: 0.01,
            kld_z: 0.99,
            update_min_d: 0.2,
            update_min_a: std::f64::consts::PI / 6.0,
            resample_interval: 0,
            max_beams: 60,
            model: LaserModel::LikelihoodField,
            laser: LaserModelParams::default(),
            motion: OdometryMotionModel::default(),
            recovery_alpha_slow: 0.001,
            recovery_alpha_fast: 0.1,
            recovery_ratio: 0.7,
            injection_candidates: 20_000,
            // every 4 m of travel at 0.2 m per update: the challenge is most of a tracking
            // filter's cost, and one every 2 m held no better
            challenge_every: 20,
            challenge_ratio: 1.1,
            challenge_fraction: 0.1,
            init: InitialBelief::Global,
            bins: BinSize::default(),
        }
    }
}

impl MclConfig {
    /// ROS AMCL's parameter defaults: 100 to 5000 particles, 30 beams, resampling every second
    /// update, no random particles (its recovery averages are 0) and therefore neither the scan
    /// proposal nor its challenge, which AMCL does not have.
    pub fn amcl() -> Self {
        MclConfig {
            min_particles: 100,
            max_particles: 5000,
            resample_interval: 2,
            max_beams: 30,
            recovery_alpha_slow: 0.0,
            recovery_alpha_fast: 0.0,
            injection_candidates: 0,
            challenge_every: 0,
            ..MclConfig::default()
        }
    }
}

/// The heaviest particles a challenge compares the scan proposal with.
const CHALLENGE_TOP: usize = 256;

/// The best poses of a challenge kept as its contender.
const CONTENDER_POSES: usize = 32;

/// Updates in a row a contender must explain the scan better than the filter before particles
/// are drawn from it. One scan cannot tell a place from its look-alike (the hospital's wards
/// repeat every 5.85 m and its wings every 27 m): a single better fit there, from a person in
/// view or the noise, pulled a filter that was tracking onto the look-alike. A contender that
/// keeps winning as the robot moves on is a different matter: the filter is at the wrong place.
pub const CONTENDER_WINS: u32 = 4;

/// The estimate's position spread (m) under which the filter counts as settled on a place…
pub const SETTLED_SPREAD_M: f64 = 0.5;

/// …and the share of the weight its cluster must hold. A cluster can be tight long before the
/// scans have told it from its look-alikes: a global filter's first tight cluster held a sixth
/// of the weight, the rest sat on look-alike wards, and counting that as settled stopped the
/// dual proposal after three to five updates, leaving the resampling to pick a ward by chance.
pub const SETTLED_SHARE: f64 = 0.8;

/// A challenger followed over updates: its poses move with the odometry (noise-free).
#[derive(Clone, Debug)]
struct Contender {
    poses: Vec<(f64, f64, f64)>,
    /// The odometry pose they were last moved to.
    odom: Pose2,
    wins: u32,
}

/// Particles per motion-sampling work item (each seeded from the filter's stream in order).
const MOTION_CHUNK: usize = 1024;

/// The particle filter.
#[derive(Clone, Debug)]
pub struct Mcl {
    pub config: MclConfig,
    pub xs: Vec<f64>,
    pub ys: Vec<f64>,
    pub ths: Vec<f64>,
    /// Normalised weights.
    pub w: Vec<f64>,
    /// `[θ, sin θ, cos θ]` per particle as the last likelihood-field weighing computed them,
    /// carried through resampling: the cluster reuses an entry whose θ is the particle's to
    /// the bit (empty when the beam model weighed).
    trig: Vec<[f64; 3]>,
    rng: SimRng,
    w_slow: f64,
    w_fast: f64,
    /// Updates that fed w_slow and w_fast.
    averaged: u64,
    last_odom: Option<Pose2>,
    table: Option<[f32; 256]>,
    /// Updates done (a scan consumed after enough motion).
    pub updates: u64,
    /// Resamplings done.
    pub resamplings: u64,
    /// A place the scan proposal found to explain a scan better than the filter, followed
    /// until it has done so for [`CONTENDER_WINS`] updates in a row (or dropped).
    contender: Option<Contender>,
    /// The dominant cluster's estimate, computed when first asked for: a global filter's
    /// first cloud covers the whole floor (100 000 particles take tens of milliseconds), and
    /// its first update usually comes before anyone asks.
    estimate: OnceLock<Option<PoseEstimate>>,
}

impl Mcl {
    pub fn new(config: MclConfig, map: &LocalizationMap, mut rng: SimRng) -> Self {
        let n = config.max_particles.max(1);
        let poses: Vec<[f64; 3]> = match config.init {
            InitialBelief::Global => map.random_free_poses(n, &mut || rng.random::<f64>()),
            InitialBelief::Gaussian { pose, sd } => (0..n)
                .map(|_| {
                    let mut g = || -> f64 { StandardNormal.sample(&mut rng) };
                    [
                        pose.x + sd[0] * g(),
                        pose.y + sd[1] * g(),
                        wrap_angle(pose.theta + sd[2] * g()),
                    ]
                })
                .collect(),
        };
        let xs = poses.iter().map(|p| p[0]).collect();
        let ys = poses.iter().map(|p| p[1]).collect();
        let ths = poses.iter().map(|p| p[2]).collect();
        Mcl {
            config,
            xs,
            ys,
            ths,
            w: vec![1.0 / n as f64; n],
            trig: Vec::new(),
            rng,
            w_slow: 0.0,
            w_fast: 0.0,
            averaged: 0,
            last_odom: None,
            table: None,
            updates: 0,
            resamplings: 0,
            contender: None,
            estimate: OnceLock::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.w.len()
    }

    pub fn is_empty(&self) -> bool {
        self.w.is_empty()
    }

    fn cluster(&self) -> Option<PoseEstimate> {
        cluster::dominant_cluster_with_trig(
            &self.xs,
            &self.ys,
            &self.ths,
            &self.trig,
            &self.w,
            &self.config.bins,
        )
    }

    /// Computes the estimate of the particles as they are now, if nobody has asked for it
    /// since the last correction: they are about to change, and the estimate stands for the
    /// set as it was built or last corrected.
    fn settle_estimate(&mut self) {
        if self.estimate.get().is_none() {
            let e = self.cluster();
            self.estimate = OnceLock::from(e);
        }
    }

    /// Moves every particle by the odometry motion `from` → `to`.
    pub fn apply_motion(&mut self, from: &Pose2, to: &Pose2) {
        self.settle_estimate();
        let d = self.config.motion.delta(from, to);
        let model = self.config.motion;
        let seeds: Vec<u64> = (0..self.len().div_ceil(MOTION_CHUNK))
            .map(|_| self.rng.next_u64())
            .collect();
        self.xs
            .par_chunks_mut(MOTION_CHUNK)
            .zip(self.ys.par_chunks_mut(MOTION_CHUNK))
            .zip(self.ths.par_chunks_mut(MOTION_CHUNK))
            .zip(seeds)
            .for_each(|(((x, y), t), seed)| {
                let mut rng = SimRng::seed_from_u64(seed);
                model.sample_slices(&d, x, y, t, &mut rng);
            });
    }

    /// The likelihood-field table of the configured laser model for scans of `range_max`.
    fn field_table(&mut self, map: &LocalizationMap, range_max: f32) -> [f32; 256] {
        *self.table.get_or_insert_with(|| {
            sensor_model::likelihood_table(&map.field, &self.config.laser, range_max as f64)
        })
    }

    /// Multiplies the weights by the scan's likelihood; returns the mean likelihood factor.
    pub fn weigh(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> f64 {
        self.settle_estimate();
        self.weigh_particles(map, beams)
    }

    /// [`Mcl::weigh`] in a correction, which replaces the estimate afterwards.
    fn weigh_particles(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> f64 {
        let old_total: f64 = self.w.iter().sum();
        match self.config.model {
            LaserModel::LikelihoodField => {
                let table = self.field_table(map, beams.range_max);
                let points = beams.returns();
                self.trig.resize(self.ths.len(), [f64::NAN; 3]);
                sensor_model::weigh_likelihood_field_keeping_trig(
                    &map.field,
                    &table,
                    &points,
                    [&self.xs, &self.ys, &self.ths],
                    &mut self.w,
                    &mut self.trig,
                );
            }
            LaserModel::Beam => sensor_model::weigh_beam_model(
                &map.rays,
                &self.config.laser,
                beams,
                &self.xs,
                &self.ys,
                &self.ths,
                &mut self.w,
            ),
        }
        // w was normalised: Σ new w = Σ w_old·p = the weighted mean of p
        let total: f64 = self.w.iter().sum();
        if total > 0.0 && total.is_finite() {
            self.w.iter_mut().for_each(|w| *w /= total);
        } else {
            let n = self.len() as f64;
            self.w.iter_mut().for_each(|w| *w = 1.0 / n);
        }
        total / old_total.max(f64::MIN_POSITIVE)
    }

    /// Consumes a scan taken when the odometry read `odom`. Returns true if the filter updated
    /// (the first scan, or enough motion since the last update).
    pub fn update(&mut self, map: &LocalizationMap, beams: &BeamSubset, odom: &Pose2) -> bool {
        MapLocalizer::predict(self, odom) && MapLocalizer::correct(self, map, beams)
    }

    /// The poses injected particles are drawn from (see [`MclConfig::injection_candidates`]);
    /// None when nothing is injected or the proposal is off.
    fn injection_pool(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
        p_inject: f64,
    ) -> Option<Vec<(f64, f64, f64)>> {
        let n = self.config.injection_candidates;
        if p_inject <= 0.0 || n == 0 || beams.is_empty() {
            return None;
        }
        let table = self.field_table(map, beams.range_max);
        let pool = injection::scan_proposal(
            map,
            &self.config.laser,
            &table,
            &beams.returns(),
            beams.range_max,
            n,
            n / injection::MCL_REFINE_FRACTION,
            &mut self.rng,
        );
        (!pool.is_empty()).then_some(pool)
    }

    /// The poses among `candidates` that explain the scan more than `ratio` times as well as
    /// the filter's best explanation of it (the best of its heaviest particles), best first.
    /// Strictly more: the field's scores saturate once every endpoint lies on an obstacle
    /// cell, so a refined pose at a look-alike place often ties with the filter's best to the
    /// bit, and a tie is no evidence against the filter's place.
    fn better_than_filter(
        &self,
        map: &LocalizationMap,
        table: &[f32; 256],
        points: &[[f32; 2]],
        candidates: &[(f64, f64, f64)],
        ratio: f64,
    ) -> Vec<(f64, f64, f64)> {
        let mut top: Vec<usize> = (0..self.len()).collect();
        let k = CHALLENGE_TOP.min(top.len());
        if k == 0 || candidates.is_empty() {
            return Vec::new();
        }
        top.select_nth_unstable_by(k - 1, |&a, &b| {
            self.w[b].total_cmp(&self.w[a]).then(a.cmp(&b))
        });
        top.truncate(k);
        let m = candidates.len();
        let pick = |own: &[f64], get: fn(&(f64, f64, f64)) -> f64| -> Vec<f64> {
            candidates
                .iter()
                .map(get)
                .chain(top.iter().map(|&i| own[i]))
                .collect()
        };
        let xs = pick(&self.xs, |p| p.0);
        let ys = pick(&self.ys, |p| p.1);
        let ths = pick(&self.ths, |p| p.2);
        let mut score = vec![1.0f64; xs.len()];
        sensor_model::weigh_likelihood_field(&map.field, table, points, &xs, &ys, &ths, &mut score);
        let own = score[m..].iter().copied().fold(f64::MIN_POSITIVE, f64::max);
        let bar = own * ratio;
        let mut better: Vec<(f64, (f64, f64, f64))> = candidates
            .iter()
            .zip(&score[..m])
            .filter(|&(_, &s)| s > bar)
            .map(|(p, &s)| (s, *p))
            .collect();
        better.sort_by(|a, b| b.0.total_cmp(&a.0));
        better.into_iter().map(|(_, p)| p).collect()
    }

    /// Wins in a row a contender needs: one while the filter has not settled on a place (its
    /// estimate's spread is over [`SETTLED_SPREAD_M`] or its cluster holds under
    /// [`SETTLED_SHARE`] of the weight, as during global localization), so the search is not
    /// slowed; [`CONTENDER_WINS`] once it has.
    fn wins_needed(&self) -> u32 {
        match self.estimate() {
            Some(e) if e.position_spread() <= SETTLED_SPREAD_M && e.weight >= SETTLED_SHARE => {
                CONTENDER_WINS
            }
            _ => 1,
        }
    }

    /// The challenge of [`MclConfig::challenge_every`] as a sequential test: every
    /// `challenge_every` updates (while no contender is followed) the scan proposal looks for
    /// poses that explain the scan markedly better than the filter; the best become the
    /// contender, which moves with the odometry and must win again at each following update.
    /// After [`CONTENDER_WINS`] wins in a row its poses are the pool particles are drawn from;
    /// one loss drops it.
    fn challenge(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
    ) -> Option<Vec<(f64, f64, f64)>> {
        let every = self.config.challenge_every;
        let n = self.config.injection_candidates;
        let odom = self.last_odom?;
        if every == 0 || n == 0 || beams.is_empty() {
            return None;
        }
        let table = self.field_table(map, beams.range_max);
        let points = beams.returns();
        if let Some(mut c) = self.contender.take() {
            let step = c.odom.between(&odom);
            let moved: Vec<(f64, f64, f64)> = c
                .poses
                .iter()
                .map(|&(x, y, th)| {
                    let p = Pose2::new(x, y, th).compose(&step);
                    (p.x, p.y, p.theta)
                })
                .collect();
            let ratio = self.config.challenge_ratio;
            let better = self.better_than_filter(map, &table, &points, &moved, ratio);
            if better.is_empty() {
                return None; // the filter explains this scan as well: dropped
            }
            c.wins += 1;
            if c.wins >= self.wins_needed() {
                return Some(better);
            }
            c.poses = better;
            c.odom = odom;
            self.contender = Some(c);
            return None;
        }
        let searching = self.searching();
        if !searching && self.updates % every != every - 1 {
            return None;
        }
        let pool = injection::scan_proposal(
            map,
            &self.config.laser,
            &table,
            &points,
            beams.range_max,
            n,
            n / injection::MCL_REFINE_FRACTION,
            &mut self.rng,
        );
        if searching {
            // Mixture MCL's dual proposal [Thrun 2001, §4], at every update: poses drawn from
            // the scan, weighed by a belief that is still about uniform over the places. While
            // the cloud's heaviest cluster sits at a look-alike, the true place gets particles
            // again at every scan that fits it better, whatever the cloud's first draws held.
            let drawn = self.better_than_filter(map, &table, &points, &pool, 1.0);
            return (!drawn.is_empty()).then_some(drawn);
        }
        let ratio = self.config.challenge_ratio;
        let mut better = self.better_than_filter(map, &table, &points, &pool, ratio);
        if !better.is_empty() && self.wins_needed() <= 1 {
            return Some(better);
        }
        better.truncate(CONTENDER_POSES);
        if !better.is_empty() {
            self.contender = Some(Contender {
                poses: better,
                odom,
                wins: 1,
            });
        }
        None
    }

    /// Whether the filter is still searching the floor: started globally and not yet settled on
    /// a place (see [`Mcl::wins_needed`]). A filter started
    /// around a known pose is not: its belief is far from uniform over the places the scan
    /// proposal finds, and drawing from them pulled its estimate along a corridor.
    fn searching(&self) -> bool {
        self.config.init == InitialBelief::Global && self.wins_needed() <= 1
    }

    fn resample(
        &mut self,
        map: &LocalizationMap,
        p_inject: f64,
        pool: Option<&Vec<(f64, f64, f64)>>,
    ) {
        let limits = CountLimits {
            min: self.config.min_particles,
            max: self.config.max_particles,
            kld: self.config.kld,
            epsilon: self.config.kld_err,
            z: normal_quantile(self.config.kld_z),
        };
        resample::resample(
            &mut self.xs,
            &mut self.ys,
            &mut self.ths,
            &mut self.trig,
            &mut self.w,
            &limits,
            &self.config.bins,
            p_inject,
            &mut self.rng,
            |u| match pool {
                Some(p) => p[((u() * p.len() as f64) as usize).min(p.len() - 1)],
                None => map.random_free_pose(u),
            },
        );
        self.resamplings += 1;
    }

    /// Whether this update resamples (see [`MclConfig::resample_interval`]).
    fn resampling_due(&self, n_eff: f64) -> bool {
        match self.config.resample_interval {
            0 => n_eff < self.len() as f64 / 2.0,
            k => (self.updates + 1).is_multiple_of(k),
        }
    }

    /// The odometry pose of the last update.
    pub fn last_odometry(&self) -> Option<Pose2> {
        self.last_odom
    }
}

/// [`Mcl::update`] in two halves: the motion gate and motion sampling, then weighing, injection,
/// resampling and the estimate.
impl MapLocalizer for Mcl {
    fn kind(&self) -> &'static str {
        "mcl"
    }

    fn max_beams(&self) -> usize {
        self.config.max_beams
    }

    fn due(&self, odom: &Pose2) -> bool {
        self.last_odom.is_none_or(|last| {
            moved_enough(
                &last,
                odom,
                self.config.update_min_d,
                self.config.update_min_a,
            )
        })
    }

    fn predict(&mut self, odom: &Pose2) -> bool {
        if !self.due(odom) {
            return false;
        }
        if let Some(last) = self.last_odom {
            self.apply_motion(&last, odom);
        }
        self.last_odom = Some(*odom);
        true
    }

    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool {
        if beams.is_empty() {
            return true;
        }
        let mean_p = self.weigh_particles(map, beams);
        // Augmented MCL: the likelihood is normalised per beam count so α's mean the same for
        // every laser
        let avg = mean_p.max(f64::MIN_POSITIVE);
        // Both averages start as the plain mean of the updates so far (an exponential average
        // that starts at the first value stays for ~1/α updates near it: a first update of a
        // spread-out filter fits poorly, and w_slow would then sit too low to ever trigger).
        self.averaged += 1;
        let early = 1.0 / self.averaged as f64;
        let (a_slow, a_fast) = (
            self.config.recovery_alpha_slow.max(early),
            self.config.recovery_alpha_fast.max(early),
        );
        self.w_slow += a_slow * (avg - self.w_slow);
        self.w_fast += a_fast * (avg - self.w_fast);
        let p_inject = if self.config.recovery_alpha_slow > 0.0 {
            let ratio = self.w_fast / self.w_slow;
            (1.0 - ratio / self.config.recovery_ratio).max(0.0)
        } else {
            0.0
        };
        let n_eff = 1.0 / self.w.iter().map(|w| w * w).sum::<f64>();
        let challenger = if p_inject > 0.0 {
            None
        } else {
            self.challenge(map, beams)
        };

        if let Some(pool) = challenger {
            self.resample(map, self.config.challenge_fraction, Some(&pool));
        } else if self.resampling_due(n_eff) || p_inject > 0.0 {
            // Unlike AMCL, the averages are not reset after an injection (Table 8.3 has no
            // reset): AMCL's reset ends the injection after one burst of a few percent, which
            // rarely finds a kidnapped robot; here random particles keep coming while the
            // scans fit worse than they used to.
            let pool = self.injection_pool(map, beams, p_inject);
            self.resample(map, p_inject, pool.as_ref());
        }
        self.updates += 1;
        self.estimate = OnceLock::from(self.cluster());
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        *self.estimate.get_or_init(|| self.cluster())
    }

    fn box_clone(&self) -> Box<dyn MapLocalizer> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

#[cfg(test)]
mod tests;
