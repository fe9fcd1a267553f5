//! Navigation (Plan and Control sets). Everything here reads the robot's belief
//! ([`NavBelief`](crate::localization::NavBelief)) and its sensor readings, never ground truth.
//!
//! - [`costmap`]: the static map inflated by the robot radius plus a margin, with a cost
//!   gradient near walls ([`shared_costmaps`]: one per inflation setting, rebuilt when a door
//!   moves);
//! - [`astar`]: the global planner, with [`shortcut`] line-of-sight shortening;
//! - [`follower`]: pure pursuit for differential-drive and Ackermann robots;
//! - [`navigator`]: task queues (deliveries, trips, waits: [`tasks`]), stop-and-wait at
//!   obstacles, re-planning, and the yield rule between robots ([`fleet`]); [`drive`] holds its
//!   systems;
//! - [`road_planner`]: A* on the outdoor road graph with the no-U-turn rule;
//! - [`behaviour`]: simple behaviours without a planner (waypoints, wander) with reactive
//!   avoidance ([`avoid`]).

pub mod astar;
pub mod avoid;
pub mod behaviour;
pub mod costmap;
pub mod drive;
pub mod fleet;
pub mod follower;
pub mod held;
pub mod local_map;
pub mod navigator;
pub mod open_list;
pub mod outcomes;
pub mod road_drive;
pub mod road_follow;
pub mod road_planner;
pub mod road_recognition;
pub mod shared_costmaps;
pub mod shortcut;
pub mod tasks;

pub use astar::{Path, PlanError, Planner, PlannerParams};
pub use behaviour::{Behaviour, BehaviourKind, NavStatus};
pub use costmap::{Costmap, CostmapParams};
pub use fleet::Fleet;
pub use follower::{FollowerParams, Steering};
pub use held::HeldCommand;
pub use navigator::{NavParams, Navigator, Phase};
pub use outcomes::{LegEvent, NavEvent, NavFailure, NavMetrics};
pub use road_follow::{Keep, RoadCommand, RoadFollowParams, road_steering};
pub use road_recognition::{
    RecognitionConfig, RoadDetection, RoadDetector, RoadRecognizer, RoadRow, detect_roads,
};
pub use shared_costmaps::NavCostmaps;
pub use tasks::{Goal, Step, Task, TaskKind};

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct NavigationPlugin;

impl SimPlugin for NavigationPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.init_resource::<Fleet>();
        schedule.add_systems(
            (
                shared_costmaps::sync_costmaps,
                drive::plan_routes,
                // the camera image of the previous tick's Sense set
                road_recognition::detect_roads,
            )
                .chain()
                .in_set(SimSet::Plan),
        );
        // All three write DriveCommand, each for the robots it drives (with a navigator, a road
        // navigator, or a behaviour): navigators, then road navigators, then behaviours, the order
        // they ran in before it was explicit. The systems stay in the order they were added in,
        // which the executor's order of Control's other systems (walk_people) depends on.
        schedule.add_systems(
            (
                behaviour::drive_behaviours,
                drive::drive_navigators.before(road_drive::system::drive_road_navigators),
                road_drive::system::drive_road_navigators.before(behaviour::drive_behaviours),
                // a held command replaces theirs
                held::apply_held_commands.after(behaviour::drive_behaviours),
            )
                .in_set(SimSet::Control),
        );
    }
}
