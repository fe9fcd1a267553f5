//! The map localizers believe in: a snapshot of the static occupancy grid taken when the world is
//! built (a localizer knows the floor plan, not where today's obstacles stand), with the
//! structures the measurement models need: the Euclidean distance field (likelihood fields), the
//! ray-casting map (beam models, expected scans) and the list of free cells (global
//! initialisation and random particles). Edits go through [`LocalizationMap::set_cells`] so all
//! views stay consistent.

use crate::core::cache::MapCache;
use crate::raycast::RayMap;
use crate::world::{Cell, DistanceField, OccupancyGrid};
use bevy_ecs::prelude::Resource;

#[derive(Resource)]
pub struct LocalizationMap {
    pub grid: OccupancyGrid,
    pub field: DistanceField,
    pub rays: RayMap,
    /// Indices of the free cells.
    free: Vec<u32>,
}

impl LocalizationMap {
    /// The map of `grid`, its distance field truncated at `max_dist` (m): the largest distance
    /// any likelihood model using it needs.
    pub fn new(grid: OccupancyGrid, max_dist: f64) -> Self {
        let rays = RayMap::from_grid(&grid);
        Self::with_rays(grid, max_dist, rays)
    }

    /// [`LocalizationMap::new`] with the ray-casting map of `grid` already built (the static
    /// world's, before any edit: the same map, so it need not be built twice).
    pub fn with_rays(grid: OccupancyGrid, max_dist: f64, rays: RayMap) -> Self {
        Self::with_rays_cached(grid, max_dist, rays, &MapCache::disabled())
    }

    /// [`LocalizationMap::with_rays`] with the distance field read from `cache` when it holds
    /// it.
    pub fn with_rays_cached(
        grid: OccupancyGrid,
        max_dist: f64,
        rays: RayMap,
        cache: &MapCache,
    ) -> Self {
        let field = DistanceField::new_cached(&grid, max_dist, cache);
        let free = Self::free_cells(&grid);
        LocalizationMap {
            grid,
            field,
            rays,
            free,
        }
    }

    fn free_cells(grid: &OccupancyGrid) -> Vec<u32> {
        (0..grid.cells.len() as u32)
            .filter(|&i| grid.cells[i as usize] == Cell::Free)
            .collect()
    }

    /// Number of free cells.
    pub fn free_count(&self) -> usize {
        self.free.len()
    }

    /// Whether the point (m) lies on a free cell of the map.
    pub fn is_free(&self, x: f64, y: f64) -> bool {
        self.grid
            .cell_of(x, y)
            .is_some_and(|(c, r)| self.grid.get(c, r) == Cell::Free)
    }

    /// A pose uniform over free space with a uniform heading, from uniform draws in [0, 1).
    /// With no free cell at all, a pose uniform over the whole grid.
    pub fn random_free_pose(&self, u: &mut dyn FnMut() -> f64) -> (f64, f64, f64) {
        let g = &self.grid;
        let (c, r) = if self.free.is_empty() {
            (u() * g.width as f64, u() * g.height as f64)
        } else {
            let i = self.free[self.free_slot(u())] as usize;
            ((i % g.width) as f64 + u(), (i / g.width) as f64 + u())
        };
        self.pose_at(c, r, u())
    }

    /// `n` poses of [`LocalizationMap::random_free_pose`] from the same draws in the same
    /// order, drawn first and then placed: the free cells they pick are scattered over the
    /// map, and with no draw between them their loads overlap.
    pub fn random_free_poses(&self, n: usize, u: &mut dyn FnMut() -> f64) -> Vec<[f64; 3]> {
        if self.free.is_empty() {
            return (0..n)
                .map(|_| {
                    let (x, y, th) = self.random_free_pose(u);
                    [x, y, th]
                })
                .collect();
        }
        let draws: Vec<[f64; 4]> = (0..n).map(|_| [u(), u(), u(), u()]).collect();
        let cells: Vec<u32> = draws
            .iter()
            .map(|d| self.free[self.free_slot(d[0])])
            .collect();
        let w = self.grid.width;
        draws
            .iter()
            .zip(cells)
            .map(|(d, i)| {
                let i = i as usize;
                let (x, y, th) = self.pose_at((i % w) as f64 + d[1], (i / w) as f64 + d[2], d[3]);
                [x, y, th]
            })
            .collect()
    }

