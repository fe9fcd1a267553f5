//! Driving behaviours (Control set). For now: waypoint following and a laser-based wander, both
//! with reactive obstacle avoidance on the latest scan. They read the robot's belief
//! ([`NavBelief`](crate::localization::NavBelief)) and its sensor readings, never ground truth.
//! Global planning: the static [`costmap`] and A* on it.

pub mod astar;
pub mod avoid;
pub mod behaviour;
pub mod costmap;
pub mod open_list;
pub mod shortcut;

pub use astar::{Path, PlanError, Planner, PlannerParams};
pub use behaviour::{Behaviour, BehaviourKind, NavStatus};
pub use costmap::{Costmap, CostmapParams};

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct NavigationPlugin;

impl SimPlugin for NavigationPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(behaviour::drive_behaviours.in_set(SimSet::Control));
    }
}
