//! Evaluation against ground truth: per-robot distance, collisions and odometry drift.

pub mod robot_metrics;

pub use robot_metrics::RobotMetrics;

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct EvalPlugin;

impl SimPlugin for EvalPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(robot_metrics::accumulate_metrics.in_set(SimSet::Evaluate));
    }
}
