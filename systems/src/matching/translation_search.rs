//! Exhaustive translation search for a fixed rotation on the reference score grid
//! ([`super::ref_grid::ScoreGrid`]): the brute-force correlation over shifts of Olson's
//! correlative scan matcher (ICRA 2009), i.e. the thesis's raster cross-correlation
//! ([Hospital thesis §5.2, eq. 29]) evaluated over a whole lattice of shifts instead of
//! sampled by DE.
//!
//! The rotated current points are quantised to grid cells once; a shift by whole cells `(i, k)`
//! then moves every point by exactly `(i, k)` cells, so the scores of all shifts are an
//! accumulation of grid rows: for each point and each row shift `k`, the slice of grid row
//! `y + k` around `x` is added into row `k` of the accumulator. The inner loop is a contiguous
//! `u16 += u8` that the compiler vectorises; the cost is points × (2r+1)² byte additions, with
//! no per-shift rounding or bounds checks.
//!
//! Several well-separated maxima are returned (greedy non-maximum suppression), because in
//! corridors with regularly spaced doors the right shift is not always the highest.

use super::ref_grid::ScoreGrid;

/// Most points one search can use (the accumulator is u16 and a cell scores at most 255).
pub(crate) const MAX_POINTS: usize = 257;

/// A shift by `(i, k)` cells and its score.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Shift {
    pub i: i32,
    pub k: i32,
    pub score: u32,
}

/// Largest shift radius (cells) one search scores: the accumulator then holds at most
/// 4095² counters (32 MB), whatever window the caller asks for.
pub(crate) const MAX_RADIUS: i32 = 2047;

/// The part of the radius worth scoring: shifts beyond it move every used point of `cells` off
/// the grid, so they all score 0. At most `radius` (negative counts as 0) and [`MAX_RADIUS`].
fn useful_radius(grid: &ScoreGrid, cells: &[(i32, i32)], radius: i32) -> i32 {
    let (w, h) = (grid.geom.w as i64, grid.geom.h as i64);
    let r = radius.clamp(0, MAX_RADIUS) as i64;
    let mut need = 0i64;
    for &(x, y) in cells.iter().take(MAX_POINTS) {
        let (x, y) = (x as i64, y as i64);
        // shifts in the window keeping the point inside the grid
        let (i0, i1) = ((-x).max(-r), (w - 1 - x).min(r));
        let (k0, k1) = ((-y).max(-r), (h - 1 - y).min(r));
        if i0 <= i1 && k0 <= k1 {
            need = need.max(i0.abs().max(i1.abs()).max(k0.abs()).max(k1.abs()));
        }
    }
    need as i32
}

