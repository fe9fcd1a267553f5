//! The `localization = [...]` list of a robot: one table per localizer, each with its own
//! parameters (AMCL's names where there is one), so several are compared on identical data.

mod fields;
mod kinds;

use super::check::PointOrPlace;
use super::check::{Checker, R};
use super::error::KeyPath;
pub(in crate::scenario) use kinds::resolve_localizers;
use serde::Deserialize;
use std::f64::consts::PI;
use systems::core::Pose2;
use systems::localization::OdometryMotionModel;
use systems::localization::de_filter::DeFilterConfig;
use systems::localization::de_mc::DeMcConfig;
use systems::localization::de_odometry::DeOdometryConfig;
use systems::localization::de_population::RangeMetric;
use systems::localization::markov_grid::MarkovGridConfig;
use systems::localization::mcl::{InitialBelief, LaserModel, LaserModelParams, MclConfig};
use systems::matching::{DeParams, MatchConfig, SearchWindow, ThesisFitness};

/// A localizer's `type`. Required in a file; the `Default` (mcl) only lets a table be written
/// with `..Default::default()`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum LocalizerType {
    #[default]
    Mcl,
    MarkovGrid,
    DeFilter,
    DeMc,
    DeOdometry,
}

impl LocalizerType {
    fn name(self) -> &'static str {
        match self {
            LocalizerType::Mcl => "mcl",
            LocalizerType::MarkovGrid => "markov_grid",
            LocalizerType::DeFilter => "de_filter",
            LocalizerType::DeMc => "de_mc",
            LocalizerType::DeOdometry => "de_odometry",
        }
    }

    /// The keys a localizer of this type reads (besides `type` and `name`).
    fn keys(self) -> &'static [&'static str] {
        const MOTION: [&str; 6] = [
            "max_beams",
            "update_min_d",
            "update_min_a",
            "alpha",
            "init",
            "init_pose",
        ];
        match self {
            LocalizerType::Mcl => &[
                "max_beams",
                "update_min_d",
                "update_min_a",
                "alpha",
                "init",
                "init_pose",
                "init_sd",
                "z_hit",
                "z_rand",
                "sigma_hit",
                "max_dist",
                "min_particles",
                "max_particles",
                "kld",
                "kld_err",
                "kld_z",
                "resample_interval",
                "model",
                "z_short",
                "z_max",
                "lambda_short",
                "recovery_alpha_slow",
                "recovery_alpha_fast",
                "injection_candidates",
                "recovery_ratio",
                "challenge_every",
                "challenge_ratio",
                "challenge_fraction",
            ],
            LocalizerType::MarkovGrid => &[
                "max_beams",
                "update_min_d",
                "update_min_a",
                "alpha",
                "init",
                "init_pose",
                "init_sd",
                "z_hit",
                "z_rand",
                "sigma_hit",
                "max_dist",
                "resolution",
                "angular_bins",
                "likelihood_exponent",
                "uniform_mix",
                "selective_threshold",
            ],
            LocalizerType::DeFilter => &[
                "max_beams",
                "update_min_d",
                "update_min_a",
                "alpha",
                "init",
                "init_pose",
                "init_sd",
                "population",
                "min_population",
                "generations",
                "tracking_generations",
                "best_weight",
                "f",
                "f_growth",
                "f_max",
                "cr",
                "rejection",
                "discard",
                "metric",
                "converge_cost",
                "converge_updates",
                "refine_rounds",
                "refine_samples",
                "injection_candidates",
            ],
            LocalizerType::DeMc => &[
                "max_beams",
                "update_min_d",
                "update_min_a",
                "alpha",
                "init",
                "init_pose",
                "init_sd",
                "population",
                "iterations",
                "tracking_iterations",
                "f",
                "noise_sd",
                "temperature",
                "metric",
                "converge_cost",
                "converge_updates",
                "refine_rounds",
                "refine_samples",
                "injection_candidates",
            ],
            LocalizerType::DeOdometry => {
                const KEYS: [&str; 10] = [
                    MOTION[0],
                    MOTION[1],
                    MOTION[2],
                    MOTION[4],
                    MOTION[5],
                    "matcher",
                    "window_xy",
                    "window_theta",
                    "min_inliers",
                    "step_sd",
                ];
                &KEYS
            }
        }
    }
}

