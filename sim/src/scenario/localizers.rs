//! The `localization = [...]` list of a robot: one table per localizer, each with its own
//! parameters (AMCL's names where there is one), so several are compared on identical data.

use super::error::KeyPath;
use super::file::PointOrPlace;
use super::resolve::{Checker, R};
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

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum LocalizerType {
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

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum MetricType {
    L1,
    L2,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum MatcherType {
    Improved,
    Correlation,
    Euclidean,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum LaserModelType {
    LikelihoodField,
    Beam,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum InitType {
    /// Uniform over free space.
    Global,
    /// A Gaussian around `init_pose` (default: the robot's start).
    Pose,
}

#[derive(Deserialize, Debug)]
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
}

impl LocalizerConfig {
    /// The distance-field truncation this localizer needs (m), if it uses the field.
    pub fn field_max_dist(&self) -> Option<f64> {
        match &self.kind {
            LocalizerKind::Mcl(m) => Some(m.laser.max_dist),
            LocalizerKind::MarkovGrid(m) => Some(m.laser.max_dist),
            LocalizerKind::DeFilter(_) | LocalizerKind::DeMc(_) | LocalizerKind::DeOdometry(_) => {
                None
            }
        }
    }
}

/// Validates one robot's list. `pose` resolves coordinates or place names; `start` is the
/// robot's start pose.
pub(super) fn resolve_localizers(
    c: &Checker,
    p: &KeyPath,
    list: &[LocalizerFile],
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<Vec<LocalizerConfig>> {
    let mut out: Vec<LocalizerConfig> = Vec::new();
    for (i, l) in list.iter().enumerate() {
        let lp = p.index(i);
        let name = match &l.name {
            Some(n) => {
                if !super::resolve::check_name(n) {
                    return c.err(
                        &lp.key("name"),
                        format!("expected letters, digits, `_` or `-`, got `{n}`"),
                    );
                }
                n.clone()
            }
            None => l.kind.name().to_string(),
        };
        if let Some(key) = l.given().into_iter().find(|k| !l.kind.keys().contains(k)) {
            return c.err(
                &lp.key(key),
                format!(
                    "`{key}` does not apply to a `{}` localizer (its keys: {})",
                    l.kind.name(),
                    l.kind.keys().join(", ")
                ),
            );
        }
        if out.iter().any(|o| o.name == name) {
            let key = if l.name.is_some() { "name" } else { "type" };
            return c.err(
                &lp.key(key),
                format!("two localizers named `{name}` on one robot: give each a `name`"),
            );
        }
        let kind = match l.kind {
            LocalizerType::Mcl => LocalizerKind::Mcl(resolve_mcl(c, &lp, l, start, pose)?),
            LocalizerType::MarkovGrid => {
                LocalizerKind::MarkovGrid(resolve_markov_grid(c, &lp, l, start, pose)?)
            }
            LocalizerType::DeFilter => {
                LocalizerKind::DeFilter(resolve_de_filter(c, &lp, l, start, pose)?)
            }
            LocalizerType::DeMc => LocalizerKind::DeMc(resolve_de_mc(c, &lp, l, start, pose)?),
            LocalizerType::DeOdometry => {
                LocalizerKind::DeOdometry(resolve_de_odometry(c, &lp, l, start, pose)?)
            }
        };
        out.push(LocalizerConfig { name, kind });
    }
    Ok(out)
}

/// Reads one localizer table's values, each checked with its key in the error.
struct Fields<'a> {
    c: &'a Checker<'a>,
    p: &'a KeyPath,
    l: &'a LocalizerFile,
}

impl Fields<'_> {
    fn count(
        &self,
        key: &str,
        v: Option<usize>,
        default: usize,
        min: usize,
        max: usize,
    ) -> R<usize> {
        match v {
            Some(n) if n < min || n > max => self.c.err(
                &self.p.key(key),
                format!("expected a whole number in [{min}, {max}], got {n}"),
            ),
            Some(n) => Ok(n),
            None => Ok(default),
        }
    }

    fn prob(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        match v {
            Some(v) => self
                .c
                .range(&self.p.key(key), v, Some(0.0), Some(1.0), false),
            None => Ok(default),
        }
    }

    fn nonneg(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        match v {
            Some(v) => self.c.range(&self.p.key(key), v, Some(0.0), None, false),
            None => Ok(default),
        }
    }

    fn positive(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        self.c.opt_positive(&self.p.key(key), v, default)
    }

    fn triple(&self, key: &str, v: Option<[f64; 3]>, default: [f64; 3], hi: f64) -> R<[f64; 3]> {
        let v = v.unwrap_or(default);
        for (k, x) in v.iter().enumerate() {
            self.c
                .range(&self.p.key(key).index(k), *x, Some(0.0), Some(hi), false)?;
        }
        Ok(v)
    }

    fn max_beams(&self, default: usize) -> R<usize> {
        match self.l.max_beams {
            Some(0) => self
                .c
                .err(&self.p.key("max_beams"), "expected at least 1 beam"),
            Some(n) => Ok(n),
            None => Ok(default),
        }
    }

    fn motion(&self, default: OdometryMotionModel) -> R<OdometryMotionModel> {
        Ok(match self.l.alpha {
            Some(a) => {
                for (k, v) in a.iter().enumerate() {
                    self.c.range(
                        &self.p.key("alpha").index(k),
                        *v,
                        Some(0.0),
                        Some(10.0),
                        false,
                    )?;
                }
                OdometryMotionModel {
                    alpha1: a[0],
                    alpha2: a[1],
                    alpha3: a[2],
                    alpha4: a[3],
                }
            }
            None => default,
        })
    }

    /// The likelihood-field parameters (AMCL's names).
    fn laser(&self, d: LaserModelParams) -> R<LaserModelParams> {
        let l = self.l;
        Ok(LaserModelParams {
            z_hit: self.prob("z_hit", l.z_hit, d.z_hit)?,
            z_rand: self.prob("z_rand", l.z_rand, d.z_rand)?,
            sigma_hit: self.positive("sigma_hit", l.sigma_hit, d.sigma_hit)?,
            z_short: self.prob("z_short", l.z_short, d.z_short)?,
            z_max: self.prob("z_max", l.z_max, d.z_max)?,
            lambda_short: self.positive("lambda_short", l.lambda_short, d.lambda_short)?,
            max_dist: match l.max_dist {
                Some(v) => self
                    .c
                    .range(&self.p.key("max_dist"), v, Some(0.0), Some(50.0), true)?,
                None => d.max_dist,
            },
        })
    }

    /// `init`, `init_pose`, `init_sd`.
    fn init(
        &self,
        start: &Pose2,
        pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
    ) -> R<InitialBelief> {
        let l = self.l;
        let init_type = l.init.unwrap_or(InitType::Global);
        if init_type == InitType::Global {
            for (key, given) in [
                ("init_pose", l.init_pose.is_some()),
                ("init_sd", l.init_sd.is_some()),
            ] {
                if given {
                    return self
                        .c
                        .err(&self.p.key(key), format!("`{key}` needs `init = \"pose\"`"));
                }
            }
        }
        Ok(match init_type {
            InitType::Global => InitialBelief::Global,
            InitType::Pose => {
                let at = match &l.init_pose {
                    Some(v) => pose(&self.p.key("init_pose"), v)?,
                    None => *start,
                };
                let sd = self.triple("init_sd", l.init_sd, [0.5, 0.5, 0.25], 1000.0)?;
                InitialBelief::Gaussian { pose: at, sd }
            }
        })
    }

    fn metric(&self) -> RangeMetric {
        match self.l.metric {
            Some(MetricType::L2) => RangeMetric::L2,
            Some(MetricType::L1) | None => RangeMetric::L1,
        }
    }
}

fn resolve_mcl(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<MclConfig> {
    let d = MclConfig::default();
    let f = Fields { c, p, l };
    let max_particles = f.count(
        "max_particles",
        l.max_particles,
        d.max_particles,
        1,
        10_000_000,
    )?;
    let min_particles = f.count(
        "min_particles",
        l.min_particles,
        d.min_particles.min(max_particles),
        1,
        10_000_000,
    )?;
    if min_particles > max_particles {
        return c.err(
            &p.key("min_particles"),
            format!("min_particles ({min_particles}) exceeds max_particles ({max_particles})"),
        );
    }
    let kld_err = match l.kld_err {
        Some(v) => c.range(&p.key("kld_err"), v, Some(0.0), Some(1.0), true)?,
        None => d.kld_err,
    };
    let kld_z = match l.kld_z {
        Some(v) => {
            if !(v > 0.0 && v < 1.0) {
                return c.err(
                    &p.key("kld_z"),
                    format!("expected a probability in (0, 1) (AMCL's default is 0.99), got {v}"),
                );
            }
            v
        }
        None => d.kld_z,
    };
    Ok(MclConfig {
        min_particles,
        max_particles,
        kld: l.kld.unwrap_or(d.kld),
        kld_err,
        kld_z,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        max_beams: f.max_beams(d.max_beams)?,
        model: match l.model {
            Some(LaserModelType::Beam) => LaserModel::Beam,
            Some(LaserModelType::LikelihoodField) | None => LaserModel::LikelihoodField,
        },
        laser: f.laser(LaserModelParams::default())?,
        motion: f.motion(d.motion)?,
        recovery_alpha_slow: f.prob(
            "recovery_alpha_slow",
            l.recovery_alpha_slow,
            d.recovery_alpha_slow,
        )?,
        recovery_alpha_fast: f.prob(
            "recovery_alpha_fast",
            l.recovery_alpha_fast,
            d.recovery_alpha_fast,
        )?,
        recovery_ratio: match l.recovery_ratio {
            Some(v) => c.range(&p.key("recovery_ratio"), v, Some(0.0), Some(1.0), true)?,
            None => d.recovery_ratio,
        },
        injection_candidates: match l.injection_candidates {
            Some(0) => 0,
            _ => f.count(
                "injection_candidates",
                l.injection_candidates,
                d.injection_candidates,
                1,
                10_000_000,
            )?,
        },
        challenge_every: match l.challenge_every {
            Some(0) => 0,
            _ => f.count(
                "challenge_every",
                l.challenge_every,
                d.challenge_every as usize,
                1,
                1_000_000,
            )? as u64,
        },
        challenge_ratio: match l.challenge_ratio {
            Some(v) => c.range(&p.key("challenge_ratio"), v, Some(1.0), None, false)?,
            None => d.challenge_ratio,
        },
        challenge_fraction: f.prob(
            "challenge_fraction",
            l.challenge_fraction,
            d.challenge_fraction,
        )?,
        init: f.init(start, pose)?,
        bins: d.bins,
    })
}

fn resolve_markov_grid(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<MarkovGridConfig> {
    let d = MarkovGridConfig::default();
    let f = Fields { c, p, l };
    let resolution = match l.resolution {
        Some(v) => c.range(&p.key("resolution"), v, Some(0.01), Some(10.0), false)?,
        None => d.resolution,
    };
    Ok(MarkovGridConfig {
        resolution,
        angular_bins: f.count("angular_bins", l.angular_bins, d.angular_bins, 4, 720)?,
        max_beams: f.max_beams(d.max_beams)?,
        laser: f.laser(d.laser)?,
        motion: f.motion(d.motion)?,
        likelihood_exponent: match l.likelihood_exponent {
            Some(v) => c.range(&p.key("likelihood_exponent"), v, Some(0.0), Some(1.0), true)?,
            None => d.likelihood_exponent,
        },
        uniform_mix: f.prob("uniform_mix", l.uniform_mix, d.uniform_mix)?,
        selective_threshold: f.prob(
            "selective_threshold",
            l.selective_threshold,
            d.selective_threshold,
        )?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
    })
}

fn resolve_de_filter(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeFilterConfig> {
    let d = DeFilterConfig::default();
    let f = Fields { c, p, l };
    let population = f.count("population", l.population, d.population, 4, 1_000_000)?;
    let min_population = f.count(
        "min_population",
        l.min_population,
        d.min_population.min(population),
        4,
        1_000_000,
    )?;
    if min_population > population {
        return c.err(
            &p.key("min_population"),
            format!("min_population ({min_population}) exceeds population ({population})"),
        );
    }
    Ok(DeFilterConfig {
        population,
        min_population,
        generations: f.count("generations", l.generations, d.generations, 0, 10_000)?,
        tracking_generations: f.count(
            "tracking_generations",
            l.tracking_generations,
            d.tracking_generations,
            0,
            10_000,
        )?,
        best_weight: f.prob("best_weight", l.best_weight, d.best_weight)?,
        f: f.positive("f", l.f, d.f)?,
        f_growth: match l.f_growth {
            Some(v) => c.range(&p.key("f_growth"), v, Some(1.0), Some(10.0), false)?,
            None => d.f_growth,
        },
        f_max: f.positive("f_max", l.f_max, d.f_max)?,
        cr: f.prob("cr", l.cr, d.cr)?,
        rejection: f.prob("rejection", l.rejection, d.rejection)?,
        discard: match l.discard {
            Some(v) => c.range(&p.key("discard"), v, Some(0.0), Some(0.9), false)?,
            None => d.discard,
        },
        metric: f.metric(),
        max_beams: f.max_beams(d.max_beams)?,
        motion: f.motion(d.motion)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
        converge_cost: f.positive("converge_cost", l.converge_cost, d.converge_cost)?,
        converge_updates: l.converge_updates.unwrap_or(d.converge_updates).max(1),
        refine_rounds: f.count("refine_rounds", l.refine_rounds, d.refine_rounds, 0, 20)?,
        refine_samples: f.count(
            "refine_samples",
            l.refine_samples,
            d.refine_samples,
            1,
            10_000,
        )?,
        refine_sd: d.refine_sd,
    })
}

fn resolve_de_mc(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeMcConfig> {
    let d = DeMcConfig::default();
    let f = Fields { c, p, l };
    Ok(DeMcConfig {
        population: f.count("population", l.population, d.population, 4, 1_000_000)?,
        iterations: f.count("iterations", l.iterations, d.iterations, 0, 10_000)?,
        tracking_iterations: f.count(
            "tracking_iterations",
            l.tracking_iterations,
            d.tracking_iterations,
            0,
            10_000,
        )?,
        f: f.positive("f", l.f, d.f)?,
        noise_sd: f.triple("noise_sd", l.noise_sd, d.noise_sd, 10.0)?,
        temperature: f.positive("temperature", l.temperature, d.temperature)?,
        metric: f.metric(),
        max_beams: f.max_beams(d.max_beams)?,
        motion: f.motion(d.motion)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
        converge_cost: f.positive("converge_cost", l.converge_cost, d.converge_cost)?,
        converge_updates: l.converge_updates.unwrap_or(d.converge_updates).max(1),
        refine_rounds: f.count("refine_rounds", l.refine_rounds, d.refine_rounds, 0, 20)?,
        refine_samples: f.count(
            "refine_samples",
            l.refine_samples,
            d.refine_samples,
            1,
            10_000,
        )?,
        refine_sd: d.refine_sd,
    })
}

fn resolve_de_odometry(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeOdometryConfig> {
    let d = DeOdometryConfig::default();
    let f = Fields { c, p, l };
    if l.init == Some(InitType::Global) {
        return c.err(
            &p.key("init"),
            "de_odometry integrates scan matches from a known pose: use `init = \"pose\"` \
             (the default) with `init_pose`, or leave both out to start at the robot's start",
        );
    }
    let start = match &l.init_pose {
        Some(v) => pose(&p.key("init_pose"), v)?,
        None => *start,
    };
    let mut matcher = match l.matcher {
        Some(MatcherType::Improved) | None => MatchConfig::improved(),
        Some(MatcherType::Correlation) => MatchConfig::thesis(ThesisFitness::Correlation, {
            let mut de = DeParams::thesis_final_experiment();
            de.generations = 1000;
            de.parallel = false;
            de
        }),
        Some(MatcherType::Euclidean) => MatchConfig::thesis(ThesisFitness::EuclideanField, {
            let mut de = DeParams::thesis_final_experiment();
            de.generations = 1000;
            de.parallel = false;
            de
        }),
    };
    matcher.window = SearchWindow {
        max_xy: f.positive("window_xy", l.window_xy, d.matcher.window.max_xy)?,
        max_theta: match l.window_theta {
            Some(v) => c.range(&p.key("window_theta"), v, Some(0.0), Some(PI), true)?,
            None => d.matcher.window.max_theta,
        },
    };
    Ok(DeOdometryConfig {
        matcher,
        max_beams: f.max_beams(d.max_beams)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        min_inliers: f.prob("min_inliers", l.min_inliers, d.min_inliers)?,
        step_sd: f.triple("step_sd", l.step_sd, d.step_sd, 10.0)?,
        start,
    })
}
