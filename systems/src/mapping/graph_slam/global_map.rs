//! The graph SLAM's map: every node's scan inserted at its optimized pose (Cartographer rebuilds
//! its map from the optimized submap poses; we go one step finer and re-insert the scans, so the
//! map is what known-pose mapping ([`crate::mapping::occupancy`]) makes of the optimized
//! trajectory).
//!
//! Kept up to date lazily: new nodes are appended; the whole map is rebuilt only when an
//! optimization moved some already inserted laser pose by more than half a cell at its
//! farthest reading (translation plus rotation × `reach`). Most optimizations move old nodes by
//! millimetres, so a recording that asks for the map every few seconds no longer pays a full
//! rebuild after each of them.

use crate::core::{Pose2, wrap_angle};
use crate::mapping::inverse_model::OccupancyParams;
use crate::mapping::occupancy::LogOddsMap;
use crate::matching::ProbGrid;
use crate::sensors::LaserScan;
use std::sync::Mutex;

#[derive(Debug)]
struct Cache {
    /// The laser poses the map holds, in node order.
    poses: Vec<Pose2>,
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

    /// The map of `scans` (laser pose, scan), in node order.
    pub fn get<'a>(&self, scans: impl Iterator<Item = (Pose2, &'a LaserScan)>) -> ProbGrid {
        let scans: Vec<(Pose2, &LaserScan)> = scans.collect();
        let mut guard = match self.cache.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        let tolerance = 0.5 * self.resolution;
        let reach = f64::from(self.params.max_range);
        let stale = guard.as_ref().is_none_or(|c| {
            c.poses.len() > scans.len()
                || c.poses.iter().zip(&scans).any(|(old, (new, scan))| {
                    let reach = reach.min(f64::from(scan.range_max));
                    old.distance(new) + wrap_angle(old.theta - new.theta).abs() * reach > tolerance
                })
        });
        if stale {
            *guard = Some(Cache {
                poses: Vec::new(),
                map: LogOddsMap::anchored(
                    self.resolution,
                    self.params.clone(),
                    super::super::matched_map::slam_anchor(self.resolution),
                ),
            });
        }
        let Some(cache) = guard.as_mut() else {
            return ProbGrid::new(0, 0, self.resolution, [0.0, 0.0], 0.5);
        };
        for (sensor, scan) in scans.iter().skip(cache.poses.len()) {
            cache.map.insert_scan(sensor, scan);
            cache.poses.push(*sensor);
        }
        cache.map.to_prob_grid()
    }
}
