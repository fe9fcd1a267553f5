//! The graph SLAM's map: every node's scan inserted at its optimized pose (Cartographer rebuilds
//! its map from the optimized submap poses; we go one step finer and re-insert the scans, so the
//! map is exactly what known-pose mapping ([`crate::mapping::occupancy`]) makes of the optimized
//! trajectory). Rebuilt from scratch when an optimization moved the nodes, extended with the new
//! nodes otherwise.

use crate::core::Pose2;
use crate::mapping::occupancy::{LogOddsMap, OccupancyParams};
use crate::matching::ProbGrid;
use crate::sensors::LaserScan;
use std::sync::Mutex;

#[derive(Debug)]
struct Cache {
    version: u64,
    inserted: usize,
    map: LogOddsMap,
}

/// A lazily updated map behind a lock (`map()` takes `&self`).
#[derive(Debug)]
pub(super) struct CachedMap {
    resolution: f64,
    params: OccupancyParams,
    cache: Mutex<Option<Cache>>,
}

impl Clone for CachedMap {
    fn clone(&self) -> Self {
        CachedMap::new(self.resolution, self.params.clone())
    }
}

impl CachedMap {
    pub fn new(resolution: f64, params: OccupancyParams) -> Self {
        CachedMap {
            resolution,
            params,
            cache: Mutex::new(None),
        }
    }

    /// The map of `scans` (laser pose, scan) as of graph `version`.
    pub fn get<'a>(
        &self,
        version: u64,
        scans: impl Iterator<Item = (Pose2, &'a LaserScan)>,
    ) -> ProbGrid {
        let mut guard = match self.cache.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        if guard.as_ref().is_none_or(|c| c.version != version) {
            *guard = Some(Cache {
                version,
                inserted: 0,
                map: LogOddsMap::new(self.resolution, self.params.clone()),
            });
        }
        let Some(cache) = guard.as_mut() else {
            return ProbGrid::new(0, 0, self.resolution, [0.0, 0.0], 0.5);
        };
        for (sensor, scan) in scans.skip(cache.inserted) {
            cache.map.insert_scan(&sensor, scan);
            cache.inserted += 1;
        }
        cache.map.to_prob_grid()
    }
}
