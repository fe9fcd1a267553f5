//! One tick, in order (systems/ARCHITECTURE.md, "One tick"): Script, Plan, Control, Physics, Sense,
//! Estimate, Map, Evaluate, Record. The schedule runs on bevy's single-threaded executor so the
//! order of every system, and so every result, is deterministic; parallelism lives inside kernels.
//!
//! Every system belongs to a [`SimSet`], and two systems of a set whose accesses conflict are
//! ordered explicitly (`.chain()`, `.before`, `.after`): [`deny_ambiguities`] makes building a
//! schedule with an unordered conflicting pair an error, and [`tick_order`] lists the systems in
//! the order the executor runs them (`sim schedule` prints it).

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{
    Chain, IntoScheduleConfigs, LogLevel, ScheduleBuildSettings, ScheduleConfigs, ScheduleLabel,
    SingleThreadedExecutor, SystemSet,
};
use bevy_ecs::system::ScheduleSystem;
use std::collections::HashMap;

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

impl SimSet {
    /// The sets in tick order.
    pub const ALL: [SimSet; 9] = [
        SimSet::Script,
        SimSet::Plan,
        SimSet::Control,
        SimSet::Physics,
        SimSet::Sense,
        SimSet::Estimate,
        SimSet::Map,
        SimSet::Evaluate,
        SimSet::Record,
    ];
}

#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct Tick;

/// A new tick schedule with the sets chained in order and the single-threaded executor.
pub fn new_schedule() -> Schedule {
    let mut schedule = Schedule::new(Tick);
    schedule.set_executor(SingleThreadedExecutor::new());
    for pair in SimSet::ALL.windows(2) {
        schedule.configure_sets(pair[1].after(pair[0]));
    }
    schedule
}

/// Makes building `schedule` fail when two systems with conflicting accesses (one writes what the
/// other reads or writes) have no order between them: bevy's ambiguity detection as an error.
/// The tests of the run's schedules use it (and `sim schedule`); a run does not need to.
pub fn deny_ambiguities(schedule: &mut Schedule) {
    schedule.set_build_settings(ScheduleBuildSettings {
        ambiguity_detection: LogLevel::Error,
        // names with their module path, so a report says where a system lives
        use_shortnames: false,
        ..ScheduleBuildSettings::default()
    });
}

/// A system of a built schedule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TickSystem {
    /// Its set (None: in no [`SimSet`]).
    pub set: Option<SimSet>,
    /// The system's name: its function's path (`systems::mapping::run_slam`).
    pub name: String,
}

/// Builds `schedule` for `world` (as its first run would) and lists its systems in the order the
/// executor runs them. An error (with the systems' names) if it cannot be built, e.g. an
/// ambiguity after [`deny_ambiguities`].
pub fn tick_order(schedule: &mut Schedule, world: &mut World) -> Result<Vec<TickSystem>, String> {
    if let Err(e) = schedule.initialize(world) {
        return Err(e.to_string(schedule.graph(), world));
    }
    let graph = schedule.graph();
    let mut set_of = HashMap::new();
    for set in SimSet::ALL {
        // a set no system was added to is unknown to the graph
        if let Ok(keys) = graph.systems_in_set(set.intern()) {
            for &key in keys {
                set_of.insert(key, set);
            }
        }
    }
    let systems = schedule
        .systems()
        .map_err(|e| format!("{e:?}"))?
        .map(|(key, system)| TickSystem {
            set: set_of.get(&key).copied(),
            name: system.name().to_string(),
        })
        .collect();
    Ok(systems)
}

/// Each feature folder exposes one plugin that adds its systems (and resources) to the schedule.
/// A plugin builds after the world is populated and adds only the systems that have something to
/// work on in it ([`any_with`], [`Chained`]): a system with nothing to do still costs the executor
/// and its parameters' fetching every tick, which in a one-robot world is most of the tick.
pub trait SimPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule);
}

/// Whether some entity of `world` has component `C`.
pub fn any_with<C: Component>(world: &mut World) -> bool {
    world
        .query_filtered::<(), With<C>>()
        .iter(world)
        .next()
        .is_some()
}

/// Systems of one set that run in the order they are added, like `.chain()`, where each may be
/// left out: a plugin adds a system only when what it works on is present.
#[derive(Default)]
pub struct Chained(Vec<ScheduleConfigs<ScheduleSystem>>);

impl Chained {
    pub fn new() -> Self {
        Chained::default()
    }

    /// Appends `system` when `present`.
    pub fn add<M>(
        mut self,
        present: bool,
        system: impl IntoScheduleConfigs<ScheduleSystem, M>,
    ) -> Self {
        if present {
            self.0.push(system.into_configs());
        }
        self
    }

    /// Adds the systems kept, in order, to `set` of `schedule`.
    pub fn add_to(self, schedule: &mut Schedule, set: SimSet) {
        if self.0.is_empty() {
            return;
        }
        let group = ScheduleConfigs::Configs {
            configs: self.0,
            collective_conditions: Vec::new(),
            metadata: Chain::Unchained,
        };
        schedule.add_systems(group.chain().in_set(set));
    }
}
