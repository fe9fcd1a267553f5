//! The tick orders of every bundled scenario's run and of a replay build with bevy's ambiguity
//! detection as an error, every system in a set, and are the orders saved in
//! sim/tests/tick_order/ (so a change of order shows in review).

use super::*;
use crate::options::parse_args;
use crate::record::mcap::McapRecording;
use crate::replay::{ReplayArgs, plan};
use crate::scenario::{bundled_scenarios, load_scenario};
use bevy_ecs::prelude::*;
use systems::core::new_schedule;
use systems::core::source::source_path;

/// Compares `order` with sim/tests/tick_order/`name`.txt (`sim schedule`'s output); writes
/// the file instead when `SIM_UPDATE_TICK_ORDER` is set (then review the diff).
fn check_saved(name: &str, order: &[TickSystem]) {
    let unset: Vec<&str> = order
        .iter()
        .filter(|s| s.set.is_none())
        .map(|s| s.name.as_str())
        .collect();
    assert!(unset.is_empty(), "{name}: systems in no SimSet: {unset:?}");
    let text = format_tick_order(order);
    let path = source_path("sim/tests/tick_order").join(format!("{name}.txt"));
    if std::env::var_os("SIM_UPDATE_TICK_ORDER").is_some() {
        std::fs::write(&path, &text).unwrap();
        return;
    }
    let saved =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        text == saved,
        "{name}: the tick order changed; it is now\n{text}\nand was ({}):\n{saved}\n\
         (SIM_UPDATE_TICK_ORDER=1 saves the new order)",
        path.display()
    );
}

#[test]
fn every_bundled_scenario_runs_an_unambiguous_saved_tick_order() {
    let scenarios = bundled_scenarios().unwrap();
    assert!(scenarios.len() >= 7, "{scenarios:?}");
    for (name, path) in scenarios {
        let sc = load_scenario(&path).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let sim = build_world(&sc, 1).unwrap();
        let order =
            run_tick_order(sim, &sc, false, dir.path()).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_saved(&name, &order);
    }
}

#[test]
fn the_replay_of_a_recording_runs_an_unambiguous_saved_tick_order() {
    let file = source_path("replays/hospital_r1-seed0.mcap");
    let scenario = source_path("replays/hospital_r1.toml");
    let a = parse_args::<ReplayArgs>(&[
        file.to_str().unwrap(),
        "--scenario",
        scenario.to_str().unwrap(),
    ])
    .unwrap();
    let plan = plan(&a, &McapRecording::open(&a.file).unwrap()).unwrap();
    let (sim, sc) = build_replay(plan, 1).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let order = run_tick_order(sim, &sc, true, dir.path()).unwrap_or_else(|e| panic!("{e}"));
    check_saved("replay-hospital_r1", &order);
}

#[derive(Resource, Default)]
struct Count(u32);

fn add_one(mut c: ResMut<Count>) {
    c.0 += 1;
}

fn double(mut c: ResMut<Count>) {
    c.0 *= 2;
}

/// The check is not vacuous: two systems of a set writing one resource, unordered, fail to
/// build; chained, they build.
#[test]
fn two_conflicting_systems_without_an_order_are_an_error() {
    let mut world = World::new();
    world.init_resource::<Count>();
    let mut schedule = new_schedule();
    schedule.add_systems((add_one, double).in_set(SimSet::Evaluate));
    deny_ambiguities(&mut schedule);
    let e = tick_order(&mut schedule, &mut world).unwrap_err();
    assert!(e.contains("add_one") && e.contains("double"), "{e}");

    let mut schedule = new_schedule();
    schedule.add_systems((add_one, double).chain().in_set(SimSet::Evaluate));
    deny_ambiguities(&mut schedule);
    let order = tick_order(&mut schedule, &mut world).unwrap();
    let names: Vec<&str> = order.iter().map(|s| s.name.as_str()).collect();
    assert!(
        names[0].ends_with("add_one") && names[1].ends_with("double"),
        "{names:?}"
    );
}
