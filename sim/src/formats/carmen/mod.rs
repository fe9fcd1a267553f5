//! CARMEN robot logs in and out: the text format of the classic SLAM datasets (Intel Research
//! Lab, MIT CSAIL, FR079, ACES…), as written by CARMEN's `logger` (format described in the
//! header every CARMEN logfile starts with, carmen.sourceforge.net/logger_playback.html).
//!
//! # Format read
//!
//! One message per line, fields separated by whitespace; a line whose first non-blank character
//! is `#` is a comment; blank lines are ignored. Every message but PARAM ends with the trailer
//! `timestamp hostname logger_timestamp` (all three required); records keep `timestamp` (the
//! IPC time, seconds), the hostname and logger time are checked and dropped. Numbers may use any
//! float notation Rust's parser accepts (`1`, `-0.5`, `.5`, `1e-3`, `1.5E+2`, `inf`); integers
//! (`num_readings`…) may also be written as integral floats (`180.0`).
//!
//! | message | fields (after the type) | goes to |
//! |---|---|---|
//! | `PARAM` | `name value …` (rest ignored) | [`CarmenLog::params`] |
//! | `ODOM` | `x y theta tv rv accel` + trailer | [`CarmenLog::odometry`] |
//! | `TRUEPOS` | `true_x true_y true_theta odom_x odom_y odom_theta` + trailer | [`CarmenLog::truth`] |
//! | `FLASER` | `n r₁…rₙ x y theta odom_x odom_y odom_theta` + trailer | [`CarmenLog::scans`] |
//! | `RLASER` | as `FLASER`, rear laser | [`CarmenLog::rear_scans`] |
//! | `ROBOTLASER1` | `laser_type start_angle field_of_view angular_resolution maximum_range accuracy remission_mode n r₁…rₙ m e₁…eₘ laser_pose_x laser_pose_y laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist side_safety_dist turn_axis` + trailer | [`CarmenLog::scans`] |
//! | `ROBOTLASER2` | as `ROBOTLASER1`, rear laser | [`CarmenLog::rear_scans`] |
//! | anything else (`SYNC`, `RAWLASER1..4`, `NMEA*`, `GPS*`, `SONAR`, `BUMP`, `POSITIONLASER`, …) | not parsed | counted in [`CarmenLog::skipped`] |
//!
//! * In laser lines, `x y theta` / `laser_pose_*` is the pose of the laser and `odom_*` /
//!   `robot_pose_*` the robot's odometry pose at the scan, both in the odometry frame.
//! * Poses are in metres and radians; every heading is wrapped to (-π, π] (REP 103). Scan
//!   geometry (`start_angle`, `angle_increment`, `fov`) is kept as given, in radians.
//! * Ranges stay as logged (f32, metres). A reading `r` is a return when it is finite and
//!   `r < max_range`; `r ≥ max_range` (CARMEN's convention) or `inf` means no return. NaN or
//!   negative ranges are errors.
//! * Duplicates: a CARMEN logger often writes the same front laser both as `ROBOTLASER1` and as
//!   the old `FLASER`. When a log has any `ROBOTLASER1` line, its `FLASER` lines are still
//!   checked but not kept, and are counted in `skipped` under `FLASER` (likewise `ROBOTLASER2`
//!   over `RLASER`).
//!
//! # FLASER / RLASER geometry
//!
//! The old lines carry neither field of view, resolution nor maximum range. Each is taken, in
//! order of preference, from [`CarmenReadOptions`], from the PARAMs, or from CARMEN's own
//! guess (`carmen_laser_guess_fov` / `carmen_laser_guess_angle_increment` in CARMEN's readlog):
//!
//! * field of view: option `fov`, else `PARAM laser_front_laser_fov` (degrees), else 100° for
//!   400/401 beams and 180° otherwise;
//! * resolution: option `resolution`, else `PARAM laser_front_laser_resolution` (degrees), else
//!   1° for 180/181 beams, 0.5° for 360/361 and 0.25° for 400/401 when the field of view is the
//!   guessed one, else `fov / (n − 1)` (beams at both edges);
//! * the first beam is at `−fov/2` — so 180 beams cover −90°…+89° (CARMEN's SICK convention),
//!   181 beams −90°…+90°, and e.g. 5 beams −90°, −45°, 0°, 45°, 90°;
//! * maximum range: option `max_range`, else `PARAM robot_front_laser_max` (metres), else 80 m
//!   (CARMEN's default for old lines).
//!
//! The rear laser reads the same with `rear` in place of `front` (`laser_rear_laser_fov`,
//! `laser_rear_laser_resolution`, `robot_rear_laser_max`).
//!
//! # Laser mounting
//!
//! Each [`ScanRecord::mount`] is the laser pose in the robot frame. When the log has any of
//! `PARAM robot_frontlaser_offset` (forward, m), `robot_frontlaser_side_offset` (left, m) or
//! `robot_frontlaser_angular_offset` (rad) — `robot_rearlaser_*` for the rear laser — the mount
//! is built from them (missing ones are 0), because corrected logs rewrite the laser pose but
//! not the odometry, so the in-line difference means nothing there. Otherwise it is
//! `robot_pose⁻¹ ⊕ laser_pose` of that line. PARAM values are global: the last value of a
//! name wins, wherever in the file it is. Every other PARAM is kept, unread, in `params`.
//!
//! # Writing
//!
//! [`write_carmen`] writes a `# CARMEN Logfile` header, the PARAMs (the log's own, plus the
//! laser ones above derived from the first front/rear scan when the log lacks them), then every
//! record in timestamp order ([`CarmenLog::events`]): `ODOM`, `TRUEPOS`, and each scan as
//! `ROBOTLASER1`/`ROBOTLASER2` so its geometry is explicit — with
//! [`CarmenWriteOptions::old_laser_lines`], also as `FLASER`/`RLASER` for tools that only read
//! those (these carry no geometry: readers rebuild it from the PARAMs, symmetric about 0).
//! Hostname is `sim`, logger_timestamp = timestamp. Numbers are written in Rust's shortest
//! round-trip form, so write → read gives identical records.
//!
//! # Errors
//!
//! Reading never panics. A malformed line of a known type is a [`CarmenError::Line`] naming
//! the file, the 1-based line, the message type and a [`LineError`]: a missing field, a field
//! that is not what the format needs (non-numeric, NaN/inf outside ranges, negative range,
//! non-integer count, non-positive maximum range or honoured PARAM), a `num_readings` /
//! `num_remissions` that does not match the fields present, or fields left over, e.g.
//! `intel.log:12: FLASER: expected 180 range readings, found 179 (…)`.
//!
//! # Use from the CLI (wired elsewhere)
//!
//! * `sim slam --carmen LOG`: `read_carmen(LOG, &opts)` with `--fov`/`--max-range` given as
//!   [`OldLaserOverrides`]; print `skipped`; feed [`CarmenLog::events`] to the SLAM runner:
//!   odometry poses as the motion input, each front scan ([`ScanRecord::to_laser_scan`]) with its
//!   [`ScanRecord::mount`] as the sensor offset and `robot_pose` as the odometry at the scan;
//!   `truth` (TRUEPOS), when present, for ATE/RPE.
//! * `sim run --carmen-out FILE`: collect the robot's wheel odometry (`OdomRecord`), its laser
//!   scans ([`ScanRecord::from_laser_scan`], with the odometry pose and mount at the scan) and
//!   ground truth (`TruePosRecord`), then [`save_carmen`].

