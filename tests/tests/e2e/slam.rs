//! SLAM end to end (issue 5): the bundled hospital_loop run with scan-to-map SLAM on the robot,
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
        "[[robots.slam]]\ntype = \"scan_to_map\"\n\
         [[robots.slam]]\ntype = \"graph\"\nresolution = 0.04",
    );
    let out = run_scenario(&scenario(&text), &RunOptions::default()).expect("runs");
    let r = &out.summary.robots[0];
    assert!(
        r.max_odometry_drift_m > 1.5,
        "wheel odometry drifts (the test is not trivial): {}",
        r.max_odometry_drift_m
    );
    let s = &r.localization["scan_to_map"];
    assert!(s.estimates > 2000, "one estimate per scan: {s:?}");
    let ate = s.ate_rmse_m.unwrap();
    assert!(ate < 0.1, "scan-to-map ATE {ate} m");
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
