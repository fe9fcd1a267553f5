//! A robot's `slam` key: one table (`slam = { type = "scan_to_map", … }`) or a list of them
//! (`[[robots.slam]]`), so several SLAM systems run on identical scans. Each becomes an entry of
//! the robot's localizers (estimates evaluated and recorded like theirs, under its name).

use super::check::{Checker, R};
use super::error::KeyPath;
use super::localizers::{LocalizerConfig, LocalizerKind};
use serde::Deserialize;
use systems::core::Pose2;
use systems::mapping::de_map_match::DeMapMatcher;
use systems::mapping::rbpf::proposal::SampleGrid;
use systems::mapping::scan_to_map::OdometryPriorModel;
use systems::mapping::{GraphSlamConfig, RbpfConfig, ScanToMapConfig};

/// A robot's `slam` key: one table or a list of them.
#[derive(Debug, Clone)]
pub enum SlamList {
    One(Box<SlamFile>),
    Many(Vec<SlamFile>),
}

/// A table or an array of tables, each with the errors of [`SlamFile`] (serde's untagged enums
/// would only say that nothing matched).
impl<'de> Deserialize<'de> for SlamList {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        match toml::Value::deserialize(d)? {
            toml::Value::Array(items) => items
                .into_iter()
                .enumerate()
                .map(|(i, v)| {
                    SlamFile::deserialize(v)
                        .map_err(|e| D::Error::custom(format!("slam[{i}]: {e}")))
                })
                .collect::<Result<Vec<_>, _>>()
                .map(SlamList::Many),
            v @ toml::Value::Table(_) => SlamFile::deserialize(v)
                .map(|f| SlamList::One(Box::new(f)))
                .map_err(|e| D::Error::custom(e.to_string())),
            other => Err(D::Error::custom(format!(
                "expected a table `{{ type = \"scan_to_map\", … }}` or `[[robots.slam]]` tables, got {}",
                other.type_str()
            ))),
        }
    }
}

impl SlamList {
    pub fn items(&self) -> &[SlamFile] {
        match self {
            SlamList::One(s) => std::slice::from_ref(s.as_ref()),
            SlamList::Many(v) => v,
        }
    }
}

/// A SLAM system's `type`. Required in a file; the `Default` is scan_to_map.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum SlamType {
    #[default]
    ScanToMap,
    Graph,
    Rbpf,
}

impl SlamType {
    fn name(self) -> &'static str {
        match self {
            SlamType::ScanToMap => "scan_to_map",
            SlamType::Graph => "graph",
            SlamType::Rbpf => "rbpf",
        }
    }
}

/// One SLAM system as written: the type and the parameters it reads.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct SlamFile {
    #[serde(rename = "type")]
    pub kind: SlamType,
    /// Unique among the robot's localizers and SLAM systems; default: the type.
    pub name: Option<String>,
    /// Map cell size (m).
    pub resolution: Option<f64>,
    /// Pyramid levels of the scan matcher.
    pub levels: Option<usize>,
    pub map_update_min_d: Option<f64>,
    pub map_update_min_a: Option<f64>,
    /// Use every n-th beam for matching.
    pub beam_stride: Option<usize>,
    /// Pull matches towards the wheel odometry (false: match on the scan alone, as Hector).
    pub odometry_prior: Option<bool>,
    /// Inverse sensor model: P(occupied) of a hit and of a crossed cell.
    pub p_hit: Option<f64>,
    pub p_miss: Option<f64>,
    /// How far a beam without a return clears free space (m).
    pub clear_range: Option<f64>,
    /// RBPF only, under GMapping's names ([SLAM thesis]): number of particles, the
    /// motion that triggers an update (m, rad), the proposal's sampling grid (m, rad).
    pub particles: Option<usize>,
    #[serde(rename = "linearUpdate")]
    pub linear_update: Option<f64>,
    #[serde(rename = "angularUpdate")]
    pub angular_update: Option<f64>,
    pub llsamplerange: Option<f64>,
    pub llsamplestep: Option<f64>,
    pub lasamplerange: Option<f64>,
    pub lasamplestep: Option<f64>,
    /// scan_to_map only: `gauss_newton` (default) or `de` (differential evolution).
    pub matcher: Option<MatcherKind>,
}

