//! `sim run --mcap PATH`: the run as an MCAP replay of ROS 2 messages (the replay format of
//! `sim/docs/recordings.md`; the MCAP layer is [`crate::record::mcap`]), for re-running estimators on
//! identical sensor data and for ROS tools (Foxglove, `ros2 bag`, mcap-ros2-support). An
//! observer in the Record set like the CARMEN export: it reads what the tick computed and draws
//! no random numbers, so a run with `--mcap` gives the same results as one without.
//!
//! Topics, per robot `<r>` (only those of the sensors the robot carries):
//!
//! | topic | type | what, when |
//! |---|---|---|
//! | `/<r>/scan` | sensor_msgs/LaserScan | every laser scan (f32 ranges as the estimators get them), frame `<r>/laser` |
//! | `/<r>/joint_states` | sensor_msgs/JointState | every encoder reading: wheel angles `ticks · 2π / ticks_per_rev` (drive shaft and steering angle for a car) |
//! | `/<r>/odom` | nav_msgs/Odometry | every wheel-odometry update (one per encoder reading), `<r>/odom` → `<r>/base_link` |
//! | `/<r>/ground_truth` | geometry_msgs/PoseStamped | the true pose at the end of every tick, frame `map` |
//! | `/<r>/gps/fix` | sensor_msgs/NavSatFix | every GPS fix |
//! | `/<r>/compass` | sensor_msgs/Imu | every compass reading: orientation only (REP 145) |
//! | `/<r>/camera/image_raw` | sensor_msgs/Image | rgb8 frames at the scenario's `record.camera_rate` |
//! | `/<r>/sonar/<k>` | sensor_msgs/Range | every reading of sonar `k` (mount order) |
//! | `/tf` | tf2_msgs/TFMessage | every tick: `map` → `<r>/odom` (the correction of the localizer the robot navigates by, else of its first localizer; identity without one) and `<r>/odom` → `<r>/base_link` |
//! | `/tf_static` | tf2_msgs/TFMessage | once: `<r>/base_link` → laser, sonar and camera mounts |
//!
//! Attachments: `scenario.toml` (the scenario file as loaded) and `run.json` ([`RunInfo`]: the
//! overrides applied, dt, the sim version and every topic's stamp period).
//!
//! Time: log time = publish time = header stamp = simulation time in integer nanoseconds; the
//! exact `f64` time is `round(ns · 1e-9 / period) · period` with the topic's period from
//! `run.json` ([`crate::record::mcap::sim_time`]). With that, ranges, wheel ticks, GPS
//! latitude/longitude and the compass quaternion as recorded, a replay can feed estimators the
//! very readings of the live run.
//!
//! The writer ends a chunk every 10 s of simulation time, so a killed run loses at most that;
//! Ctrl-C and SIGTERM end the run at the end of a tick and the file is finished properly.

mod convert;
mod record;
mod robot;

pub use convert::{ACKERMANN_JOINTS, DIFF_DRIVE_JOINTS, ticks_of_angle};
pub use record::{McapPlugin, record_mcap};
pub use robot::TopicInfo;

use crate::record::mcap::messages::{TFMessage, TransformStamped};
use crate::record::mcap::{Channel, McapRecorder, McapStats, ROS2_PROFILE};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use robot::RobotTopics;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `run.json` attachment.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct RunInfo {
    pub sim_version: String,
    pub scenario: String,
    /// The scenario file, absolute when it could be resolved (the `scenario.toml` attachment
    /// holds its text; relative paths in it are relative to this file's folder).
    pub scenario_file: String,
    pub seed: u64,
    pub dt: f64,
    /// Planned duration (s); the last message shows how far an interrupted run got.
    pub duration: f64,
    pub end_when_done: bool,
    pub camera_record_rate: f64,
    pub stamps: String,
    pub topics: Vec<TopicInfo>,
}

impl RunInfo {
    /// The stamp period of `topic` (s), if the run recorded it.
    pub fn period(&self, topic: &str) -> Option<f64> {
        self.topics
            .iter()
            .find(|t| t.topic == topic)
            .map(|t| t.period_s)
    }
}

const STAMP_RULE: &str = "log time = publish time = header stamp = simulation time in integer \
     nanoseconds; exact time = round(ns * 1e-9 / period_s) * period_s";

/// The replay being written (a resource while the run lasts).
#[derive(Resource)]
pub struct McapExport {
    rec: McapRecorder,
    robots: Vec<RobotTopics>,
    tf: Channel<TFMessage>,
    /// The first write error; nothing more is written after it.
    error: Option<anyhow::Error>,
    /// Reused between ticks.
    transforms: Vec<TransformStamped>,
}

/// What was written.
#[derive(Clone, Debug)]
pub struct McapWritten {
    pub path: PathBuf,
    pub stats: McapStats,
}

impl McapExport {
    /// Starts `path` for the robots of `world` (built from `scenario`): channels, the
    /// attachments and the static transforms.
    pub fn new(world: &mut World, scenario: &Scenario, path: &Path) -> anyhow::Result<Self> {
        let mut rec = McapRecorder::create(path, ROS2_PROFILE)?;
        let mut topics = Vec::new();
        let mut statics = Vec::new();
        let robots = robot::robot_topics(world, &mut rec, scenario.dt, &mut topics, &mut statics)?;
        let tf = rec.channel::<TFMessage>("/tf")?;
        let tf_static = rec.channel::<TFMessage>("/tf_static")?;
        let scenario_file = std::fs::canonicalize(&scenario.source)
            .map_or_else(|_| scenario.source.clone(), |p| p.display().to_string());
        let info = RunInfo {
            sim_version: env!("CARGO_PKG_VERSION").to_string(),
            scenario: scenario.name.clone(),
            scenario_file,
            seed: scenario.seed,
            dt: scenario.dt,
            duration: scenario.duration,
            end_when_done: scenario.end_when_done,
            camera_record_rate: scenario.record.camera_rate,
            stamps: STAMP_RULE.to_string(),
            topics,
        };
        if let Ok(text) = std::fs::read_to_string(&scenario.source) {
            rec.attach("scenario.toml", "application/toml", text.as_bytes())?;
        }
        let json = serde_json::to_string_pretty(&info)?;
        rec.attach("run.json", "application/json", json.as_bytes())?;
        if !statics.is_empty() {
            rec.write(
                tf_static,
                0,
                &TFMessage {
                    transforms: statics,
                },
            )?;
        }
        Ok(McapExport {
            rec,
            robots,
            tf,
            error: None,
            transforms: Vec::new(),
        })
    }

    /// Writes the summary and footer: the file is complete.
    pub fn finish(self) -> anyhow::Result<McapWritten> {
        let rec = self.rec;
        let path = rec.path().to_path_buf();
        if let Some(e) = self.error {
            return Err(e);
        }
        let stats = rec.finish()?;
        Ok(McapWritten { path, stats })
    }
}

#[cfg(test)]
mod tests;