/// How a DE localizer compares scans (`metric`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum MetricType {
    L1,
    L2,
}

/// The scan matcher of `de_odometry` (`matcher`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum MatcherType {
    Improved,
    Correlation,
    Euclidean,
}

/// MCL's laser model (`model`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum LaserModelType {
    LikelihoodField,
    Beam,
}

/// A localizer's initial belief (`init`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum InitType {
    /// Uniform over free space.
    Global,
    /// A Gaussian around `init_pose` (default: the robot's start).
    Pose,
}

/// One `[[robots.localization]]` table: the type and the parameters that type reads (the others
/// are errors); those not given take the type's defaults.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct LocalizerFile {
    #[serde(rename = "type")]
    pub kind: LocalizerType,
    /// Unique per robot; default: the type.
    pub name: Option<String>,
    pub min_particles: Option<usize>,
    pub max_particles: Option<usize>,
    pub kld: Option<bool>,
    pub kld_err: Option<f64>,
    pub kld_z: Option<f64>,
    /// MCL: resample every this many updates (0: when N_eff < N/2).
    pub resample_interval: Option<usize>,
    pub update_min_d: Option<f64>,
    pub update_min_a: Option<f64>,
    pub max_beams: Option<usize>,
    pub model: Option<LaserModelType>,
    pub z_hit: Option<f64>,
    pub z_rand: Option<f64>,
    pub sigma_hit: Option<f64>,
    pub z_short: Option<f64>,
    pub z_max: Option<f64>,
    pub lambda_short: Option<f64>,
    pub max_dist: Option<f64>,
    /// Odometry motion noise [α1, α2, α3, α4].
    pub alpha: Option<[f64; 4]>,
    pub recovery_alpha_slow: Option<f64>,
    pub recovery_alpha_fast: Option<f64>,
    pub injection_candidates: Option<usize>,
    pub recovery_ratio: Option<f64>,
    pub challenge_every: Option<usize>,
    pub challenge_ratio: Option<f64>,
    pub challenge_fraction: Option<f64>,
    pub init: Option<InitType>,
    pub init_pose: Option<PointOrPlace>,
    /// Standard deviations of the initial Gaussian [x (m), y (m), yaw (rad)].
    pub init_sd: Option<[f64; 3]>,
    // markov_grid
    pub resolution: Option<f64>,
    pub angular_bins: Option<usize>,
    pub likelihood_exponent: Option<f64>,
    pub uniform_mix: Option<f64>,
    pub selective_threshold: Option<f64>,
    // de_filter, de_mc
    pub population: Option<usize>,
    pub min_population: Option<usize>,
    pub generations: Option<usize>,
    pub tracking_generations: Option<usize>,
    pub iterations: Option<usize>,
    pub tracking_iterations: Option<usize>,
    pub best_weight: Option<f64>,
    pub f: Option<f64>,
    pub f_growth: Option<f64>,
    pub f_max: Option<f64>,
    pub cr: Option<f64>,
    pub rejection: Option<f64>,
    pub discard: Option<f64>,
    pub metric: Option<MetricType>,
    pub noise_sd: Option<[f64; 3]>,
    pub temperature: Option<f64>,
    pub converge_cost: Option<f64>,
    pub converge_updates: Option<u32>,
    pub refine_rounds: Option<usize>,
    pub refine_samples: Option<usize>,
    // de_odometry
    pub matcher: Option<MatcherType>,
    pub window_xy: Option<f64>,
    pub window_theta: Option<f64>,
    pub min_inliers: Option<f64>,
    pub step_sd: Option<[f64; 3]>,
}

