//! A run's outputs: the Rerun recording, the camera frames both recordings share, and the exports
//! asked for (CARMEN logs, maps, the MCAP replay) join the schedule's Record set as plugins
//! ([`output_plugins`]) before the first tick and are finished after the last one. They only
//! observe: the run computes the same with or without them.

use crate::build::SimWorld;
use crate::formats::carmen::export::{CarmenExport, CarmenExportPlugin};
use crate::formats::maps::{KnownPoseMapsPlugin, can_map};
use crate::record::frames::{FrameOutputs, FramesPlugin, RecordedFrames, log_frames_rrd};
use crate::record::rrd::slam::record_slam_final;
use crate::record::rrd::{RrdPlugin, RrdRecorder};
use crate::record::topics::{McapExport, McapPlugin};
use crate::run::exports::{Exported, RunExports};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::path::Path;
use systems::core::{SimClock, SimPlugin};
use systems::localization::{Filter, Localizers};

/// The plugins of the outputs asked for, in the order they join the schedule: the .rrd
/// recording (`rrd`), the CARMEN logs, the known-pose maps, the camera frames when a recording
/// wants them, the MCAP replay. Their files are opened here, so a bad path fails before the
/// first tick.
pub fn output_plugins(
    world: &mut World,
    scenario: &Scenario,
    rrd: Option<&Path>,
    exports: &RunExports,
) -> anyhow::Result<Vec<Box<dyn SimPlugin>>> {
    let mut plugins: Vec<Box<dyn SimPlugin>> = Vec::new();
    if let Some(path) = rrd {
        plugins.push(Box::new(RrdPlugin::new(path, scenario)?));
    }
    if let Some(out) = &exports.carmen_out {
        let export = CarmenExport::new(scenario, out)?;
        plugins.push(Box::new(CarmenExportPlugin::new(export)));
    }
    if exports.save_map.is_some() {
        if !can_map(world) {
            anyhow::bail!(
                "--save-map: {} has no robot with a laser or a SLAM system to map with",
                scenario.source
            );
        }
        plugins.push(Box::new(KnownPoseMapsPlugin {
            resolution: scenario.grid.resolution,
        }));
    }
    let mcap = match &exports.mcap {
        Some(path) => Some(McapPlugin::new(world, scenario, path)?),
        None => None,
    };
    let frames = FrameOutputs {
        raw: mcap.is_some(),
        jpeg: rrd.is_some(),
    };
    if let Some(p) = FramesPlugin::new(world, scenario.record.camera_rate, frames)? {
        plugins.push(Box::new(p));
    }
    if let Some(p) = mcap {
        plugins.push(Box::new(p));
    }
    Ok(plugins)
}

/// Adds the recording, the camera frames and the exports to a built world.
pub(crate) fn install(
    sim: &mut SimWorld,
    scenario: &Scenario,
    rrd: Option<&Path>,
    exports: &RunExports,
) -> anyhow::Result<()> {
    for p in output_plugins(&mut sim.world, scenario, rrd, exports)? {
        p.build(&mut sim.world, &mut sim.schedule);
    }
    Ok(())
}

/// The run is over: SLAM systems run their final optimization and the camera frames still being
/// rendered go to the recordings (before the recording's last frame and the summary read them);
/// the frame worker's error, if any.
pub(crate) fn finish_estimators_and_frames(w: &mut World) -> Option<String> {
    finish_slam(w);
    finish_frames(w)
}

/// Writes the end of the recording and the exports.
pub(crate) fn finish_files(
    w: &mut World,
    scenario: &Scenario,
    exports: &RunExports,
) -> anyhow::Result<Exported> {
    if w.contains_resource::<RrdRecorder>() {
        record_slam_final(w);
    }
    if let Some(mut rec) = w.remove_resource::<RrdRecorder>() {
        rec.finish()?;
    }
    exports.finish(w, scenario)
}

/// The camera frames still being rendered go to the recordings; the worker's error, if any.
fn finish_frames(w: &mut World) -> Option<String> {
    let (mut frames, error) = w.remove_resource::<RecordedFrames>()?.finish();
    let now = w.resource::<SimClock>().now();
    if let Some(mut r) = w.get_resource_mut::<RrdRecorder>() {
        log_frames_rrd(&mut r, &mut frames, now);
    }
    if let Some(mut export) = w.get_resource_mut::<McapExport>() {
        export.write_frames(&mut frames);
    }
    error
}

/// The run is over: SLAM systems run their final optimization (before the recording's last
/// frame and the summary read their results).
fn finish_slam(w: &mut World) {
    let mut q = w.query::<&mut Localizers>();
    for mut locs in q.iter_mut(w) {
        for l in locs.items.iter_mut() {
            if let Filter::Scan(e) = &mut l.filter {
                e.finish();
            }
        }
    }
}
