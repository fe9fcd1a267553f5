//! The multi-resolution map of the Hector scan matcher (Kohlbrecher et al., SSRR 2011, §IV.A and
//! §IV.C): level 0 is built from the probability grid, each next level has half the resolution,
//! and the matcher reads every level through bilinear interpolation between the four cell CENTRES
//! around a point (eq. 1) with its analytic gradient (eqs. 2–3), [`PyramidLevel::sample`].
//!
//! Choices, each measured on the hospital map (5 cm cells, SICK LMS100 scans):
//!
//! * Level 0 ([`Surfaces`]). In Hector's own maps an end point marks the cell it falls in, so
//!   surfaces lie inside occupied cells and M = occupancy peaks on them ([`Surfaces::InCells`]).
//!   A map_server map's obstacles fill whole cells and the beams stop on their FACES, where that
//!   M is only 0.5 and rises into the wall: a match started at the true pose drifted by up to
//!   3.5 cm, the end points pulled into the walls of the side the scan sees most of. For such
//!   maps level 0 samples the cell corners instead ([`Surfaces::OnFaces`]), M = max P·(1 − min P)
//!   over the cells sharing a corner, which is 1 where occupied meets free and 0 inside walls and
//!   free space; the drift from the truth is then below 0.1 mm.
//! * Coarse cells. Hector builds each level from the scans; we are handed a finished grid, so a
//!   coarse cell combines its 2 × 2 children, by default with their MAXIMUM ([`Combine::Max`]),
//!   which keeps a one-cell wall at full strength on every level (the mean would halve it per
//!   level, a 5 cm wall would be a faint 0.125 at 20 cm cells, where the matcher needs it most).
//! * Smoothing. M of a binary map is flat inside walls and free space, so its gradient vanishes
//!   beyond one cell from a surface and a level's basin is about one of its cells. Each coarse
//!   level therefore gets `smoothing` passes of m ← max(m, [1 2 1]/4 ⊗ [1 2 1]/4 ∗ m): the max
//!   keeps the ridges at 1 (a plain blur lowered them to ≈ 0.5, and with residuals that never
//!   vanish Gauss-Newton overshot and needed 3× the evaluations), each pass adds a cell of slope.
//!   Three levels with three passes brought back 112 of 112 starts 0.5 m and 0.1 rad off (16
//!   directions, 7 poses), 109 of 112 from 0.7 m, in 14–15 evaluations; unsmoothed 89 and 58 of
//!   112, in 16–22. Level 0 is never smoothed: it sets the final precision.
//!
//! Edits: [`MapPyramid::update_region`] recomputes only what depends on a changed window (its
//! corners, the coarse cells above it and the band a smoothing pass spreads them over), and
//! [`MapPyramid::update_cells`] does so for scattered cells tile by tile; both are bit-identical
//! to a full [`MapPyramid::rebuild`]. Memory: about 4/3 of the grid in f32 (plus the unsmoothed
//! coarse levels, 1/3 more, when smoothing).

pub use level::{Combine, MapSample, PyramidLevel, PyramidOptions, Surfaces};

use super::ProbGrid;
use crate::world::grid::place_rows;
use build::{combine_level, corner_values};
use level::Window;

/// Level 0 from the grid (its cells, or its corners for [`Surfaces::OnFaces`]), level k with
/// 2^k times its cell size.
#[derive(Clone, Debug, PartialEq)]
pub struct MapPyramid {
    levels: Vec<PyramidLevel>,
    options: PyramidOptions,
    /// Size of the grid the pyramid was built from.
    grid_size: [usize; 2],
}

/// Tile edge (cells) [`MapPyramid::update_cells`] bins changed cells into.
pub const UPDATE_TILE: usize = 32;

impl MapPyramid {
    /// `levels` (at least 1) levels with the default options ([`PyramidOptions::slam_map`]).
    pub fn new(grid: &ProbGrid, levels: usize) -> Self {
        Self::with_options(grid, levels, PyramidOptions::default())
    }

    /// `levels` (at least 1) levels built as `options` say.
    pub fn with_options(grid: &ProbGrid, levels: usize, options: PyramidOptions) -> Self {
        let mut p = Self::empty(grid, levels, options);
        p.rebuild(grid);
        p
    }

    /// The levels for `grid`, every value 0.
    fn empty(grid: &ProbGrid, levels: usize, options: PyramidOptions) -> Self {
        let mut out = Vec::with_capacity(levels.max(1));
        let (mut w, mut h, mut res, mut origin) =
            (grid.width, grid.height, grid.resolution, grid.origin);
        if options.surfaces == Surfaces::OnFaces {
            // one sample per cell corner: corner (i, j) is the centre of this level's cell (i, j)
            (w, h) = (w + 1, h + 1);
            origin = [origin[0] - 0.5 * res, origin[1] - 0.5 * res];
        }
        for k in 0..levels.max(1) {
            if k > 0 {
                (w, h, res) = (w.div_ceil(2), h.div_ceil(2), res * 2.0);
            }
            let keep_raw = k > 0 && options.smoothing > 0;
            out.push(PyramidLevel {
                width: w,
                height: h,
                resolution: res,
                origin,
                m: vec![0.0; w * h],
                raw: if keep_raw { vec![0.0; w * h] } else { vec![] },
            });
        }
        MapPyramid {
            levels: out,
            options,
            grid_size: [grid.width, grid.height],
        }
    }

