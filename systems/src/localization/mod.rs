//! Estimators: they read sensor readings only, never ground truth. For now: wheel odometry, which
//! also provides the belief controllers navigate by.

pub mod odometry;

pub use odometry::{NavBelief, OdometryModel, WheelOdometry};

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct LocalizationPlugin;

impl SimPlugin for LocalizationPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(odometry::integrate_odometry.in_set(SimSet::Estimate));
    }
}