mod error;
pub mod export;
mod fields;
mod read;
mod write;

pub use error::{CarmenError, LineError};
pub use read::{CarmenReadOptions, OldLaserOverrides, parse_carmen, read_carmen};
pub use write::{CarmenWriteOptions, save_carmen, write_carmen, write_carmen_with};

use std::collections::BTreeMap;
use systems::core::Pose2;
use systems::sensors::LaserScan;

/// A whole CARMEN log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CarmenLog {
    /// Every `PARAM name value`, last value wins.
    pub params: BTreeMap<String, String>,
    /// `ODOM` lines, in file order.
    pub odometry: Vec<OdomRecord>,
    /// Front laser scans (`ROBOTLASER1`, or `FLASER` when the log has no `ROBOTLASER1`).
    pub scans: Vec<ScanRecord>,
    /// Rear laser scans (`ROBOTLASER2`, or `RLASER` when the log has no `ROBOTLASER2`).
    pub rear_scans: Vec<ScanRecord>,
    /// `TRUEPOS` lines (ground truth, as written by CARMEN's simulator).
    pub truth: Vec<TruePosRecord>,
    /// Lines not kept, by message type: unknown types and superseded old laser lines.
    pub skipped: BTreeMap<String, usize>,
}

/// `ODOM`: the robot's odometry pose and velocities.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OdomRecord {
    pub timestamp: f64,
    /// Odometry pose (m, m, rad).
    pub pose: Pose2,
    /// Translational velocity (m/s).
    pub tv: f64,
    /// Rotational velocity (rad/s).
    pub rv: f64,
    /// Acceleration (m/s²).
    pub accel: f64,
}

