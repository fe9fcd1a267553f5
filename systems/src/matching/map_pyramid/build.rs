//! Building the pyramid's levels: corner samples for surfaces on faces, the 2 × 2 combine and the
//! max-preserving smoothing, each over a window so edits stay local.

use super::level::{Combine, PyramidLevel, PyramidOptions, Window};
use crate::matching::ProbGrid;

/// Corner (i, j) (the lower-left corner of cell (i, j)) gets max P · (1 − min P) over the cells
/// sharing it: ≈ 1 where an occupied and a free cell meet, 0 inside walls and inside free space,
/// so M peaks ON the faces the beams end at. (Hector's M, the occupancy interpolated between
/// cell centres, is 0.5 on such a face and rises into the wall: a match pulled the end points up
/// to half a cell, 3.5 cm at 5 cm cells, into the walls of the side the scan sees most of.)
pub(super) fn corner_values(grid: &ProbGrid, level: &mut PyramidLevel, win: Window) {
    let (w, h) = (grid.width, grid.height);
    // the cell columns the window's corners touch
    let (c0, c1) = (win[0].saturating_sub(1), win[2].min(w));
    let (mut vmax, mut vmin) = (vec![0f32; c1 - c0], vec![0f32; c1 - c0]);
    for j in win[1]..win[3] {
        // the max and min of the one or two cells above each other at corner row j
        let below = (j >= 1).then(|| &grid.p[(j - 1) * w + c0..(j - 1) * w + c1]);
        let above = (j < h).then(|| &grid.p[j * w + c0..j * w + c1]);
        match (below, above) {
            (Some(b), Some(a)) => {
                for (k, (&x, &y)) in b.iter().zip(a).enumerate() {
                    vmax[k] = x.max(y);
                    vmin[k] = x.min(y);
                }
            }
            (Some(x), None) | (None, Some(x)) => {
                vmax.copy_from_slice(x);
                vmin.copy_from_slice(x);
            }
            (None, None) => unreachable!("a grid has at least one row"),
        }
        let out = &mut level.m[j * level.width..(j + 1) * level.width];
        let corner = |l: usize, r: usize| vmax[l].max(vmax[r]) * (1.0 - vmin[l].min(vmin[r]));
        // corner i touches cell columns i − 1 and i where they exist: the first and the last
        // corner of a row one column only
        let (i0, i1) = (win[0].max(1), win[2].min(w));
        if win[0] == 0 {
            out[0] = corner(0, 0);
        }
        if win[2] == w + 1 {
            out[w] = corner(w - 1 - c0, w - 1 - c0);
        }
        if i0 < i1 {
            let pairs = vmax[i0 - 1 - c0..i1 - c0].windows(2);
            let mins = vmin[i0 - 1 - c0..i1 - c0].windows(2);
            for ((o, x), n) in out[i0..i1].iter_mut().zip(pairs).zip(mins) {
                *o = x[0].max(x[1]) * (1.0 - n[0].min(n[1]));
            }
        }
    }
}

/// One row of [1 2 1]/4 with replicated ends; the same expression for every cell, so a window's
/// values match the whole level's bit for bit.
fn blur_row(row: &[f32], out: &mut [f32]) {
    let n = row.len();
    let cell = |l: f32, c: f32, r: f32| 0.25 * (l + r) + 0.5 * c;
    if n == 1 {
        out[0] = row[0];
        return;
    }
    out[0] = cell(row[0], row[0], row[1]);
    out[n - 1] = cell(row[n - 2], row[n - 1], row[n - 1]);
    for (o, w) in out[1..n - 1].iter_mut().zip(row.windows(3)) {
        *o = cell(w[0], w[1], w[2]);
    }
}

