//! A replay of our own file reproduces the live run's estimates bit for bit (localizers and SLAM);
//! a foreign-style file (only `/scan` and `/odom`, stamps from another epoch) localizes; bad
//! files and arguments are clear errors.

use super::*;
use crate::record::mcap::messages::{LaserScan, Odometry, PoseStamped};
use crate::record::mcap::{McapRecorder, ROS2_PROFILE};
use crate::run::{RobotLocalization, run_scenario_exporting};
use crate::scenario::assets_dir;
use std::path::Path;

fn scenario_file(name: &str) -> PathBuf {
    assets_dir().join(format!("scenarios/{name}.toml"))
}

/// A live run of `name` for `duration` s, recorded to `mcap`.
fn live(name: &str, duration: f64, mcap: &Path) -> RunOutput {
    live_with(name, &[], duration, mcap)
}

/// [`live`] with `--set` overrides.
fn live_with(name: &str, sets: &[&str], duration: f64, mcap: &Path) -> RunOutput {
    let source = crate::scenario::source::Source::load(&scenario_file(name)).unwrap();
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let plan = crate::batch::sets::plan_sets(&sets, &[], &[]).unwrap();
    let mut sc = source.scenario(&plan.sets[0]).unwrap();
    sc.duration = duration;
    let exports = RunExports {
        mcap: Some(mcap.to_path_buf()),
        ..Default::default()
    };
    run_scenario_exporting(&sc, &RunOptions::default(), &exports).unwrap()
}

fn args(file: &Path, extra: &[&str]) -> ReplayArgs {
    let mut v = vec![file.to_str().unwrap()];
    v.extend_from_slice(extra);
    crate::options::parse_args::<ReplayArgs>(&v).unwrap()
}

fn replay_file(a: &ReplayArgs) -> anyhow::Result<RunOutput> {
    let rec = open_recording(a)?;
    replay(
        plan(a, &rec)?,
        &RunOptions::default(),
        &RunExports::default(),
    )
}

/// Figures against the truth agree to 1e-6: the live run's first tick starts from the physics
/// engine's f32 copy of the start pose (the replay from the pose itself), and the truth's heading
/// goes through a quaternion.
const TRUTH_TOLERANCE: f64 = 1e-6;

fn close(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() < TRUTH_TOLERANCE,
        (a, b) => a.is_none() && b.is_none(),
    }
}

/// Every estimate and stamp, as bits.
fn estimate_bits(l: &[RobotLocalization]) -> Vec<(String, String, Vec<[u64; 4]>)> {
    l.iter()
        .flat_map(|r| {
            r.localizers.iter().map(|(name, samples)| {
                let bits = samples
                    .iter()
                    .map(|s| {
                        let e = s.estimate;
                        [s.t, e.x, e.y, e.theta].map(f64::to_bits)
                    })
                    .collect();
                (r.robot.clone(), name.clone(), bits)
            })
        })
        .collect()
}

#[test]
fn replaying_our_own_file_reproduces_every_estimate_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("patrol.mcap");
    let live = live("hospital_patrol", 6.0, &file);
    let replayed = replay_file(&args(&file, &[])).unwrap();
    let (a, b) = (
        estimate_bits(&live.localization),
        estimate_bits(&replayed.localization),
    );
    // four robots with five localizers each, every one with estimates
    assert_eq!(a.len(), 20);
    assert!(a.iter().all(|(.., s)| s.len() > 5), "{a:?}");
    assert_eq!(a, b);
    assert_eq!(replayed.summary.sim_time_s, live.summary.sim_time_s);
    for (l, r) in live.summary.robots.iter().zip(&replayed.summary.robots) {
        assert!(
            (l.distance_m - r.distance_m).abs() < TRUTH_TOLERANCE,
            "{} vs {}",
            l.distance_m,
            r.distance_m
        );
        assert!((l.odometry_ate_m - r.odometry_ate_m).abs() < TRUTH_TOLERANCE);
        for ((n, lm), (m, rm)) in l.localization.iter().zip(&r.localization) {
            assert_eq!(n, m);
            assert!(
                close(lm.ate_rmse_m, rm.ate_rmse_m),
                "{n}: {:?} vs {:?}",
                lm.ate_rmse_m,
                rm.ate_rmse_m
            );
        }
    }
    // another seed gives other random numbers, hence other estimates
    let other = replay_file(&args(&file, &["--seed", "7"])).unwrap();
    assert_ne!(estimate_bits(&other.localization), a);
}

