//! Evaluation against ground truth: per-robot distance, collisions and odometry drift, and the
//! accuracy of every localizer (ATE, RPE, convergence, tracking).

pub mod localization_metrics;
pub mod robot_metrics;
pub mod trajectory;

pub use localization_metrics::{LocalizationSamples, LocalizerMetrics, judged_samples};
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
            )
                .in_set(SimSet::Evaluate),
        );
    }
}
