//! Writer tests (round trips), the event merge, conversions, and random garbage that must
//! never make the reader panic.

use crate::formats::carmen::*;
use std::f64::consts::PI;

fn opts() -> CarmenReadOptions {
    CarmenReadOptions::default()
}

/// A log as the simulator would build it, with awkward floats and every record type.
fn sample_log() -> CarmenLog {
    let mut log = CarmenLog::default();
    log.params.insert("robot_name".into(), "r1".into());
    let mount = Pose2::new(0.1 + 0.2, -1e-7, 0.05);
    for k in 0..6 {
        let t = 1_700_000_000.0 + k as f64 * 0.1 + 1e-6 / 3.0;
        let odom = Pose2::new(k as f64 / 3.0, -(k as f64).sqrt(), PI - 0.4 * k as f64);
        let truth = Pose2::new(odom.x + 1e-3, odom.y, odom.theta + 1e-4);
        log.odometry.push(OdomRecord {
            timestamp: t,
            pose: odom,
            tv: 0.3,
            rv: -1.0 / 7.0,
            accel: 0.0,
        });
        log.truth.push(TruePosRecord {
            timestamp: t,
            truth,
            odom,
        });
        let ranges = (0..9)
            .map(|i| match i {
                3 => f32::INFINITY,
                4 => 30.0,
                _ => 0.5 + i as f32 / 3.0,
            })
            .collect();
        let inc = (270f64 / 8.0).to_radians();
        let mut s = ScanRecord::new(t + 0.05, ranges, -2.356194490192345, inc, 30.0, odom, mount);
        s.remissions = if k % 2 == 0 { vec![] } else { vec![0.25, 1e-3] };
        s.info.laser_tv = 0.3;
        log.scans.push(s.clone());
        if k % 3 == 0 {
            let rear_mount = Pose2::new(-0.2, 0.0, PI);
            let mut r = ScanRecord::new(t + 0.07, vec![1.0, 2.0], -0.5, 1.0, 5.0, odom, rear_mount);
            r.source = ScanSource::RobotLaser2;
            log.rear_scans.push(r);
        }
    }
    log
}

