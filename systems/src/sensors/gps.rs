//! GPS receiver ([Park thesis §4.1.2]: LS20031, 1–10 Hz, cold start under 35 s, hot start
//! under 2 s; accuracy and error model: [Park thesis §5.3.1, §5.3.3]). A fix is the true
//! antenna position plus
//!
//! - a **bias**, a first-order Gauss–Markov process per axis (stationary σ `bias_std`, time
//!   constant `bias_tau`), so the mean of many fixes can sit metres off the truth as the thesis
//!   measured (up to 6.31 m between buildings);
//! - a fresh **error per fix** of log-normal length LN(μ, σ) (the thesis's sensor model,
//!   LN(1, 0.506)) in a uniformly random direction;
//! - rarely, an **outlier**: with probability `outlier_probability` the fix is instead off by a
//!   distance uniform in `outlier_range` (tens of metres).
//!
//! The parameters come from the zone the robot is in ([`crate::world::Zones`]). No fix is
//! reported before `first_fix` seconds (cold or hot start). Readings follow
//! sensor_msgs/NavSatFix: latitude and longitude in degrees through the world's
//! [`GeoFrame`], altitude, status and a diagonal covariance.

use crate::body::TruePose;
use crate::core::clock::RateTimer;
use crate::core::{SimClock, SimRng};
use crate::world::roads::{GeoFrame, GeoPoint, LocalProjection};
use crate::world::zones::{GpsZone, Zones};
use bevy_ecs::prelude::*;
use rand::RngExt;
use rand_distr::StandardNormal;

#[derive(Clone, Debug, PartialEq)]
pub struct GpsSpec {
    /// Fixes per second (the LS20031 does 1–10 Hz).
    pub rate: f64,
    /// Seconds from power-on to the first fix (cold start ≤ 35 s, hot start ≤ 2 s).
    pub first_fix: f64,
    /// Reported altitude (m): the park is flat.
    pub altitude: f64,
}

/// Time to first fix after a cold and after a hot start (s).
pub const COLD_START_S: f64 = 35.0;
pub const HOT_START_S: f64 = 2.0;

impl Default for GpsSpec {
    fn default() -> Self {
        GpsSpec {
            rate: 5.0,
            first_fix: HOT_START_S,
            altitude: 0.0,
        }
    }
}

/// One fix, shaped like sensor_msgs/NavSatFix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsFix {
    pub stamp: f64,
    pub position: GeoPoint,
    pub altitude: f64,
    /// Diagonal of the position covariance (m², east, north, up), COVARIANCE_TYPE_APPROXIMATED:
    /// what the zone's error model predicts, not the actual error.
    pub covariance: [f64; 3],
}

/// The error model's state: the bias.
#[derive(Clone, Debug, PartialEq)]
pub struct GpsErrorModel {
    bias: [f64; 2],
    last: Option<f64>,
}

impl Default for GpsErrorModel {
    fn default() -> Self {
        Self::new()
    }
}

impl GpsErrorModel {
    pub fn new() -> Self {
        GpsErrorModel {
            bias: [0.0; 2],
            last: None,
        }
    }

    /// The fix (local metres) for the true position `truth` at time `t` in zone `zone`.
    pub fn sample(
        &mut self,
        t: f64,
        truth: [f64; 2],
        zone: &GpsZone,
        rng: &mut SimRng,
    ) -> [f64; 2] {
        // the bias: drawn from its stationary law at the first fix, then propagated exactly
        let n0: f64 = rng.sample(StandardNormal);
        let n1: f64 = rng.sample(StandardNormal);
        match self.last {
            None => self.bias = [zone.bias_std * n0, zone.bias_std * n1],
            Some(last) => {
                let a = if zone.bias_tau > 0.0 {
                    (-(t - last).max(0.0) / zone.bias_tau).exp()
                } else {
                    0.0
                };
                let s = zone.bias_std * (1.0 - a * a).max(0.0).sqrt();
                self.bias = [a * self.bias[0] + s * n0, a * self.bias[1] + s * n1];
            }
        }
        self.last = Some(t);
        let u: f64 = rng.random();
        let bearing = rng.random::<f64>() * std::f64::consts::TAU;
        let n: f64 = rng.sample(StandardNormal);
        if u < zone.outlier_probability {
            let [lo, hi] = zone.outlier_range;
            let d = lo + (hi - lo) * rng.random::<f64>();
            return [truth[0] + d * bearing.cos(), truth[1] + d * bearing.sin()];
        }
        let d = (zone.mu + zone.sigma * n).exp();
        [
            truth[0] + self.bias[0] + d * bearing.cos(),
            truth[1] + self.bias[1] + d * bearing.sin(),
        ]
    }
}

/// Expected squared error per horizontal axis (m²) of a zone: bias variance plus half the mean
/// square of the log-normal length, `E[d²] = exp(2μ + 2σ²)`.
pub fn expected_variance(zone: &GpsZone) -> f64 {
    zone.bias_std * zone.bias_std + 0.5 * (2.0 * zone.mu + 2.0 * zone.sigma * zone.sigma).exp()
}

#[derive(Component, Clone, Debug)]
pub struct Gps {
    pub spec: GpsSpec,
    pub rng: SimRng,
    pub timer: RateTimer,
    pub enabled: bool,
    pub model: GpsErrorModel,
}

impl Gps {
    pub fn new(spec: GpsSpec, rng: SimRng) -> Self {
        Gps {
            timer: RateTimer::new(spec.rate, 0.0),
            spec,
            rng,
            enabled: true,
            model: GpsErrorModel::new(),
        }
    }
}