    /// The index into the free cells a uniform draw picks (some free cell exists).
    fn free_slot(&self, u: f64) -> usize {
        ((u * self.free.len() as f64) as usize).min(self.free.len() - 1)
    }

    /// The pose at fractional cell (c, r), heading from a uniform draw.
    fn pose_at(&self, c: f64, r: f64, u: f64) -> (f64, f64, f64) {
        let g = &self.grid;
        let th = (u * 2.0 - 1.0) * std::f64::consts::PI;
        (
            g.origin[0] + c * g.resolution,
            g.origin[1] + r * g.resolution,
            th,
        )
    }

    /// Local edit of the believed map (e.g. a door the robots are told about).
    pub fn set_cells(&mut self, cells: &[(usize, usize, Cell)]) {
        let mut changed = Vec::new();
        let mut ray_edits = Vec::new();
        for &(c, r, cell) in cells {
            if c < self.grid.width && r < self.grid.height && self.grid.get(c, r) != cell {
                self.grid.set(c, r, cell);
                changed.push((c, r));
                ray_edits.push((c, r, cell == Cell::Occupied));
            }
        }
        if changed.is_empty() {
            return;
        }
        self.field.update(&self.grid, &changed);
        self.rays.set_cells(&ray_edits);
        self.free = Self::free_cells(&self.grid);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raycast::StaticWorld;

    /// Poses drawn together are the poses drawn one by one from the same stream, with or
    /// without free cells.
    #[test]
    fn poses_drawn_together_are_those_drawn_one_by_one() {
        let mut grid = OccupancyGrid::new(37, 23, 0.1, [-1.0, 2.0], Cell::Free);
        grid.set(3, 4, Cell::Occupied);
        let full = OccupancyGrid::new(5, 4, 0.2, [0.0, 0.0], Cell::Occupied);
        for grid in [grid, full] {
            let map = LocalizationMap::new(grid, 1.0);
            let stream = |seed: u64| {
                let mut x = seed;
                move || {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (x >> 11) as f64 / (1u64 << 53) as f64
                }
            };
            let mut u = stream(9);
            let one_by_one: Vec<[f64; 3]> = (0..500)
                .map(|_| {
                    let (x, y, th) = map.random_free_pose(&mut u);
                    [x, y, th]
                })
                .collect();
            let together = map.random_free_poses(500, &mut stream(9));
            let bits =
                |v: &[[f64; 3]]| -> Vec<u64> { v.iter().flatten().map(|x| x.to_bits()).collect() };
            assert_eq!(bits(&one_by_one), bits(&together));
        }
    }

    /// The localizers' map built on the static world's ray caster casts every ray and scan as
    /// one built on its own.
    #[test]
    fn a_map_on_the_static_world_s_rays_casts_as_its_own() {
        let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
        let grid = crate::world::map_file::load_map(&path).unwrap();
        let own = LocalizationMap::new(grid.clone(), 2.0);
        let ground = StaticWorld::new(grid.clone());
        let shared = LocalizationMap::with_rays(grid, 2.0, ground.rays().clone());
        assert_eq!(own.field.cells, shared.field.cells);
        assert_eq!(own.free_count(), shared.free_count());
        let mut hits = 0;
        for k in 0..5_000 {
            let p = [
                (k * 37 % 640) as f32 * 0.1 + 0.05,
                (k * 53 % 320) as f32 * 0.1 + 0.05,
            ];
            let angle = k as f32 * 0.7331;
            let (a, b) = (
                own.rays.cast(p, angle, 20.0),
                shared.rays.cast(p, angle, 20.0),
            );
            assert_eq!(a.to_bits(), b.to_bits(), "ray {k}");
            hits += usize::from(a < 20.0);
        }
        assert!(hits > 2_500, "{hits}");
        let (mut a, mut b) = (vec![0.0f32; 1081], vec![0.0f32; 1081]);
        let start = -135f32.to_radians();
        let inc = 0.25f32.to_radians();
        own.rays.cast_scan([20.0, 15.0], start, inc, 20.0, &mut a);
        shared
            .rays
            .cast_scan([20.0, 15.0], start, inc, 20.0, &mut b);
        assert_eq!(a, b);
    }
}