#[test]
fn a_slam_run_replays_to_the_same_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("loop.mcap");
    // the SLAM system is added by an override, in the live run and in the replay
    let slam = "robots.0.slam.type=rbpf";
    let live = live_with("hospital_loop", &[slam], 8.0, &file);
    let replayed = replay_file(&args(&file, &["--set", slam])).unwrap();
    let bits = estimate_bits(&live.localization);
    assert_eq!(bits.len(), 2, "{bits:?}");
    assert!(bits.iter().all(|(.., s)| s.len() > 10), "{bits:?}");
    assert_eq!(bits, estimate_bits(&replayed.localization));
    // the final (optimized) trajectories agree too
    for (l, r) in live.summary.robots.iter().zip(&replayed.summary.robots) {
        for ((_, lm), (_, rm)) in l.localization.iter().zip(&r.localization) {
            let (a, b) = (&lm.final_trajectory, &rm.final_trajectory);
            assert_eq!(a.is_some(), b.is_some());
            if let (Some(a), Some(b)) = (a, b) {
                assert!(close(a.ate_rmse_m, b.ate_rmse_m));
            }
        }
    }
}

/// Our file's scans and odometry re-written as another ROS 2 system would have them: topics
/// `/scan`, `/odom` and `/truth`, stamps from a wall clock, no attachments; the last odometry
/// message stamped `odom_ahead_ns` later than it was.
fn foreign_copy(own: &Path, robot: &str, out: &Path, with_scan: bool, odom_ahead_ns: i64) {
    let rec = McapRecording::open(own).unwrap();
    let mut w = McapRecorder::create(out, ROS2_PROFILE).unwrap();
    let epoch = 1_700_000_000_000_000_000i64;
    let shift = |h: &mut crate::record::mcap::messages::Header| {
        h.stamp =
            crate::record::mcap::messages::Time::from_nanos((h.stamp.as_nanos() + epoch) as u64);
    };
    enum Msg {
        Scan(LaserScan),
        Odom(Box<Odometry>),
        Truth(PoseStamped),
    }
    let mut msgs: Vec<(u64, Msg)> = Vec::new();
    if with_scan {
        for (t, mut m) in rec
            .decode_topic::<LaserScan>(&format!("/{robot}/scan"))
            .unwrap()
        {
            shift(&mut m.header);
            msgs.push((t, Msg::Scan(m)));
        }
    }
    let odom = rec
        .decode_topic::<Odometry>(&format!("/{robot}/odom"))
        .unwrap();
    let n = odom.len();
    for (i, (t, mut m)) in odom.into_iter().enumerate() {
        shift(&mut m.header);
        if i + 1 == n {
            let ns = m.header.stamp.as_nanos() + odom_ahead_ns;
            m.header.stamp = crate::record::mcap::messages::Time::from_nanos(ns as u64);
        }
        msgs.push((t, Msg::Odom(Box::new(m))));
    }
    let truth_topic = format!("/{robot}/ground_truth");
    for (t, mut m) in rec.decode_topic::<PoseStamped>(&truth_topic).unwrap() {
        shift(&mut m.header);
        msgs.push((t, Msg::Truth(m)));
    }
    msgs.sort_by_key(|m| m.0);
    let scan = with_scan.then(|| w.channel::<LaserScan>("/scan").unwrap());
    let odom = w.channel::<Odometry>("/odom").unwrap();
    let truth = w.channel::<PoseStamped>("/truth").unwrap();
    for (t, m) in msgs {
        let t = t + epoch as u64;
        match m {
            Msg::Scan(m) => w.write(scan.unwrap(), t, &m),
            Msg::Odom(m) => w.write(odom, t, &*m),
            Msg::Truth(m) => w.write(truth, t, &m),
        }
        .unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn a_foreign_file_of_scans_and_odometry_localizes_the_chosen_robot() {
    let dir = tempfile::tempdir().unwrap();
    let own = dir.path().join("own.mcap");
    live("hospital_patrol", 10.0, &own);
    let foreign = dir.path().join("foreign.mcap");
    foreign_copy(&own, "r2", &foreign, true, 0);
    let scenario = scenario_file("hospital_patrol");
    let sc = scenario.to_str().unwrap();
    // several robots in the scenario: which one is it?
    let e = replay_file(&args(&foreign, &["--scenario", sc]))
        .err()
        .unwrap();
    assert!(e.to_string().contains("--robot"), "{e}");
    let e = replay_file(&args(&foreign, &["--scenario", sc, "--robot", "r9"]))
        .err()
        .unwrap();
    assert!(
        e.to_string().contains("r9") && e.to_string().contains("r1, r2, r3"),
        "{e}"
    );
    let out = replay_file(&args(
        &foreign,
        &["--scenario", sc, "--robot", "r2", "--truth-topic", "/truth"],
    ))
    .unwrap();
    assert_eq!(out.summary.robots.len(), 1);
    let r = &out.summary.robots[0];
    assert_eq!(r.name, "r2");
    // odometry poses as recorded: the same drift as the live run's wheel odometry
    assert!(r.distance_m > 5.0, "{}", r.distance_m);
    assert!(r.odometry_ate_m < 0.5, "{}", r.odometry_ate_m);
    let mcl = &r.localization["mcl"];
    assert!(mcl.estimates > 20, "{}", mcl.estimates);
    let ate = mcl.ate_rmse_m.unwrap();
    assert!(ate < 0.3, "mcl ATE {ate} m");
}

/// `hospital_patrol` without any `[robots.sensors.encoder]`, its paths made absolute, written
/// to `dir`: a scenario for replaying an odometry topic.
fn patrol_without_encoders(dir: &Path) -> PathBuf {
    let maps = assets_dir().join("maps");
    let text = std::fs::read_to_string(scenario_file("hospital_patrol"))
        .unwrap()
        .replace("\"../maps/", &format!("\"{}/", maps.display()));
    let mut kept = Vec::new();
    let mut skip = false;
    for line in text.lines() {
        if line.starts_with('[') {
            skip = line.trim() == "[robots.sensors.encoder]";
        }
        if !skip {
            kept.push(line);
        }
    }
    let path = dir.join("no_encoders.toml");
    std::fs::write(&path, kept.join("\n")).unwrap();
    path
}

/// Foxglove's Python writer (mcap-ros2-support, zstd chunks by default as rosbag2 writes them)
/// re-writes one robot's `/scan`, `/odom` and `/truth` (tests/foreign_mcap.py). The file
/// replays in a scenario without encoders, each compression giving the same estimates; scans
/// with other angles than the scenario's laser are replayed with a note saying so.
#[test]
fn a_zstd_file_of_another_writer_replays_without_encoders() {
    use systems::core::test_tools::{TestTool, test_tool};
    let Some(venv) = test_tool(TestTool::McapReaders) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let own = dir.path().join("own.mcap");
    live("hospital_patrol", 10.0, &own);
    let rewrite = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let script = systems::core::source::source_path("tests/foreign_mcap.py");
        let run = std::process::Command::new(venv.join("bin/python"))
            .arg(script)
            .arg(&own)
            .arg(&out)
            .args(["--robot", "r2"])
            .args(extra)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&run.stdout).to_string()
            + &String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{text}");
        out
    };
    let scenario = patrol_without_encoders(dir.path());
    let sc = scenario.to_str().unwrap();
    let flags = ["--scenario", sc, "--robot", "r2", "--truth-topic", "/truth"];
    // the scenario alone is not runnable: its robots' localizers have no odometry
    let e = crate::scenario::load_scenario(&scenario)
        .unwrap_err()
        .to_string();
    assert!(e.contains("[robots.sensors.encoder]"), "{e}");

    let zstd = rewrite("zstd.mcap", &[]);
    let out = replay_file(&args(&zstd, &flags)).unwrap();
    let r = &out.summary.robots[0];
    assert_eq!(r.name, "r2");
    let ate = r.localization["mcl"].ate_rmse_m.unwrap();
    assert!(ate < 0.3, "mcl ATE {ate} m");
    let plan_of = |f: &Path| {
        let a = args(f, &flags);
        plan(&a, &open_recording(&a).unwrap()).unwrap()
    };
    assert!(plan_of(&zstd).feeds[0].notes.is_empty());
    for compression in ["lz4", "none"] {
        let other = rewrite(
            &format!("{compression}.mcap"),
            &["--compression", compression],
        );
        let again = replay_file(&args(&other, &flags)).unwrap();
        assert_eq!(
            again.summary.deterministic_part(),
            out.summary.deterministic_part(),
            "{compression}"
        );
    }

    let finer = rewrite("finer.mcap", &["--increment-scale", "0.5"]);
    let notes = &plan_of(&finer).feeds[0].notes;
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("every 0.125°") && notes[0].contains("every 0.250°"),
        "{}",
        notes[0]
    );
}

