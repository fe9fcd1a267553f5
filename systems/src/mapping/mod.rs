//! Mapping: building maps from sensor data, and judging them against ground truth.
//!
//! * [`occupancy`] — occupancy grid mapping with known poses (Thrun et al., *Probabilistic
//!   Robotics*, §9.2): the log-odds map scans are inserted into, growing by blocks, exported as a
//!   [`crate::matching::ProbGrid`] or a map_server map;
//! * [`quality`] — map quality against a true map: precision (estimated walls on true walls)
//!   and recall (observable true walls covered), after aligning the frames;
//! * [`align`] — that alignment: from the robot's true start pose, optionally refined by chamfer
//!   matching;
//! * [`matched_map`] — a map matched against and inserted into scan after scan (map, mirror,
//!   pyramid);
//! * [`scan_to_map`] — scan-to-map SLAM (Hector-style Gauss-Newton with an odometry prior);
//! * [`de_map_match`] — differential evolution as scan-to-map SLAM's alternative matcher;
//! * [`graph_slam`] — graph SLAM: submaps, branch-and-bound loop closure, pose-graph optimization
//!   (Cartographer-style);
//! * [`rbpf`] — Rao-Blackwellized particle filter SLAM (GMapping-style: a map per particle,
//!   improved proposal from scan matching, adaptive resampling);
//! * [`pose_graph`] — sparse pose adjustment on SE(2) with a Huber kernel, the back end of
//!   graph-based SLAM;
//! * `insert` — applying one scan's hits and misses to log-odds cells (private);
//! * `grow` — a grid's extent on a fixed cell lattice and growth by whole blocks (private).

pub mod align;
pub mod de_map_match;
pub mod graph_slam;
mod grow;
mod insert;
pub mod inverse_model;
pub mod matched_map;
pub mod occupancy;
pub mod pose_graph;
pub mod quality;
pub mod rbpf;
pub mod scan_to_map;

#[cfg(test)]
mod tests;

pub use align::{refine_alignment, start_pose_alignment};
pub use insert::InsertStats;
pub use inverse_model::OccupancyParams;
pub use occupancy::LogOddsMap;
pub use quality::{MapQuality, map_quality, quality_with_start_pose};

pub use graph_slam::{GraphSlam, GraphSlamConfig};
pub use rbpf::{RbpfConfig, RbpfSlam};
pub use scan_to_map::{ScanToMapConfig, ScanToMapSlam};

use crate::core::{KernelPool, SimPlugin, SimSet};
use crate::localization::localizer::{FeedQuery, feed_query};
use crate::localization::{LocalizationMap, Localizers};
use bevy_ecs::prelude::*;

/// Adds the SLAM systems' feed to the Map set.
pub struct MappingPlugin;

impl SimPlugin for MappingPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        if crate::core::any_with::<Localizers>(world) {
            schedule.add_systems(run_slam.in_set(SimSet::Map));
        }
    }
}

/// Map: every SLAM system (a [`crate::localization::Filter::Scan`] among a robot's localizers)
/// consumes this tick's scans with the odometry pose at each scan's time.
pub fn run_slam(map: Option<Res<LocalizationMap>>, pool: Res<KernelPool>, mut robots: FeedQuery) {
    // scans of a faulted laser never come: no degraded state for the SLAM systems
    feed_query(map.as_deref(), &pool, &mut robots, false, |f| f.is_scan());
}
