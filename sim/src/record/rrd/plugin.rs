//! The .rrd recording as a plugin of the tick: the recorder, the SLAM and outdoor parts' states,
//! and their systems chained in the Record set.

use super::RrdRecorder;
use super::events::record_events;
use super::navigation::record_navigation;
use super::outdoor::{OutdoorRecording, record_outdoor};
use super::record_rrd;
use super::slam::{SlamRecording, record_slam};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use std::cell::Cell;
use std::path::Path;
use systems::core::{SimPlugin, SimSet};

/// `--rrd`: the file is opened by [`RrdPlugin::new`], before the plugin joins the schedule.
pub struct RrdPlugin {
    resources: Cell<Option<(RrdRecorder, SlamRecording, OutdoorRecording)>>,
}

impl RrdPlugin {
    /// Opens `path` for the run of `scenario` (at its `[record]` rates) and logs the map.
    pub fn new(path: &Path, scenario: &Scenario) -> anyhow::Result<Self> {
        let rc = &scenario.record;
        let rec = RrdRecorder::create(path, &scenario.name, &scenario.grid, rc)?;
        let slam = SlamRecording::new(rc.scan_rate, rc.slam_rate);
        let outdoor = OutdoorRecording::new(rc.rate, rc.particle_rate);
        Ok(RrdPlugin {
            resources: Cell::new(Some((rec, slam, outdoor))),
        })
    }
}

impl SimPlugin for RrdPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        let (rec, slam, outdoor) = self.resources.take().expect("RrdPlugin is built once");
        world.insert_resource(rec);
        world.insert_resource(slam);
        world.insert_resource(outdoor);
        // all five write the recorder
        schedule.add_systems(
            (
                record_rrd,
                record_navigation,
                record_slam,
                record_outdoor,
                record_events,
            )
                .chain()
                .in_set(SimSet::Record),
        );
    }
}