/// The scan matcher of `scan_to_map` (`matcher`).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum MatcherKind {
    GaussNewton,
    De,
}

impl SlamFile {
    /// The keys given that `kind` does not use.
    fn foreign_keys(&self) -> Vec<&'static str> {
        let rbpf_keys = [
            ("particles", self.particles.is_some()),
            ("linearUpdate", self.linear_update.is_some()),
            ("angularUpdate", self.angular_update.is_some()),
            ("llsamplerange", self.llsamplerange.is_some()),
            ("llsamplestep", self.llsamplestep.is_some()),
            ("lasamplerange", self.lasamplerange.is_some()),
            ("lasamplestep", self.lasamplestep.is_some()),
        ];
        let matcher_keys = [
            ("levels", self.levels.is_some()),
            ("map_update_min_d", self.map_update_min_d.is_some()),
            ("map_update_min_a", self.map_update_min_a.is_some()),
            ("odometry_prior", self.odometry_prior.is_some()),
        ];
        let mut foreign: Vec<(&'static str, bool)> = match self.kind {
            SlamType::Rbpf => matcher_keys.to_vec(),
            SlamType::ScanToMap | SlamType::Graph => rbpf_keys.to_vec(),
        };
        if self.kind != SlamType::ScanToMap {
            foreign.push(("matcher", self.matcher.is_some()));
        }
        foreign
            .iter()
            .filter(|(_, given)| *given)
            .map(|(k, _)| *k)
            .collect()
    }
}

/// Validates the robot's SLAM systems; they start at the robot's start pose.
pub(super) fn resolve_slam(
    c: &Checker,
    p: &KeyPath,
    list: Option<&SlamList>,
    start: &Pose2,
    taken: &[LocalizerConfig],
) -> R<Vec<LocalizerConfig>> {
    let Some(list) = list else {
        return Ok(Vec::new());
    };
    let many = matches!(list, SlamList::Many(_));
    let mut out: Vec<LocalizerConfig> = Vec::new();
    for (i, s) in list.items().iter().enumerate() {
        let sp = if many { p.index(i) } else { p.clone() };
        let name = match &s.name {
            Some(n) if !super::check::check_name(n) => {
                return c.err(
                    &sp.key("name"),
                    format!("expected letters, digits, `_` or `-`, got `{n}`"),
                );
            }
            Some(n) => n.clone(),
            None => s.kind.name().to_string(),
        };
        if taken.iter().chain(out.iter()).any(|o| o.name == name) {
            let key = if s.name.is_some() { "name" } else { "type" };
            return c.err(
                &sp.key(key),
                format!("`{name}` is already the name of a localizer or SLAM system of this robot: give each a `name`"),
            );
        }
        if let Some(k) = s.foreign_keys().first() {
            let users = match (s.kind, *k) {
                (_, "matcher") => "`scan_to_map`",
                (SlamType::Rbpf, _) => "`scan_to_map` and `graph`",
                _ => "`rbpf`",
            };
            return c.err(
                &sp.key(k),
                format!("`{k}` applies to {users}, not to `{}`", s.kind.name()),
            );
        }
        let d = ScanToMapConfig::default();
        let resolution = match s.resolution {
            Some(v) => c.range(&sp.key("resolution"), v, Some(0.005), Some(1.0), false)?,
            None => d.resolution,
        };
        let levels = match s.levels {
            Some(v) if !(1..=6).contains(&v) => {
                return c.err(&sp.key("levels"), format!("expected 1 to 6, got {v}"));
            }
            Some(v) => v,
            None => d.levels,
        };
        let beam_stride = match s.beam_stride {
            Some(0) => return c.err(&sp.key("beam_stride"), "expected at least 1, got 0"),
            Some(v) => v,
            None => d.beam_stride,
        };
        let mut occupancy = d.occupancy.clone();
        if let Some(v) = s.p_hit {
            occupancy.p_hit = c.range(&sp.key("p_hit"), v, Some(0.5), Some(1.0), true)? as f32;
        }
        if let Some(v) = s.p_miss {
            occupancy.p_miss = c.range(&sp.key("p_miss"), v, Some(0.0), Some(0.5), true)? as f32;
            if occupancy.p_miss >= 0.5 {
                return c.err(
                    &sp.key("p_miss"),
                    format!("expected a number below 0.5, got {v}"),
                );
            }
        }
        if let Some(v) = s.clear_range {
            occupancy.clear_range =
                c.range(&sp.key("clear_range"), v, Some(0.0), None, false)? as f32;
        }
        let mut matcher = d.matcher;
        matcher.levels = levels;
        let config = ScanToMapConfig {
            resolution,
            levels,
            occupancy,
            matcher,
            map_update_min_d: c.opt_positive(
                &sp.key("map_update_min_d"),
                s.map_update_min_d,
                d.map_update_min_d,
            )?,
            map_update_min_a: c.opt_positive(
                &sp.key("map_update_min_a"),
                s.map_update_min_a,
                d.map_update_min_a,
            )?,
            beam_stride,
            prior: match s.odometry_prior {
                Some(false) => None,
                _ => Some(OdometryPriorModel::default()),
            },
            init_pose: *start,
            de_matcher: (s.matcher == Some(MatcherKind::De)).then(DeMapMatcher::default),
        };
        let kind = match s.kind {
            SlamType::Rbpf => LocalizerKind::Rbpf(Box::new(rbpf_config(c, &sp, s, config)?)),
            SlamType::ScanToMap => LocalizerKind::ScanToMap(Box::new(config)),
            SlamType::Graph => LocalizerKind::Graph(Box::new(GraphSlamConfig {
                local: config,
                ..GraphSlamConfig::default()
            })),
        };
        out.push(LocalizerConfig { name, kind });
    }
    Ok(out)
}