    /// This pyramid carried over to `grid`, the grid it was built from grown by whole cells
    /// with the old cell (0, 0) now at `at`: every level is copied into place and what depends
    /// on the new cells is recomputed, so the result equals [`MapPyramid::with_options`] on
    /// `grid` wherever the old part of `grid` holds what it held (the caller then updates the
    /// window of its own changes, as after any change). None, for a full build, where the
    /// copy would not land on whole cells of every level (`at` not a multiple of 2^(levels−1))
    /// or with surfaces on faces (level 0 on cell corners).
    pub fn grown(&self, grid: &ProbGrid, at: [usize; 2]) -> Option<MapPyramid> {
        let [ow, oh] = self.grid_size;
        let top = 1usize << (self.levels.len() - 1);
        let fits = at[0] + ow <= grid.width && at[1] + oh <= grid.height;
        if self.options.surfaces != Surfaces::InCells || !fits || at[0] % top + at[1] % top != 0 {
            return None;
        }
        let mut p = Self::empty(grid, self.levels.len(), self.options);
        for (k, (old, new)) in self.levels.iter().zip(&mut p.levels).enumerate() {
            let (x, y) = (at[0] >> k, at[1] >> k);
            if x + old.width > new.width || y + old.height > new.height {
                return None;
            }
            for (from, to) in [(&old.m, &mut new.m), (&old.raw, &mut new.raw)] {
                if from.is_empty() {
                    continue;
                }
                place_rows(from, old.width, to, new.width, [x, y]);
            }
        }
        // the new cells: the strips left and right of the old part, then below and above it
        let (x0, y0, x1, y1) = (at[0], at[1], at[0] + ow, at[1] + oh);
        let strips = [
            [0, 0, x0, grid.height],
            [x1, 0, grid.width, grid.height],
            [x0, 0, x1, y0],
            [x0, y1, x1, grid.height],
        ];
        for [c0, r0, c1, r1] in strips {
            p.update_region(grid, c0, r0, c1, r1);
        }
        Some(p)
    }

    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Level `k` (0 = finest).
    pub fn level(&self, k: usize) -> &PyramidLevel {
        &self.levels[k]
    }

    pub fn options(&self) -> PyramidOptions {
        self.options
    }

    /// Recomputes every level from `grid` (same size, resolution and origin as at construction;
    /// a different grid needs a new pyramid).
    pub fn rebuild(&mut self, grid: &ProbGrid) {
        self.update_region(grid, 0, 0, grid.width, grid.height);
    }

    /// Recomputes what depends on the listed (col, row) cells of `grid` (out-of-grid ones are
    /// ignored): the cells are binned into [`UPDATE_TILE`]² tiles and each run of adjacent
    /// dirty tiles in a tile row is one [`MapPyramid::update_region`]. For a SLAM front end
    /// whose changes are scattered along a scan (a bounding box would be most of the map).
    pub fn update_cells(&mut self, grid: &ProbGrid, cells: &[(usize, usize)]) {
        let (tw, th) = (
            grid.width.div_ceil(UPDATE_TILE),
            grid.height.div_ceil(UPDATE_TILE),
        );
        let mut dirty = vec![false; tw * th];
        for &(c, r) in cells {
            if c < grid.width && r < grid.height {
                dirty[(r / UPDATE_TILE) * tw + c / UPDATE_TILE] = true;
            }
        }
        for ty in 0..th {
            let row = &dirty[ty * tw..(ty + 1) * tw];
            let mut tx = 0;
            while tx < tw {
                if !row[tx] {
                    tx += 1;
                    continue;
                }
                let start = tx;
                while tx < tw && row[tx] {
                    tx += 1;
                }
                self.update_region(
                    grid,
                    start * UPDATE_TILE,
                    ty * UPDATE_TILE,
                    tx * UPDATE_TILE,
                    (ty + 1) * UPDATE_TILE,
                );
            }
        }
    }

    /// Recomputes what depends on the cells [c0, c1) × [r0, r1) of `grid` (clipped to the grid):
    /// a SLAM front end that changed a few cells calls this with their bounding box.
    pub fn update_region(&mut self, grid: &ProbGrid, c0: usize, r0: usize, c1: usize, r1: usize) {
        assert!(
            [grid.width, grid.height] == self.grid_size,
            "pyramid built for a {:?} grid, got {}×{}",
            self.grid_size,
            grid.width,
            grid.height
        );
        let (c1, r1) = (c1.min(grid.width), r1.min(grid.height));
        if c0 >= c1 || r0 >= r1 {
            return;
        }
        let base = &mut self.levels[0];
        let mut win: Window = match self.options.surfaces {
            Surfaces::InCells => {
                for r in r0..r1 {
                    let row = r * grid.width;
                    base.m[row + c0..row + c1].copy_from_slice(&grid.p[row + c0..row + c1]);
                }
                [c0, r0, c1, r1]
            }
            Surfaces::OnFaces => {
                // cell (c, r) has the corners (c..=c+1, r..=r+1)
                let win = [c0, r0, c1 + 1, r1 + 1];
                corner_values(grid, base, win);
                win
            }
        };
        for k in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(k);
            win = combine_level(&fine[k - 1], &mut coarse[0], win, self.options);
        }
    }
}

mod build;
mod level;
#[cfg(test)]
mod tests;
