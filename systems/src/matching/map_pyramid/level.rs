//! The pyramid's vocabulary: how its levels are derived ([`PyramidOptions`]) and one level with
//! its bilinear sample. A leaf of its own so that the level builders (`build`) and the pyramid
//! that drives them share these types without importing each other.

/// How a coarse cell combines its 2 × 2 children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// The largest child: thin walls survive at every level.
    Max,
    /// The mean of the children (the children that exist, at an odd edge).
    Mean,
}

/// Where the map's surfaces lie, which decides what level 0 holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surfaces {
    /// Inside the occupied cells, as in a map built from scans by marking the cell that holds
    /// each end point (Hector's own maps): level 0 is the grid, M the occupancy (Hector).
    InCells,
    /// On the faces between occupied and free cells, as in a map_server map whose obstacles fill
    /// whole cells and stop beams at their faces: level 0 samples the cell CORNERS with
    /// M = max P · (1 − min P) over the (up to four) cells sharing the corner.
    OnFaces,
}

/// How the levels are derived.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PyramidOptions {
    pub surfaces: Surfaces,
    pub combine: Combine,
    /// Max-preserving [1 2 1]/4 smoothing passes applied to every level above 0.
    pub smoothing: usize,
}

impl PyramidOptions {
    /// Hector's convention for maps built from scans: M = occupancy, max-combined, three
    /// smoothing passes on the coarse levels.
    pub fn slam_map() -> Self {
        PyramidOptions {
            surfaces: Surfaces::InCells,
            combine: Combine::Max,
            smoothing: 3,
        }
    }

    /// For a map_server map (whole-cell obstacles): surfaces on faces, otherwise as
    /// [`PyramidOptions::slam_map`].
    pub fn static_map() -> Self {
        PyramidOptions {
            surfaces: Surfaces::OnFaces,
            ..Self::slam_map()
        }
    }
}

impl Default for PyramidOptions {
    /// [`PyramidOptions::slam_map`].
    fn default() -> Self {
        Self::slam_map()
    }
}

/// One level: values at cell centres, cell (c, r) covering
/// [ox + c·res, ox + (c+1)·res) × [oy + r·res, oy + (r+1)·res), row-major, row 0 at the bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct PyramidLevel {
    pub width: usize,
    pub height: usize,
    pub resolution: f64,
    pub origin: [f64; 2],
    /// The (possibly smoothed) occupancy value M per cell, what the matcher reads.
    pub m: Vec<f32>,
    /// The unsmoothed combined values the next level is built from (empty when `m` is them).
    pub(super) raw: Vec<f32>,
}

/// M at a point and its gradient (per metre), eqs. 1–3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSample {
    pub value: f64,
    pub gradient: [f64; 2],
}

impl PyramidLevel {
    /// Bilinear interpolation between the four cell centres around (x, y) (eq. 1) and its
    /// gradient (eqs. 2–3). `None` when any of the four centres lies outside the level: such a
    /// point contributes nothing to a match.
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> Option<MapSample> {
        let inv = 1.0 / self.resolution;
        // centre of cell (c, r) is at grid coordinate (c, r) after the half-cell shift
        let gx = (x - self.origin[0]) * inv - 0.5;
        let gy = (y - self.origin[1]) * inv - 0.5;
        // NaN fails these comparisons too; on non-negative values truncation is floor (and
        // needs no libm call without SSE4.1)
        if !(gx >= 0.0 && gy >= 0.0) {
            return None;
        }
        let (ix, iy) = (gx as usize, gy as usize);
        if ix >= self.width.saturating_sub(1) || iy >= self.height.saturating_sub(1) {
            return None;
        }
        let (u, v) = (gx - ix as f64, gy - iy as f64);
        let i = iy * self.width + ix;
        let m00 = self.m[i] as f64;
        let m10 = self.m[i + 1] as f64;
        let m01 = self.m[i + self.width] as f64;
        let m11 = self.m[i + self.width + 1] as f64;
        let bottom = m00 + u * (m10 - m00);
        let top = m01 + u * (m11 - m01);
        Some(MapSample {
            value: bottom + v * (top - bottom),
            gradient: [
                ((1.0 - v) * (m10 - m00) + v * (m11 - m01)) * inv,
                (top - bottom) * inv,
            ],
        })
    }

    /// The unsmoothed values (the combine input of the next level).
    pub(super) fn raw(&self) -> &[f32] {
        if self.raw.is_empty() {
            &self.m
        } else {
            &self.raw
        }
    }
}

/// A window of cells [c0, c1) × [r0, r1).
pub(super) type Window = [usize; 4];