/// Scores every shift `(i, k) ∈ [−radius, radius]²` (in cells) of `cells` (the grid cells of
/// the rotated points, possibly outside the grid; at most [`MAX_POINTS`] are used) and appends
/// to `out` up to `maxima` shifts: the best, then repeatedly the best more than `separation`
/// cells (Chebyshev) from all chosen ones. Ties go to the first in row-major order. Only the
/// shifts that can score are scored (the radius shrinks to [`useful_radius`], so a huge
/// `radius` costs no more than the grid's size); returns how many were scored.
pub(crate) fn best_shifts(
    grid: &ScoreGrid,
    cells: &[(i32, i32)],
    radius: i32,
    maxima: usize,
    separation: i32,
    acc: &mut Vec<u16>,
    out: &mut Vec<Shift>,
) -> u64 {
    let radius = useful_radius(grid, cells, radius);
    let side = (2 * radius + 1) as usize;
    acc.clear();
    acc.resize(side * side, 0);
    let (w, h) = (grid.geom.w as i64, grid.geom.h as i64);
    let r = radius as i64;
    for &(x, y) in cells.iter().take(MAX_POINTS) {
        let (x, y) = (x as i64, y as i64);
        // shifts keeping the point inside the grid
        let i0 = (-r).max(-x);
        let i1 = r.min(w - 1 - x);
        let k0 = (-r).max(-y);
        let k1 = r.min(h - 1 - y);
        if i0 > i1 || k0 > k1 {
            continue;
        }
        let len = (i1 - i0 + 1) as usize;
        for k in k0..=k1 {
            let src = ((y + k) * w + x + i0) as usize;
            let dst = (k + r) as usize * side + (i0 + r) as usize;
            let row = &grid.score[src..src + len];
            for (a, &s) in acc[dst..dst + len].iter_mut().zip(row) {
                *a += s as u16;
            }
        }
    }
    let first = out.len();
    for _ in 0..maxima {
        let mut best: Option<(usize, u16)> = None;
        for (n, &v) in acc.iter().enumerate() {
            if best.is_none_or(|b| v > b.1) {
                best = Some((n, v));
            }
        }
        let Some((n, v)) = best else { break };
        if v == 0 && out.len() > first {
            break;
        }
        let (i, k) = ((n % side) as i32 - radius, (n / side) as i32 - radius);
        out.push(Shift {
            i,
            k,
            score: v as u32,
        });
        // suppress the neighbourhood of the chosen maximum
        let (ci, ck) = (i + radius, k + radius);
        let s = side as i32;
        for kk in (ck - separation).max(0)..=(ck + separation).min(s - 1) {
            let row = kk as usize * side;
            for ii in (ci - separation).max(0)..=(ci + separation).min(s - 1) {
                acc[row + ii as usize] = 0;
            }
        }
    }
    (side * side) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_shift_that_puts_points_on_the_outline() {
        // an L outline; the current points are the same outline displaced by (−0.7, 0.4) m
        let mut outline = Vec::new();
        for k in 0..40 {
            outline.push([2.03, -1.01 + 0.05 * k as f32]);
            outline.push([2.03 - 0.05 * k as f32, 0.99]);
        }
        let grid = ScoreGrid::build(&outline, 0.1, 0.3, 1);
        let current: Vec<(i32, i32)> = outline
            .iter()
            .step_by(3)
            .map(|p| grid.geom.cell_coords([p[0] - 0.7, p[1] + 0.4]))
            .collect();
        let (mut acc, mut out) = (Vec::new(), Vec::new());
        best_shifts(&grid, &current, 15, 3, 3, &mut acc, &mut out);
        assert_eq!(out.len(), 3);
        assert_eq!((out[0].i, out[0].k), (7, -4));
        assert!(out[1].score <= out[0].score && out[2].score <= out[1].score);
        for s in &out[1..] {
            assert!((s.i - 7).abs() > 3 || (s.k + 4).abs() > 3);
        }
        // brute-force check of the winning score
        let w = grid.geom.w;
        let direct: u32 = current
            .iter()
            .map(|&(x, y)| {
                grid.score[((y + out[0].k) as usize) * w + (x + out[0].i) as usize] as u32
            })
            .sum();
        assert_eq!(direct, out[0].score);
    }

    #[test]
    fn points_off_the_grid_score_nothing() {
        let grid = ScoreGrid::build(&[[0.0, 0.0]], 0.1, 0.3, 1);
        let (mut acc, mut out) = (Vec::new(), Vec::new());
        best_shifts(
            &grid,
            &[(1000, 1000), (-500, 3)],
            5,
            2,
            1,
            &mut acc,
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].score, 0);
    }

    #[test]
    fn a_huge_radius_scores_only_the_shifts_that_can_score() {
        // the outline test again with the largest radius there is, and points far off the grid
        // on both sides (i32 extremes): same answer, a small accumulator, no overflow
        let mut outline = Vec::new();
        for k in 0..40 {
            outline.push([2.03, -1.01 + 0.05 * k as f32]);
            outline.push([2.03 - 0.05 * k as f32, 0.99]);
        }
        let grid = ScoreGrid::build(&outline, 0.1, 0.3, 1);
        let mut current: Vec<(i32, i32)> = outline
            .iter()
            .step_by(3)
            .map(|p| grid.geom.cell_coords([p[0] - 0.7, p[1] + 0.4]))
            .collect();
        let (mut acc, mut out) = (Vec::new(), Vec::new());
        let scored = best_shifts(&grid, &current, 15, 3, 3, &mut acc, &mut out);
        assert_eq!(scored, 31 * 31);
        current.extend([(i32::MIN, i32::MAX), (i32::MAX, i32::MIN)]);
        for radius in [i32::MAX, 1_000_000_000, 100_000] {
            let (mut acc, mut huge) = (Vec::new(), Vec::new());
            let scored = best_shifts(&grid, &current, radius, 3, 3, &mut acc, &mut huge);
            // the points lie within a grid size of the grid
            let side = (4 * grid.geom.w.max(grid.geom.h) + 1) as u64;
            assert!(scored <= side * side, "{scored} shifts scored");
            assert_eq!(acc.len() as u64, scored);
            assert_eq!(huge[0], out[0], "radius {radius}");
        }
    }
}
