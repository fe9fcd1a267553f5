//! A run's outputs: the Rerun recording, the camera frames both recordings share, and the exports
//! asked for (CARMEN logs, maps, the MCAP replay) join the schedule's Record set as plugins
//! ([`output_plugins`]) before the first tick and are finished after the last one. They only
//! observe: the run computes the same with or without them.

use crate::build::SimWorld;
use crate::formats::carmen::export::{CarmenExport, CarmenExportPlugin};
use crate::formats::maps::{KnownPoseMapsPlugin, can_map};
#[cfg(feature = "rrd")]
use crate::record::frames::log_frames_rrd;
use crate::record::frames::{FrameOutputs, FramesPlugin, RecordedFrames};
#[cfg(feature = "rrd")]
use crate::record::rrd::slam::record_slam_final;
#[cfg(feature = "rrd")]
use crate::record::rrd::{RrdPlugin, RrdRecorder};
use crate::record::topics::{McapExport, McapPlugin};
use crate::run::exports::{Exported, RunExports};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::path::Path;
use systems::core::SimPlugin;
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
        #[cfg(feature = "rrd")]
        plugins.push(Box::new(RrdPlugin::new(path, scenario)?));
        #[cfg(not(feature = "rrd"))]
        return Err(crate::record::without_rrd(path));
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

/// Writes the end of the recording and the exports, each whatever became of the others: the
/// files written, and the failures (whether the recording's among them).
pub(crate) fn finish_files(
    w: &mut World,
    scenario: &Scenario,
    exports: &RunExports,
) -> (Exported, Failures) {
    let mut failures = Failures::default();
    #[cfg(feature = "rrd")]
    {
        if w.contains_resource::<RrdRecorder>() {
            record_slam_final(w);
        }
        if let Some(mut rec) = w.remove_resource::<RrdRecorder>()
            && let Err(e) = rec.finish()
        {
            failures.errors.push(format!("{e:#}"));
            failures.recording = true;
        }
    }
    let exported = exports.finish(w, scenario, &mut failures.errors);
    (exported, failures)
}

/// The outputs of a run that could not be written (each error names its file).
#[derive(Clone, Debug, Default)]
pub struct Failures {
    /// One message per output that failed.
    pub errors: Vec<String>,
    /// Whether the Rerun recording is among them.
    pub recording: bool,
}

impl Failures {
    /// `then` (what came after the outputs, e.g. writing the summary) when no output failed;
    /// else an error listing the failures, and `then`'s error after them.
    pub fn or(self, then: anyhow::Result<()>) -> anyhow::Result<()> {
        if self.errors.is_empty() {
            return then;
        }
        let mut lines = self.errors;
        if let Err(e) = then {
            lines.push(format!("{e:#}"));
        }
        Err(anyhow::anyhow!("{}", lines.join("\n")))
    }
}

/// A run that went to its end but could not write some of its outputs: what it left anyway
/// (`done`: the summary, the files that were written) and the failures. The error
/// [`crate::Simulation::finish`] and the run functions return then; a command that writes more
/// after the run (the summary, trajectories) takes `done` back with [`OutputsFailed::split`].
pub struct OutputsFailed<T> {
    /// What the run left.
    pub done: Box<T>,
    /// The outputs that failed.
    pub failures: Failures,
}

impl<T: Send + Sync + 'static> OutputsFailed<T> {
    /// The run's result and the outputs that failed (none for a success); other errors stay
    /// errors.
    pub fn split(r: anyhow::Result<T>) -> anyhow::Result<(T, Failures)> {
        match r {
            Ok(done) => Ok((done, Failures::default())),
            Err(e) => {
                let f = e.downcast::<OutputsFailed<T>>()?;
                Ok((*f.done, f.failures))
            }
        }
    }

    /// `Ok(done)` when nothing failed, else this error.
    pub fn check(done: T, failures: Failures) -> anyhow::Result<T> {
        if failures.errors.is_empty() {
            Ok(done)
        } else {
            Err(OutputsFailed {
                done: Box::new(done),
                failures,
            }
            .into())
        }
    }
}

impl<T> std::fmt::Display for OutputsFailed<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.failures.errors.join("\n"))
    }
}

impl<T> std::fmt::Debug for OutputsFailed<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OutputsFailed")
            .field("failures", &self.failures)
            .finish_non_exhaustive()
    }
}

impl<T> std::error::Error for OutputsFailed<T> {}

/// The camera frames still being rendered go to the recordings; the worker's error, if any.
fn finish_frames(w: &mut World) -> Option<String> {
    let (mut frames, error) = w.remove_resource::<RecordedFrames>()?.finish();
    #[cfg(feature = "rrd")]
    {
        let now = w.resource::<systems::core::SimClock>().now();
        if let Some(mut r) = w.get_resource_mut::<RrdRecorder>() {
            log_frames_rrd(&mut r, &mut frames, now);
        }
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