/// `TRUEPOS`: ground truth next to the odometry at the same time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TruePosRecord {
    pub timestamp: f64,
    pub truth: Pose2,
    pub odom: Pose2,
}

/// Which line a scan came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ScanSource {
    /// Old front-laser line; geometry from options/PARAMs/guess.
    Flaser,
    /// Old rear-laser line; geometry from options/PARAMs/guess.
    Rlaser,
    /// New front-laser line; geometry from the line.
    #[default]
    RobotLaser1,
    /// New rear-laser line; geometry from the line.
    RobotLaser2,
}

/// The `ROBOTLASER` fields a SLAM system does not need, kept so a log can be written back.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotLaserInfo {
    /// CARMEN's laser type code (0 = SICK LMS).
    pub laser_type: i32,
    /// Range accuracy (m).
    pub accuracy: f64,
    pub remission_mode: i32,
    pub laser_tv: f64,
    pub laser_rv: f64,
    pub forward_safety_dist: f64,
    pub side_safety_dist: f64,
    pub turn_axis: f64,
}

impl Default for RobotLaserInfo {
    /// What CARMEN assumes for old lines: a SICK LMS with 1 cm accuracy, no remissions.
    fn default() -> Self {
        RobotLaserInfo {
            laser_type: 0,
            accuracy: 0.01,
            remission_mode: 0,
            laser_tv: 0.0,
            laser_rv: 0.0,
            forward_safety_dist: 0.0,
            side_safety_dist: 0.0,
            turn_axis: 0.0,
        }
    }
}

/// One laser scan with the poses CARMEN logs next to it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanRecord {
    pub timestamp: f64,
    pub source: ScanSource,
    /// Ranges (m) as logged; see [`ScanRecord::is_return`].
    pub ranges: Vec<f32>,
    /// Angle of the first beam in the laser frame (rad).
    pub start_angle: f64,
    /// Angle between consecutive beams (rad).
    pub angle_increment: f64,
    /// Field of view (rad): as logged for ROBOTLASER, the nominal one for FLASER.
    pub fov: f64,
    /// Maximum range (m); readings at or beyond it are no return.
    pub max_range: f64,
    /// Laser pose in the odometry frame, as logged.
    pub laser_pose: Pose2,
    /// Robot odometry pose at the scan.
    pub robot_pose: Pose2,
    /// Laser pose in the robot frame (see the module doc for where it comes from).
    pub mount: Pose2,
    /// Remission (intensity) values; empty for old lines.
    pub remissions: Vec<f32>,
    pub info: RobotLaserInfo,
}

impl ScanRecord {
    /// A front-laser scan from the simulator: laser pose = `robot_pose ⊕ mount`, field of view
    /// spanning the beams.
    pub fn new(
        timestamp: f64,
        ranges: Vec<f32>,
        start_angle: f64,
        angle_increment: f64,
        max_range: f64,
        robot_pose: Pose2,
        mount: Pose2,
    ) -> Self {
        let fov = angle_increment * ranges.len().saturating_sub(1) as f64;
        ScanRecord {
            timestamp,
            source: ScanSource::RobotLaser1,
            ranges,
            start_angle,
            angle_increment,
            fov,
            max_range,
            laser_pose: robot_pose.compose(&mount),
            robot_pose,
            mount,
            remissions: Vec::new(),
            info: RobotLaserInfo::default(),
        }
    }