fn written(log: &CarmenLog, old_laser_lines: bool) -> String {
    let mut out = Vec::new();
    write_carmen_with(&mut out, log, &CarmenWriteOptions { old_laser_lines }).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn round_trip_write_read_is_identical() {
    let log = sample_log();
    let text = written(&log, false);
    let back = parse_carmen(&text, "rt.log", &opts()).unwrap();
    assert_eq!(back.odometry, log.odometry);
    assert_eq!(back.truth, log.truth);
    assert_eq!(back.scans, log.scans);
    assert_eq!(back.rear_scans, log.rear_scans);
    assert!(back.skipped.is_empty(), "{:?}", back.skipped);
    assert_eq!(back.params["robot_name"], "r1");
    assert_eq!(
        back.params["robot_frontlaser_offset"],
        (0.1 + 0.2).to_string()
    );
    assert_eq!(
        back.params["robot_rearlaser_angular_offset"],
        PI.to_string()
    );
    assert_eq!(back.params["robot_front_laser_max"], "30");
    // Writing what was read gives the same text.
    let mut again = Vec::new();
    write_carmen(&mut again, &back).unwrap();
    assert_eq!(String::from_utf8(again).unwrap(), text);
    // Records come out in timestamp order, hostname `sim`, logger time = timestamp.
    let stamps: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("PARAM"))
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            assert_eq!(f[f.len() - 2], "sim", "{l}");
            assert_eq!(f[f.len() - 1], f[f.len() - 3], "{l}");
            f[f.len() - 1].parse().unwrap()
        })
        .collect();
    assert!(stamps.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn old_laser_lines_carry_the_same_scans() {
    let log = sample_log();
    let text = written(&log, true);
    let back = parse_carmen(&text, "rt.log", &opts()).unwrap();
    assert_eq!(
        back.scans, log.scans,
        "ROBOTLASER1 wins over the FLASER duplicates"
    );
    assert_eq!(back.skipped["FLASER"], log.scans.len());
    assert_eq!(back.skipped["RLASER"], log.rear_scans.len());
    // A tool that reads only FLASER gets the same scans, geometry from the PARAMs.
    let old_only: String = text
        .lines()
        .filter(|l| !l.starts_with("ROBOTLASER"))
        .map(|l| format!("{l}\n"))
        .collect();
    let back = parse_carmen(&old_only, "old.log", &opts()).unwrap();
    assert_eq!(back.scans.len(), log.scans.len());
    for (a, b) in back.scans.iter().zip(&log.scans) {
        assert_eq!(a.source, ScanSource::Flaser);
        assert_eq!(
            (&a.ranges, a.timestamp, a.max_range),
            (&b.ranges, b.timestamp, b.max_range)
        );
        assert_eq!(
            (a.laser_pose, a.robot_pose, a.mount),
            (b.laser_pose, b.robot_pose, b.mount)
        );
        assert!((a.start_angle - b.start_angle).abs() < 1e-12);
        assert!((a.angle_increment - b.angle_increment).abs() < 1e-12);
    }
    let r = &back.rear_scans[0];
    assert_eq!((r.source, r.max_range), (ScanSource::Rlaser, 5.0));
    assert!((r.start_angle + 0.5).abs() < 1e-12 && (r.angle_increment - 1.0).abs() < 1e-12);
}

#[test]
fn params_that_are_not_one_word_are_refused() {
    let mut log = CarmenLog::default();
    log.params.insert("robot_name".into(), "two words".into());
    let e = write_carmen(&mut Vec::new(), &log).unwrap_err();
    assert!(e.to_string().contains("robot_name"), "{e}");
}

#[test]
fn events_merge_by_timestamp_with_odometry_first_on_ties() {
    let text = "ROBOTLASER1 0 0 0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 2.0 h 0\n\
                TRUEPOS 0 0 0 0 0 0 2.0 h 0\n\
                ODOM 0 0 0 0 0 0 3.0 h 0\n\
                ODOM 0 0 0 0 0 0 2.0 h 0\n\
                ROBOTLASER2 0 0 0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1.0 h 0\n";
    let log = parse_carmen(text, "ev.log", &opts()).unwrap();
    let ev: Vec<(f64, &str)> = log
        .events()
        .map(|e| {
            let kind = match e {
                CarmenEvent::Odometry(_) => "odom",
                CarmenEvent::Truth(_) => "truth",
                CarmenEvent::Scan(_) => "scan",
                CarmenEvent::RearScan(_) => "rear",
            };
            (e.timestamp(), kind)
        })
        .collect();
    let want = [
        (1.0, "rear"),
        (2.0, "odom"),
        (2.0, "truth"),
        (2.0, "scan"),
        (3.0, "odom"),
    ];
    assert_eq!(ev, want);
}

#[test]
fn laser_scan_conversion_maps_no_return_both_ways() {
    let scan = LaserScan {
        stamp: 4.5,
        angle_min: -1.0,
        angle_increment: 0.5,
        range_min: 0.1,
        range_max: 10.0,
        ranges: vec![1.0, f32::INFINITY, f32::NAN, 12.0, f32::NEG_INFINITY],
    };
    let s =
        ScanRecord::from_laser_scan(&scan, Pose2::new(1.0, 0.0, 0.0), Pose2::new(0.2, 0.0, 0.0));
    assert_eq!(s.ranges, vec![1.0, 10.0, 10.0, 10.0, 10.0]);
    assert_eq!((s.laser_pose.x, s.fov, s.timestamp), (1.2, 2.0, 4.5));
    let back = s.to_laser_scan();
    assert_eq!(back.ranges[0], 1.0);
    assert!(back.ranges[1..].iter().all(|r| *r == f32::INFINITY));
    assert_eq!(
        (back.angle_min, back.angle_increment, back.range_max),
        (-1.0, 0.5, 10.0)
    );
}

/// xorshift64*: a tiny deterministic generator, so the garbage is the same on every run.
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[test]
fn garbage_and_truncated_lines_never_panic() {
    let mut seeds: Vec<String> = written(&sample_log(), true)
        .lines()
        .map(String::from)
        .collect();
    for name in [
        "flaser_odom.log",
        "robotlaser1.log",
        "params.log",
        "unknown_types.log",
    ] {
        let path = systems::core::source::source_path("tests/fixtures/carmen").join(name);
        let text = std::fs::read_to_string(path).unwrap();
        seeds.extend(text.lines().map(String::from));
    }
    let junk = [
        "nan",
        "inf",
        "-inf",
        "-1",
        "1e999",
        "1e-400",
        "abc",
        "#",
        "",
        "180",
        "4294967296",
        "99999999999999999999",
        "-0",
        "0x10",
        "1.5",
        "\u{00e9}\u{0000}",
        "PARAM",
        "FLASER",
        "ROBOTLASER1",
        "2147483648",
        "-2147483649",
        "1e9",
        "18446744073709551615",
    ];
    let mut g = Gen(0x9E37_79B9_7F4A_7C15);
    let (mut ok, mut err) = (0, 0);
    for _ in 0..4000 {
        let base = &seeds[g.below(seeds.len())];
        let mut toks: Vec<String> = base.split_whitespace().map(String::from).collect();
        for _ in 0..=g.below(3) {
            let i = g.below(toks.len() + 1);
            match g.below(5) {
                0 => toks.truncate(i),
                1 if i < toks.len() => toks[i] = junk[g.below(junk.len())].to_string(),
                2 if i < toks.len() => {
                    toks.remove(i);
                }
                3 => toks.insert(i, junk[g.below(junk.len())].to_string()),
                _ => {
                    let bytes: Vec<u8> = (0..g.below(40)).map(|_| g.next() as u8).collect();
                    toks.insert(i, String::from_utf8_lossy(&bytes).into_owned());
                }
            }
        }
        let line = toks.join(" ");
        // Also cut the raw text at an arbitrary character.
        let cut: String = line
            .chars()
            .take(g.below(line.chars().count() + 1))
            .collect();
        for text in [line, cut] {
            match parse_carmen(&text, "junk.log", &opts()) {
                Ok(_) => ok += 1,
                Err(e) => {
                    assert!(e.to_string().starts_with("junk.log:1: "), "{e}");
                    err += 1;
                }
            }
        }
    }
    assert!(ok > 100 && err > 1000, "ok {ok}, err {err}");
}