#[test]
fn missing_topics_attachments_and_damage_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let own = dir.path().join("own.mcap");
    live("hospital_patrol", 2.0, &own);
    let scenario = scenario_file("hospital_patrol");
    let sc = scenario.to_str().unwrap();
    let msg = |a: &ReplayArgs| match replay_file(a) {
        Ok(_) => panic!("{a:?} replayed"),
        Err(e) => e.to_string(),
    };

    // a foreign file without its scans
    let no_scan = dir.path().join("no_scan.mcap");
    foreign_copy(&own, "r1", &no_scan, false, 0);
    let e = msg(&args(&no_scan, &["--scenario", sc, "--robot", "r1"]));
    assert!(
        e.contains("no_scan.mcap") && e.contains("no topic /scan") && e.contains("/odom"),
        "{e}"
    );
    // one message stamped 10 years after the others (a stamp that fits ROS 2's 32-bit
    // seconds): refused before the replay starts (it would run for ever), naming the reading
    let far = dir.path().join("far.mcap");
    let years_10 = 3650 * 86_400 * 1_000_000_000i64;
    foreign_copy(&own, "r1", &far, true, years_10);
    let e = msg(&args(&far, &["--scenario", sc, "--robot", "r1"]));
    assert!(
        e.contains("far.mcap")
            && e.contains("r1's last odometry pose")
            && e.contains("(3650.0 days)"),
        "{e}"
    );
    // a topic of the wrong type
    let e = msg(&args(
        &no_scan,
        &["--scenario", sc, "--robot", "r1", "--scan-topic", "/odom"],
    ));
    assert!(e.contains("/odom") && e.contains("LaserScan"), "{e}");
    // not ours and no scenario
    let e = msg(&args(&no_scan, &[]));
    assert!(e.contains("--scenario") && e.contains("run.json"), "{e}");
    // ours, with a robot the scenario does not have
    let e = msg(&args(&own, &["--robot", "nobody"]));
    assert!(e.contains("nobody"), "{e}");
    // a missing odometry topic: the message names both types read_poses accepts
    let e = msg(&args(&own, &["--robot", "r1", "--odom-topic", "/nosuch"]));
    assert!(
        e.contains("no topic /nosuch")
            && e.contains("nav_msgs/msg/Odometry")
            && e.contains("geometry_msgs/msg/PoseStamped"),
        "{e}"
    );
    // a bad override names the key
    let e = msg(&args(&own, &["--set", "robots.0.sensors.laser.rate=-1"]));
    assert!(e.contains("robots.0.sensors.laser.rate"), "{e}");

    // truncated and corrupt files
    let bytes = std::fs::read(&own).unwrap();
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let e = msg(&args(&cut, &[]));
    assert!(e.contains("cut.mcap") && e.contains("--recover"), "{e}");
    // --recover replays the complete chunks before the cut: the first part of the run
    let whole = replay_file(&args(&own, &[])).unwrap();
    let part = replay_file(&args(&cut, &["--recover"])).unwrap();
    let estimates = |o: &RunOutput| o.summary.robots[0].localization["mcl"].estimates;
    assert!(
        part.summary.sim_time_s < whole.summary.sim_time_s && estimates(&part) > 0,
        "{} s, {} estimates",
        part.summary.sim_time_s,
        estimates(&part)
    );
    let bad = dir.path().join("bad.mcap");
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 3;
    for b in &mut flipped[mid..mid + 64] {
        *b ^= 0x5a;
    }
    std::fs::write(&bad, &flipped).unwrap();
    let e = msg(&args(&bad, &[]));
    assert!(e.contains("bad.mcap"), "{e}");
    let e = msg(&args(&dir.path().join("none.mcap"), &[]));
    assert!(e.contains("none.mcap") && e.contains("cannot read"), "{e}");
}

