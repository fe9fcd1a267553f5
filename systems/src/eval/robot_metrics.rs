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
            m.odometry_heading_error_rad = wrap_angle(o.pose.theta - truth.pose.theta).abs();
        }
    }
}
