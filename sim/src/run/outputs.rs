//! A run's outputs: the Rerun recording, the camera frames both recordings share, and the exports
//! asked for (CARMEN logs, maps, the MCAP replay) join the schedule's Record set before the first
//! tick and are finished after the last one. They only observe: the run computes the same with
//! or without them.

use crate::build::SimWorld;
use crate::record::frames::{
    FrameOutputs, RecordedFrames, collect_frames, log_frames_rrd, record_frames_rrd,
};
use crate::record::rrd::outdoor::{OutdoorRecording, record_outdoor};
use crate::record::rrd::slam::{SlamRecording, record_slam, record_slam_final};
use crate::record::topics::{McapExport, record_mcap};
use crate::record::{RrdRecorder, record_navigation, record_rrd};
use crate::run::exports::{Exported, RunExports};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::path::Path;
use systems::core::{SimClock, SimSet};
use systems::localization::{Filter, Localizers};
use systems::sensors::Camera;

/// Adds the recording, the camera frames and the exports to a built world.
pub(crate) fn install(
    sim: &mut SimWorld,
    scenario: &Scenario,
    rrd: Option<&Path>,
    exports: &RunExports,
) -> anyhow::Result<()> {
    if let Some(path) = rrd {
        let rec = RrdRecorder::create(path, &scenario.name, &scenario.grid, &scenario.record)?;
        sim.world.insert_resource(rec);
        sim.world.insert_resource(SlamRecording::new(
            scenario.record.scan_rate,
            scenario.record.slam_rate,
        ));
        sim.world.insert_resource(OutdoorRecording::new(
            scenario.record.rate,
            scenario.record.particle_rate,
        ));
        sim.schedule.add_systems(
            (record_rrd, record_navigation, record_slam, record_outdoor)
                .chain()
                .in_set(SimSet::Record),
        );
    }
    exports.install(sim, scenario)?;
    install_frames(sim, scenario, rrd.is_some(), exports)
}

/// Renders whole camera frames for the recordings on a worker thread when a recording is
/// written and a robot carries a camera ([`crate::record::frames`]).
fn install_frames(
    sim: &mut SimWorld,
    scenario: &Scenario,
    rrd: bool,
    exports: &RunExports,
) -> anyhow::Result<()> {
    let outputs = FrameOutputs {
        raw: exports.mcap.is_some(),
        jpeg: rrd,
    };
    let cameras = sim.world.query::<&Camera>().iter(&sim.world).count();
    if cameras == 0 || !(outputs.raw || outputs.jpeg) {
        return Ok(());
    }
    let frames = RecordedFrames::new(scenario.record.camera_rate, outputs)?;
    sim.world.insert_resource(frames);
    let collect = collect_frames.in_set(SimSet::Record).before(record_mcap);
    if outputs.jpeg {
        sim.schedule
            .add_systems((collect, record_frames_rrd.in_set(SimSet::Record)).chain());
    } else {
        sim.schedule.add_systems(collect);
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
