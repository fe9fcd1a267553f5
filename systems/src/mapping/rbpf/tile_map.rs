//! A particle's occupancy map in the RBPF: log-odds cells in square tiles shared between
//! particles and copied on write. GMapping shares map patches between the particles of one
//! lineage through its tree of trajectories (Grisetti, Stachniss & Burgard, "Improved Techniques
//! for Grid Mapping with Rao-Blackwellized Particle Filters", IEEE T-RO 23(1), 2007, §V); here a
//! resampled copy of a particle clones only its table of tile pointers, and a tile is copied the
//! first time a scan writes to it while another particle still holds it. A map of 30 particles
//! therefore costs about one map plus the tiles the particles wrote since they last split.
//!
//! Cells lie on the lattice anchored at the world origin (cell (i, j) covers
//! [i·res, (i+1)·res) × [j·res, (j+1)·res)); the table grows by whole tiles to hold each scan.

use super::super::insert::{
    CellStore, GridFrame, InsertStats, LogOddsModel, apply_beams, beam_box, prepare_beams,
};
use super::super::inverse_model::{OccupancyParams, probability};
use super::super::occupancy::MAX_CELLS;
use crate::core::Pose2;
use crate::matching::ProbGrid;
use crate::sensors::LaserScan;
use std::sync::Arc;

/// log2 of the tile side in cells.
const TILE_BITS: u32 = 6;
/// Tile side (cells).
pub const TILE: usize = 1 << TILE_BITS;
const MASK: i64 = TILE as i64 - 1;

#[derive(Clone, Debug)]
struct Tile {
    /// log-odds, `row * TILE + col`.
    l: Vec<f32>,
    /// The scan that last updated each cell (one update per cell per scan).
    stamp: Vec<u32>,
}

impl Tile {
    fn empty() -> Self {
        Tile {
            l: vec![0.0; TILE * TILE],
            stamp: vec![0; TILE * TILE],
        }
    }
}

#[derive(Clone, Debug)]
pub struct TileMap {
    resolution: f64,
    /// Lattice tile coordinates of `tiles[0]`.
    t0: [i64; 2],
    /// Table size in tiles.
    tw: usize,
    th: usize,
    /// `row * tw + col`; None: never written (every cell unknown).
    tiles: Vec<Option<Arc<Tile>>>,
    scan_id: u32,
}

impl TileMap {
    pub fn new(resolution: f64) -> Self {
        assert!(resolution > 0.0, "resolution must be positive");
        TileMap {
            resolution,
            t0: [0, 0],
            tw: 0,
            th: 0,
            tiles: Vec::new(),
            scan_id: 0,
        }
    }

    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Lattice cell of a world point.
    #[inline]
    pub fn cell(&self, x: f64, y: f64) -> [i64; 2] {
        [
            (x / self.resolution).floor() as i64,
            (y / self.resolution).floor() as i64,
        ]
    }

    /// The log-odds of a lattice cell (0, unknown, outside the written tiles).
    #[inline]
    pub fn get(&self, c: [i64; 2]) -> f32 {
        let tx = (c[0] >> TILE_BITS) - self.t0[0];
        let ty = (c[1] >> TILE_BITS) - self.t0[1];
        if tx < 0 || ty < 0 || tx >= self.tw as i64 || ty >= self.th as i64 {
            return 0.0;
        }
        match &self.tiles[ty as usize * self.tw + tx as usize] {
            Some(t) => t.l[((c[1] & MASK) as usize) << TILE_BITS | (c[0] & MASK) as usize],
            None => 0.0,
        }
    }

    /// The evidence of occupation at a world point, interpolated bilinearly between the centres
    /// of the four cells around it: per cell, its log-odds over `l_max` clamped to [0, 1], so
    /// free and never-seen space both count 0 (with P(occupied) itself, unknown space at 0.5
    /// outbids free space at P ≈ 0.4 and pulls the scan points that see new space into it).
    #[inline]
    pub fn interpolated(&self, x: f64, y: f64, l_max: f32) -> f64 {
        let gx = x / self.resolution - 0.5;
        let gy = y / self.resolution - 0.5;
        let (fx, fy) = (gx.floor(), gy.floor());
        let (c, r) = (fx as i64, fy as i64);
        let (tx, ty) = (gx - fx, gy - fy);
        let inv = 1.0 / l_max;
        let p = |c: i64, r: i64| (self.get([c, r]).max(0.0) * inv).min(1.0) as f64;
        let bottom = p(c, r) * (1.0 - tx) + p(c + 1, r) * tx;
        let top = p(c, r + 1) * (1.0 - tx) + p(c + 1, r + 1) * tx;
        bottom * (1.0 - ty) + top * ty
    }

    /// Tiles written so far (shared ones counted once per holder).
    pub fn tiles(&self) -> usize {
        self.tiles.iter().flatten().count()
    }

