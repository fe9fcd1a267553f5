//! `sim schedule`: the tick order of a run and of a replay, set by set.

use crate::common::{expect_failure, run_ok};

/// The set headers of `sim schedule`'s output, in order.
fn sets(out: &str) -> Vec<&str> {
    out.lines().filter(|l| !l.starts_with(' ')).collect()
}

const SETS: [&str; 9] = [
    "Script", "Plan", "Control", "Physics", "Sense", "Estimate", "Map", "Evaluate", "Record",
];

#[test]
fn schedule_prints_every_set_in_tick_order_with_its_systems() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_ok(&["schedule"], dir.path());
    assert_eq!(sets(&out), SETS, "{out}");
    for want in [
        "   1 sim::build::script::fire_events",
        " systems::mapping::run_slam",
        " sim::record::rrd::record_rrd",
        " sim::record::topics::record::record_mcap",
    ] {
        assert!(out.contains(want), "expected `{want}` in:\n{out}");
    }
    // the numbers count up through the sets
    let numbers: Vec<usize> = out
        .lines()
        .filter_map(|l| l.split_whitespace().next()?.parse().ok())
        .collect();
    assert_eq!(numbers, (1..=numbers.len()).collect::<Vec<_>>(), "{out}");
    // the outputs' files went to a temporary folder
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

    let replay = run_ok(&["schedule", "hospital_patrol", "--replay"], dir.path());
    assert_eq!(sets(&replay), SETS, "{replay}");
    assert!(
        replay.contains("Physics\n  (none)\n")
            && replay.contains(" sim::replay::feed::feed_recorded"),
        "{replay}"
    );
}

#[test]
fn schedule_of_an_unknown_scenario_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(&["schedule", "nowhere"], dir.path(), &["nowhere"]);
}
