//! The static world resource: the occupancy grid plus the structures derived from it (the
//! ray-casting map; the physics collider tiles, rebuilt by the physics bridge from the dirty list).
//! Every edit goes through [`StaticWorld::set_cells`] so all views stay consistent.

use super::raymap::RayMap;
use crate::core::cache::MapCache;
use crate::world::grid::{Cell, OccupancyGrid};
use bevy_ecs::prelude::Resource;
use std::sync::Arc;

/// Side of a physics collider tile, in cells (64 cells = 3.2 m at 5 cm).
pub const COLLIDER_TILE: usize = 64;

#[derive(Resource)]
pub struct StaticWorld {
    grid: OccupancyGrid,
    /// Shared by the worlds of a sharing cache until one of them edits it.
    rays: Arc<RayMap>,
    dirty_tiles: Vec<(usize, usize)>,
    /// Incremented on every edit (planners and recorders can watch it).
    pub version: u64,
}

impl StaticWorld {
    pub fn new(grid: OccupancyGrid) -> Self {
        Self::new_cached(grid, &MapCache::disabled())
    }

    /// [`StaticWorld::new`] with the ray map read from `cache` when it holds this grid's (the
    /// copy other worlds hold, when it shares).
    pub fn new_cached(grid: OccupancyGrid, cache: &MapCache) -> Self {
        let rays = RayMap::from_grid_shared(&grid, cache);
        StaticWorld {
            grid,
            rays,
            dirty_tiles: Vec::new(),
            version: 0,
        }
    }

    pub fn grid(&self) -> &OccupancyGrid {
        &self.grid
    }

    pub fn rays(&self) -> &RayMap {
        &self.rays
    }

    /// Number of collider tiles along x and y.
    pub fn tile_counts(&self) -> (usize, usize) {
        (
            self.grid.width.div_ceil(COLLIDER_TILE),
            self.grid.height.div_ceil(COLLIDER_TILE),
        )
    }

    /// Local edit: sets cells, updates the ray map and marks the touched collider tiles dirty.
    pub fn set_cells(&mut self, cells: &[(usize, usize, Cell)]) {
        let mut ray_edits = Vec::with_capacity(cells.len());
        for &(col, row, cell) in cells {
            if col >= self.grid.width || row >= self.grid.height {
                continue;
            }
            if self.grid.get(col, row) == cell {
                continue;
            }
            self.grid.set(col, row, cell);
            ray_edits.push((col, row, cell == Cell::Occupied));
            let tile = (col / COLLIDER_TILE, row / COLLIDER_TILE);
            if !self.dirty_tiles.contains(&tile) {
                self.dirty_tiles.push(tile);
            }
        }
        if !ray_edits.is_empty() {
            Arc::make_mut(&mut self.rays).set_cells(&ray_edits);
            self.version += 1;
        }
    }

    /// Sets every cell whose centre lies in the world rectangle [x0, x1] × [y0, y1].
    pub fn set_region(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, cell: Cell) {
        let g = &self.grid;
        let mut edits = Vec::new();
        for row in 0..g.height {
            let cy = g.origin[1] + (row as f64 + 0.5) * g.resolution;
            if cy < y0 || cy > y1 {
                continue;
            }
            for col in 0..g.width {
                let cx = g.origin[0] + (col as f64 + 0.5) * g.resolution;
                if cx >= x0 && cx <= x1 {
                    edits.push((col, row, cell));
                }
            }
        }
        self.set_cells(&edits);
    }

    /// Collider tiles changed since the last call (consumed by the physics bridge).
    pub fn take_dirty_tiles(&mut self) -> Vec<(usize, usize)> {
        std::mem::take(&mut self.dirty_tiles)
    }
}
