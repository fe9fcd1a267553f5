//! `sim run --carmen-out OUT`: a simulated run exported as CARMEN logs, so
//! other SLAM tools can process our runs. One log per robot with a laser and wheel encoders
//! (`OUT` for one such robot, else `OUT` with `-<robot>` after its stem), holding:
//!
//! - `ODOM`: the wheel-odometry pose whenever it moved on (every tick with encoder readings),
//!   with the translational and rotational velocity over the last step (`accel` 0);
//! - `ROBOTLASER1`: every laser scan with the odometry pose at its time (laser pose = that pose
//!   ⊕ mount), readings without a return written as the maximum range (CARMEN's convention);
//! - `TRUEPOS`: the true base pose at each scan's time next to the odometry pose;
//! - `PARAM robot_frontlaser_offset / side_offset / angular_offset` (the mount), and the laser's
//!   field of view, resolution and maximum range, for readers of old `FLASER` lines.
//!
//! Timestamps are simulated seconds. The exporter is an observer in the Record set: it reads
//! the sensors, the odometry and ground truth after they are computed and draws no random
//! numbers, so a run with `--carmen-out` gives the same results as one without.

use crate::formats::carmen::{
    CarmenLog, CarmenWriteOptions, OdomRecord, ScanRecord, TruePosRecord, save_carmen,
};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::cell::Cell;
use std::path::{Path, PathBuf};
use systems::core::{RobotIndex, SimPlugin, SimSet, wrap_angle};
use systems::localization::WheelOdometry;
use systems::sensors::{Laser, LaserScans, LaserTruth};

/// One robot's log in the making.
struct RobotLog {
    index: u32,
    path: PathBuf,
    log: CarmenLog,
}

/// The logs being collected (a resource while the run lasts).
#[derive(Resource)]
pub struct CarmenExport {
    robots: Vec<RobotLog>,
}

/// The file of robot `robot` when `count` robots are exported: `out` itself for one, else
/// `<stem>-<robot>.<ext>` next to it.
pub fn robot_file(out: &Path, robot: &str, count: usize) -> PathBuf {
    if count <= 1 {
        return out.to_path_buf();
    }
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("run");
    let name = match out.extension().and_then(|e| e.to_str()) {
        Some(ext) => format!("{stem}-{robot}.{ext}"),
        None => format!("{stem}-{robot}"),
    };
    out.with_file_name(name)
}

/// The robots of `scenario` that can be exported (a laser and wheel encoders): index and name.
pub fn exported_robots(scenario: &Scenario) -> Vec<(u32, &str)> {
    scenario
        .robots
        .iter()
        .enumerate()
        .filter(|(_, r)| r.laser.is_some() && r.encoder.is_some())
        .map(|(i, r)| (i as u32, r.name.as_str()))
        .collect()
}

impl CarmenExport {
    /// The logs of `scenario`'s robots with a laser and encoders (an error if there is none).
    pub fn new(scenario: &Scenario, out: &Path) -> anyhow::Result<Self> {
        let chosen = exported_robots(scenario);
        if chosen.is_empty() {
            anyhow::bail!(
                "--carmen-out: {} has no robot with a laser and wheel encoders to export",
                scenario.source
            );
        }
        Ok(CarmenExport {
            robots: chosen
                .iter()
                .map(|&(index, name)| RobotLog {
                    index,
                    path: robot_file(out, name, chosen.len()),
                    log: CarmenLog::default(),
                })
                .collect(),
        })
    }

    /// Writes every log; returns the files written.
    pub fn save(&self) -> anyhow::Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        for r in &self.robots {
            save_carmen(&r.path, &r.log, &CarmenWriteOptions::default())?;
            written.push(r.path.clone());
        }
        Ok(written)
    }
}

/// `--carmen-out`: [`record_carmen`] in the Record set; the logs ([`CarmenExport::new`], which
/// fails when no robot can be exported) are made before the plugin joins the schedule.
pub struct CarmenExportPlugin {
    export: Cell<Option<CarmenExport>>,
}

impl CarmenExportPlugin {
    pub fn new(export: CarmenExport) -> Self {
        CarmenExportPlugin {
            export: Cell::new(Some(export)),
        }
    }
}

impl SimPlugin for CarmenExportPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.insert_resource(
            self.export
                .take()
                .expect("CarmenExportPlugin is built once"),
        );
        schedule.add_systems(record_carmen.in_set(SimSet::Record));
    }
}

/// Record set: this tick's odometry, scans and true poses of the exported robots.
pub fn record_carmen(
    mut export: ResMut<CarmenExport>,
    robots: Query<(
        &RobotIndex,
        &Laser,
        &LaserScans,
        &LaserTruth,
        &WheelOdometry,
    )>,
) {
    for (idx, laser, scans, truth, odom) in robots.iter() {
        let Some(r) = export.robots.iter_mut().find(|r| r.index == idx.0) else {
            continue;
        };
        let log = &mut r.log;
        let last = log.odometry.last();
        if last.is_none_or(|o| odom.stamp > o.timestamp) {
            let (tv, rv) = match last {
                Some(o) if odom.stamp > o.timestamp => {
                    let d = o.pose.between(&odom.pose);
                    let dt = odom.stamp - o.timestamp;
                    (d.x / dt, wrap_angle(d.theta) / dt)
                }
                _ => (0.0, 0.0),
            };
            log.odometry.push(OdomRecord {
                timestamp: odom.stamp,
                pose: odom.pose,
                tv,
                rv,
                accel: 0.0,
            });
        }
        let mount = laser.spec.mount;
        let to_base = mount.inverse();
        for (scan, sensor) in scans.scans.iter().zip(&truth.poses) {
            let at = odom.pose_at(scan.stamp);
            log.scans.push(ScanRecord::from_laser_scan(scan, at, mount));
            log.truth.push(TruePosRecord {
                timestamp: scan.stamp,
                truth: sensor.compose(&to_base),
                odom: at,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn several_robots_get_a_suffix_on_the_stem() {
        let out = Path::new("dir/run.log");
        assert_eq!(robot_file(out, "r1", 1), PathBuf::from("dir/run.log"));
        assert_eq!(robot_file(out, "r1", 2), PathBuf::from("dir/run-r1.log"));
        assert_eq!(
            robot_file(Path::new("run"), "r2", 3),
            PathBuf::from("run-r2")
        );
    }
}
