//! SLAM end to end: the bundled hospital_loop run with scan-to-map SLAM on the robot,
//! judged against ground truth; and the errors of the `slam` key.

use crate::common::*;
use sim::{RunOptions, run_scenario};

/// hospital_loop with `slam` entries added to its robot.
fn hospital_loop_with(slam: &str) -> String {
    let text = std::fs::read_to_string(bundled("hospital_loop")).unwrap();
    text.replacen("# lap 1\n", &format!("{slam}\n# lap 1\n"), 1)
}

#[test]
fn scan_to_map_and_graph_slam_track_two_laps_of_the_hospital_while_odometry_drifts() {
    let text = hospital_loop_with(
        "[[robots.slam]]\ntype = \"scan_to_map\"\n[[robots.slam]]\ntype = \"graph\"",
    );
    let out = run_scenario(&scenario(&text), &RunOptions::default()).expect("runs");
    let r = &out.summary.robots[0];
    assert!(
        r.odometry_ate_m >= 1.0,
        "wheel odometry alone drifts (the test is not trivial): ATE {} m",
        r.odometry_ate_m
    );
    let s = &r.localization["scan_to_map"];
    assert!(s.estimates > 2000, "one estimate per scan: {s:?}");
    let scan_to_map_ate = s.ate_rmse_m.unwrap();
    assert!(scan_to_map_ate < 0.1, "scan-to-map ATE {scan_to_map_ate} m");
    assert!(s.final_error_m.unwrap() < 0.15, "{s:?}");
    // graph SLAM: online poses, and the optimized trajectory after the last optimization
    let g = &r.localization["graph"];
    assert!(g.estimates > 2000, "one estimate per scan: {g:?}");
    let online = g.ate_rmse_m.unwrap();
    assert!(online < 0.1, "graph SLAM online ATE {online} m");
    let f = g
        .final_trajectory
        .expect("a SLAM system reports its final trajectory");
    assert_eq!(f.poses, g.estimates, "one optimized pose per scan");
    let ate = f.ate_rmse_m.unwrap();
    assert!(ate < 0.05, "graph SLAM ATE after optimization {ate} m");
    // loop closure beats scan-to-map alone (both with their default 5 cm cells)
    assert!(
        ate < scan_to_map_ate,
        "graph {ate} m, scan-to-map {scan_to_map_ate} m"
    );
}

#[test]
fn slam_errors_name_the_key() {
    let base = hospital_loop_with("");
    for (slam, want) in [
        ("slam = { type = \"graph_x\" }", "unknown variant `graph_x`"),
        (
            "slam = { type = \"scan_to_map\", resolution = 0.0 }",
            "slam.resolution",
        ),
        (
            "slam = { type = \"scan_to_map\", levels = 9 }",
            "slam.levels",
        ),
        (
            "slam = { type = \"scan_to_map\", p_miss = 0.7 }",
            "slam.p_miss",
        ),
        (
            "slam = { type = \"scan_to_map\", name = \"mcl\" }",
            "slam.name",
        ),
        ("slam = 3", "expected a table"),
    ] {
        let text = base.replacen(
            "[robots.sensors.laser]",
            &format!("{slam}\n[robots.sensors.laser]"),
            1,
        );
        let e = scenario_error(&text);
        assert!(e.contains(want), "{slam}: {e}");
    }
}

/// The maze experiment of [Hospital thesis] (`sim experiment maze-slam`, maze only):
/// DE scan-to-scan odometry drifts through the maze, while matching against the map —
/// scan-to-map SLAM and the RBPF — does not; every method is judged at the same poses.
#[test]
fn in_the_maze_scan_to_scan_matching_drifts_and_matching_against_the_map_does_not() {
    use sim::experiment::slam_compare::{SlamExperimentOptions, run_slam_experiment};
    let rows = run_slam_experiment(&SlamExperimentOptions {
        scenarios: vec!["maze_run".to_string()],
        methods: ["wheel_odometry", "de_scan_to_scan", "scan_to_map", "rbpf"]
            .map(String::from)
            .to_vec(),
        threads: 2,
        progress: false,
    })
    .expect("the experiment runs");
    for r in &rows {
        eprintln!("{r:?}");
    }
    let row = |m: &str| rows.iter().find(|r| r.method == m).unwrap();
    let (de, s2m, rbpf) = (row("de_scan_to_scan"), row("scan_to_map"), row("rbpf"));
    // at least the thesis's 76 scan poses, the same for every method
    assert!(
        rows.iter().all(|r| r.poses >= 76 && r.poses == de.poses),
        "{rows:?}"
    );
    let ate = |r: &sim::experiment::slam_compare::SlamRow| r.ate_rmse_m.unwrap();
    // the ordering: scan-to-scan drifts more than either map-based method
    assert!(
        ate(de) > 2.0 * ate(s2m),
        "DE {} vs scan-to-map {}",
        ate(de),
        ate(s2m)
    );
    assert!(
        ate(de) > 2.0 * ate(rbpf),
        "DE {} vs RBPF {}",
        ate(de),
        ate(rbpf)
    );
    assert!(de.final_error_m.unwrap() > s2m.final_error_m.unwrap());
    assert!(ate(s2m) < 0.1 && ate(rbpf) < 0.15, "{s2m:?} {rbpf:?}");
    // and the maps built from their trajectories show it
    assert!(s2m.map_quality.precision > de.map_quality.precision);
    assert!(s2m.map_quality.precision > 0.85 && rbpf.map_quality.precision > 0.85);
}
