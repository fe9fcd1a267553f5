//! The precomputed grids of W. Hess, D. Kohler, H. Rapp, D. Andor, "Real-Time Loop Closure in 2D
//! LIDAR SLAM", ICRA 2016, §V-C, eq. 15: grid `h` holds, at cell (c, r), the maximum of the map
//! over the 2^h × 2^h cells [c, c + 2^h − 1] × [r, r + 2^h − 1]. Summing grid `h` at a scan's
//! cells then bounds from above the score of every one of the 2^h × 2^h translations a search
//! node of height h stands for (eq. 14), and the bound is reached: it is exact on a single cell.
//!
//! Values are P(occupied) quantized to u8 (p · 255, rounded), as Cartographer stores its
//! probability grids: scores become integer sums, so the branch-and-bound and the exhaustive
//! search compare exactly the same numbers, and the grids take a quarter of the memory.
//!
//! Each level is built in O(n) from the one below it: a window of 2^h is two windows of 2^(h−1)
//! side by side, so level h is the maximum of level h − 1 and level h − 1 shifted by 2^(h−1),
//! first along the rows, then along the columns (the doubling of van Herk / Gil–Werman's
//! separable max filter). The plain version, kept for the tests and the benchmark, slides a 1-D
//! window maximum (monotone deque) along the rows and columns of the map for every level.

use crate::matching::ProbGrid;

/// One level: `pad` = 2^h − 1 extra cells before column 0 and row 0, so that windows which
/// start left of or below the map (and still overlap it) have a value.
#[derive(Clone, Debug)]
pub(super) struct Level {
    pub(super) pad: i32,
    pub(super) stride: usize,
    pub(super) rows: usize,
    pub(super) data: Vec<u8>,
}

impl Level {
    /// The bound at map cell (c, r) (the window's lower-left cell); 0 off the stored area, where
    /// the whole window lies outside the map (no evidence).
    #[inline(always)]
    pub(super) fn get(&self, c: i32, r: i32) -> u8 {
        let (x, y) = ((c + self.pad) as u32, (r + self.pad) as u32);
        // negative coordinates wrap to huge u32 values and fail the test
        if (x as usize) < self.stride && (y as usize) < self.rows {
            self.data[y as usize * self.stride + x as usize]
        } else {
            0
        }
    }
}

/// The map at every height 0..depth (level 0 is the quantized map itself). Build it once per
/// submap or map and reuse it for every query.
#[derive(Clone, Debug)]
pub struct PrecomputedGrids {
    pub(super) levels: Vec<Level>,
    pub(super) resolution: f64,
    pub(super) origin: [f64; 2],
}

