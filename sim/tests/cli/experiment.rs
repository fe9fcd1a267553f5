//! `sim experiment` (`maze-slam`, `park`, `de-match`): bad options are refused before any
//! simulation, naming the option.

use crate::common::{expect_failure, sim};

#[test]
fn slam_experiment_and_bench_refuse_bad_options_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &[
            "experiment",
            "maze-slam",
            "--methods",
            "scan_to_map,gmapping",
        ],
        dir.path(),
        &["--methods", "unknown method `gmapping`"],
    );
    expect_failure(
        &["bench", "slam", "--modes", "hector"],
        dir.path(),
        &["--modes", "hector"],
    );
    expect_failure(
        &["bench", "slam", "--duration", "-5"],
        dir.path(),
        &["--duration", "positive"],
    );
}

#[test]
fn maze_slam_names_scenarios_when_one_has_nothing_to_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(
        &[
            "experiment",
            "maze-slam",
            "--scenarios",
            "park_route_short",
            "--methods",
            "wheel_odometry",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--scenarios") && err.contains("park_route_short"),
        "{err}"
    );
    assert!(!err.contains("--carmen-out"), "{err}");
    assert!(
        !err.contains("simulating"),
        "checked before simulating: {err}"
    );
}

#[test]
fn park_refuses_absurd_run_counts_and_repeated_routes() {
    let dir = tempfile::tempdir().unwrap();
    for runs in ["100001", "4294967296"] {
        expect_failure(
            &["experiment", "park", "--runs", runs],
            dir.path(),
            &["--runs", "100000", runs],
        );
    }
    // commas and spaces both separate routes; the same route twice is refused
    for routes in [
        &["park_route_short,park_route_short"][..],
        &["park_route_short", "park_route_short"][..],
    ] {
        let mut args = vec!["experiment", "park", "--runs", "1", "--routes"];
        args.extend(routes);
        expect_failure(
            &args,
            dir.path(),
            &["--routes", "park_route_short", "twice"],
        );
    }
}

#[test]
fn park_per_run_needs_json() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["experiment", "park", "--runs", "1", "--per-run"],
        dir.path(),
        &["--per-run", "--json"],
    );
}

#[test]
fn de_match_refuses_too_many_pairs_before_capturing() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["bench", "de-match", "--pairs", "4294967296"][..],
        &["bench", "de-match", "--pairs", "0"],
        &["experiment", "de-match", "--pairs", "4294967296"],
        &["experiment", "de-match", "--pairs", "10001"],
    ] {
        expect_failure(args, dir.path(), &["--pairs: expected 1 to 10000 pairs"]);
    }
}

#[test]
fn localization_refuses_bad_seeds_sets_and_scenarios_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &[&str]); 6] = [
        (&["--seeds", "5..5"], &["--seeds 5..5", "empty"]),
        (
            &["--seeds", "0..200000"],
            &["--seeds 0..200000", "at most 100000"],
        ),
        (&["--duration", "0"], &["--duration", "positive"]),
        (
            &["--set", "robots.0.localization.0.max_particles=0"],
            &["--set robots.0.localization.0.max_particles=0"],
        ),
        (
            &["--set", "robots.0.localization.9={type=\"mcl\"}"],
            &["robots[0].localization", "index 9 is out of range"],
        ),
        (&["--scenario", "no_such_world"], &["no_such_world"]),
    ];
    for (extra, want) in cases {
        let mut args = vec!["experiment", "localization"];
        args.extend(extra);
        expect_failure(&args, dir.path(), want);
    }
}

#[test]
fn localization_refuses_a_scenario_without_localizers() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &[
            "experiment",
            "localization",
            "--scenario",
            "park_route_short",
            "--seeds",
            "0..1",
        ],
        dir.path(),
        &["park_route_short", "no robot has a localizer"],
    );
}
