//! Files a run exports besides the recording, on request: CARMEN logs (`--carmen-out`,
//! [`crate::formats::carmen::export`]), maps (`--save-map`, [`crate::formats::maps`]) and an MCAP replay
//! (`--mcap`, [`crate::record::topics`]). All are observers in the Record set (plugins, see
//! [`crate::run::output_plugins`]): they never change what the run computes.

use crate::formats::carmen::export::CarmenExport;
use crate::formats::maps::{SavedMap, run_maps, save_maps};
use crate::record::topics::{McapExport, McapWritten};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::path::PathBuf;
use systems::core::Pose2;

/// What to export.
#[derive(Clone, Debug, Default)]
pub struct RunExports {
    /// Write the run as CARMEN logs here (see [`crate::formats::carmen::export`] for several robots).
    pub carmen_out: Option<PathBuf>,
    /// Save the maps here (see [`crate::formats::maps`]).
    pub save_map: Option<PathBuf>,
    /// Write an MCAP replay of ROS 2 messages here (see [`crate::record::topics`]).
    pub mcap: Option<PathBuf>,
}

/// What was exported.
#[derive(Clone, Debug, Default)]
pub struct Exported {
    /// The CARMEN logs written, one per exported robot.
    pub carmen_logs: Vec<PathBuf>,
    /// The maps saved (known-pose maps and SLAM maps).
    pub maps: Vec<SavedMap>,
    /// The MCAP replay, if one was written.
    pub mcap: Option<McapWritten>,
}

impl RunExports {
    /// Whether any export is asked for.
    pub fn writes_files(&self) -> bool {
        self.carmen_out.is_some() || self.save_map.is_some() || self.mcap.is_some()
    }

    /// Writes the exports of a finished run, each whatever became of the others: what was
    /// written; a message naming the file for each export that failed is pushed to `errors`.
    /// Maps are judged against the scenario's map: SLAM systems start at the robot's true
    /// start pose, so their map frame is the world frame.
    pub(crate) fn finish(
        &self,
        world: &mut World,
        scenario: &Scenario,
        errors: &mut Vec<String>,
    ) -> Exported {
        let mut done = Exported::default();
        if let Some(export) = world.remove_resource::<CarmenExport>() {
            match export.save() {
                Ok(logs) => done.carmen_logs = logs,
                Err(e) => errors.push(format!("{e:#}")),
            }
        }
        if let Some(export) = world.remove_resource::<McapExport>() {
            match export.finish() {
                Ok(m) => done.mcap = Some(m),
                Err(e) => errors.push(format!("{e:#}")),
            }
        }
        if let Some(path) = &self.save_map {
            let maps = run_maps(world);
            if maps.is_empty() {
                errors.push(format!(
                    "--save-map: {} has no robot with a laser or a SLAM system to map with",
                    scenario.source
                ));
            } else {
                match save_maps(path, &maps, Some((&scenario.grid, &Pose2::default()))) {
                    Ok(m) => done.maps = m,
                    Err(e) => errors.push(format!("{e:#}")),
                }
            }
        }
        done
    }
}
