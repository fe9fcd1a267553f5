//! Reading one `[[robots.localization]]` table's values, each checked with its key path in the
//! error message.

use super::*;

/// Reads one localizer table's values, each checked with its key in the error.
pub(super) struct Fields<'a> {
    pub c: &'a Checker<'a>,
    pub p: &'a KeyPath,
    pub l: &'a LocalizerFile,
}

impl Fields<'_> {
    pub(super) fn count(
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

    pub(super) fn prob(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        match v {
            Some(v) => self
                .c
                .range(&self.p.key(key), v, Some(0.0), Some(1.0), false),
            None => Ok(default),
        }
    }

    pub(super) fn nonneg(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        match v {
            Some(v) => self.c.range(&self.p.key(key), v, Some(0.0), None, false),
            None => Ok(default),
        }
    }

    pub(super) fn positive(&self, key: &str, v: Option<f64>, default: f64) -> R<f64> {
        self.c.opt_positive(&self.p.key(key), v, default)
    }

    pub(super) fn triple(
        &self,
        key: &str,
        v: Option<[f64; 3]>,
        default: [f64; 3],
        hi: f64,
    ) -> R<[f64; 3]> {
        let v = v.unwrap_or(default);
        for (k, x) in v.iter().enumerate() {
            self.c
                .range(&self.p.key(key).index(k), *x, Some(0.0), Some(hi), false)?;
        }
        Ok(v)
    }

    /// `injection_candidates`: candidates per round of the scan proposal, 0 for none.
    pub(super) fn injection_candidates(&self, default: usize) -> R<usize> {
        let given = self.l.injection_candidates;
        self.count("injection_candidates", given, default, 0, 10_000_000)
    }

    pub(super) fn max_beams(&self, default: usize) -> R<usize> {
        match self.l.max_beams {
            Some(0) => self
                .c
                .err(&self.p.key("max_beams"), "expected at least 1 beam"),
            Some(n) => Ok(n),
            None => Ok(default),
        }
    }

    pub(super) fn motion(&self, default: OdometryMotionModel) -> R<OdometryMotionModel> {
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
    pub(super) fn laser(&self, d: LaserModelParams) -> R<LaserModelParams> {
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
    pub(super) fn init(
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

    pub(super) fn metric(&self) -> RangeMetric {
        match self.l.metric {
            Some(MetricType::L2) => RangeMetric::L2,
            Some(MetricType::L1) | None => RangeMetric::L1,
        }
    }
}
