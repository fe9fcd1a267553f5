//! The improved matcher's reference model: two square grids over the reference scan, built once
//! per match by letting every reference point stamp the cells within a radius
//! (O(points · (2·radius/cell)²), the construction of [`super::euclidean::EuclideanField`]).
//!
//! * [`ScoreGrid`] — for every cell centre within `radius` of a reference point, a score
//!   `255 · (1 − d²/radius²)` of the distance `d` to the nearest one. It is the smooth
//!   correlation surface of the coarse searches: a soft version of the binary correlation map of
//!   [Hospital thesis §5.2, eq. 29] (a point scores by how close it lands to the reference
//!   outline instead of whether it shares a 0.2 m cell with it), as in Olson's correlative scan
//!   matching ("Real-time correlative scan matching", ICRA 2009).
//! * [`NearestGrid`] — for every cell centre within `radius` of a reference point, the index of
//!   the nearest one among every `stride`-th point: O(1) correspondence candidates for the
//!   refinement ([`super::refine`]), whose lookup then checks the scan neighbours of the
//!   candidate (so with a stride of 3 the exact nearest point along a surface is still found).
//!   Two bytes a cell, and no distance array (a stamp recomputes the distance to the stored
//!   point), so a 40 m × 40 m scan at 0.1 m costs 320 KB.

use super::error::MatchError;

/// Marks a cell of [`NearestGrid`] with no reference point within the radius.
pub(crate) const NONE: u16 = u16::MAX;

/// Most points a [`NearestGrid`] can index.
pub(crate) const MAX_INDEXED: usize = NONE as usize;

/// Placement of a square grid over a point set.
/// The most cells a matcher's grid over one reference scan may have (64 Mi).
pub(crate) const MAX_GRID_CELLS: usize = 64 << 20;

#[derive(Clone, Copy, Debug)]
pub(crate) struct GridGeom {
    /// World position of the corner of cell (0, 0).
    pub origin: [f32; 2],
    pub inv_cell: f32,
    pub cell: f32,
    pub w: usize,
    pub h: usize,
}

impl GridGeom {
    /// Refuses a grid of `cell` over `points` (plus `margin`) with more than
    /// [`MAX_GRID_CELLS`] cells, before [`ScoreGrid::build`] or [`NearestGrid::build`]
    /// allocates it.
    pub(crate) fn check_size(
        points: &[[f32; 2]],
        cell: f32,
        margin: f32,
    ) -> Result<(), MatchError> {
        let g = GridGeom::covering(points, cell, margin);
        match g.w.checked_mul(g.h) {
            Some(n) if n <= MAX_GRID_CELLS => Ok(()),
            _ => Err(MatchError::ReferenceTooWide {
                width_m: g.w as f32 * cell,
                height_m: g.h as f32 * cell,
                cell_m: cell,
            }),
        }
    }

    /// Covers the bounding box of `points` (finite, non-empty) plus `margin` and a cell.
    fn covering(points: &[[f32; 2]], cell: f32, margin: f32) -> GridGeom {
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for p in points {
            for j in 0..2 {
                lo[j] = lo[j].min(p[j]);
                hi[j] = hi[j].max(p[j]);
            }
        }
        if points.is_empty() {
            (lo, hi) = ([0.0; 2], [0.0; 2]);
        }
        let margin = margin + cell;
        let origin = [lo[0] - margin, lo[1] - margin];
        GridGeom {
            origin,
            inv_cell: 1.0 / cell,
            cell,
            w: ((hi[0] + margin - origin[0]) / cell).ceil() as usize + 1,
            h: ((hi[1] + margin - origin[1]) / cell).ceil() as usize + 1,
        }
    }

    /// Integer cell coordinates of a point (may be outside the grid).
    #[inline(always)]
    pub fn cell_coords(&self, q: [f32; 2]) -> (i32, i32) {
        (
            ((q[0] - self.origin[0]) * self.inv_cell).floor() as i32,
            ((q[1] - self.origin[1]) * self.inv_cell).floor() as i32,
        )
    }

