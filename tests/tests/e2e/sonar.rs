//! Sonars end to end: the scenario's `hospital` layout measures the room and another robot, a
//! sensor fault silences them, and the recording holds `robots/<name>/sonar`.

use crate::common::*;
use sim::{RunOptions, run_scenario};
use systems::sensors::SonarReadings;

/// Robot `a` (radius 0.25) at (3, 5) facing +x with the seed's four SRF02, robot `b` 2 m ahead.
fn two_robots(extra: &str) -> String {
    format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"a\"\nstart = [3.0, 5.0, 0.0]\n[robots.sensors.sonar]\n\
         layout = \"hospital\"\nnoise_std = 0.0\n[[robots]]\nname = \"b\"\nstart = [5.0, 5.0, 0.0]\n{extra}"
    )
}

#[test]
fn hospital_layout_sees_the_room_and_the_other_robot() {
    let mut sim = world(&two_robots(""));
    sim.step();
    let r = sim.world.get::<SonarReadings>(sim.robots[0]).unwrap();
    assert!(r.fired && r.stamp == 0.0, "{r:?}");
    assert_eq!(r.latest.len(), 4);
    // front: sensor at x = 3.25, b's disc from 4.75 → 1.5 m
    assert!((r.latest[0] - 1.5).abs() < 0.03, "{r:?}");
    // rear: sensor at x = 2.75, wall face at 0.1 → 2.65 m
    assert!((r.latest[3] - 2.65).abs() < 0.03, "{r:?}");
    // ±45°: from (3.18, 5 ± 0.18) the cone's outer edge (72.5°) meets the wall at y = 9.9 / 0.1
    // after 4.72 / sin 72.5° = 4.95 m
    for k in [1, 2] {
        assert!((r.latest[k] - 4.95).abs() < 0.06, "{r:?}");
    }
    // 15 Hz against 50 ms ticks: the next set comes at 1/15 s, in the second tick
    sim.step();
    let r = sim.world.get::<SonarReadings>(sim.robots[0]).unwrap();
    assert!(r.fired && (r.stamp - 1.0 / 15.0).abs() < 1e-9, "{r:?}");
    // robot b has no sonars
    assert!(sim.world.get::<SonarReadings>(sim.robots[1]).is_none());
}

#[test]
fn a_sonar_fault_stops_new_readings() {
    let mut sim = world(&two_robots(
        "[[events]]\nat = 0.1\ntype = \"sensor_fault\"\nrobot = \"a\"\nsensor = \"sonar\"\n",
    ));
    let mut fired = Vec::new();
    for _ in 0..20 {
        sim.step();
        let r = sim.world.get::<SonarReadings>(sim.robots[0]).unwrap();
        if r.fired {
            fired.push(r.stamp);
        }
    }
    // t = 0 and 1/15 s, then silent from the tick starting at 0.1 s
    assert_eq!(fired.len(), 2, "{fired:?}");
}

#[test]
fn recording_has_the_sonar_entity() {
    let Some(rerun) = test_tool(TestTool::Rerun) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sonar.rrd");
    run_scenario(
        &scenario(&two_robots("")),
        &RunOptions {
            rrd: Some(path.clone()),
            threads: 2,
            progress: false,
            trajectory_period: None,
        },
    )
    .unwrap();
    let paths = entity_paths(&check_rrd_with(&rerun, &path));
    assert!(paths.iter().any(|p| p == "/robots/a/sonar"), "{paths:?}");
    assert!(!paths.iter().any(|p| p == "/robots/b/sonar"), "{paths:?}");
}
