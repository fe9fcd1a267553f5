//! The `localization = [...]` list of a robot: one table per localizer, each with its own
//! parameters (AMCL's names where there is one), so several are compared on identical data.

use super::error::KeyPath;
use super::file::PointOrPlace;
use super::resolve::{Checker, R};
use serde::Deserialize;
use systems::core::Pose2;
use systems::localization::OdometryMotionModel;
use systems::localization::mcl::{InitialBelief, LaserModel, LaserModelParams, MclConfig};

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum LocalizerType {
    Mcl,
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
    pub init: Option<InitType>,
    pub init_pose: Option<PointOrPlace>,
    /// Standard deviations of the initial Gaussian [x (m), y (m), yaw (rad)].
    pub init_sd: Option<[f64; 3]>,
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
}

impl LocalizerConfig {
    /// The distance-field truncation this localizer needs (m), if it uses the field.
    pub fn field_max_dist(&self) -> Option<f64> {
        match &self.kind {
            LocalizerKind::Mcl(m) => Some(m.laser.max_dist),
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
            None => match l.kind {
                LocalizerType::Mcl => "mcl".to_string(),
            },
        };
        if out.iter().any(|o| o.name == name) {
            let key = if l.name.is_some() { "name" } else { "type" };
            return c.err(
                &lp.key(key),
                format!("two localizers named `{name}` on one robot: give each a `name`"),
            );
        }
        let kind = match l.kind {
            LocalizerType::Mcl => LocalizerKind::Mcl(resolve_mcl(c, &lp, l, start, pose)?),
        };
        out.push(LocalizerConfig { name, kind });
    }
    Ok(out)
}

fn resolve_mcl(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<MclConfig> {
    let d = MclConfig::default();
    let count = |key: &str, v: Option<usize>, default: usize| -> R<usize> {
        match v {
            Some(0) => c.err(&p.key(key), "expected at least 1 particle"),
            Some(n) if n > 10_000_000 => c.err(&p.key(key), format!("{n} is more than 10000000")),
            Some(n) => Ok(n),
            None => Ok(default),
        }
    };
    let max_particles = count("max_particles", l.max_particles, d.max_particles)?;
    let min_particles = count(
        "min_particles",
        l.min_particles,
        d.min_particles.min(max_particles),
    )?;
    if min_particles > max_particles {
        return c.err(
            &p.key("min_particles"),
            format!("min_particles ({min_particles}) exceeds max_particles ({max_particles})"),
        );
    }
    let prob = |key: &str, v: Option<f64>, default: f64| -> R<f64> {
        match v {
            Some(v) => c.range(&p.key(key), v, Some(0.0), Some(1.0), false),
            None => Ok(default),
        }
    };
    let nonneg = |key: &str, v: Option<f64>, default: f64| -> R<f64> {
        match v {
            Some(v) => c.range(&p.key(key), v, Some(0.0), None, false),
            None => Ok(default),
        }
    };
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
    let max_beams = match l.max_beams {
        Some(0) => return c.err(&p.key("max_beams"), "expected at least 1 beam"),
        Some(n) => n,
        None => d.max_beams,
    };
    let dl = LaserModelParams::default();
    let laser = LaserModelParams {
        z_hit: prob("z_hit", l.z_hit, dl.z_hit)?,
        z_rand: prob("z_rand", l.z_rand, dl.z_rand)?,
        sigma_hit: c.opt_positive(&p.key("sigma_hit"), l.sigma_hit, dl.sigma_hit)?,
        z_short: prob("z_short", l.z_short, dl.z_short)?,
        z_max: prob("z_max", l.z_max, dl.z_max)?,
        lambda_short: c.opt_positive(&p.key("lambda_short"), l.lambda_short, dl.lambda_short)?,
        max_dist: match l.max_dist {
            Some(v) => c.range(&p.key("max_dist"), v, Some(0.0), Some(50.0), true)?,
            None => dl.max_dist,
        },
    };
    let motion = match l.alpha {
        Some(a) => {
            for (k, v) in a.iter().enumerate() {
                c.range(&p.key("alpha").index(k), *v, Some(0.0), Some(10.0), false)?;
            }
            OdometryMotionModel {
                alpha1: a[0],
                alpha2: a[1],
                alpha3: a[2],
                alpha4: a[3],
            }
        }
        None => d.motion,
    };
    let init_type = l.init.unwrap_or(InitType::Global);
    if init_type == InitType::Global {
        for (key, given) in [
            ("init_pose", l.init_pose.is_some()),
            ("init_sd", l.init_sd.is_some()),
        ] {
            if given {
                return c.err(&p.key(key), format!("`{key}` needs `init = \"pose\"`"));
            }
        }
    }
    let init = match init_type {
        InitType::Global => InitialBelief::Global,
        InitType::Pose => {
            let at = match &l.init_pose {
                Some(v) => pose(&p.key("init_pose"), v)?,
                None => *start,
            };
            let sd = l.init_sd.unwrap_or([0.5, 0.5, 0.25]);
            for (k, v) in sd.iter().enumerate() {
                c.range(
                    &p.key("init_sd").index(k),
                    *v,
                    Some(0.0),
                    Some(1000.0),
                    false,
                )?;
            }
            InitialBelief::Gaussian { pose: at, sd }
        }
    };
    Ok(MclConfig {
        min_particles,
        max_particles,
        kld: l.kld.unwrap_or(d.kld),
        kld_err,
        kld_z,
        update_min_d: nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        max_beams,
        model: match l.model {
            Some(LaserModelType::Beam) => LaserModel::Beam,
            Some(LaserModelType::LikelihoodField) | None => LaserModel::LikelihoodField,
        },
        laser,
        motion,
        recovery_alpha_slow: prob(
            "recovery_alpha_slow",
            l.recovery_alpha_slow,
            d.recovery_alpha_slow,
        )?,
        recovery_alpha_fast: prob(
            "recovery_alpha_fast",
            l.recovery_alpha_fast,
            d.recovery_alpha_fast,
        )?,
        init,
        bins: d.bins,
    })
}
