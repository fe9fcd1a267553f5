//! What every feature's resolver shares: the checker that turns a bad value into an error
//! naming the file, line and key, the name rule, and points given as coordinates or place
//! names. A leaf: it imports nothing else of the scenario but its errors.

use super::error::{ErrorContext, KeyPath, ScenarioError};
use serde::Deserialize;

/// A point given as coordinates or as the name of a place.
#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
pub enum PointOrPlace {
    Coords(Vec<f64>),
    Place(String),
}

pub(super) type R<T> = Result<T, ScenarioError>;

pub(super) struct Checker<'a> {
    pub(super) cx: ErrorContext<'a>,
    /// Where the robots' odometry comes from (what a localizer needs besides the laser).
    pub(super) odometry: OdometrySource,
}

/// Where the robots' odometry comes from: what decides whether a robot with localizers or SLAM
/// needs `[robots.sensors.encoder]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OdometrySource {
    /// The simulated wheel encoders (a run; a replay of recorded encoder ticks).
    #[default]
    Encoders,
    /// Recorded odometry poses (a replay of an odometry topic): no encoder needed.
    Recorded,
}

impl Checker<'_> {
    pub(super) fn err<T>(&self, path: &KeyPath, msg: impl Into<String>) -> R<T> {
        Err(self.cx.at(path, msg))
    }

    /// A finite number in [lo, hi] (either bound optional), `open_lo` excluding lo.
    pub(super) fn range(
        &self,
        path: &KeyPath,
        v: f64,
        lo: Option<f64>,
        hi: Option<f64>,
        open_lo: bool,
    ) -> R<f64> {
        let below = match lo {
            Some(l) if open_lo => v <= l,
            Some(l) => v < l,
            None => false,
        };
        let above = hi.is_some_and(|h| v > h);
        if !v.is_finite() || below || above {
            let want = match (lo, hi) {
                (Some(l), Some(h)) if open_lo => format!("a number in ({l}, {h}]"),
                (Some(l), Some(h)) => format!("a number in [{l}, {h}]"),
                (Some(l), None) if open_lo => format!("a number greater than {l}"),
                (Some(l), None) => format!("a number of at least {l}"),
                (None, Some(h)) => format!("a number of at most {h}"),
                (None, None) => "a finite number".to_string(),
            };
            return self.err(path, format!("expected {want}, got {v}"));
        }
        Ok(v)
    }

    pub(super) fn positive(&self, path: &KeyPath, v: f64) -> R<f64> {
        self.range(path, v, Some(0.0), None, true)
    }

    pub(super) fn opt_positive(&self, path: &KeyPath, v: Option<f64>, default: f64) -> R<f64> {
        match v {
            Some(v) => self.positive(path, v),
            None => Ok(default),
        }
    }

    pub(super) fn finite(&self, path: &KeyPath, vals: &[f64]) -> R<()> {
        if vals.iter().any(|v| !v.is_finite()) {
            return self.err(path, format!("expected finite numbers, got {vals:?}"));
        }
        Ok(())
    }
}

pub(super) fn check_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}
