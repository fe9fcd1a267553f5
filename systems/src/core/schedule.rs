//! One tick, in order (systems/ARCHITECTURE.md, "One tick"): Script, Plan, Control, Physics, Sense,
//! Estimate, Map, Evaluate, Record. The schedule runs on bevy's single-threaded executor so the
//! order of every system, and so every result, is deterministic; parallelism lives inside kernels.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{ScheduleLabel, SingleThreadedExecutor};

#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimSet {
    /// Scenario events fire (goals, doors, kidnapping, sensor faults).
    Script,
    /// Global planners.
    Plan,
    /// Followers and behaviours turn goals into drive commands.
    Control,
    /// Kinematics and rapier2d contacts produce the ground-truth pose.
    Physics,
    /// Sensors sample ground truth at their own rates and add noise.
    Sense,
    /// Estimators read sensor readings only.
    Estimate,
    /// Mapping and SLAM.
    Map,
    /// Errors against ground truth.
    Evaluate,
    /// Recording.
    Record,
}

#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct Tick;

/// A new tick schedule with the sets chained in order and the single-threaded executor.
pub fn new_schedule() -> Schedule {
    let mut schedule = Schedule::new(Tick);
    schedule.set_executor(SingleThreadedExecutor::new());
    schedule.configure_sets(
        (
            SimSet::Script,
            SimSet::Plan,
            SimSet::Control,
            SimSet::Physics,
            SimSet::Sense,
            SimSet::Estimate,
            SimSet::Map,
            SimSet::Evaluate,
            SimSet::Record,
        )
            .chain(),
    );
    schedule
}

/// Each feature folder exposes one plugin that adds its systems (and resources) to the schedule.
pub trait SimPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule);
}