    /// A simulated [`LaserScan`] as a CARMEN scan. REP 117 readings without a CARMEN meaning
    /// (`inf` = no return, `-inf` = too close, `nan` = invalid) and readings beyond `range_max`
    /// all become `range_max`, CARMEN's "no return".
    pub fn from_laser_scan(scan: &LaserScan, robot_pose: Pose2, mount: Pose2) -> Self {
        let max = scan.range_max;
        let ranges = scan
            .ranges
            .iter()
            .map(|&r| if r.is_finite() && r < max { r } else { max })
            .collect();
        ScanRecord::new(
            scan.stamp,
            ranges,
            scan.angle_min as f64,
            scan.angle_increment as f64,
            max as f64,
            robot_pose,
            mount,
        )
    }

    /// This scan as the simulator's [`LaserScan`] (sensor frame, REP 117: no return = `inf`).
    pub fn to_laser_scan(&self) -> LaserScan {
        LaserScan {
            stamp: self.timestamp,
            angle_min: self.start_angle as f32,
            angle_increment: self.angle_increment as f32,
            range_min: 0.0,
            range_max: self.max_range as f32,
            ranges: self
                .ranges
                .iter()
                .map(|&r| if self.is_return(r) { r } else { f32::INFINITY })
                .collect(),
        }
    }

    /// Angle of beam `i` in the laser frame (rad).
    pub fn angle(&self, i: usize) -> f64 {
        self.start_angle + i as f64 * self.angle_increment
    }

    /// Whether a reading is a return: finite and below the maximum range.
    pub fn is_return(&self, r: f32) -> bool {
        r.is_finite() && (r as f64) < self.max_range
    }

    /// `(angle, range)` of every return, laser frame.
    pub fn returns(&self) -> impl Iterator<Item = (f64, f32)> + '_ {
        self.ranges
            .iter()
            .enumerate()
            .filter(|&(_, &r)| self.is_return(r))
            .map(|(i, &r)| (self.angle(i), r))
    }
}

/// One record of a log, for replaying it in time order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CarmenEvent<'a> {
    Odometry(&'a OdomRecord),
    Truth(&'a TruePosRecord),
    Scan(&'a ScanRecord),
    RearScan(&'a ScanRecord),
}

impl CarmenEvent<'_> {
    pub fn timestamp(&self) -> f64 {
        match self {
            CarmenEvent::Odometry(o) => o.timestamp,
            CarmenEvent::Truth(t) => t.timestamp,
            CarmenEvent::Scan(s) | CarmenEvent::RearScan(s) => s.timestamp,
        }
    }
}

impl CarmenLog {
    /// The front scans in time order (as [`CarmenLog::events`] yields them): what a SLAM system
    /// is fed.
    pub fn front_scans(&self) -> Vec<&ScanRecord> {
        self.events()
            .filter_map(|e| match e {
                CarmenEvent::Scan(s) => Some(s),
                _ => None,
            })
            .collect()
    }

    /// Every record merged by timestamp. Ties keep the order odometry, truth, front scan, rear
    /// scan (so a scan sees the odometry of its own instant), then the order within each list.
    pub fn events(&self) -> impl Iterator<Item = CarmenEvent<'_>> + '_ {
        let mut keys: Vec<(f64, u8, usize)> = Vec::with_capacity(
            self.odometry.len() + self.truth.len() + self.scans.len() + self.rear_scans.len(),
        );
        keys.extend(
            self.odometry
                .iter()
                .enumerate()
                .map(|(i, r)| (r.timestamp, 0, i)),
        );
        keys.extend(
            self.truth
                .iter()
                .enumerate()
                .map(|(i, r)| (r.timestamp, 1, i)),
        );
        keys.extend(
            self.scans
                .iter()
                .enumerate()
                .map(|(i, r)| (r.timestamp, 2, i)),
        );
        keys.extend(
            self.rear_scans
                .iter()
                .enumerate()
                .map(|(i, r)| (r.timestamp, 3, i)),
        );
        keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        keys.into_iter().map(move |(_, kind, i)| match kind {
            0 => CarmenEvent::Odometry(&self.odometry[i]),
            1 => CarmenEvent::Truth(&self.truth[i]),
            2 => CarmenEvent::Scan(&self.scans[i]),
            _ => CarmenEvent::RearScan(&self.rear_scans[i]),
        })
    }

    /// Total number of lines skipped.
    pub fn skipped_total(&self) -> usize {
        self.skipped.values().sum()
    }
}