/// P(occupied) → u8; NaN counts as 0 (no evidence).
fn quantize(p: f32) -> u8 {
    if p.is_nan() {
        0
    } else {
        (p.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// `out[i] = max(input[i + 1 − win ..= i])` over the cells that exist, for i in
/// 0..input.len() + win − 1 (the window slides on and off both ends). Monotone deque: every index
/// enters and leaves it once, O(n) whatever `win`.
fn sliding_max(input: &[u8], win: usize, out: &mut [u8], deque: &mut Vec<usize>) {
    debug_assert_eq!(out.len(), input.len() + win - 1);
    deque.clear();
    let mut head = 0;
    for (i, o) in out.iter_mut().enumerate() {
        if i < input.len() {
            // drop the smaller-or-equal values behind: they can never be a maximum again
            while deque.len() > head && input[deque[deque.len() - 1]] <= input[i] {
                deque.pop();
            }
            deque.push(i);
        }
        // drop the front once it slid out of the window
        while head < deque.len() && deque[head] + win <= i {
            head += 1;
        }
        *o = if head < deque.len() {
            input[deque[head]]
        } else {
            0
        };
    }
}

/// Level `h` from level `below` (h − 1) of a `w` × `h` map: shift s = 2^(h−1). A stored index
/// of level h is the stored index of level h − 1 plus s (its pad is s larger), so a cell's two
/// half-windows are at indices x − s and x of the level below, 0 where that is off its stored
/// area.
fn double(below: &Level, s: usize) -> Level {
    let (stride, rows) = (below.stride + s, below.rows + s);
    // along the rows: below.rows rows of stride
    let mut horiz = vec![0u8; stride * below.rows];
    for (src, dst) in below
        .data
        .chunks_exact(below.stride)
        .zip(horiz.chunks_exact_mut(stride))
    {
        // dst[x] = max(src[x − s], src[x]) where they exist
        dst[..below.stride].copy_from_slice(src);
        for (d, &v) in dst[s..].iter_mut().zip(src) {
            *d = (*d).max(v);
        }
    }
    // along the columns: row y = max(horiz row y − s, horiz row y)
    let mut data = vec![0u8; stride * rows];
    data[..horiz.len()].copy_from_slice(&horiz);
    for (d, &v) in data[s * stride..].iter_mut().zip(&horiz) {
        *d = (*d).max(v);
    }
    Level {
        pad: below.pad + s as i32,
        stride,
        rows,
        data,
    }
}

impl PrecomputedGrids {
    /// Levels 0..`depth` (at least one). Hess et al. use depth 7 at 5 cm (a top node covers
    /// 64 × 64 cells, 3.2 m).
    pub fn new(grid: &ProbGrid, depth: usize) -> Self {
        let depth = depth.max(1);
        let base = Level {
            pad: 0,
            stride: grid.width,
            rows: grid.height,
            data: grid.p.iter().map(|&p| quantize(p)).collect(),
        };
        let mut levels = Vec::with_capacity(depth);
        levels.push(base);
        for level in 1..depth {
            let next = double(&levels[level - 1], 1 << (level - 1));
            levels.push(next);
        }
        PrecomputedGrids {
            levels,
            resolution: grid.resolution,
            origin: grid.origin,
        }
    }

    /// [`PrecomputedGrids::new`] by a sliding window maximum over the map for every level: the
    /// plain version the tests and the `loop_closure` benchmark compare it with.
    pub fn new_plain(grid: &ProbGrid, depth: usize) -> Self {
        let depth = depth.max(1);
        let (w, h) = (grid.width, grid.height);
        let base: Vec<u8> = grid.p.iter().map(|&p| quantize(p)).collect();
        let mut levels = Vec::with_capacity(depth);
        let mut deque = Vec::new();
        for level in 0..depth {
            let win = 1usize << level;
            let pad = win - 1;
            let (stride, rows) = (w + pad, h + pad);
            // along the rows: h rows of w + pad
            let mut horiz = vec![0u8; stride * h];
            for r in 0..h {
                sliding_max(
                    &base[r * w..(r + 1) * w],
                    win,
                    &mut horiz[r * stride..(r + 1) * stride],
                    &mut deque,
                );
            }
            // along the columns (gathered into a contiguous buffer)
            let mut data = vec![0u8; stride * rows];
            let mut col = vec![0u8; h];
            let mut col_out = vec![0u8; rows];
            for c in 0..stride {
                for r in 0..h {
                    col[r] = horiz[r * stride + c];
                }
                sliding_max(&col, win, &mut col_out, &mut deque);
                for (r, &v) in col_out.iter().enumerate() {
                    data[r * stride + c] = v;
                }
            }
            levels.push(Level {
                pad: pad as i32,
                stride,
                rows,
                data,
            });
        }
        PrecomputedGrids {
            levels,
            resolution: grid.resolution,
            origin: grid.origin,
        }
    }

    /// Number of levels (the depth of the branch-and-bound tree).
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// Metres per cell of the map.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Bytes held by the levels.
    pub fn memory_bytes(&self) -> usize {
        self.levels.iter().map(|l| l.data.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sliding_max_matches_brute_force() {
        let input: Vec<u8> = (0..37u32).map(|i| ((i * 97 + 13) % 251) as u8).collect();
        let mut dq = Vec::new();
        for win in [1usize, 2, 4, 8, 64] {
            let mut out = vec![0u8; input.len() + win - 1];
            sliding_max(&input, win, &mut out, &mut dq);
            for (i, &o) in out.iter().enumerate() {
                let lo = (i + 1).saturating_sub(win);
                let hi = i.min(input.len() - 1);
                let m = input[lo..=hi].iter().copied().max().unwrap_or(0);
                assert_eq!(o, m, "win {win} i {i}");
            }
        }
    }

    /// The doubling builds every level exactly as the sliding window over the map does, on
    /// odd sizes, a one-cell map and deep levels wider than the map.
    #[test]
    fn doubling_equals_the_sliding_window() {
        for (w, h, depth) in [(11, 7, 4), (1, 1, 3), (37, 5, 7), (64, 65, 6)] {
            let mut g = ProbGrid::new(w, h, 0.1, [0.0, 0.0], 0.0);
            for (k, p) in g.p.iter_mut().enumerate() {
                *p = ((k * 7919 % 1009) as f32) / 1008.0;
            }
            let (fast, plain) = (
                PrecomputedGrids::new(&g, depth),
                PrecomputedGrids::new_plain(&g, depth),
            );
            assert_eq!(fast.depth(), plain.depth());
            for (a, b) in fast.levels.iter().zip(&plain.levels) {
                assert_eq!(
                    (a.pad, a.stride, a.rows),
                    (b.pad, b.stride, b.rows),
                    "{w} x {h}"
                );
                assert!(a.data == b.data, "{w} x {h}, level pad {}", a.pad);
            }
        }
    }

    #[test]
    fn levels_hold_the_window_maximum() {
        let mut g = ProbGrid::new(11, 7, 0.1, [0.0, 0.0], 0.0);
        for (k, p) in g.p.iter_mut().enumerate() {
            *p = ((k * 37 % 101) as f32) / 100.0;
        }
        let pre = PrecomputedGrids::new(&g, 4);
        assert_eq!(pre.depth(), 4);
        for (h, level) in pre.levels.iter().enumerate() {
            let win = 1i32 << h;
            for r in -win..g.height as i32 + 1 {
                for c in -win..g.width as i32 + 1 {
                    let mut m = 0u8;
                    for dr in 0..win {
                        for dc in 0..win {
                            let (cc, rr) = (c + dc, r + dr);
                            if cc >= 0 && rr >= 0 && cc < g.width as i32 && rr < g.height as i32 {
                                m = m.max(quantize(g.get(cc as usize, rr as usize)));
                            }
                        }
                    }
                    assert_eq!(level.get(c, r), m, "level {h} at ({c}, {r})");
                }
            }
        }
    }
}
