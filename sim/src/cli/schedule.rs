//! `sim schedule [SCENARIO] [--replay]`: the tick order of a scenario's run, the systems per
//! [`SimSet`] in the order the executor runs them (systems/ARCHITECTURE.md, "One tick"). The world
//! is built as a run builds it, with every output such a run can have (the .rrd recording, the
//! MCAP replay, the CARMEN logs when a robot can be exported, the maps when a robot can map; a
//! replay: the recording and the maps), their files in a temporary folder; bevy's ambiguity
//! detection is an error, so the command fails naming any two conflicting systems left
//! unordered.

use crate::build::{SimWorld, build_world};
use crate::formats::carmen::export::exported_robots;
use crate::formats::maps::can_map;
use crate::replay::{ReplayPlan, build_replay};
use crate::run::exports::RunExports;
use crate::run::output_plugins;
use crate::scenario::{Scenario, scenario_arg};
use std::fmt::Write as _;
use std::path::Path;
use systems::core::{SimSet, TickSystem, deny_ambiguities, tick_order};

#[derive(clap::Args, Clone, Debug)]
pub struct ScheduleArgs {
    /// A scenario file or the name of a bundled scenario (default: hospital_patrol).
    pub scenario: Option<String>,
    /// The schedule of a replay of the scenario (`sim replay`): the estimators and the evaluation
    /// fed with recorded readings.
    #[arg(long)]
    pub replay: bool,
}

/// `sim schedule`.
pub fn schedule_command(a: &ScheduleArgs) -> anyhow::Result<()> {
    let sc = scenario_arg(a.scenario.as_deref())?;
    let dir = tempfile::tempdir()?;
    let sim = if a.replay {
        let plan = ReplayPlan {
            scenario: sc.clone(),
            run: None,
            feeds: Vec::new(),
        };
        build_replay(plan, 1)?.0
    } else {
        build_world(&sc, 1)?
    };
    let order = run_tick_order(sim, &sc, a.replay, dir.path())?;
    print!("{}", format_tick_order(&order));
    Ok(())
}

/// The tick order of `sim` (built from `scenario` for a run, or for a replay) once every output
/// such a run can have joins it, their files written in `dir`. An error if the schedule has two
/// conflicting systems without an order between them.
pub fn run_tick_order(
    mut sim: SimWorld,
    scenario: &Scenario,
    replay: bool,
    dir: &Path,
) -> anyhow::Result<Vec<TickSystem>> {
    let exports = RunExports {
        // only robots with a laser and encoders can be exported; `sim replay` exports none
        carmen_out: (!replay && !exported_robots(scenario).is_empty()).then(|| dir.join("run.log")),
        save_map: can_map(&mut sim.world).then(|| dir.join("map")),
        mcap: (!replay).then(|| dir.join("run.mcap")),
    };
    let rrd = dir.join("run.rrd");
    for p in output_plugins(&mut sim.world, scenario, Some(&rrd), &exports)? {
        p.build(&mut sim.world, &mut sim.schedule);
    }
    deny_ambiguities(&mut sim.schedule);
    tick_order(&mut sim.schedule, &mut sim.world).map_err(|e| anyhow::anyhow!("{e}"))
}

/// The systems per set, numbered in executor order:
///
/// ```text
/// Script
///    1 sim::build::script::fire_events
/// Plan
///    2 systems::navigation::shared_costmaps::sync_costmaps
/// ```
///
/// A set without systems shows `(none)`; systems in no set come last, under `(no set)`.
pub fn format_tick_order(order: &[TickSystem]) -> String {
    let mut out = String::new();
    let sets = SimSet::ALL.map(Some).into_iter().chain([None]);
    for set in sets {
        let systems: Vec<(usize, &TickSystem)> = order
            .iter()
            .enumerate()
            .filter(|(_, s)| s.set == set)
            .collect();
        match set {
            Some(set) => writeln!(out, "{set:?}"),
            None if systems.is_empty() => continue,
            None => writeln!(out, "(no set)"),
        }
        .unwrap();
        if systems.is_empty() {
            out.push_str("  (none)\n");
        }
        for (i, s) in systems {
            writeln!(out, "{:>4} {}", i + 1, s.name).unwrap();
        }
    }
    out
}

#[cfg(test)]
mod tests;
