//! Files a run exports besides the recording, on request: CARMEN logs (`--carmen-out`,
//! [`crate::formats::carmen::export`]), maps (`--save-map`, [`crate::formats::maps`]) and an MCAP replay
//! (`--mcap`, [`crate::record::topics`]). All are observers in the Record set: they never change what
//! the run computes.

use crate::build::SimWorld;
use crate::formats::carmen::export::{CarmenExport, record_carmen};
use crate::formats::maps::{KnownPoseMaps, SavedMap, map_known_poses, run_maps, save_maps};
use crate::record::topics::{McapExport, McapWritten, record_mcap};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::path::PathBuf;
use systems::core::{Pose2, SimSet};

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
    pub carmen_logs: Vec<PathBuf>,
    pub maps: Vec<SavedMap>,
    pub mcap: Option<McapWritten>,
}

impl RunExports {
    /// Adds the exporters to a built world (before the first tick).
    pub(crate) fn install(&self, sim: &mut SimWorld, scenario: &Scenario) -> anyhow::Result<()> {
        if let Some(out) = &self.carmen_out {
            sim.world.insert_resource(CarmenExport::new(scenario, out)?);
            sim.schedule
                .add_systems(record_carmen.in_set(SimSet::Record));
        }
        if self.save_map.is_some() {
            let maps = KnownPoseMaps::new(&mut sim.world, scenario.grid.resolution);
            sim.world.insert_resource(maps);
            sim.schedule
                .add_systems(map_known_poses.in_set(SimSet::Record));
        }
        if let Some(path) = &self.mcap {
            let export = McapExport::new(&mut sim.world, scenario, path)?;
            sim.world.insert_resource(export);
            sim.schedule.add_systems(record_mcap.in_set(SimSet::Record));
        }
        Ok(())
    }

    /// Writes the exports of a finished run. Maps are judged against the scenario's map: SLAM
    /// systems start at the robot's true start pose, so their map frame is the world frame.
    pub(crate) fn finish(
        &self,
        world: &mut World,
        scenario: &Scenario,
    ) -> anyhow::Result<Exported> {
        let mut done = Exported::default();
        if let Some(export) = world.remove_resource::<CarmenExport>() {
            done.carmen_logs = export.save()?;
        }
        if let Some(export) = world.remove_resource::<McapExport>() {
            done.mcap = Some(export.finish()?);
        }
        if let Some(path) = &self.save_map {
            let maps = run_maps(world);
            if maps.is_empty() {
                anyhow::bail!(
                    "--save-map: {} has no robot with a laser or a SLAM system to map with",
                    scenario.source
                );
            }
            done.maps = save_maps(path, &maps, Some((&scenario.grid, &Pose2::default())))?;
        }
        Ok(done)
    }
}