/// Recomputes `coarse` above the window `win` of `fine`; returns the coarse window of changed
/// raw (unsmoothed) values.
pub(super) fn combine_level(
    fine: &PyramidLevel,
    coarse: &mut PyramidLevel,
    win: Window,
    options: PyramidOptions,
) -> Window {
    let cwin = [
        win[0] / 2,
        win[1] / 2,
        win[2].div_ceil(2),
        win[3].div_ceil(2),
    ];
    let src = fine.raw();
    let (fw, fh) = (fine.width, fine.height);
    let dst = if coarse.raw.is_empty() {
        &mut coarse.m
    } else {
        &mut coarse.raw
    };
    let f = |a: f32, b: f32, d: f32, e: f32| match options.combine {
        Combine::Max => a.max(b).max(d.max(e)),
        Combine::Mean => 0.25 * ((a + b) + (d + e)),
    };
    // coarse columns with two children; an odd last column repeats its child (max does not
    // notice, mean weighs it twice), as does an odd last row
    let paired = cwin[2].min(fw / 2);
    for r in cwin[1]..cwin[3] {
        let lo = &src[2 * r * fw..][..fw];
        let hi = &src[(2 * r + 1).min(fh - 1) * fw..][..fw];
        let out = &mut dst[r * coarse.width..(r + 1) * coarse.width];
        if cwin[0] < paired {
            let cols = 2 * cwin[0]..2 * paired;
            let pairs = lo[cols.clone()]
                .chunks_exact(2)
                .zip(hi[cols].chunks_exact(2));
            for (o, (a, b)) in out[cwin[0]..paired].iter_mut().zip(pairs) {
                *o = f(a[0], a[1], b[0], b[1]);
            }
        }
        for c in paired.max(cwin[0])..cwin[2] {
            out[c] = f(lo[2 * c], lo[2 * c], hi[2 * c], hi[2 * c]);
        }
    }
    if options.smoothing > 0 {
        smooth_window(coarse, cwin, options.smoothing);
    }
    cwin
}

/// Recomputes the smoothed values `m` wherever `passes` max-preserving [1 2 1]/4 passes over
/// `raw` can reach from the changed window `win`: the output band is `passes` cells wider on each
/// side, and it is computed from raw values `passes` cells wider again, so its edge values are
/// exactly what smoothing the whole level gives (a pass moves information one cell).
fn smooth_window(level: &mut PyramidLevel, win: Window, passes: usize) {
    let (w, h) = (level.width, level.height);
    let grow = |win: Window, n: usize| {
        [
            win[0].saturating_sub(n),
            win[1].saturating_sub(n),
            (win[2] + n).min(w),
            (win[3] + n).min(h),
        ]
    };
    let out = grow(win, passes);
    let inp = grow(win, 2 * passes);
    let (iw, ih) = (inp[2] - inp[0], inp[3] - inp[1]);
    let mut a: Vec<f32> = Vec::with_capacity(iw * ih);
    for r in inp[1]..inp[3] {
        a.extend_from_slice(&level.raw[r * w + inp[0]..r * w + inp[2]]);
    }
    let mut b = vec![0f32; iw * ih];
    // clamping at the level's true edges replicates them; clamping at an interior window edge
    // is wrong, but that error stays `passes` cells away from `out`
    for _ in 0..passes {
        for (row, out) in a.chunks_exact(iw).zip(b.chunks_exact_mut(iw)) {
            blur_row(row, out);
        }
        for r in 0..ih {
            let (dn, up) = (r.saturating_sub(1), (r + 1).min(ih - 1));
            let (dn, mid, up) = (&b[dn * iw..][..iw], &b[r * iw..][..iw], &b[up * iw..][..iw]);
            for (((a, &d), &m), &u) in a[r * iw..][..iw].iter_mut().zip(dn).zip(mid).zip(up) {
                *a = a.max(0.25 * (d + u) + 0.5 * m);
            }
        }
    }
    for r in out[1]..out[3] {
        let src = &a[(r - inp[1]) * iw + (out[0] - inp[0])..][..out[2] - out[0]];
        level.m[r * w + out[0]..r * w + out[2]].copy_from_slice(src);
    }
}
