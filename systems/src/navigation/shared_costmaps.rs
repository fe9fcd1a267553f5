//! The costmaps the navigators share: one per distinct inflation setting (robot radius plus
//! safety margin), built from the static world and rebuilt when it changes (a door opens or
//! closes): every robot's planner sees the edit at the next tick. A rebuild of the hospital
//! costmap takes ≈ 19 ms (`cargo bench -p systems --bench planner`), and doors move a few times
//! per run, so a whole rebuild is cheaper to get right than a windowed one.

use super::costmap::{Costmap, CostmapParams};
use crate::core::cache::MapCache;
use crate::raycast::StaticWorld;
use bevy_ecs::prelude::*;

#[derive(Resource, Clone, Debug)]
pub struct NavCostmaps {
    pub maps: Vec<(CostmapParams, Costmap)>,
    /// The static world's version they were built from.
    pub world_version: u64,
    /// Bumped on every rebuild (navigators and the recorder watch it).
    pub version: u64,
}

impl NavCostmaps {
    /// Costmaps for each parameter set of `params` (deduplicated; look indices up with
    /// [`NavCostmaps::index_of`]).
    pub fn new(world: &StaticWorld, params: &[CostmapParams]) -> Self {
        Self::new_cached(world, params, &MapCache::disabled())
    }

    /// [`NavCostmaps::new`] with each costmap read from `cache` when it holds it.
    pub fn new_cached(world: &StaticWorld, params: &[CostmapParams], cache: &MapCache) -> Self {
        let mut maps: Vec<(CostmapParams, Costmap)> = Vec::new();
        for p in params {
            if !maps.iter().any(|(q, _)| q == p) {
                maps.push((*p, Costmap::from_grid_cached(world.grid(), p, cache)));
            }
        }
        NavCostmaps {
            maps,
            world_version: world.version,
            version: 0,
        }
    }

    pub fn index_of(&self, params: &CostmapParams) -> Option<usize> {
        self.maps.iter().position(|(p, _)| p == params)
    }

    pub fn get(&self, i: usize) -> &Costmap {
        &self.maps[i.min(self.maps.len() - 1)].1
    }
}

/// Plan (first): rebuild the costmaps after a static-world edit.
pub fn sync_costmaps(world: Res<StaticWorld>, costmaps: Option<ResMut<NavCostmaps>>) {
    let Some(mut c) = costmaps else {
        return;
    };
    if c.world_version == world.version {
        return;
    }
    for (p, map) in c.maps.iter_mut() {
        *map = Costmap::from_grid(world.grid(), p);
    }
    c.world_version = world.version;
    c.version += 1;
}
