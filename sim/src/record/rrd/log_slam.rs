//! The recording of `sim slam`: a SLAM system replaying a CARMEN log. Entities as in `sim run`
//! (`systems/ARCHITECTURE.md`, "Entity paths"), for the robot named after the log: its SLAM system under `robots/<name>/slam`
//! ([`super::slam`]), its wheel odometry path `robots/<name>/odometry/path` and, when the log has
//! `TRUEPOS` lines, its true path `robots/<name>/truth/path` (new segments, in their own frames,
//! the odometry frame for a log of `sim run --carmen-out`), and the default layout
//! ([`super::blueprint`]). The `sim_time` timeline counts seconds from the log's first record.

use super::slam::{SlamTrack, log_slam_scan, log_slam_state, slam_entity};
use super::stream::RrdStream;
use super::{close_recording, open_recording};
use crate::record::path_trace::PathTrace;
use std::path::Path;
use systems::core::Pose2;
use systems::localization::ScanEstimator;
use systems::sensors::LaserScan;

/// Scans logged per second of log time.
const SCAN_RATE: f64 = 5.0;

pub struct ReplayRecorder {
    rec: RrdStream,
    robot: String,
    base: String,
    /// Timestamp of the log's first record (the timeline's zero).
    t0: f64,
    track: SlamTrack,
    scan_at: Option<f64>,
    odometry: PathTrace,
    truth: PathTrace,
    error: Option<String>,
}

impl ReplayRecorder {
    /// Opens `path` for SLAM system `slam` (the robot's only one) of robot `robot`, logging its
    /// map, trajectory and graph `slam_rate` times per second of log time (0: at the end).
    pub fn create(
        path: &Path,
        robot: &str,
        slam: &str,
        (t0, slam_rate): (f64, f64),
    ) -> anyhow::Result<Self> {
        Ok(ReplayRecorder {
            rec: open_recording(path, robot)?,
            robot: robot.to_string(),
            base: slam_entity(robot, slam, 1),
            t0,
            track: SlamTrack::new(slam_rate),
            scan_at: None,
            odometry: PathTrace::default(),
            truth: PathTrace::default(),
            error: None,
        })
    }

    fn check(&mut self, res: rerun::RecordingStreamResult<()>) {
        if let Err(e) = res {
            self.error.get_or_insert_with(|| e.to_string());
        }
    }

    /// After the SLAM consumed `scan` (at log time `stamp`, odometry pose `odom`, true pose
    /// `truth` if known, laser mount `mount`): logs what is due.
    pub fn scan(
        &mut self,
        est: &dyn ScanEstimator,
        scan: &LaserScan,
        (stamp, odom, truth, mount): (f64, &Pose2, Option<Pose2>, &Pose2),
    ) {
        let t = stamp - self.t0;
        self.odometry.push(odom, t);
        if let Some(p) = truth {
            self.truth.push(&p, t);
        }
        self.rec.set_duration_secs("sim_time", t);
        if self.scan_at.is_none_or(|a| t - a >= 1.0 / SCAN_RATE - 1e-9)
            && let Some(e) = est.estimate()
        {
            self.scan_at = Some(t);
            let res = log_slam_scan(&mut self.rec, &self.base, scan, &e.pose.compose(mount));
            self.check(res);
        }
        if self.track.state_due(t) {
            self.log_state(est);
        }
    }

    fn log_state(&mut self, est: &dyn ScanEstimator) {
        let res = log_slam_state(&mut self.rec, &self.base, est);
        self.check(res);
        let grey = rerun::Color::from_rgb(150, 150, 150);
        for (leaf, path, colour) in [
            ("odometry", &mut self.odometry, grey),
            (
                "truth",
                &mut self.truth,
                rerun::Color::from_rgb(31, 119, 180),
            ),
        ] {
            let strips = path.take_new();
            if !strips.is_empty() {
                let entity = format!("robots/{}/{leaf}/path", self.robot);
                super::rows::path(&mut self.rec, &entity, strips, colour);
            }
        }
    }

    /// Logs the final state at log time `stamp` and closes the file.
    pub fn finish(mut self, est: &dyn ScanEstimator, stamp: f64) -> anyhow::Result<()> {
        self.rec.set_duration_secs("sim_time", stamp - self.t0);
        self.log_state(est);
        let paths = self.rec.entity_paths();
        let layout = super::blueprint::default_layout(&super::blueprint::Inputs {
            paths: &paths,
            position_axis: 0.5,
            heading_axis: 0.2,
            drift_axis: 0.5,
            goal_axis: 1.0,
            time_span: Some([0.0, self.rec.latest_secs()]),
            ..Default::default()
        });
        if let Err(e) = super::blueprint::send(&self.rec, &layout) {
            self.error.get_or_insert_with(|| format!("{e:#}"));
        }
        close_recording(&mut self.rec, self.error.take())
    }
}