    /// Row-major index of the cell containing `q`, if inside.
    #[inline(always)]
    pub fn index(&self, q: [f32; 2]) -> Option<usize> {
        let u = (q[0] - self.origin[0]) * self.inv_cell;
        let v = (q[1] - self.origin[1]) * self.inv_cell;
        if u >= 0.0 && v >= 0.0 && u < self.w as f32 && v < self.h as f32 {
            Some((v as usize).min(self.h - 1) * self.w + (u as usize).min(self.w - 1))
        } else {
            None
        }
    }

    /// Calls `f(cell index, squared distance from the cell centre to p, cell centre)` for every
    /// cell whose centre is within `radius` of `p`.
    #[inline(always)]
    fn stamp(&self, p: [f32; 2], radius: f32, mut f: impl FnMut(usize, f32, [f32; 2])) {
        let reach = (radius * self.inv_cell).ceil() as i64;
        let r2 = radius * radius;
        let pc = ((p[0] - self.origin[0]) * self.inv_cell).floor() as i64;
        let pr = ((p[1] - self.origin[1]) * self.inv_cell).floor() as i64;
        let (c0, c1) = ((pc - reach).max(0), (pc + reach).min(self.w as i64 - 1));
        let (r0, r1) = ((pr - reach).max(0), (pr + reach).min(self.h as i64 - 1));
        for r in r0..=r1 {
            let cy = self.origin[1] + (r as f32 + 0.5) * self.cell;
            let dy = cy - p[1];
            let base = r as usize * self.w;
            for c in c0..=c1 {
                let cx = self.origin[0] + (c as f32 + 0.5) * self.cell;
                let dx = cx - p[0];
                let d2 = dx * dx + dy * dy;
                if d2 < r2 {
                    f(base + c as usize, d2, [cx, cy]);
                }
            }
        }
    }
}

/// Scores `255 · (1 − d²/radius²)` of the distance to the nearest reference point.
#[derive(Clone, Debug)]
pub(crate) struct ScoreGrid {
    pub geom: GridGeom,
    /// Row-major, 0 = no reference point within the radius.
    pub score: Vec<u8>,
}

impl ScoreGrid {
    /// `points` finite and non-empty, `cell`, `radius` > 0; only every `stride`-th point
    /// stamps (points much denser than the cells add nothing).
    pub fn build(points: &[[f32; 2]], cell: f32, radius: f32, stride: usize) -> ScoreGrid {
        let geom = GridGeom::covering(points, cell, radius);
        let r2 = radius * radius;
        let mut best = vec![r2; geom.w * geom.h];
        for p in points.iter().step_by(stride.max(1)) {
            geom.stamp(*p, radius, |i, d2, _| {
                if d2 < best[i] {
                    best[i] = d2;
                }
            });
        }
        let score = best
            .iter()
            .map(|&d2| {
                if d2 >= r2 {
                    0
                } else {
                    (255.0 * (1.0 - d2 / r2)).round().clamp(1.0, 255.0) as u8
                }
            })
            .collect();
        ScoreGrid { geom, score }
    }

    /// Score of the cell containing `q` (0 outside).
    #[inline(always)]
    pub fn score_at(&self, q: [f32; 2]) -> u8 {
        self.geom.index(q).map_or(0, |i| self.score[i])
    }

    /// Sum of the scores of `points` moved by `(t_x, t_y, θ)`: the coarse correlation.
    pub fn correlate(&self, points: &[[f32; 2]], p: &[f64; 3]) -> u32 {
        let (s, c) = p[2].sin_cos();
        let (s, c, tx, ty) = (s as f32, c as f32, p[0] as f32, p[1] as f32);
        points
            .iter()
            .map(|b| self.score_at([c * b[0] - s * b[1] + tx, s * b[0] + c * b[1] + ty]) as u32)
            .sum()
    }
}

/// Index of the nearest reference point per cell.
#[derive(Clone, Debug)]
pub(crate) struct NearestGrid {
    pub geom: GridGeom,
    /// Row-major, [`NONE`] = no reference point within the radius.
    pub nearest: Vec<u16>,
}