#[derive(Component, Clone, Debug, Default)]
pub struct GpsReadings {
    pub fixes: Vec<GpsFix>,
}

/// Sense: the fixes due in this tick, at the truth interpolated to their stamps. Without a
/// [`GeoFrame`] (the world builder inserts one for every world with a GPS) latitude and
/// longitude are taken around (0°, 0°).
pub fn sample_gps(
    clock: Res<SimClock>,
    frame: Option<Res<GeoFrame>>,
    zones: Option<Res<Zones>>,
    mut receivers: Query<(&TruePose, &mut Gps, &mut GpsReadings)>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    let projection = frame.map(|f| f.0).unwrap_or_else(|| {
        LocalProjection::new(GeoPoint::new(0.0, 0.0)).expect("(0°, 0°) is a valid reference")
    });
    let open = Zones::default();
    let zones = zones.as_deref().unwrap_or(&open);
    let mut due = Vec::new();
    for (truth, mut gps, mut out) in receivers.iter_mut() {
        out.fixes.clear();
        let gps = &mut *gps;
        gps.timer.due(start, end, &mut due);
        if !gps.enabled {
            continue;
        }
        for &t in &due {
            if t < gps.spec.first_fix {
                continue;
            }
            let f = ((t - start) / dt).clamp(0.0, 1.0);
            let pose = truth.interpolate(f);
            let at = [pose.x, pose.y];
            let zone = zones.gps_at(at);
            let fix = gps.model.sample(t, at, &zone, &mut gps.rng);
            let var = expected_variance(&zone);
            out.fixes.push(GpsFix {
                stamp: t,
                position: projection.to_geo(fix),
                altitude: gps.spec.altitude,
                covariance: [var, var, 4.0 * var],
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::world::zones::ZoneKind;

    fn errors(zone: &GpsZone, n: usize, rate: f64, seed: u64) -> Vec<[f64; 2]> {
        let mut rng = stream_rng(seed, "gps", "test");
        let mut m = GpsErrorModel::new();
        (0..n)
            .map(|k| m.sample(k as f64 / rate, [10.0, -5.0], zone, &mut rng))
            .map(|p| [p[0] - 10.0, p[1] + 5.0])
            .collect()
    }

    #[test]
    fn without_bias_the_error_length_is_the_thesis_log_normal() {
        let zone = GpsZone {
            bias_std: 0.0,
            outlier_probability: 0.0,
            ..ZoneKind::Open.gps()
        };
        let logs: Vec<f64> = errors(&zone, 20_000, 5.0, 1)
            .iter()
            .map(|e| e[0].hypot(e[1]).ln())
            .collect();
        let n = logs.len() as f64;
        let mean = logs.iter().sum::<f64>() / n;
        let std = (logs.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!((mean - 1.0).abs() < 0.02, "mean of ln d = {mean}");
        assert!((std - 0.506).abs() < 0.02, "std of ln d = {std}");
        // most errors 0.5–4 m, as the thesis says (e^(1 ± 1.96·0.506) = 1.0–7.3 m)
        let within = logs.iter().filter(|l| l.exp() <= 4.0).count() as f64 / n;
        assert!(within > 0.7, "{within}");
    }

    #[test]
    fn the_bias_puts_the_mean_fix_metres_off_between_buildings() {
        // 100 fixes 200 ms apart, as the thesis sampled each place; the mean stays off the truth
        let zone = ZoneKind::Buildings.gps();
        let offsets: Vec<f64> = (0..40)
            .map(|seed| {
                let e = errors(&zone, 100, 5.0, seed);
                let m = e.iter().fold([0.0, 0.0], |s, p| {
                    [s[0] + p[0] / 100.0, s[1] + p[1] / 100.0]
                });
                m[0].hypot(m[1])
            })
            .collect();
        let mut sorted = offsets.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[20];
        assert!(
            (2.0..10.0).contains(&median),
            "median offset of the mean fix {median} m"
        );
        // in the open the mean fix is within about 1–2 m
        let open: Vec<f64> = (0..40)
            .map(|seed| {
                let e = errors(&ZoneKind::Open.gps(), 100, 5.0, seed);
                let m = e.iter().fold([0.0, 0.0], |s, p| {
                    [s[0] + p[0] / 100.0, s[1] + p[1] / 100.0]
                });
                m[0].hypot(m[1])
            })
            .collect();
        assert!(
            open.iter().all(|&d| d < 10.0),
            "the mean fix is always within 10 m in the open"
        );
        let mut o = open.clone();
        o.sort_by(f64::total_cmp);
        assert!(o[20] < median, "open {} vs buildings {median}", o[20]);
    }

    #[test]
    fn outliers_are_rare_and_tens_of_metres_off() {
        let zone = GpsZone {
            outlier_probability: 0.05,
            ..ZoneKind::Open.gps()
        };
        let e = errors(&zone, 10_000, 5.0, 3);
        let far: Vec<f64> = e
            .iter()
            .map(|e| e[0].hypot(e[1]))
            .filter(|&d| d >= 20.0)
            .collect();
        let share = far.len() as f64 / e.len() as f64;
        assert!((0.04..0.06).contains(&share), "{share}");
        assert!(far.iter().all(|&d| d <= 60.0));
    }

    #[test]
    fn same_seed_same_fixes() {
        let z = ZoneKind::Trees.gps();
        assert_eq!(errors(&z, 50, 10.0, 9), errors(&z, 50, 10.0, 9));
        assert_ne!(errors(&z, 50, 10.0, 9), errors(&z, 50, 10.0, 10));
    }
}
