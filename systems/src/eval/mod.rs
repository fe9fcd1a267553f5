//! Evaluation against ground truth: per-robot distance, collisions and odometry drift, and the
//! accuracy of every localizer (ATE, RPE, convergence, tracking), and navigation outcomes.

pub mod localization_metrics;
pub mod navigation_metrics;
pub mod road_metrics;
pub mod robot_metrics;
pub mod trajectory;

pub use localization_metrics::{
    LocalizationSamples, LocalizerMetrics, TrajectoryMetrics, judged_samples, pair_with_truth,
};
pub use navigation_metrics::NavOutcome;
pub use robot_metrics::RobotMetrics;
pub use trajectory::Sample;

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct EvalPlugin;

impl SimPlugin for EvalPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(
            (
                robot_metrics::accumulate_metrics,
                localization_metrics::sample_localization,
                road_metrics::evaluate_road_runs,
                navigation_metrics::evaluate_navigation.after(robot_metrics::accumulate_metrics),
            )
                .in_set(SimSet::Evaluate),
        );
    }
}
