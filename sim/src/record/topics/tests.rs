//! The replay holds the very readings the estimators got: each tick's live scans, encoder
//! readings, GPS fixes and compass readings are rebuilt bit for bit from the decoded messages,
//! their times from the stamps and the periods of `run.json`.

use super::*;
use crate::build::{SimWorld, build_world};
use crate::record::mcap::messages::{Imu, JointState, LaserScan, NavSatFix, Odometry};
use crate::record::mcap::{McapRecording, time_on_grid};
use crate::scenario::{assets_dir, load_scenario};
use systems::core::{RobotIndex, SimPlugin};
use systems::localization::WheelOdometry;
use systems::sensors::{
    CompassReading, CompassReadings, EncoderReading, EncoderReadings, GpsFix, GpsReadings,
    LaserScan as Scan, LaserScans,
};

/// Adds the MCAP export of `path` to a built world, as a run with `--mcap` does.
fn install(sim: &mut SimWorld, sc: &Scenario, path: &Path) -> anyhow::Result<()> {
    McapPlugin::new(&mut sim.world, sc, path)?.build(&mut sim.world, &mut sim.schedule);
    Ok(())
}

/// Everything the first robot's sensors produced, tick by tick.
#[derive(Default)]
struct Live {
    scans: Vec<Scan>,
    encoders: Vec<EncoderReading>,
    fixes: Vec<GpsFix>,
    compass: Vec<CompassReading>,
    odometry: Vec<(f64, systems::core::Pose2)>,
}

fn run_live(name: &str, duration: f64, path: &Path) -> (Live, McapWritten) {
    let mut sc = load_scenario(&assets_dir().join(format!("scenarios/{name}.toml"))).unwrap();
    sc.duration = duration;
    let mut sim = build_world(&sc, 1).unwrap();
    let exports = crate::RunExports {
        mcap: Some(path.to_path_buf()),
        ..Default::default()
    };
    install(&mut sim, &sc, path).unwrap();
    let mut live = Live::default();
    for _ in 0..(duration / sc.dt).round() as usize {
        sim.step();
        let w = &mut sim.world;
        let mut q = w.query::<(
            &RobotIndex,
            Option<&LaserScans>,
            Option<&EncoderReadings>,
            Option<&GpsReadings>,
            Option<&CompassReadings>,
            Option<&WheelOdometry>,
        )>();
        for (i, scans, enc, gps, compass, odom) in q.iter(w) {
            if i.0 != 0 {
                continue;
            }
            live.scans
                .extend(scans.iter().flat_map(|s| s.scans.clone()));
            live.encoders
                .extend(enc.iter().flat_map(|e| e.readings.clone()));
            live.fixes.extend(gps.iter().flat_map(|g| g.fixes.clone()));
            live.compass
                .extend(compass.iter().flat_map(|c| c.readings.clone()));
            if let Some(o) = odom {
                let last = live.odometry.last().map(|p| p.0);
                live.odometry.extend(
                    o.trail()
                        .iter()
                        .filter(|(t, _)| last.is_none_or(|l| *t > l)),
                );
            }
        }
    }
    let mut errors = Vec::new();
    let done = exports.finish(&mut sim.world, &sc, &mut errors);
    assert_eq!(errors, Vec::<String>::new());
    (live, done.mcap.unwrap())
}

/// The topic's period from `run.json`.
fn period(rec: &McapRecording, topic: &str) -> f64 {
    let run: serde_json::Value =
        serde_json::from_slice(&rec.attachment("run.json").unwrap().data).unwrap();
    let t = run["topics"].as_array().unwrap().iter();
    t.filter(|t| t["topic"] == topic)
        .map(|t| t["period_s"].as_f64().unwrap())
        .next()
        .unwrap()
}

/// The exact simulation time of a decoded message of `topic`.
fn times<T: crate::record::mcap::RosMessage>(rec: &McapRecording, topic: &str) -> Vec<(f64, T)> {
    let p = period(rec, topic);
    let msgs = rec.decode_topic::<T>(topic).unwrap();
    msgs.into_iter()
        .map(|(ns, m)| (time_on_grid(ns, p), m))
        .collect()
}