/// The RBPF's configuration: GMapping's parameters from the file, the map's (resolution,
/// occupancy model, beam stride, start pose) from the shared keys.
fn rbpf_config(c: &Checker, sp: &KeyPath, s: &SlamFile, shared: ScanToMapConfig) -> R<RbpfConfig> {
    let d = RbpfConfig::default();
    let particles = match s.particles {
        Some(n) if !(1..=10_000).contains(&n) => {
            return c.err(
                &sp.key("particles"),
                format!("expected 1 to 10000, got {n}"),
            );
        }
        Some(n) => n,
        None => d.particles,
    };
    let sample = |key: &str, v: Option<f64>, default: f64| -> R<f64> {
        match v {
            Some(v) => c.range(&sp.key(key), v, Some(0.0), Some(1.0), false),
            None => Ok(default),
        }
    };
    let g = d.sample;
    Ok(RbpfConfig {
        particles,
        linear_update: c.opt_positive(&sp.key("linearUpdate"), s.linear_update, d.linear_update)?,
        angular_update: c.opt_positive(
            &sp.key("angularUpdate"),
            s.angular_update,
            d.angular_update,
        )?,
        sample: SampleGrid {
            llsamplerange: sample("llsamplerange", s.llsamplerange, g.llsamplerange)?,
            llsamplestep: sample("llsamplestep", s.llsamplestep, g.llsamplestep)?,
            lasamplerange: sample("lasamplerange", s.lasamplerange, g.lasamplerange)?,
            lasamplestep: sample("lasamplestep", s.lasamplestep, g.lasamplestep)?,
        },
        resolution: shared.resolution,
        occupancy: shared.occupancy,
        beam_stride: s.beam_stride.unwrap_or(d.beam_stride),
        init_pose: shared.init_pose,
        ..d
    })
}
