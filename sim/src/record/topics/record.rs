//! The Record-set system of the MCAP replay: this tick's readings, poses and transforms of
//! every robot, in robot index order, then `/tf`.

use super::McapExport;
use super::convert::*;
use super::robot::RobotTopics;
#[cfg(feature = "rrd")]
use crate::record::frames::record_frames_rrd;
use crate::record::frames::{RecordedFrame, RecordedFrames, collect_frames};
use crate::record::mcap::McapRecorder;
use crate::record::mcap::messages::{Image, Range};
use crate::record::mcap::stamp_ns;
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::cell::Cell;
use std::path::Path;
use systems::body::TruePose;
use systems::core::{RobotIndex, SimClock, SimPlugin, SimSet};
use systems::localization::nav_source::NavSource;
use systems::localization::{Localizers, WheelOdometry};
use systems::sensors::{CompassReadings, EncoderReadings, GpsReadings, LaserScans, SonarReadings};

/// What a robot offers this tick.
type RobotData<'a> = (
    &'a RobotIndex,
    &'a TruePose,
    Option<&'a LaserScans>,
    Option<&'a EncoderReadings>,
    Option<&'a WheelOdometry>,
    Option<&'a GpsReadings>,
    Option<&'a CompassReadings>,
    Option<&'a SonarReadings>,
    Option<&'a Localizers>,
    Option<&'a NavSource>,
);

/// `--mcap`: [`record_mcap`] in the Record set. The file is opened by [`McapPlugin::new`],
/// before the plugin joins the schedule; built after the camera frames'
/// ([`crate::record::frames::FramesPlugin`]), whose systems it orders itself with.
pub struct McapPlugin {
    export: Cell<Option<McapExport>>,
}

impl McapPlugin {
    /// Starts `path` for the robots of `world` (built from `scenario`).
    pub fn new(world: &mut World, scenario: &Scenario, path: &Path) -> anyhow::Result<Self> {
        Ok(McapPlugin {
            export: Cell::new(Some(McapExport::new(world, scenario, path)?)),
        })
    }
}

impl SimPlugin for McapPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.insert_resource(self.export.take().expect("McapPlugin is built once"));
        let frames = world.get_resource::<RecordedFrames>().map(|f| f.outputs());
        let system = record_mcap.in_set(SimSet::Record);
        // With camera frames: after they are collected, and before the .rrd logs its images (both
        // take this tick's frames, the raw image here, the JPEG there; the order they always
        // ran in). No order with systems not in the schedule: it would change the executor's
        // order of the others.
        match frames {
            #[cfg(feature = "rrd")]
            Some(f) if f.jpeg => {
                schedule.add_systems(system.after(collect_frames).before(record_frames_rrd))
            }
            Some(_) => schedule.add_systems(system.after(collect_frames)),
            None => schedule.add_systems(system),
        };
    }
}

/// Record set, after [`crate::record::frames::collect_frames`]: writes this tick's messages
/// and the camera frames collected in it (see the module doc of [`crate::record::topics`]).
pub fn record_mcap(
    export: ResMut<McapExport>,
    clock: Res<SimClock>,
    frames: Option<ResMut<RecordedFrames>>,
    robots: Query<RobotData<'_>>,
) {
    let export = export.into_inner();
    if let Some(mut frames) = frames {
        export.write_frames(&mut frames.ready);
    }
    if export.error.is_some() {
        return;
    }
    let rec = &mut export.rec;
    let now = clock.now();
    let mut rows: Vec<RobotData<'_>> = robots.iter().collect();
    rows.sort_by_key(|r| r.0.0);
    export.transforms.clear();
    let result = rows.iter().try_for_each(|row| {
        let Some(t) = export.robots.iter_mut().find(|t| t.index == row.0.0) else {
            return Ok(());
        };
        write_robot(rec, t, row, now, &mut export.transforms)
    });
    let result = result.and_then(|()| {
        if export.transforms.is_empty() {
            return Ok(());
        }
        let msg = crate::record::mcap::messages::TFMessage {
            transforms: std::mem::take(&mut export.transforms),
        };
        let r = rec.write(export.tf, stamp_ns(now), &msg);
        export.transforms = msg.transforms;
        r
    });
    if let Err(e) = result {
        export.error = Some(e);
    }
}

