//! `[robots.sensors.laser]` and `[robots.sensors.encoder]`: presets with overrides, checked,
//! and the range limits every range sensor shares.

use super::check::{Checker, R};
use super::error::KeyPath;
use serde::Deserialize;
use systems::core::Pose2;
use systems::sensors::{EncoderSpec, LaserSpec};

/// `[robots.sensors.laser]`: a preset (default `sick_lms100`) and the values that override it.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct LaserFile {
    pub preset: Option<String>,
    pub fov_deg: Option<f64>,
    pub increment_deg: Option<f64>,
    pub min_range: Option<f64>,
    pub max_range: Option<f64>,
    pub rate: Option<f64>,
    pub noise_std: Option<f64>,
    pub dropout: Option<f64>,
    /// [x, y, yaw] in the robot frame.
    pub mount: Option<[f64; 3]>,
}

/// `[robots.sensors.encoder]`: wheel encoders; the values not given are the defaults.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct EncoderFile {
    pub ticks_per_rev: Option<u32>,
    pub left_radius_error: Option<f64>,
    pub right_radius_error: Option<f64>,
    pub wheel_base_error: Option<f64>,
    pub slip_std: Option<f64>,
    pub rate: Option<f64>,
}

/// The keys every range sensor (laser, sonar) has, as written.
pub(super) struct RangeKeys {
    pub min_range: Option<f64>,
    pub max_range: Option<f64>,
    pub rate: Option<f64>,
    pub noise_std: Option<f64>,
}

impl RangeKeys {
    /// Applies the keys given over a preset's `[min_range, max_range, rate, noise_std]`,
    /// checking each (max_range up to `max_cap` m) and that min_range < max_range.
    pub(super) fn apply(&self, c: &Checker, p: &KeyPath, v: [&mut f64; 4], max_cap: f64) -> R<()> {
        let [min, max, rate, noise] = v;
        if let Some(x) = self.min_range {
            *min = c.range(&p.key("min_range"), x, Some(0.0), None, false)?;
        }
        if let Some(x) = self.max_range {
            *max = c.range(&p.key("max_range"), x, Some(0.0), Some(max_cap), true)?;
        }
        if *min >= *max {
            let key = if self.min_range.is_some() {
                "min_range"
            } else {
                "max_range"
            };
            return c.err(
                &p.key(key),
                format!("min_range ({min}) must be below max_range ({max})"),
            );
        }
        if let Some(x) = self.rate {
            *rate = c.range(&p.key("rate"), x, Some(0.0), Some(1000.0), true)?;
        }
        if let Some(x) = self.noise_std {
            *noise = c.range(&p.key("noise_std"), x, Some(0.0), Some(10.0), false)?;
        }
        Ok(())
    }
}

pub(super) fn resolve_laser(c: &Checker, p: &KeyPath, l: &LaserFile) -> R<LaserSpec> {
    let preset = l.preset.as_deref().unwrap_or("sick_lms100");
    let Some(mut s) = LaserSpec::preset(preset) else {
        return c.err(
            &p.key("preset"),
            format!(
                "unknown laser preset `{preset}`; known: {}",
                LaserSpec::PRESETS.join(", ")
            ),
        );
    };
    if let Some(v) = l.fov_deg {
        s.fov = c
            .range(&p.key("fov_deg"), v, Some(0.0), Some(360.0), true)?
            .to_radians();
    }
    if let Some(v) = l.increment_deg {
        s.increment = c
            .range(&p.key("increment_deg"), v, Some(0.0), Some(90.0), true)?
            .to_radians();
    }
    if s.beams() > LaserSpec::MAX_BEAMS {
        return c.err(
            &p.key("increment_deg"),
            format!(
                "{} beams per scan is more than {}",
                s.beams(),
                LaserSpec::MAX_BEAMS
            ),
        );
    }
    RangeKeys {
        min_range: l.min_range,
        max_range: l.max_range,
        rate: l.rate,
        noise_std: l.noise_std,
    }
    .apply(
        c,
        p,
        [
            &mut s.min_range,
            &mut s.max_range,
            &mut s.rate,
            &mut s.noise_std,
        ],
        1000.0,
    )?;
    if let Some(v) = l.dropout {
        s.dropout = c.range(&p.key("dropout"), v, Some(0.0), Some(1.0), false)?;
    }
    if let Some(m) = l.mount {
        c.finite(&p.key("mount"), &m)?;
        s.mount = Pose2::new(m[0], m[1], m[2]);
    }
    Ok(s)
}

pub(super) fn resolve_encoder(c: &Checker, p: &KeyPath, e: &EncoderFile) -> R<EncoderSpec> {
    let mut s = EncoderSpec::default();
    if let Some(t) = e.ticks_per_rev {
        if t == 0 {
            return c.err(
                &p.key("ticks_per_rev"),
                "expected at least 1 tick per revolution",
            );
        }
        s.ticks_per_rev = t;
    }
    let rel = |key: &str, v: Option<f64>| -> R<f64> {
        match v {
            Some(v) => c.range(&p.key(key), v, Some(-0.5), Some(0.5), false),
            None => Ok(0.0),
        }
    };
    s.left_radius_error = rel("left_radius_error", e.left_radius_error)?;
    s.right_radius_error = rel("right_radius_error", e.right_radius_error)?;
    s.wheel_base_error = rel("wheel_base_error", e.wheel_base_error)?;
    if let Some(v) = e.slip_std {
        s.slip_std = c.range(&p.key("slip_std"), v, Some(0.0), Some(1.0), false)?;
    }
    if let Some(v) = e.rate {
        s.rate = c.range(&p.key("rate"), v, Some(0.0), Some(10_000.0), true)?;
    }
    Ok(s)
}
