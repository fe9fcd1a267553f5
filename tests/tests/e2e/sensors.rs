//! Lasers against analytic geometry; encoders and odometry drift.

use crate::common::*;
use systems::body::TruePose;
use systems::eval::RobotMetrics;
use systems::sensors::{LaserScans, LaserSpec};

/// Exact range from (x, y) at angle a to the inner faces of the square room (0.1 .. 9.9).
fn room_range(x: f64, y: f64, a: f64) -> f64 {
    let (dx, dy) = (a.cos(), a.sin());
    let mut t = f64::INFINITY;
    if dx > 1e-12 {
        t = t.min((9.9 - x) / dx);
    }
    if dx < -1e-12 {
        t = t.min((0.1 - x) / dx);
    }
    if dy > 1e-12 {
        t = t.min((9.9 - y) / dy);
    }
    if dy < -1e-12 {
        t = t.min((0.1 - y) / dy);
    }
    t
}

#[test]
fn laser_ranges_match_the_square_room() {
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r\"\nstart = [3.3, 4.1, 0.7]\n[robots.sensors.laser]\npreset = \"sick_lms100\"\nnoise_std = 0.0\n"
    );
    let mut sim = world(&text);
    sim.step();
    let e = sim.robots[0];
    let scans = sim.world.get::<LaserScans>(e).unwrap();
    // a 50 Hz laser fires at t = 0, 20 and 40 ms within the first 50 ms tick
    let stamps: Vec<f64> = scans.scans.iter().map(|s| s.stamp).collect();
    assert_eq!(stamps.len(), 3, "{stamps:?}");
    assert!((stamps[1] - 0.02).abs() < 1e-9 && (stamps[2] - 0.04).abs() < 1e-9);
    let mut worst: f64 = 0.0;
    for scan in &scans.scans {
        assert_eq!(scan.ranges.len(), 1081);
        for (k, &r) in scan.ranges.iter().enumerate() {
            let a = 0.7 + scan.angle_min as f64 + k as f64 * scan.angle_increment as f64;
            worst = worst.max((r as f64 - room_range(3.3, 4.1, a)).abs());
        }
    }
    assert!(worst < 2e-3, "worst range error {worst} m");
}

#[test]
fn lasers_see_other_robots_and_respect_their_range() {
    // robot a looks along +x at robot b (radius 0.25) 2 m ahead; a short-range laser sees nothing
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"a\"\nstart = [3.0, 5.0, 0.0]\n[robots.sensors.laser]\nnoise_std = 0.0\n[[robots]]\nname = \"b\"\nstart = [5.0, 5.0, 0.0]\n[robots.sensors.laser]\nnoise_std = 0.0\nmax_range = 1.0\nmin_range = 0.05\n"
    );
    let mut sim = world(&text);
    sim.step();
    let a = sim.world.get::<LaserScans>(sim.robots[0]).unwrap().scans[0].clone();
    let mid = a.ranges.len() / 2; // beam at 0 rad
    assert!((a.ranges[mid] - 1.75).abs() < 2e-3, "{}", a.ranges[mid]);
    let b = sim.world.get::<LaserScans>(sim.robots[1]).unwrap().scans[0].clone();
    // b at 5 m from every wall with 1 m range: +Inf everywhere except towards robot a (2 m): +Inf too
    assert!(b.ranges.iter().all(|r| *r == f32::INFINITY));
}

#[test]
fn laser_rate_is_independent_of_dt() {
    for dt in ["0.01", "0.05", "0.2"] {
        let text = format!(
            "{SQUARE_ROOM}\n[[robots]]\nname = \"r\"\nstart = [5.0, 5.0, 0.0]\n[robots.sensors.laser]\npreset = \"hokuyo_urg04lx\"\n"
        )
        .replace("dt = 0.05", &format!("dt = {dt}"));
        let mut sim = world(&text);
        let ticks = (2.0 / dt.parse::<f64>().unwrap()).round() as usize;
        let mut count = 0;
        let mut stamps = Vec::new();
        for _ in 0..ticks {
            sim.step();
            let s = sim.world.get::<LaserScans>(sim.robots[0]).unwrap();
            count += s.scans.len();
            stamps.extend(s.scans.iter().map(|s| s.stamp));
        }
        // 10 Hz over (0, 2] plus the scan at t = 0
        assert_eq!(count, 21, "dt {dt}: {stamps:?}");
    }
    assert_eq!(LaserSpec::hokuyo_urg04lx().beams(), 667);
}

#[test]
fn odometry_drift_grows_with_distance() {
    // a robot driving laps with 1 % wheel-radius errors: drift after 2 laps > after 1 lap
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r\"\nstart = [2.0, 2.0, 0.0]\nbehaviour = {{ type = \"waypoints\", points = [[8.0, 2.0], [8.0, 8.0], [2.0, 8.0], [2.0, 2.0]], loop = true, speed = 1.0 }}\n[robots.sensors.encoder]\nleft_radius_error = 0.01\nright_radius_error = -0.005\nwheel_base_error = 0.01\n"
    )
    .replace("duration = 1.0", "duration = 100.0");
    let mut sim = world(&text);
    let e = sim.robots[0];
    let mut drifts = Vec::new();
    for _ in 0..3 {
        for _ in 0..(25.0 / 0.05) as usize {
            sim.step();
        }
        let m = sim.world.get::<RobotMetrics>(e).unwrap().clone();
        drifts.push((m.distance_m, m.odometry_drift_m));
    }
    assert!(drifts[2].0 > 40.0, "{drifts:?}");
    assert!(drifts[0].1 > 0.05, "drift visible: {drifts:?}");
    assert!(drifts[2].1 > drifts[0].1, "drift grows: {drifts:?}");
    // with perfect calibration there is only tick quantisation
    let perfect = text
        .replace("left_radius_error = 0.01", "")
        .replace("right_radius_error = -0.005", "")
        .replace("wheel_base_error = 0.01", "");
    let mut sim = world(&perfect);
    for _ in 0..(25.0 / 0.05) as usize {
        sim.step();
    }
    let m = sim.world.get::<RobotMetrics>(sim.robots[0]).unwrap();
    assert!(m.odometry_drift_m < 0.02, "{m:?}");
    let _ = sim.world.get::<TruePose>(sim.robots[0]).unwrap();
}
