//! `sim replay FILE.mcap`: re-runs localization, SLAM and evaluation on recorded sensor data,
//! without physics, sensors, control or navigation (the replay format of `sim/docs/recordings.md`).
//!
//! The world is built from the scenario as for a live run, with only the estimators' and the
//! evaluation's systems ([`crate::build::BuildMode::Replay`]); a feed system in the Sense set
//! (`feed`) hands each robot, tick by tick, the scans, encoder readings or odometry poses and
//! true poses read from the file (`source`). Scenario events still fire (a door that closes
//! changes the map the localizers believe in).
//!
//! Our own files (`sim run --mcap`) carry the scenario and the run's seed, tick and topic
//! periods (attachments `scenario.toml` and `run.json`), and exact stamps: with the same seed
//! the localizers and SLAM systems get bit for bit the readings of the live run in the same
//! ticks, draw the same random numbers, and so reproduce its estimates exactly. Error figures
//! agree to about 1e-7 m, not bit for bit: the truth's heading comes back from a quaternion, and
//! a live run's first tick starts from the physics engine's f32 copy of the start pose.
//!
//! Files of other ROS 2 systems: `--scenario` gives the map, the robot (`--robot` if it has
//! several) with its laser mount and localizers; sensor_msgs/LaserScan from `--scan-topic`
//! (`/scan`) and nav_msgs/Odometry poses from `--odom-topic` (`/odom`) are fed in, times are
//! header stamps counted from the first one. Ground truth (PoseStamped or Odometry in the map
//! frame) only with `--truth-topic`; without it the error figures are against the start pose
//! and mean nothing. Road localization (GPS, compass, camera) is not replayed: it needs every
//! camera frame and the road navigator's decisions.

mod args;
mod feed;
mod plan;
mod source;

pub use args::ReplayArgs;
pub use feed::{ReplayFeed, ReplayFeedPlugin, feed_recorded};
pub use plan::{ReplayPlan, plan};
pub use source::{RobotFeed, TopicFlags};

use crate::build::{BuildMode, Reusable, SimWorld, build_world_with};
use crate::record::mcap::McapRecording;
use crate::run::exports::RunExports;
use crate::run::report::report_run;
use crate::run::{OutputsFailed, RunOptions, RunOutput, run_built};
use crate::scenario::Scenario;
use feed::FedRobot;
use std::path::PathBuf;
use systems::body::TruePose;
use systems::core::SimPlugin;
use systems::localization::{OdometryModel, WheelOdometry};
use systems::sensors::EncoderReadings;

/// Replays `plan` (see the module doc).
pub fn replay(
    plan: ReplayPlan,
    opts: &RunOptions,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    let (sim, scenario) = build_replay(plan, opts.threads)?;
    run_built(sim, &scenario, opts, exports)
}

/// The world of a replay of `plan` (with a kernel pool of `threads` workers): built for
/// [`BuildMode::Replay`], with the recorded readings fed in the Sense set
/// ([`ReplayFeedPlugin`]); and the scenario it replays.
pub fn build_replay(plan: ReplayPlan, threads: usize) -> anyhow::Result<(SimWorld, Scenario)> {
    let ReplayPlan {
        scenario, feeds, ..
    } = plan;
    let mut sim = build_world_with(
        &scenario,
        threads,
        BuildMode::Replay,
        Reusable::default(),
        &crate::cache::process_cache(),
    )?;
    let mut robots = Vec::with_capacity(feeds.len());
    for (&entity, feed) in sim.robots.iter().zip(feeds) {
        if !feed.odometry.is_empty() {
            // odometry poses replace the encoder: wheel odometry must not integrate ticks
            sim.world.entity_mut(entity).remove::<EncoderReadings>();
            if sim.world.get::<WheelOdometry>(entity).is_none() {
                // no encoder in the scenario: the odometry only holds the recorded poses
                let start = sim.world.get::<TruePose>(entity).map(|t| t.pose);
                let model = OdometryModel::DiffDrive {
                    left_radius: 1.0,
                    right_radius: 1.0,
                    wheel_base: 1.0,
                };
                let odom = WheelOdometry::new(model, 1, start.unwrap_or_default());
                sim.world.entity_mut(entity).insert(odom);
            }
        }
        robots.push(FedRobot::new(entity, feed));
    }
    sim.compose_schedule();
    ReplayFeedPlugin::new(ReplayFeed { robots }).build(&mut sim.world, &mut sim.schedule);
    Ok((sim, scenario))
}

/// The file `sim replay` reads: whole, or with `--recover` what precedes its damage (then
/// named in [`McapRecording::damage`]).
pub fn open_recording(a: &ReplayArgs) -> anyhow::Result<McapRecording> {
    if a.recover {
        McapRecording::open_recovering(&a.file)
    } else {
        McapRecording::open(&a.file)
    }
}

/// `sim replay`.
pub fn replay_command(a: &ReplayArgs) -> anyhow::Result<()> {
    let rec = open_recording(a)?;
    if let Some(damage) = &rec.damage {
        eprintln!(
            "{}: {damage}; replaying the {} messages before it",
            a.file.display(),
            rec.messages.len()
        );
    }
    let plan = plan(a, &rec)?;
    drop(rec);
    let sc = &plan.scenario;
    if !a.out.quiet {
        let topics: Vec<&str> = plan
            .feeds
            .iter()
            .flat_map(|f| f.topics.iter().map(String::as_str))
            .collect();
        eprintln!(
            "replaying {} ({} robots, {:.1} s recorded, seed {}) from {}: {}",
            sc.name,
            sc.robots.len(),
            sc.duration,
            sc.seed,
            a.file.display(),
            topics.join(", ")
        );
        if plan.feeds.iter().any(|f| f.truth.is_empty()) {
            eprintln!(
                "note: no ground truth topic (--truth-topic): error figures are against the start \
                 pose and mean nothing"
            );
        }
        for note in plan.feeds.iter().flat_map(|f| &f.notes) {
            eprintln!("note: {note}");
        }
    }
    let rrd = a.out.rrd_path(|| {
        let stem = a.file.file_stem().and_then(|s| s.to_str()).unwrap_or("run");
        PathBuf::from(format!("{stem}-replay.rrd"))
    });
    let exports = RunExports {
        save_map: a.out.save_map.clone(),
        ..Default::default()
    };
    let run = replay(plan, &a.out.run_options(rrd.clone()), &exports);
    let (out, failures) = OutputsFailed::split(run)?;
    let mut report = a.out.report(rrd.as_deref(), None);
    if failures.recording {
        report.rrd = None;
    }
    failures.or(report_run(&out, &report))
}

#[cfg(test)]
mod tests;