    /// Whether this map holds the very same tile as `other` at every place (no copy yet).
    pub fn shares_all_tiles_with(&self, other: &TileMap) -> bool {
        self.t0 == other.t0
            && self.tw == other.tw
            && self.tiles.len() == other.tiles.len()
            && self
                .tiles
                .iter()
                .zip(&other.tiles)
                .all(|(a, b)| match (a, b) {
                    (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                    (None, None) => true,
                    _ => false,
                })
    }

    /// Inserts `scan` taken from `sensor` (the laser's pose in the map frame) with the inverse
    /// sensor model of `params` (see [`super::super::occupancy`]); `beams` is scratch space.
    pub(crate) fn insert(
        &mut self,
        sensor: &Pose2,
        scan: &LaserScan,
        params: &OccupancyParams,
        model: &LogOddsModel,
        beams: &mut Vec<super::super::insert::Beam>,
    ) -> InsertStats {
        let mut stats = InsertStats::default();
        if !(sensor.x.is_finite() && sensor.y.is_finite() && sensor.theta.is_finite()) {
            return stats;
        }
        prepare_beams(
            params,
            sensor,
            [scan.angle_min, scan.angle_increment],
            [scan.range_min, scan.range_max],
            &scan.ranges,
            beams,
            &mut stats,
        );
        let (lo, hi) = beam_box([sensor.x, sensor.y], beams);
        let (a, b) = (self.cell(lo[0], lo[1]), self.cell(hi[0], hi[1]));
        self.grow_to_hold([a[0] - 1, a[1] - 1], [b[0] + 1, b[1] + 1]);
        self.next_scan();
        let grid = GridFrame {
            width: self.tw * TILE,
            height: self.th * TILE,
            resolution: self.resolution,
            origin: [
                (self.t0[0] * TILE as i64) as f64 * self.resolution,
                (self.t0[1] * TILE as i64) as f64 * self.resolution,
            ],
        };
        let id = self.scan_id;
        stats.hits = apply_beams(self, &grid, sensor, beams, model, id);
        stats
    }

    fn next_scan(&mut self) {
        self.scan_id = self.scan_id.wrapping_add(1);
        if self.scan_id == 0 {
            for t in self.tiles.iter_mut().flatten() {
                Arc::make_mut(t).stamp.iter_mut().for_each(|s| *s = 0);
            }
            self.scan_id = 1;
        }
    }

    /// Grows the tile table to hold lattice cells lo..=hi.
    fn grow_to_hold(&mut self, lo: [i64; 2], hi: [i64; 2]) {
        let (tlo, thi) = (
            [lo[0] >> TILE_BITS, lo[1] >> TILE_BITS],
            [hi[0] >> TILE_BITS, hi[1] >> TILE_BITS],
        );
        let (n0, n1) = if self.tiles.is_empty() {
            (tlo, thi)
        } else {
            let cur_hi = [
                self.t0[0] + self.tw as i64 - 1,
                self.t0[1] + self.th as i64 - 1,
            ];
            (
                [tlo[0].min(self.t0[0]), tlo[1].min(self.t0[1])],
                [thi[0].max(cur_hi[0]), thi[1].max(cur_hi[1])],
            )
        };
        // as a growing map does: past MAX_CELLS (a pose kilometres off) the scan goes into the
        // table as it is, without the space in between
        let span = |i: usize| (n1[i] as f64 - n0[i] as f64 + 1.0) * TILE as f64;
        if span(0) * span(1) > MAX_CELLS as f64 {
            return;
        }
        let (nw, nh) = ((n1[0] - n0[0] + 1) as usize, (n1[1] - n0[1] + 1) as usize);
        if n0 == self.t0 && nw == self.tw && nh == self.th {
            return;
        }
        let mut tiles = vec![None; nw * nh];
        let (dx, dy) = ((self.t0[0] - n0[0]) as usize, (self.t0[1] - n0[1]) as usize);
        for r in 0..self.th {
            for c in 0..self.tw {
                tiles[(r + dy) * nw + c + dx] = self.tiles[r * self.tw + c].take();
            }
        }
        (self.t0, self.tw, self.th, self.tiles) = (n0, nw, nh, tiles);
    }

    /// P(occupied) per cell over the tile table (0.5 unknown).
    pub fn to_prob_grid(&self) -> ProbGrid {
        let (w, h) = (self.tw * TILE, self.th * TILE);
        let origin = [
            (self.t0[0] * TILE as i64) as f64 * self.resolution,
            (self.t0[1] * TILE as i64) as f64 * self.resolution,
        ];
        let mut g = ProbGrid::new(w, h, self.resolution, origin, 0.5);
        for (k, t) in self.tiles.iter().enumerate() {
            let Some(t) = t else { continue };
            let (tc, tr) = ((k % self.tw) * TILE, (k / self.tw) * TILE);
            for r in 0..TILE {
                let row = &t.l[r * TILE..(r + 1) * TILE];
                let out = (tr + r) * w + tc;
                for (dst, &l) in g.p[out..out + TILE].iter_mut().zip(row) {
                    *dst = probability(l);
                }
            }
        }
        g
    }
}

impl CellStore for TileMap {
    #[inline]
    fn update_once(&mut self, i: usize, id: u32, delta: f32, lo: f32, hi: f32) {
        let w = self.tw * TILE;
        let (c, r) = (i % w, i / w);
        let slot = &mut self.tiles[(r >> TILE_BITS) * self.tw + (c >> TILE_BITS)];
        let k = (r & (TILE - 1)) << TILE_BITS | (c & (TILE - 1));
        if slot.as_ref().is_some_and(|t| t.stamp[k] == id) {
            return;
        }
        let t = Arc::make_mut(slot.get_or_insert_with(|| Arc::new(Tile::empty())));
        t.stamp[k] = id;
        t.l[k] = (t.l[k] + delta).max(lo).min(hi);
    }
}