impl LocalizerFile {
    /// The keys given in the file (besides `type` and `name`).
    fn given(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        macro_rules! given {
            ($($f:ident),* $(,)?) => {
                $(if self.$f.is_some() { v.push(stringify!($f)); })*
            };
        }
        given!(
            min_particles,
            max_particles,
            kld,
            kld_err,
            kld_z,
            resample_interval,
            update_min_d,
            update_min_a,
            max_beams,
            model,
            z_hit,
            z_rand,
            sigma_hit,
            z_short,
            z_max,
            lambda_short,
            max_dist,
            alpha,
            recovery_alpha_slow,
            recovery_alpha_fast,
            injection_candidates,
            recovery_ratio,
            challenge_every,
            challenge_ratio,
            challenge_fraction,
            init,
            init_pose,
            init_sd,
            resolution,
            angular_bins,
            likelihood_exponent,
            uniform_mix,
            selective_threshold,
            population,
            min_population,
            generations,
            tracking_generations,
            iterations,
            tracking_iterations,
            best_weight,
            f,
            f_growth,
            f_max,
            cr,
            rejection,
            discard,
            metric,
            noise_sd,
            temperature,
            converge_cost,
            converge_updates,
            refine_rounds,
            refine_samples,
            matcher,
            window_xy,
            window_theta,
            min_inliers,
            step_sd,
        );
        v
    }
}

/// The index of the localizer called `name` among a robot's, for a key that names the one to
/// navigate by; an error naming `key` and the robot's localizers otherwise.
pub(in crate::scenario) fn localizer_index(
    c: &Checker,
    key: &KeyPath,
    name: &str,
    localizers: &[LocalizerConfig],
) -> R<usize> {
    if let Some(i) = localizers.iter().position(|l| l.name == name) {
        return Ok(i);
    }
    let known: Vec<&str> = localizers.iter().map(|l| l.name.as_str()).collect();
    c.err(
        key,
        if known.is_empty() {
            format!("no localizer named `{name}`: the robot has no `[[robots.localization]]`")
        } else {
            format!(
                "no localizer named `{name}`; the robot has: {}",
                known.join(", ")
            )
        },
    )
}

/// A validated localizer.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalizerConfig {
    pub name: String,
    pub kind: LocalizerKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LocalizerKind {
    Mcl(MclConfig),
    MarkovGrid(MarkovGridConfig),
    DeFilter(DeFilterConfig),
    DeMc(DeMcConfig),
    DeOdometry(DeOdometryConfig),
    /// Scan-to-map SLAM (from the robot's `slam` key).
    ScanToMap(Box<systems::mapping::ScanToMapConfig>),
    /// Graph SLAM (from the robot's `slam` key).
    Graph(Box<systems::mapping::GraphSlamConfig>),
    /// Rao-Blackwellized particle filter SLAM (from the robot's `slam` key).
    Rbpf(Box<systems::mapping::RbpfConfig>),
}

impl LocalizerConfig {
    /// How it starts: None for an estimator that does not localize in the map (DE odometry,
    /// SLAM), else whether its first belief covers the whole map (global localization) or a
    /// known pose.
    pub fn starts_global(&self) -> Option<bool> {
        let init = match &self.kind {
            LocalizerKind::Mcl(m) => m.init,
            LocalizerKind::MarkovGrid(m) => m.init,
            LocalizerKind::DeFilter(m) => m.init,
            LocalizerKind::DeMc(m) => m.init,
            LocalizerKind::DeOdometry(_)
            | LocalizerKind::ScanToMap(_)
            | LocalizerKind::Graph(_)
            | LocalizerKind::Rbpf(_) => return None,
        };
        Some(matches!(
            init,
            systems::localization::mcl::InitialBelief::Global
        ))
    }

    /// The distance-field truncation this localizer needs (m), if it uses the field.
    pub fn field_max_dist(&self) -> Option<f64> {
        match &self.kind {
            LocalizerKind::Mcl(m) => Some(m.laser.max_dist),
            LocalizerKind::MarkovGrid(m) => Some(m.laser.max_dist),
            LocalizerKind::DeFilter(_)
            | LocalizerKind::DeMc(_)
            | LocalizerKind::DeOdometry(_)
            | LocalizerKind::ScanToMap(_)
            | LocalizerKind::Graph(_)
            | LocalizerKind::Rbpf(_) => None,
        }
    }
}
