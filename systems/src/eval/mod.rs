//! Evaluation against ground truth: per-robot distance, collisions and odometry drift, and the
//! accuracy of every localizer (ATE, RPE, convergence, tracking), and navigation outcomes.

pub mod localization_metrics;
pub mod navigation_metrics;
pub mod road_metrics;
pub mod robot_metrics;
pub mod tracking;
pub mod trajectory;

pub use localization_metrics::{
    LocalizationSamples, LocalizerMetrics, TrajectoryMetrics, judged_samples, pair_with_truth,
};
pub use navigation_metrics::NavOutcome;
pub use robot_metrics::RobotMetrics;
pub use tracking::{LostEpisode, TrackingRecord, tracking_record};
pub use trajectory::Sample;

use crate::core::{Chained, SimPlugin, SimSet, any_with};
use bevy_ecs::prelude::*;

pub struct EvalPlugin;

impl SimPlugin for EvalPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        // evaluate_navigation reads the metrics accumulate_metrics writes; the other two share
        // nothing with them, and are chained too so that the order is the same in every run
        Chained::new()
            .add(
                any_with::<RobotMetrics>(world),
                robot_metrics::accumulate_metrics,
            )
            .add(
                any_with::<NavOutcome>(world),
                navigation_metrics::evaluate_navigation,
            )
            .add(
                any_with::<LocalizationSamples>(world),
                localization_metrics::sample_localization,
            )
            .add(
                any_with::<road_metrics::RoadRunMetrics>(world),
                road_metrics::evaluate_road_runs,
            )
            .add_to(schedule, SimSet::Evaluate);
    }
}