#[test]
fn a_recording_without_its_scenario_attachment_needs_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let own = dir.path().join("own.mcap");
    live("hospital_patrol", 1.0, &own);
    // copy everything but the scenario
    let rec = McapRecording::open(&own).unwrap();
    let stripped = dir.path().join("stripped.mcap");
    let mut w = McapRecorder::create(&stripped, ROS2_PROFILE).unwrap();
    for a in rec.attachments.iter().filter(|a| a.name != "scenario.toml") {
        w.attach(&a.name, &a.media_type, &a.data).unwrap();
    }
    w.finish().unwrap();
    let e = replay_file(&args(&stripped, &[]))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("stripped.mcap") && e.contains("no scenario.toml attachment"),
        "{e}"
    );
}

/// The `--set` example of `sim replay --help` is a key the scenario parser takes.
#[test]
fn the_set_example_of_the_help_applies_to_a_bundled_scenario() {
    use clap::Args;
    let cmd = ReplayArgs::augment_args(clap::Command::new("replay"));
    let help = cmd
        .get_arguments()
        .find(|a| a.get_id() == "sets")
        .and_then(|a| a.get_help())
        .map(|h| h.to_string())
        .unwrap();
    // the backquoted `key=value` (the other quote is a command)
    let example = help
        .split('`')
        .skip(1)
        .step_by(2)
        .find(|s| s.contains('='))
        .unwrap_or_else(|| panic!("no example in {help}"));
    let source = crate::scenario::source::Source::load(&scenario_file("hospital_patrol")).unwrap();
    let plan = crate::batch::sets::plan_sets(&[example.to_string()], &[], &[]).unwrap();
    let sc = source.scenario(&plan.sets[0]);
    assert!(sc.is_ok(), "{example}: {:?}", sc.err());
}
