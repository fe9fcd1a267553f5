//! `sim run --mcap`: the replay of a run decodes with Foxglove's ROS 2 readers
//! (tests/check_mcap.py: every message decoded and re-encoded byte for byte), with the message
//! counts and mean rates the scenario implies, indoors (lasers, encoders) and outdoors (GPS,
//! compass, camera, sonars).

use crate::common::*;
use sim::Scenario;
use sim::record::mcap::McapRecording;
use sim::scenario::load_scenario;
use std::path::Path;
use std::process::Command;

/// Readings of a sensor firing at `k · period` in [from, duration].
fn firings(period: f64, from: f64, duration: f64) -> usize {
    let last = (duration / period + 1e-6).floor() as usize;
    let first = (from / period - 1e-6).ceil().max(0.0) as usize;
    last + 1 - first
}

/// Topic → expected message count, and topic → expected mean rate (Hz).
type Expected = (Vec<(String, usize)>, Vec<(String, f64)>);

/// What a run of `s` must record.
fn expected(s: &Scenario) -> Expected {
    let d = s.duration;
    let ticks = (d / s.dt).round() as usize;
    let mut counts = vec![("/tf".to_string(), ticks), ("/tf_static".to_string(), 1)];
    let mut rates = vec![("/tf".to_string(), 1.0 / s.dt)];
    for r in &s.robots {
        let mut add = |leaf: &str, n: usize, hz: f64| {
            let topic = format!("/{}/{leaf}", r.name);
            counts.push((topic.clone(), n));
            rates.push((topic, hz));
        };
        add("ground_truth", ticks, 1.0 / s.dt);
        if let Some(l) = &r.laser {
            add("scan", firings(1.0 / l.rate, 0.0, d), l.rate);
        }
        if let Some(e) = &r.encoder {
            add("joint_states", firings(1.0 / e.rate, 0.0, d), e.rate);
            add("odom", firings(1.0 / e.rate, 0.0, d), e.rate);
        }
        if let Some(g) = &r.gps {
            add("gps/fix", firings(1.0 / g.rate, g.first_fix, d), g.rate);
        }
        if let Some(c) = &r.compass {
            add("compass", firings(1.0 / c.rate, 0.0, d), c.rate);
        }
        if r.camera.is_some() {
            let hz = s.record.camera_rate;
            add("camera/image_raw", firings(1.0 / hz, 0.0, d), hz);
        }
        if let Some(sonar) = &r.sonar {
            for k in 0..sonar.mounts.len() {
                let n = firings(1.0 / sonar.spec.rate, 0.0, d);
                add(&format!("sonar/{k}"), n, sonar.spec.rate);
            }
        }
    }
    (counts, rates)
}

/// tests/check_mcap.py on `path` with these counts and rates (skipped without the readers).
fn check_with_ros2_readers(path: &Path, counts: &[(String, usize)], rates: &[(String, f64)]) {
    let Some(venv) = test_tool(TestTool::McapReaders) else {
        return;
    };
    let json: serde_json::Map<String, serde_json::Value> = counts
        .iter()
        .map(|(t, n)| (t.clone(), (*n).into()))
        .collect();
    let counts_file = path.with_extension("counts.json");
    std::fs::write(&counts_file, serde_json::to_string(&json).unwrap()).unwrap();
    let mut cmd = Command::new(venv.join("bin/python"));
    cmd.arg(repo_file("check_mcap.py"))
        .arg(path)
        .arg(&counts_file);
    for (t, hz) in rates {
        cmd.arg("--rates").arg(format!("{t}={hz}"));
    }
    let out = cmd.output().unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.contains(" passed, 0 failed"), "{text}");
}

/// `sim run NAME --mcap … --duration 3`, then both readers; returns the recording.
fn run_and_check(name: &str) -> McapRecording {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("{name}.mcap"));
    let p = path.to_str().unwrap();
    sim_run(&[name, "--mcap", p, "--duration", "3", "--no-rrd", "--quiet"]).unwrap();
    let mut s = load_scenario(&bundled(name)).unwrap();
    s.duration = 3.0;
    let (counts, rates) = expected(&s);
    check_with_ros2_readers(&path, &counts, &rates);
    let rec = McapRecording::open(&path).unwrap();
    for (topic, n) in &counts {
        let got = rec.channel(topic).map_or(0, |c| c.message_count as usize);
        assert_eq!(got, *n, "{topic}");
    }
    let run: serde_json::Value =
        serde_json::from_slice(&rec.attachment("run.json").unwrap().data).unwrap();
    assert_eq!(run["scenario"], name);
    assert_eq!(run["dt"], s.dt);
    assert_eq!(run["duration"], 3.0);
    let toml = &rec.attachment("scenario.toml").unwrap();
    assert_eq!(toml.media_type, "application/toml");
    assert_eq!(toml.data, std::fs::read(bundled(name)).unwrap());
    rec
}

#[test]
fn indoor_replay_has_every_scan_and_odometry_update() {
    let rec = run_and_check("hospital_delivery");
    // every message's log time is its header stamp
    use sim::record::mcap::messages::{LaserScan, Odometry};
    let scans = rec.decode_topic::<LaserScan>("/r1/scan").unwrap();
    assert!(
        scans
            .iter()
            .all(|(t, m)| *t as i64 == m.header.stamp.as_nanos())
    );
    assert_eq!(scans[0].1.header.frame_id, "r1/laser");
    assert_eq!(scans[0].1.ranges.len(), 1081);
    let odom = rec.decode_topic::<Odometry>("/r2/odom").unwrap();
    assert_eq!(
        (
            odom[0].1.header.frame_id.as_str(),
            odom[0].1.child_frame_id.as_str()
        ),
        ("r2/odom", "r2/base_link")
    );
}

#[test]
fn outdoor_replay_has_gps_compass_camera_and_sonars() {
    use sim::record::mcap::messages::{Image, Imu, NavSatFix, Range};
    let rec = run_and_check("park_route_short");
    let fix = &rec.decode_topic::<NavSatFix>("/car/gps/fix").unwrap()[0].1;
    assert!((fix.latitude - 50.0645).abs() < 0.01 && (fix.longitude - 14.418).abs() < 0.01);
    let imu = &rec.decode_topic::<Imu>("/car/compass").unwrap()[0].1;
    assert_eq!(imu.angular_velocity_covariance[0], -1.0);
    assert!(imu.orientation_covariance[8] > 0.0);
    let img = &rec.decode_topic::<Image>("/car/camera/image_raw").unwrap()[0].1;
    assert_eq!(img.encoding, "rgb8");
    assert_eq!(img.data.len(), (img.step * img.height) as usize);
    let sonar = &rec.decode_topic::<Range>("/car/sonar/0").unwrap()[0].1;
    assert_eq!(sonar.radiation_type, Range::ULTRASOUND);
    assert_eq!(sonar.header.frame_id, "car/sonar_0");
}