impl NearestGrid {
    /// `points` finite, non-empty and at most [`MAX_INDEXED`]; `cell`, `radius` > 0; only
    /// every `stride`-th point (and the last) stamps.
    pub fn build(points: &[[f32; 2]], cell: f32, radius: f32, stride: usize) -> NearestGrid {
        debug_assert!(points.len() <= MAX_INDEXED);
        let geom = GridGeom::covering(points, cell, radius);
        let mut nearest = vec![NONE; geom.w * geom.h];
        let n = points.len().min(MAX_INDEXED);
        if n == 0 {
            return NearestGrid { geom, nearest };
        }
        let stride = stride.max(1);
        let stamped = (0..n)
            .step_by(stride)
            .chain((!(n - 1).is_multiple_of(stride)).then_some(n - 1));
        for idx in stamped {
            let p = &points[idx];
            geom.stamp(*p, radius, |i, d2, c| {
                let old = nearest[i];
                let replace = old == NONE || {
                    // distance from the same cell centre to the stored point
                    let o = points[old as usize];
                    (c[0] - o[0]).powi(2) + (c[1] - o[1]).powi(2) > d2
                };
                if replace {
                    nearest[i] = idx as u16;
                }
            });
        }
        NearestGrid { geom, nearest }
    }

    /// The stored nearest reference index of the cell containing `q`.
    #[inline(always)]
    pub fn lookup(&self, q: [f32; 2]) -> Option<usize> {
        let i = self.geom.index(q)?;
        let n = self.nearest[i];
        (n != NONE).then_some(n as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell_centre(g: &GridGeom, i: usize) -> (f32, f32) {
        let (r, c) = (i / g.w, i % g.w);
        (
            g.origin[0] + (c as f32 + 0.5) * g.cell,
            g.origin[1] + (r as f32 + 0.5) * g.cell,
        )
    }

    #[test]
    fn nearest_and_score_follow_the_distance() {
        let pts = [[0.0, 0.0], [1.0, 0.0]];
        let n = NearestGrid::build(&pts, 0.1, 0.3, 1);
        assert_eq!(n.lookup([0.04, 0.02]), Some(0));
        assert_eq!(n.lookup([0.93, -0.05]), Some(1));
        assert_eq!(n.lookup([0.5, 0.0]), None);
        assert_eq!(n.lookup([50.0, 0.0]), None);
        let g = ScoreGrid::build(&pts, 0.1, 0.3, 1);
        assert!(g.score_at([0.04, 0.02]) > 200);
        assert_eq!(g.score_at([0.5, 0.0]), 0);
        assert_eq!(g.score_at([50.0, 0.0]), 0);
        // farther from the point, lower score
        assert!(g.score_at([0.25, 0.0]) < g.score_at([0.12, 0.0]));
        assert!(g.correlate(&pts, &[0.0; 3]) > g.correlate(&pts, &[0.2, 0.0, 0.0]));
    }

    #[test]
    fn nearest_is_the_closest_to_the_cell_centre() {
        // points close together: every cell must hold the one nearest its centre
        let pts: Vec<[f32; 2]> = (0..50)
            .map(|k| [0.037 * k as f32, 0.02 * (k % 3) as f32])
            .collect();
        let n = NearestGrid::build(&pts, 0.1, 0.3, 1);
        for i in 0..n.nearest.len() {
            let (cx, cy) = cell_centre(&n.geom, i);
            let best = pts
                .iter()
                .map(|p| (cx - p[0]).powi(2) + (cy - p[1]).powi(2))
                .fold(f32::INFINITY, f32::min);
            if best < 0.3 * 0.3 - 1e-4 {
                let o = pts[n.nearest[i] as usize];
                let d = (cx - o[0]).powi(2) + (cy - o[1]).powi(2);
                assert!((d - best).abs() < 1e-5, "cell {i}");
            }
        }
    }
}
