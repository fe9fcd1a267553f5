//! Timed scenario events: kidnapping, sensor faults, new routes.

use crate::common::*;
use systems::body::TruePose;
use systems::eval::RobotMetrics;
use systems::localization::WheelOdometry;
use systems::sensors::LaserScans;

fn room_with(robot_and_events: &str) -> String {
    format!("{SQUARE_ROOM}\n{robot_and_events}").replace("duration = 1.0", "duration = 10.0")
}

#[test]
fn teleport_moves_the_truth_but_not_the_odometry() {
    let text = room_with(
        "[[robots]]\nname = \"r\"\nstart = [2.0, 2.0, 0.0]\n[robots.sensors.encoder]\n[[events]]\nat = 1.0\ntype = \"teleport\"\nrobot = \"r\"\npose = [7.0, 7.0, 1.0]\n",
    );
    let mut sim = world(&text);
    for _ in 0..30 {
        sim.step();
    }
    let e = sim.robots[0];
    let truth = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!(
        (truth.x - 7.0).abs() < 1e-4 && (truth.y - 7.0).abs() < 1e-4,
        "{truth:?}"
    );
    assert!((truth.theta - 1.0).abs() < 1e-4);
    let odom = sim.world.get::<WheelOdometry>(e).unwrap().pose;
    assert!(
        (odom.x - 2.0).abs() < 1e-6 && (odom.y - 2.0).abs() < 1e-6,
        "{odom:?}"
    );
    let m = sim.world.get::<RobotMetrics>(e).unwrap();
    assert!((m.odometry_drift_m - 50f64.sqrt()).abs() < 1e-3, "{m:?}");
    assert!(m.distance_m < 1e-6, "a kidnapping is not driving: {m:?}");
}

#[test]
fn a_laser_fault_silences_the_laser_for_its_window() {
    let text = room_with(
        "[[robots]]\nname = \"r\"\nstart = [5.0, 5.0, 0.0]\n[robots.sensors.laser]\nrate = 10.0\n[[events]]\nat = 1.0\ntype = \"sensor_fault\"\nrobot = \"r\"\nsensor = \"laser\"\nactive = true\n[[events]]\nat = 2.0\ntype = \"sensor_fault\"\nrobot = \"r\"\nsensor = \"laser\"\nactive = false\n",
    );
    let mut sim = world(&text);
    let mut stamps = Vec::new();
    for _ in 0..60 {
        sim.step();
        let s = sim.world.get::<LaserScans>(sim.robots[0]).unwrap();
        stamps.extend(s.scans.iter().map(|s| s.stamp));
    }
    // events act from the first tick starting at their time: the scan stamped 1.0 belongs to
    // the tick ending at 1.0, so the fault silences the stamps in (1.0, 2.0]
    let silenced = |t: &f64| *t > 1.0 + 1e-9 && *t < 2.0 + 1e-9;
    assert!(!stamps.iter().any(silenced), "{stamps:?}");
    assert!(stamps.iter().any(|t| *t > 2.5) && stamps.iter().any(|t| *t < 0.95));
    // 0.0 … 1.0 and 2.1 … 3.0 at 10 Hz
    assert_eq!(stamps.len(), 11 + 10, "{stamps:?}");
}

#[test]
fn a_waypoints_event_sends_an_idle_robot_on_its_way() {
    let text = room_with(
        "[[robots]]\nname = \"r\"\nstart = [2.0, 2.0, 0.0]\n[robots.sensors.encoder]\n[[events]]\nat = 1.0\ntype = \"waypoints\"\nrobot = \"r\"\npoints = [[6.0, 2.0]]\n",
    );
    let mut sim = world(&text);
    for _ in 0..20 {
        sim.step();
    }
    let e = sim.robots[0];
    assert!(
        sim.world.get::<TruePose>(e).unwrap().pose.x < 2.001,
        "idle before the event"
    );
    for _ in 0..200 {
        sim.step();
    }
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!((p.x - 6.0).abs() < 0.5 && (p.y - 2.0).abs() < 0.2, "{p:?}");
}
