//! Per-robot ground-truth metrics: distance driven, collisions (contact starts with walls and with
//! other robots) and wheel-odometry drift (position and heading error of the odometry estimate;
//! both start at the true start pose, so the drift is the accumulated error).

use crate::body::{Collisions, Physics, TruePose};
use crate::core::{RobotIndex, wrap_angle};
use crate::localization::WheelOdometry;
use bevy_ecs::prelude::*;

#[derive(Component, Clone, Debug, Default)]
pub struct RobotMetrics {
    pub distance_m: f64,
    pub collisions: Collisions,
    /// Current odometry position error (m).
    pub odometry_drift_m: f64,
    pub max_odometry_drift_m: f64,
    /// Σ of the squared odometry position error over the ticks, and the ticks counted.
    pub odometry_sq_sum: f64,
    pub odometry_samples: u64,
    /// Current odometry heading error (rad).
    pub odometry_heading_error_rad: f64,
}

/// Evaluate: accumulate the metrics of this tick.
pub fn accumulate_metrics(
    physics: Res<Physics>,
    mut robots: Query<(
        &RobotIndex,
        &TruePose,
        Option<&WheelOdometry>,
        &mut RobotMetrics,
    )>,
) {
    for (idx, truth, odom, mut m) in robots.iter_mut() {
        m.distance_m += truth.prev.distance(&truth.pose);
        m.collisions = physics.collisions(idx.0);
        if let Some(o) = odom {
            m.odometry_drift_m = o.pose.distance(&truth.pose);
            m.max_odometry_drift_m = m.max_odometry_drift_m.max(m.odometry_drift_m);
            m.odometry_sq_sum += m.odometry_drift_m * m.odometry_drift_m;
            m.odometry_samples += 1;
            m.odometry_heading_error_rad = wrap_angle(o.pose.theta - truth.pose.theta).abs();
        }
    }
}

impl RobotMetrics {
    /// The absolute trajectory error of wheel odometry alone: RMSE of its position error over
    /// every tick (m); 0 without odometry.
    pub fn odometry_ate_m(&self) -> f64 {
        if self.odometry_samples == 0 {
            return 0.0;
        }
        (self.odometry_sq_sum / self.odometry_samples as f64).sqrt()
    }
}
