//! Laser scans collected during a run, with the true sensor pose of each, for SCANS files and
//! the scan-matching experiments: one scan per robot per period of simulated time.

use crate::formats::scans::ScanRecord;
use bevy_ecs::prelude::*;
use systems::core::{RobotId, RobotIndex};
use systems::sensors::{LaserScans, LaserTruth};

/// Laser scans to collect during a run, with the true sensor pose of each (SCANS files, scan
/// matching experiments). Passed to [`super::run_scenario_capturing`]; a separate argument rather than
/// a [`super::RunOptions`] field so existing `RunOptions { .. }` literals keep compiling.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanCapture {
    /// Keep one scan per robot every `period_s` seconds of simulated time: the first scan whose
    /// stamp reaches each multiple of the period (every scan if the laser is slower).
    pub period_s: f64,
    /// Only these robots (by name); `None` = every robot with a laser.
    pub robots: Option<Vec<String>>,
}

/// Per-robot state of a scan capture.
pub(super) struct Capturer<'a> {
    capture: &'a ScanCapture,
    /// (robot index → next multiple of the period to take)
    next: Vec<u64>,
    scans: Vec<ScanRecord>,
}

impl<'a> Capturer<'a> {
    pub(super) fn new(capture: &'a ScanCapture) -> Self {
        Capturer {
            capture,
            next: Vec::new(),
            scans: Vec::new(),
        }
    }

    /// The scans taken, in time order.
    pub(super) fn into_scans(self) -> Vec<ScanRecord> {
        self.scans
    }

    /// Takes the scans of this tick (robots in index order).
    pub(super) fn collect(&mut self, w: &mut World) {
        let mut q = w.query::<(&RobotIndex, &RobotId, &LaserScans, &LaserTruth)>();
        let mut rows: Vec<_> = q.iter(w).collect();
        rows.sort_by_key(|(i, ..)| **i);
        let period = self.capture.period_s;
        // a scan at k·period may carry rounding (0.30000000000000004): accept it a hair early
        let eps = 1e-6 * period.max(1e-3);
        for (i, id, scans, truth) in rows {
            if let Some(names) = &self.capture.robots
                && !names.contains(&id.0)
            {
                continue;
            }
            let slot = i.0 as usize;
            if self.next.len() <= slot {
                self.next.resize(slot + 1, 0);
            }
            for (scan, pose) in scans.scans.iter().zip(&truth.poses) {
                if scan.stamp + eps < self.next[slot] as f64 * period {
                    continue;
                }
                self.next[slot] = ((scan.stamp + eps) / period).floor() as u64 + 1;
                self.scans.push(ScanRecord {
                    index: self.scans.len() as u64,
                    robot: id.0.clone(),
                    stamp: scan.stamp,
                    pose: *pose,
                    angle_min: scan.angle_min,
                    angle_increment: scan.angle_increment,
                    range_min: scan.range_min,
                    range_max: scan.range_max,
                    ranges: scan.ranges.clone(),
                });
            }
        }
    }
}