#[test]
fn scans_and_encoder_readings_come_back_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("maze.mcap");
    let (live, written) = run_live("maze_run", 2.0, &path);
    assert_eq!(written.path, path);
    let rec = McapRecording::open(&path).unwrap();
    assert_eq!(written.stats.messages as usize, rec.messages.len());
    let name = "scout";
    let scans = times::<LaserScan>(&rec, &format!("/{name}/scan"));
    assert_eq!(scans.len(), live.scans.len());
    assert_eq!(scans.len(), 21, "10 Hz for 2 s, t = 0 included");
    for ((t, m), s) in scans.iter().zip(&live.scans) {
        let back = Scan {
            stamp: *t,
            angle_min: m.angle_min,
            angle_increment: m.angle_increment,
            range_min: m.range_min,
            range_max: m.range_max,
            ranges: m.ranges.clone(),
        };
        assert_eq!(back.stamp.to_bits(), s.stamp.to_bits());
        let bits = |r: &[f32]| r.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.ranges), bits(&s.ranges));
        assert_eq!(back, *s);
    }
    let joints = times::<JointState>(&rec, &format!("/{name}/joint_states"));
    assert_eq!(joints.len(), live.encoders.len());
    assert_eq!(joints.len(), 101);
    for ((t, m), r) in joints.iter().zip(&live.encoders) {
        assert_eq!(m.name, DIFF_DRIVE_JOINTS);
        let back = EncoderReading {
            stamp: *t,
            left_ticks: ticks_of_angle(m.position[0], 4096),
            right_ticks: ticks_of_angle(m.position[1], 4096),
            steer: 0.0,
        };
        assert_eq!(back, *r);
        assert_eq!(back.stamp.to_bits(), r.stamp.to_bits());
    }
    // odometry: every update, positions exact, yaw through the quaternion
    let odom = times::<Odometry>(&rec, &format!("/{name}/odom"));
    assert_eq!(odom.len(), live.odometry.len() + 1, "plus the start pose");
    for ((t, m), (s, p)) in odom[1..].iter().zip(&live.odometry) {
        assert_eq!(t.to_bits(), s.to_bits());
        let q = &m.pose.pose;
        assert_eq!((q.position.x, q.position.y), (p.x, p.y));
        assert!(systems::core::wrap_angle(q.orientation.yaw() - p.theta).abs() < 1e-14);
    }
}

#[test]
fn gps_and_compass_readings_come_back_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("park.mcap");
    let (live, _) = run_live("park_route_short", 2.5, &path);
    let rec = McapRecording::open(&path).unwrap();
    let fixes = times::<NavSatFix>(&rec, "/car/gps/fix");
    assert_eq!(fixes.len(), live.fixes.len());
    assert_eq!(fixes.len(), 3, "5 Hz from the first fix at 2 s");
    for ((t, m), f) in fixes.iter().zip(&live.fixes) {
        assert_eq!(t.to_bits(), f.stamp.to_bits());
        assert_eq!(m.latitude.to_bits(), f.position.lat.to_bits());
        assert_eq!(m.longitude.to_bits(), f.position.lon.to_bits());
        let c = &m.position_covariance;
        assert_eq!([c[0], c[4], c[8]], f.covariance);
    }
    let compass = times::<Imu>(&rec, "/car/compass");
    assert_eq!(compass.len(), live.compass.len());
    assert_eq!(compass.len(), 26);
    for ((t, m), r) in compass.iter().zip(&live.compass) {
        let o = &m.orientation;
        let back =
            CompassReading::from_orientation(*t, [o.x, o.y, o.z, o.w], m.orientation_covariance[8]);
        assert_eq!(back, *r);
        assert_eq!(back.azimuth.to_bits(), r.azimuth.to_bits());
    }
    let joints = times::<JointState>(&rec, "/car/joint_states");
    assert_eq!(joints.len(), live.encoders.len());
    for ((t, m), r) in joints.iter().zip(&live.encoders) {
        assert_eq!(m.name, ACKERMANN_JOINTS);
        assert_eq!(t.to_bits(), r.stamp.to_bits());
        assert_eq!(ticks_of_angle(m.position[0], 512), r.left_ticks);
        assert_eq!(m.position[1].to_bits(), r.steer.to_bits());
    }
}

#[test]
fn an_unwritable_path_is_a_clear_error() {
    let sc = load_scenario(&assets_dir().join("scenarios/maze_run.toml")).unwrap();
    let mut sim = build_world(&sc, 1).unwrap();
    let exports = crate::RunExports {
        mcap: Some("/nonexistent-dir/run.mcap".into()),
        ..Default::default()
    };
    let e = install(&mut sim, &sc, exports.mcap.as_deref().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/nonexistent-dir/run.mcap: cannot create the MCAP file"),
        "{e}"
    );
}

#[test]
fn a_write_error_during_the_run_is_reported_at_the_end() {
    // /dev/full opens, then every write fails with "no space left on device"
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let mut sc = load_scenario(&assets_dir().join("scenarios/maze_run.toml")).unwrap();
    sc.duration = 12.0; // past the first automatic flush (10 s)
    let mut sim = build_world(&sc, 1).unwrap();
    let exports = crate::RunExports {
        mcap: Some(full.to_path_buf()),
        ..Default::default()
    };
    let installed = install(&mut sim, &sc, full);
    let e = match installed {
        Err(e) => e.to_string(),
        Ok(()) => {
            for _ in 0..(sc.duration / sc.dt).round() as usize {
                sim.step();
            }
            let mut errors = Vec::new();
            let done = exports.finish(&mut sim.world, &sc, &mut errors);
            assert!(done.mcap.is_none());
            errors.join("\n")
        }
    };
    assert!(e.starts_with("/dev/full: cannot"), "{e}");
}
