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
pub mod collision_guard;
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

use crate::core::{Chained, SimPlugin, SimSet, any_with};
use bevy_ecs::prelude::*;

pub struct NavigationPlugin;

impl SimPlugin for NavigationPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.init_resource::<Fleet>();
        let navigators = any_with::<Navigator>(world);
        let road_navigators = any_with::<road_drive::RoadNavigator>(world);
        Chained::new()
            .add(
                world.contains_resource::<NavCostmaps>(),
                shared_costmaps::sync_costmaps,
            )
            .add(navigators, drive::plan_routes)
            // the camera image of the previous tick's Sense set
            .add(
                any_with::<RoadDetector>(world),
                road_recognition::detect_roads,
            )
            .add_to(schedule, SimSet::Plan);
        // All four write DriveCommand, each for the robots it drives (with a navigator, a road
        // navigator, a behaviour, or a command held by the program), in this order.
        Chained::new()
            .add(navigators, drive::drive_navigators)
            .add(road_navigators, road_drive::system::drive_road_navigators)
            .add(any_with::<Behaviour>(world), behaviour::drive_behaviours)
            // a held command replaces theirs
            .add(any_with::<HeldCommand>(world), held::apply_held_commands)
            .add_to(schedule, SimSet::Control);
    }
}
