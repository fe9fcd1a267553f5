//! Reader tests: the fixtures under tests/fixtures/carmen, each message type, PARAMs, skipped
//! types, and an error naming line and field for each way a known line can be malformed.

use crate::formats::carmen::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    systems::core::source::source_path("tests/fixtures/carmen").join(name)
}

fn read(name: &str) -> CarmenLog {
    read_carmen(&fixture(name), &CarmenReadOptions::default()).unwrap()
}

fn parse(text: &str) -> Result<CarmenLog, CarmenError> {
    parse_carmen(text, "t.log", &CarmenReadOptions::default())
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn classic_flaser_odom_log() {
    let log = read("flaser_odom.log");
    assert_eq!(log.odometry.len(), 4);
    assert_eq!(log.scans.len(), 4);
    assert!(log.rear_scans.is_empty() && log.truth.is_empty() && log.skipped.is_empty());
    let o = &log.odometry[1];
    assert_eq!(
        (o.timestamp, o.pose.x, o.pose.theta),
        (975781813.85, 0.1, 0.01)
    );
    assert_eq!((o.tv, o.rv, o.accel), (0.2, 0.02, 0.0));
    let s = &log.scans[2];
    assert_eq!(s.source, ScanSource::Flaser);
    assert_eq!(s.timestamp, 975781814.4);
    assert_eq!(s.ranges, vec![2.4, 2.9, 81.91, 2.85, 2.56]);
    // 5 beams, nothing in the log about geometry: 180° from -90°, CARMEN's 80 m.
    assert!(close(s.start_angle, -FRAC_PI_2) && close(s.angle_increment, FRAC_PI_4));
    assert!(close(s.fov, PI) && s.max_range == 80.0);
    assert_eq!((s.laser_pose.y, s.laser_pose.theta), (0.001, 0.02));
    assert_eq!(s.robot_pose, s.laser_pose);
    assert_eq!(s.mount, Pose2::IDENTITY);
    // 81.91 m is beyond the maximum range: no return.
    let angles: Vec<f64> = s.returns().map(|(a, _)| a).collect();
    assert_eq!(angles.len(), 4);
    assert!(close(angles[2], FRAC_PI_4));
    // REP 103: -π is wrapped to π.
    assert_eq!(log.odometry[3].pose.theta, PI);
    assert_eq!(log.scans[3].laser_pose.theta, PI);
    assert_eq!(log.scans[3].robot_pose.theta, PI);
}

#[test]
fn robotlaser1_log_with_truth_and_remissions() {
    let log = read("robotlaser1.log");
    assert_eq!(
        (log.odometry.len(), log.truth.len(), log.scans.len()),
        (2, 2, 2)
    );
    let t = &log.truth[1];
    assert_eq!((t.timestamp, t.truth.x, t.truth.theta), (101.0, 1.52, 1.56));
    assert_eq!(t.odom, Pose2::new(1.5, 2.0, FRAC_PI_2));
    let s = &log.scans[1];
    assert_eq!(s.source, ScanSource::RobotLaser1);
    assert_eq!((s.start_angle, s.fov), (-FRAC_PI_2, PI));
    assert_eq!((s.angle_increment, s.max_range), (FRAC_PI_4, 8.0));
    assert_eq!(s.ranges, vec![1.5, 2.5, 9.5, 2.5, 1.5]);
    assert_eq!(s.remissions, vec![120.0, 130.0, 0.0, 130.0, 120.0]);
    assert!(!s.is_return(9.5) && s.is_return(7.99) && !s.is_return(f32::INFINITY));
    assert_eq!(
        (s.info.remission_mode, s.info.laser_tv, s.info.laser_rv),
        (1, 0.5, 0.1)
    );
    assert_eq!(
        (s.info.forward_safety_dist, s.info.side_safety_dist),
        (0.3, 0.2)
    );
    assert_eq!(s.timestamp, 101.05);
    // No PARAMs: the mount is the laser pose in the robot frame, from the line.
    for s in &log.scans {
        assert!(close(s.mount.x, 0.1) && close(s.mount.y, 0.0) && close(s.mount.theta, 0.0));
    }
    assert!(log.scans[0].remissions.is_empty());
}

#[test]
fn params_set_old_laser_geometry_and_mounting() {
    let log = read("params.log");
    assert_eq!(log.params["robot_length"], "0.5");
    assert_eq!(log.params["laser_front_laser_dev"], "/dev/ttyS0");
    assert_eq!(log.params.len(), 10);
    assert_eq!(log.scans.len(), 2);
    for s in &log.scans {
        assert!(close(s.fov, 100f64.to_radians()) && close(s.start_angle, (-50f64).to_radians()));
        assert!(close(s.angle_increment, 25f64.to_radians()) && s.max_range == 10.0);
        assert_eq!(s.mount, Pose2::new(0.15, -0.02, 0.05));
    }
    assert!(!log.scans[1].is_return(12.5));
    let r = &log.rear_scans[0];
    assert_eq!(r.source, ScanSource::Rlaser);
    assert!(close(r.start_angle, -FRAC_PI_2) && close(r.angle_increment, FRAC_PI_2));
    assert_eq!((r.max_range, r.mount), (80.0, Pose2::new(-0.2, 0.0, 0.0)));
}

#[test]
fn options_override_params() {
    let mut opts = CarmenReadOptions::default();
    opts.front.fov = Some(90f64.to_radians());
    opts.front.max_range = Some(5.0);
    opts.rear.resolution = Some(0.5);
    let log = read_carmen(&fixture("params.log"), &opts).unwrap();
    let s = &log.scans[0];
    assert!(close(s.start_angle, (-45f64).to_radians()) && s.max_range == 5.0);
    assert!(
        close(s.angle_increment, 25f64.to_radians()),
        "PARAM resolution still applies"
    );
    assert_eq!(log.rear_scans[0].angle_increment, 0.5);
    opts.front.fov = Some(7.0);
    let e = read_carmen(&fixture("params.log"), &opts).unwrap_err();
    assert!(e.to_string().contains("front.fov"), "{e}");
}

#[test]
fn unknown_types_are_skipped_and_counted() {
    let log = read("unknown_types.log");
    assert_eq!((log.odometry.len(), log.scans.len()), (2, 1));
    let want = [
        ("BUMP", 1),
        ("NMEAGGA", 1),
        ("POSITIONLASER", 1),
        ("RAWLASER1", 2),
        ("SONAR", 1),
        ("SYNC", 2),
    ];
    let got: Vec<(&str, usize)> = log.skipped.iter().map(|(k, v)| (k.as_str(), *v)).collect();
    assert_eq!(got, want);
    assert_eq!(log.skipped_total(), 8);
}

fn flaser(n: usize) -> String {
    format!("FLASER {n} {} 0 0 0 0 0 0 1 h 1", vec!["1"; n].join(" "))
}

#[test]
fn flaser_beam_counts_follow_carmen_conventions() {
    let deg = f64::to_radians;
    for (n, start, inc) in [
        (180, -90.0, 1.0),
        (181, -90.0, 1.0),
        (360, -90.0, 0.5),
        (361, -90.0, 0.5),
        (401, -50.0, 0.25),
        (7, -90.0, 30.0),
        (1, -90.0, 0.0),
    ] {
        let s = parse(&flaser(n)).unwrap().scans.remove(0);
        assert!(close(s.start_angle, deg(start)), "{n}: {}", s.start_angle);
        assert!(
            close(s.angle_increment, deg(inc)),
            "{n}: {}",
            s.angle_increment
        );
    }
    // An explicit field of view other than the guessed one spreads the beams edge to edge.
    let text = format!("PARAM laser_front_laser_fov 90 h 0\n{}", flaser(181));
    let s = parse(&text).unwrap().scans.remove(0);
    assert!(close(s.angle_increment, deg(0.5)) && close(s.start_angle, deg(-45.0)));
}

#[test]
fn robotlaser_supersedes_old_lines_of_the_same_laser() {
    let rl = "ROBOTLASER1 0 -1.5 3 1.5 8 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0 2 h 2";
    let text = format!(
        "{}\n{rl}\n{}\n",
        flaser(3),
        flaser(3).replace("FLASER", "RLASER")
    );
    let log = parse(&text).unwrap();
    assert_eq!(log.scans.len(), 1);
    assert_eq!(log.scans[0].source, ScanSource::RobotLaser1);
    assert_eq!(log.rear_scans.len(), 1, "no ROBOTLASER2: RLASER is kept");
    assert_eq!(log.skipped.get("FLASER"), Some(&1));
}

#[test]
fn mount_from_the_line_without_params() {
    let robot = Pose2::new(3.0, -1.0, 1.0);
    let mount = Pose2::new(0.2, 0.1, 0.3);
    let l = robot.compose(&mount);
    let text = format!(
        "FLASER 2 1 1 {} {} {} {} {} {} 1 h 1",
        l.x, l.y, l.theta, robot.x, robot.y, robot.theta
    );
    let m = parse(&text).unwrap().scans[0].mount;
    assert!(
        close(m.x, 0.2) && close(m.y, 0.1) && close(m.theta, 0.3),
        "{m:?}"
    );
}

#[test]
fn comments_blank_lines_and_crlf() {
    let text = "# header\r\n\r\n   \t \r\n  # indented comment\r\nODOM 1 2 0.5 0 0 0 1e1 h 0\r\n\
                SYNC x\r\n\nODOM 1 2 3 4\r\n";
    let e = parse(text).unwrap_err();
    assert_eq!(e.line(), Some(8), "{e}");
    let log = parse(&text.replace("ODOM 1 2 3 4", "# ODOM 1 2 3 4")).unwrap();
    assert_eq!(log.odometry.len(), 1);
    assert_eq!(log.odometry[0].timestamp, 10.0);
    assert_eq!(log.skipped_total(), 1);
}

#[test]
fn malformed_known_lines_name_line_and_field() {
    let rl =
        |mid: &str| format!("ROBOTLASER1 0 -1.57 3.14 0.785 {mid} 0 0 0 0 0 0 0 0 0 0 0 1 h 1");
    let cases: Vec<(String, &[&str])> = vec![
        ("ODOM 1 2 3 0 0".into(), &["ODOM", "missing field `accel`"]),
        (
            "ODOM 1 2 3 0 0 0 1 h".into(),
            &["missing field `logger_timestamp`"],
        ),
        (
            "ODOM 1 2 x 0 0 0 1 h 1".into(),
            &["field `theta`", "finite number", "`x`"],
        ),
        (
            "ODOM 1 2 nan 0 0 0 1 h 1".into(),
            &["field `theta`", "`nan`"],
        ),
        ("ODOM 1 2 3 0 0 inf 1 h 1".into(), &["field `accel`"]),
        (
            "ODOM 1 2 3 0 0 0 1 h 1 9".into(),
            &["unexpected field", "`logger_timestamp`", "`9`"],
        ),
        (
            "FLASER 5 1 2 3 4 0 0 0 0 0 0 1 h 1".into(),
            &["FLASER", "expected 5 range readings, found 4"],
        ),
        (
            "FLASER 3 1 nan 3 0 0 0 0 0 0 1 h 1".into(),
            &["field `range_readings[1]`", "`nan`"],
        ),
        (
            "FLASER 3 1 2 -3 0 0 0 0 0 0 1 h 1".into(),
            &["`range_readings[2]`"],
        ),
        (
            "FLASER 3 1 2 3 0 0 0 0 0 y 1 h 1".into(),
            &["field `odom_theta`", "`y`"],
        ),
        (
            "FLASER x 1 2".into(),
            &["field `num_readings`", "non-negative integer"],
        ),
        ("FLASER 2.5 1 2".into(), &["field `num_readings`"]),
        ("FLASER".into(), &["missing field `num_readings`"]),
        (
            "RLASER 1 1".into(),
            &["RLASER", "expected 1 range readings, found 0"],
        ),
        (
            "TRUEPOS 1 2 3 4 5".into(),
            &["TRUEPOS", "missing field `odom_theta`"],
        ),
        ("TRUEPOS 1 2 3 4 5 6 t h 1".into(), &["field `timestamp`"]),
        (
            rl("8 0.01 0 2 1 2 2 5"),
            &["ROBOTLASER1", "expected 2 remission values, found 1"],
        ),
        (rl("8 0.01 0 10 1 2 3 0"), &["expected 10 range readings"]),
        (rl("8 0.01 0 2 1 2 x"), &["field `num_remissions`"]),
        (
            rl("0 0.01 0 2 1 2 0"),
            &["field `maximum_range`", "positive"],
        ),
        (
            rl("8 0.01 z 2 1 2 0"),
            &["field `remission_mode`", "integer"],
        ),
        (rl("8 0.01 0 1 1 1 nan"), &["field `remission_values[0]`"]),
        (
            "ROBOTLASER2 abc -1.57 3.14 0.785 8 0.01 0 0 0".into(),
            &["ROBOTLASER2", "field `laser_type`"],
        ),
        (
            "PARAM robot_front_laser_max -3 nohost 0".into(),
            &[
                "PARAM",
                "field `robot_front_laser_max`",
                "positive number (m)",
            ],
        ),
        (
            "PARAM robot_frontlaser_offset abc".into(),
            &["`robot_frontlaser_offset`"],
        ),
        (
            "PARAM laser_front_laser_fov nan".into(),
            &["`laser_front_laser_fov`"],
        ),
        ("PARAM onlyname".into(), &["missing field `param_value`"]),
    ];
    for (bad, needles) in cases {
        let text = format!("# ok\nODOM 0 0 0 0 0 0 1 h 1\n{bad}\nODOM 0 0 0 0 0 0 2 h 2\n");
        let e = parse(&text).expect_err(&bad);
        let msg = e.to_string();
        assert_eq!(e.line(), Some(3), "{msg}");
        assert!(msg.starts_with("t.log:3: "), "{msg}");
        for n in needles {
            assert!(msg.contains(n), "`{bad}`: {msg} lacks {n}");
        }
    }
}

#[test]
fn file_errors_name_the_file() {
    let opts = CarmenReadOptions::default();
    let missing = fixture("no_such.log");
    let e = read_carmen(&missing, &opts).unwrap_err();
    assert!(
        e.to_string().contains("no_such.log") && e.line().is_none(),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    let gz = dir.path().join("intel.clf.gz");
    std::fs::write(&gz, [0x1f, 0x8b, 8, 0, 0, 0]).unwrap();
    let e = read_carmen(&gz, &opts).unwrap_err();
    assert!(e.to_string().contains("intel.clf.gz") && e.to_string().contains("gunzip"));
}

/// A log of a few MB is parsed in parallel runs of lines: the log is the one a line-by-line
/// read gives (PARAMs anywhere applied in order), and of two malformed lines in different runs
/// the error names the first.
#[test]
fn a_large_log_parses_in_parallel_as_line_by_line() {
    let beams = |k: usize| {
        (0..181)
            .map(|b| format!("{:.3}", 1.0 + ((k * 7 + b) % 50) as f64 * 0.1))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut lines = vec!["PARAM laser_front_laser_fov 180".to_string()];
    for k in 0..3000 {
        let t = k as f64 * 0.1;
        lines.push(format!("ODOM {t} 0 0 0 0 0 {t} h {t}"));
        lines.push(format!("FLASER 181 {} {t} 0 0 {t} 0 0 {t} h {t}", beams(k)));
        lines.push(format!("TRUEPOS {t} 0 0 {t} 0 0 {t} h {t}"));
        if k == 1500 {
            // a PARAM half-way changes every old line's geometry, as it did line by line
            lines.push("PARAM robot_front_laser_max 30".into());
            lines.push("NAVIGATOR something else".into());
        }
    }
    let text = lines.join("\n");
    assert!(text.len() > 2 << 20, "{} bytes", text.len());
    let opts = CarmenReadOptions::default();
    let parallel = super::parse_on(&text, "t.log", &opts, 3).unwrap();
    assert_eq!(parallel, super::parse_on(&text, "t.log", &opts, 1).unwrap());
    assert_eq!(parallel, parse(&text).unwrap());
    assert_eq!(parallel.scans.len(), 3000);
    assert_eq!(parallel.odometry.len(), 3000);
    assert_eq!(parallel.truth.len(), 3000);
    assert_eq!(parallel.skipped.get("NAVIGATOR"), Some(&1));
    assert_eq!(parallel.scans[2999].max_range, 30.0);
    assert!(parallel.scans.iter().all(|s| close(s.fov, PI)));
    // errors: the first of two, whichever thread found it
    let mut bad = lines.clone();
    bad[6000] = "ODOM 1 2 x 0 0 0 1 h 1".into();
    bad[8000] = "TRUEPOS 1 2".into();
    for threads in [1, 2, 3, 8] {
        let e = super::parse_on(&bad.join("\n"), "t.log", &opts, threads)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.log:6001: ODOM"), "{threads}: {e}");
    }
}