fn write_robot(
    rec: &mut McapRecorder,
    t: &mut RobotTopics,
    row: &RobotData<'_>,
    now: f64,
    transforms: &mut Vec<crate::record::mcap::messages::TransformStamped>,
) -> anyhow::Result<()> {
    let (_, truth, scans, encoders, odom, gps, compass, sonars, locs, nav) = *row;
    if let (Some((ch, scan_time)), Some(scans)) = (t.scan, scans) {
        for s in &scans.scans {
            rec.write(
                ch,
                stamp_ns(s.stamp),
                &laser_scan(s, &t.laser_frame, scan_time),
            )?;
        }
    }
    if let (Some((ch, tpr, ackermann)), Some(enc)) = (t.joints, encoders) {
        for r in &enc.readings {
            rec.write(
                ch,
                stamp_ns(r.stamp),
                &joint_state(r, tpr, ackermann, &t.base),
            )?;
        }
    }
    if let Some(odom) = odom {
        let first = encoders.and_then(|e| e.readings.first()).map(|r| r.stamp);
        write_odometry(rec, t, odom, first)?;
        update_correction(t, odom, locs, nav);
        transforms.push(transform(now, "map", &t.odom_frame, &t.correction));
        transforms.push(transform(odom.stamp, &t.odom_frame, &t.base, &odom.pose));
    }
    if let (Some(ch), Some(gps)) = (t.gps, gps) {
        for f in &gps.fixes {
            rec.write(ch, stamp_ns(f.stamp), &nav_sat_fix(f, &t.base))?;
        }
    }
    if let (Some(ch), Some(compass)) = (t.compass, compass) {
        for r in &compass.readings {
            rec.write(ch, stamp_ns(r.stamp), &compass_imu(r, &t.base))?;
        }
    }
    if let (Some(s), Some(readings)) = (&t.sonars, sonars)
        && readings.fired
    {
        for (k, &range) in readings.latest.iter().enumerate() {
            let (Some(&ch), Some(frame)) = (s.channels.get(k), s.frames.get(k)) else {
                continue;
            };
            let msg = Range {
                header: header(readings.stamp, frame),
                radiation_type: Range::ULTRASOUND,
                field_of_view: s.field_of_view,
                min_range: s.min_range,
                max_range: s.max_range,
                range,
            };
            rec.write(ch, stamp_ns(readings.stamp), &msg)?;
        }
    }
    rec.write(
        t.truth,
        stamp_ns(now),
        &pose_stamped(now, "map", &truth.pose),
    )
}

/// Every odometry pose integrated since the last one written; before them, the start pose at
/// the first encoder reading (which only sets the odometry's origin), so there is one message
/// per reading. `first`: the stamp of this tick's first encoder reading.
fn write_odometry(
    rec: &mut McapRecorder,
    t: &mut RobotTopics,
    odom: &WheelOdometry,
    first: Option<f64>,
) -> anyhow::Result<()> {
    let Some(ch) = t.odom else {
        return Ok(());
    };
    let start = match (t.last_odom, first) {
        (None, Some(stamp)) => Some((stamp, t.odom_start)),
        _ => None,
    };
    for &(stamp, pose) in start.iter().chain(odom.trail()) {
        if t.last_odom.is_some_and(|(last, _)| stamp <= last) {
            continue;
        }
        let msg = odometry(stamp, &t.odom_frame, &t.base, &pose, t.last_odom);
        rec.write(ch, stamp_ns(stamp), &msg)?;
        t.last_odom = Some((stamp, pose));
    }
    Ok(())
}

/// map → odom: the navigation source's correction when the robot navigates by a localizer,
/// else that of its first localizer (scenario order) from its latest estimate, computed in the
/// tick of the estimate (when the odometry at its stamp is still known).
fn update_correction(
    t: &mut RobotTopics,
    odom: &WheelOdometry,
    locs: Option<&Localizers>,
    nav: Option<&NavSource>,
) {
    if let Some(src) = nav {
        t.correction = src.correction;
        t.correction_stamp = src.stamp;
        return;
    }
    let Some(latest) = locs.and_then(|l| l.items.first()).and_then(|l| l.latest) else {
        return;
    };
    if latest.stamp > t.correction_stamp {
        let at = odom.pose_at(latest.stamp);
        t.correction = latest.estimate.pose.compose(&at.inverse());
        t.correction_stamp = latest.stamp;
    }
}

impl McapExport {
    /// Writes camera frames (`sensor_msgs/Image`, rgb8) to their robots' topics (taking their
    /// raw images).
    pub fn write_frames(&mut self, frames: &mut [RecordedFrame]) {
        if self.error.is_some() {
            return;
        }
        let rec = &mut self.rec;
        for f in frames {
            let Some(img) = f.raw.take() else { continue };
            let Some(t) = self.robots.iter().find(|t| t.index == f.robot.0) else {
                continue;
            };
            let Some(ch) = t.camera else { continue };
            let msg = Image::rgb8(
                header(img.stamp, &t.camera_frame),
                img.width,
                img.height,
                img.rgb,
            );
            if let Err(e) = rec.write_owned(ch, stamp_ns(img.stamp), msg) {
                self.error = Some(e);
                return;
            }
        }
    }
}
