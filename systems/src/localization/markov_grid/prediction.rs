//! Prediction of the grid by the odometry motion model (Probabilistic Robotics §8.2, Table 8.1
//! line 3, with the motion of Table 5.5): the mass of every cell (x, y, θ) moves by the odometry
//! motion (δrot1, δtrans, δrot2) as seen from that cell's heading, then a separable Gaussian blur
//! adds the motion noise. Mass that lands in occupied or unknown cells is dropped; the caller
//! renormalises.
//!
//! Every cell of a θ layer moves by the same displacement, and every layer turns by the same
//! angle, so the motion is exact without interpolation: each layer moves by whole cells and
//! keeps the fraction left over as its [`SubCell`] offset (and all layers one heading offset),
//! carried to the next motion; the correction and the estimate read a cell's pose at its centre
//! plus that offset. Splitting each cell's mass over the cells around its destination instead
//! (trilinear interpolation) blurs the belief by about a sixth of a cell² per axis at every
//! update, whatever the motion noise: at 0.25 m per update and α = 0.01 that is 16 times the
//! odometry's own variance, and along a corridor, where a scan says little about the position
//! along it, the histogram drifted away from the robot by half a metre.

use super::belief_ops::Tally;
use super::layout::{Layout, Span};
use crate::localization::motion_model::OdometryDelta;
use rayon::prelude::*;

/// Where the mass of the grid sits within its cells, carried from motion to motion: per θ
/// layer, the position offset from the cell centres (cells, each axis within ±½), and for all
/// layers, the heading offset from the bin centres (bins, within ±½).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SubCell {
    pub xy: Vec<[f64; 2]>,
    pub theta: f64,
}

impl SubCell {
    /// No offsets: every cell's pose at its centre.
    pub fn centred(layout: &Layout) -> Self {
        SubCell {
            xy: vec![[0.0; 2]; layout.n_theta],
            theta: 0.0,
        }
    }

    /// The heading of layer `k`'s cells.
    pub fn heading(&self, layout: &Layout, k: usize) -> f64 {
        layout.theta(k) + self.theta * layout.theta_step()
    }

    /// The position offset (m) of layer `k`'s cells from their centres.
    pub fn offset(&self, layout: &Layout, k: usize) -> (f64, f64) {
        let [ox, oy] = self.xy[k];
        (ox * layout.resolution, oy * layout.resolution)
    }

    /// The position of cell (i, j) of layer `k`.
    pub fn position(&self, layout: &Layout, k: usize, i: usize, j: usize) -> (f64, f64) {
        let (x, y) = layout.centre(i, j);
        let (ox, oy) = self.offset(layout, k);
        (x + ox, y + oy)
    }
}

/// What lies beyond the edge of a grid that is a window of a larger lattice ([`super::window`]):
/// the window's place in `whole`, and the value of every free cell of `whole` outside it.
#[derive(Clone, Copy, Debug)]
pub struct Edge<'a> {
    pub whole: &'a Layout,
    pub at: [usize; 2],
    pub value: f32,
}

/// Moves `src` (all θ layers, at the offsets `sub`) by `d` into `dst`, and `sub` to the offsets
/// of the moved mass. Every free cell of `dst` is written: the mass from its source cell if that
/// lies in the grid, 0 otherwise (mass that leaves the grid or lands on an occupied or unknown
/// cell is dropped), or, for a window with its `edge`, the edge's value where the source cell
/// lies outside the window on a free cell of the whole lattice. Neither `src` nor `dst` holds
/// anything outside free space. Returns `dst`'s tally (sum and peak).
pub fn shift(
    layout: &Layout,
    d: &OdometryDelta,
    sub: &mut SubCell,
    src: &[f32],
    dst: &mut [f32],
    edge: Option<Edge>,
) -> Tally {
    let (moves, turn) = layer_moves(layout, edge.map_or(layout, |e| e.whole), d, sub);
    let (nx, ny) = (layout.nx as isize, layout.ny as isize);
    let layer = layout.layer();
    let mut tally = Tally::default();
    // the spans of each row, in the order the layout lists them (by row, then column)
    let rows = row_spans(layout);
    for (k, m) in moves.iter().enumerate() {
        let from = &src[k * layer..(k + 1) * layer];
        let into = &mut dst[m.to * layer..(m.to + 1) * layer];
        // the target columns whose source column lies in the grid
        let (a, b) = (
            m.ix.clamp(0, nx) as usize,
            (nx + m.ix).clamp(0, nx) as usize,
        );
        for (tj, spans) in rows.iter().enumerate() {
            let (Some(first), Some(last)) = (spans.first(), spans.last()) else {
                continue;
            };
            let row = &mut into[tj * layout.nx..][..layout.nx];
            let j = tj as isize - m.iy;
            // the free extent of the row that has a source: one copy, then the cells of it
            // that are not free cleared, and the free cells outside it too
            let lo = (first.i0 as usize).max(a);
            let hi = ((last.i0 + last.len) as usize).min(b);
            if j < 0 || j >= ny || lo >= hi {
                for s in *spans {
                    row[s.i0 as usize..][..s.len as usize].fill(0.0);
                }
                continue;
            }
            let shift = |i: usize| (i as isize - m.ix) as usize;
            let source = &from[j as usize * layout.nx..][..layout.nx];
            row[lo..hi].copy_from_slice(&source[shift(lo)..shift(hi)]);
            let mut free_to = first.i0 as usize;
            for s in *spans {
                let (s0, s1) = (s.i0 as usize, (s.i0 + s.len) as usize);
                // the gap before this span, within the copy
                row[free_to.max(lo)..s0.min(hi).max(free_to.max(lo))].fill(0.0);
                // this span's cells outside the copy
                row[s0..s1.min(lo).max(s0)].fill(0.0);
                row[s0.max(hi).min(s1)..s1].fill(0.0);
                free_to = s1;
            }
            tally.add(&row[lo..hi]);
        }
    }
    if let Some(e) = edge {
        inflow(layout, &e, &moves, &rows, dst, &mut tally);
    }
    for m in &moves {
        sub.xy[m.to] = m.rest;
    }
    sub.theta = turn;
    tally
}

/// The cells of a window whose source under `moves` lies outside it, on a free cell of the
/// whole lattice: they take the edge's value (tallied).
fn inflow(
    layout: &Layout,
    e: &Edge,
    moves: &[LayerMove],
    rows: &[&[Span]],
    dst: &mut [f32],
    tally: &mut Tally,
) {
    let (nx, ny) = (layout.nx as isize, layout.ny as isize);
    let (wx, wy) = (e.whole.nx as isize, e.whole.ny as isize);
    let [ax, ay] = e.at.map(|a| a as isize);
    for m in moves {
        let into = &mut dst[m.to * layout.layer()..][..layout.layer()];
        for (tj, spans) in rows.iter().enumerate() {
            let j = tj as isize - m.iy;
            let row_outside = j < 0 || j >= ny;
            let wj = j + ay;
            if wj < 0 || wj >= wy {
                continue;
            }
            for s in *spans {
                for i in s.i0 as isize..(s.i0 + s.len) as isize {
                    let si = i - m.ix;
                    if !row_outside && si >= 0 && si < nx {
                        continue;
                    }
                    let wi = si + ax;
                    if wi >= 0 && wi < wx && e.whole.free[(wj * wx + wi) as usize] {
                        into[tj * layout.nx + i as usize] = e.value;
                        tally.add(&[e.value]);
                    }
                }
            }
        }
    }
}

/// The layout's spans row by row (they are listed by row, then column).
fn row_spans(layout: &Layout) -> Vec<&[Span]> {
    let mut rows = vec![&layout.spans[..0]; layout.ny];
    let mut rest = &layout.spans[..];
    while let Some(s) = rest.first() {
        let n = rest.iter().take_while(|t| t.j == s.j).count();
        rows[s.j as usize] = &rest[..n];
        rest = &rest[n..];
    }
    rows
}

/// Where one θ layer's mass goes: layer `to`, by `ix`, `iy` whole cells, leaving `rest` (cells,
/// each within ±½) as the moved mass's offset.
struct LayerMove {
    to: usize,
    ix: isize,
    iy: isize,
    rest: [f64; 2],
}

/// Every layer's move under the motion `d`, and the heading offset (bins) left over for all
/// layers: each layer moves by its offset plus the motion as seen from its heading, rounded to
/// whole cells, and all turn by the same whole bins. A move past the extent of the lattice
/// `extent` (the grid's, or the whole one a window is part of) drops all the mass, as any longer
/// one: clamped there so the cell arithmetic stays within integers.
fn layer_moves(
    layout: &Layout,
    extent: &Layout,
    d: &OdometryDelta,
    sub: &SubCell,
) -> (Vec<LayerMove>, f64) {
    let nt = layout.n_theta as isize;
    let turn = sub.theta + (d.rot1 + d.rot2) / layout.theta_step();
    let dk = turn.round();
    let beyond = (extent.nx + extent.ny + 2) as f64;
    let moves = sub
        .xy
        .iter()
        .enumerate()
        .map(|(k, &[ox, oy])| {
            let th = sub.heading(layout, k) + d.rot1;
            let sx = (ox + d.trans * th.cos() / layout.resolution).clamp(-beyond, beyond);
            let sy = (oy + d.trans * th.sin() / layout.resolution).clamp(-beyond, beyond);
            let (ix, iy) = (sx.round(), sy.round());
            LayerMove {
                to: (k as isize + dk as isize).rem_euclid(nt) as usize,
                ix: ix as isize,
                iy: iy as isize,
                rest: [sx - ix, sy - iy],
            }
        })
        .collect();
    (moves, turn - dk)
}

/// A normalised blur kernel of variance `var` (cells²): for less than half a cell², the
/// three taps (var/2, 1 − var, var/2), whose variance is exactly `var` where a sampled
/// Gaussian's would be far less; otherwise [`kernel`] with σ = √var.
pub fn kernel_of_variance(var: f64) -> Vec<f32> {
    if var < 0.5 {
        let side = (0.5 * var.max(0.0)) as f32;
        vec![side, 1.0 - 2.0 * side, side]
    } else {
        kernel(var.sqrt())
    }
}

/// A normalised Gaussian kernel of standard deviation `sigma` (in cells), radius ⌈3σ⌉.
pub fn kernel(sigma: f64) -> Vec<f32> {
    let r = (3.0 * sigma).ceil().max(1.0) as isize;
    let k: Vec<f64> = (-r..=r)
        .map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp())
        .collect();
    let s: f64 = k.iter().sum();
    k.iter().map(|v| (v / s) as f32).collect()
}

/// Blurs every θ layer of `p` along x and y with `k`; mass that leaves free space is dropped.
/// Each cell adds its taps in order, starting from 0, skipping those off the grid; written tap
/// by tap over whole rows so the adds vectorise, the layers in parallel (a layer of scratch
/// per task).
pub fn blur_xy(layout: &Layout, k: &[f32], p: &mut [f32]) {
    let (nx, ny, layer) = (layout.nx, layout.ny, layout.layer());
    let r = k.len() / 2;
    p.par_chunks_mut(layer).for_each_init(
        || vec![0.0f32; layer],
        |tmp, layer| {
            // along x into tmp: tap t reads cell i + t − r
            for (row, out) in layer.chunks_exact(nx).zip(tmp.chunks_exact_mut(nx)) {
                out.fill(0.0);
                for (t, &w) in k.iter().enumerate() {
                    // cells i with 0 ≤ i + t − r < nx
                    let (lo, hi) = (r.saturating_sub(t), (nx + r).saturating_sub(t).min(nx));
                    if lo >= hi {
                        continue;
                    }
                    let src = &row[lo + t - r..hi + t - r];
                    for (o, &v) in out[lo..hi].iter_mut().zip(src) {
                        *o += w * v;
                    }
                }
            }
            // along y back into the layer: tap t reads row j + t − r
            for j in 0..ny {
                let out = &mut layer[j * nx..(j + 1) * nx];
                out.fill(0.0);
                for (t, &w) in k.iter().enumerate() {
                    let Some(s) = (j + t).checked_sub(r).filter(|&s| s < ny) else {
                        continue;
                    };
                    for (o, &v) in out.iter_mut().zip(&tmp[s * nx..(s + 1) * nx]) {
                        *o += w * v;
                    }
                }
                for (o, &f) in out.iter_mut().zip(&layout.free[j * nx..(j + 1) * nx]) {
                    if !f {
                        *o = 0.0;
                    }
                }
            }
        },
    );
}

/// Blurs `p` across θ layers (circularly) with `k`, into `dst`; the output layers in parallel.
pub fn blur_theta(layout: &Layout, k: &[f32], p: &[f32], dst: &mut [f32]) {
    let layer = layout.layer();
    let nt = layout.n_theta as isize;
    let r = (k.len() / 2) as isize;
    dst.par_chunks_mut(layer).enumerate().for_each(|(kk, out)| {
        out.fill(0.0);
        for (t, &w) in k.iter().enumerate() {
            let s = (kk as isize + t as isize - r).rem_euclid(nt) as usize * layer;
            for sp in &layout.spans {
                let a = sp.j as usize * layout.nx + sp.i0 as usize;
                let b = a + sp.len as usize;
                for (o, &v) in out[a..b].iter_mut().zip(&p[s + a..s + b]) {
                    *o += w * v;
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{Pose2, stream_rng};
    use crate::localization::motion_model::OdometryMotionModel;
    use crate::localization::test_drive::hospital;
    use rand::RngExt;

    /// The shift as first written: clear the target, copy each free run of a layer to its moved
    /// place, then clear the cells that are not free.
    fn shift_plain(l: &Layout, d: &OdometryDelta, sub: &mut SubCell, src: &[f32], dst: &mut [f32]) {
        dst.fill(0.0);
        let (moves, turn) = layer_moves(l, l, d, sub);
        let (nx, ny, layer) = (l.nx as isize, l.ny as isize, l.layer());
        for (k, m) in moves.iter().enumerate() {
            for s in &l.spans {
                let tj = s.j as isize + m.iy;
                let (a, b) = (
                    (s.i0 as isize + m.ix).max(0),
                    ((s.i0 + s.len) as isize + m.ix).min(nx),
                );
                if tj < 0 || tj >= ny || a >= b {
                    continue;
                }
                let (t, f) = (m.to * layer, k * layer + s.j as usize * l.nx);
                dst[t + (tj * nx + a) as usize..t + (tj * nx + b) as usize]
                    .copy_from_slice(&src[f + (a - m.ix) as usize..f + (b - m.ix) as usize]);
            }
        }
        for (c, v) in dst.iter_mut().enumerate() {
            if !l.free[c % layer] {
                *v = 0.0;
            }
        }
        for m in &moves {
            sub.xy[m.to] = m.rest;
        }
        sub.theta = turn;
    }

    /// The blur along x and y as first written: cell by cell, tap by tap.
    fn blur_xy_plain(layout: &Layout, k: &[f32], p: &mut [f32]) {
        let (nx, ny) = (layout.nx, layout.ny);
        let r = (k.len() / 2) as isize;
        let mut tmp = vec![0.0f32; layout.layer()];
        for layer in p.chunks_mut(layout.layer()) {
            for j in 0..ny {
                for i in 0..nx {
                    let mut acc = 0.0;
                    for (t, &w) in k.iter().enumerate() {
                        let s = i as isize + t as isize - r;
                        if s >= 0 && (s as usize) < nx {
                            acc += w * layer[j * nx + s as usize];
                        }
                    }
                    tmp[j * nx + i] = acc;
                }
            }
            for j in 0..ny {
                for i in 0..nx {
                    let c = j * nx + i;
                    let mut acc = 0.0;
                    for (t, &w) in k.iter().enumerate() {
                        let s = j as isize + t as isize - r;
                        if s >= 0 && (s as usize) < ny {
                            acc += w * tmp[s as usize * nx + i];
                        }
                    }
                    layer[c] = if layout.free[c] { acc } else { 0.0 };
                }
            }
        }
    }

    /// The blur across θ as first written: one layer after another.
    fn blur_theta_plain(layout: &Layout, k: &[f32], p: &[f32], dst: &mut [f32]) {
        let layer = layout.layer();
        let nt = layout.n_theta as isize;
        let r = (k.len() / 2) as isize;
        dst.fill(0.0);
        for kk in 0..nt {
            let out = kk as usize * layer;
            for (t, &w) in k.iter().enumerate() {
                let s = (kk + t as isize - r).rem_euclid(nt) as usize * layer;
                for sp in &layout.spans {
                    let a = sp.j as usize * layout.nx + sp.i0 as usize;
                    for c in a..a + sp.len as usize {
                        dst[out + c] += w * p[s + c];
                    }
                }
            }
        }
    }

    /// Both blurs write what the plain ones do, bit for bit, for kernels from 1 tap to wider
    /// than the grid's θ layers.
    #[test]
    fn blurs_equal_the_plain_blurs() {
        let map = hospital();
        let l = Layout::new(&map.grid, 0.25, 36);
        let mut rng = stream_rng(4, "test", "blur");
        let src: Vec<f32> = (0..l.len())
            .map(|c| {
                if l.free[c % l.layer()] {
                    rng.random_range(0.0..1.0)
                } else {
                    0.0
                }
            })
            .collect();
        for variance in [0.01, 0.3, 2.0, 40.0, 2000.0] {
            let k = kernel_of_variance(variance);
            let (mut fast, mut plain) = (src.clone(), src.clone());
            blur_xy(&l, &k, &mut fast);
            blur_xy_plain(&l, &k, &mut plain);
            assert!(
                fast.iter()
                    .zip(&plain)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            let (mut fast, mut plain) = (vec![5.0; l.len()], vec![0.0; l.len()]);
            blur_theta(&l, &k, &src, &mut fast);
            blur_theta_plain(&l, &k, &src, &mut plain);
            assert!(
                fast.iter()
                    .zip(&plain)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
    }

    /// The shift writes what the plain one does, whatever the target's free cells held, for
    /// small steps, turns, long jumps and jumps off the grid.
    #[test]
    fn shift_equals_the_plain_shift() {
        let map = hospital();
        let l = Layout::new(&map.grid, 0.25, 36);
        let mut rng = stream_rng(3, "test", "shift");
        let mut src = vec![0.0f32; l.len()];
        for layer in src.chunks_mut(l.layer()) {
            for (v, &f) in layer.iter_mut().zip(&l.free) {
                if f {
                    *v = rng.random_range(0.0..1.0);
                }
            }
        }
        let model = OdometryMotionModel::default();
        let mut sub = SubCell::centred(&l);
        for (x, y, th) in [
            (0.25, 0.0, 0.0),
            (0.1, -0.3, 0.2),
            (-0.6, 0.4, -1.0),
            (3.0, 2.0, 3.0),
            (-20.0, 7.0, 0.5),
            (100.0, -100.0, 0.0),
        ] {
            let d = model.delta(&Pose2::IDENTITY, &Pose2::new(x, y, th));
            // the target's free cells hold stale values, the others nothing
            let mut fast: Vec<f32> = (0..l.len())
                .map(|c| if l.free[c % l.layer()] { 7.0 } else { 0.0 })
                .collect();
            let mut plain = vec![0.0f32; l.len()];
            let (mut sub_fast, mut sub_plain) = (sub.clone(), sub.clone());
            let total = shift(&l, &d, &mut sub_fast, &src, &mut fast, None).sum();
            shift_plain(&l, &d, &mut sub_plain, &src, &mut plain);
            assert!(
                fast.iter()
                    .zip(&plain)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            assert_eq!(sub_fast, sub_plain);
            let plain_total: f64 = plain.iter().map(|&v| v as f64).sum();
            assert!((total - plain_total).abs() <= 1e-12 * plain_total);
            sub = sub_fast;
            src = fast;
            if src.iter().all(|&v| v == 0.0) {
                break;
            }
        }
    }

    /// A window of the lattice shifted with its edge writes what the whole lattice shifted
    /// writes on the window's cells, where every free cell outside the window holds the edge's
    /// value.
    #[test]
    fn a_window_shifts_as_the_whole_lattice_with_its_background() {
        use super::super::layout::Rect;
        let map = hospital();
        let whole = Layout::new(&map.grid, 0.25, 36);
        let r = Rect {
            i0: 30,
            j0: 12,
            nx: 40,
            ny: 30,
        };
        let win = whole.crop(&r);
        let background = 3e-9f32;
        let mut rng = stream_rng(5, "test", "window-shift");
        let inside =
            |i: usize, j: usize| i >= r.i0 && i < r.i0 + r.nx && j >= r.j0 && j < r.j0 + r.ny;
        let mut src_whole = vec![0.0f32; whole.len()];
        for (c, v) in src_whole.iter_mut().enumerate() {
            let cell = c % whole.layer();
            let (i, j) = (cell % whole.nx, cell / whole.nx);
            if whole.free[cell] {
                *v = if inside(i, j) {
                    rng.random_range(0.0..1.0)
                } else {
                    background
                };
            }
        }
        let window_of = |v: &[f32]| -> Vec<f32> {
            let mut w = Vec::with_capacity(win.len());
            for layer in v.chunks(whole.layer()) {
                for j in r.j0..r.j0 + r.ny {
                    w.extend_from_slice(&layer[j * whole.nx + r.i0..][..r.nx]);
                }
            }
            w
        };
        let model = OdometryMotionModel::default();
        for (x, y, th) in [
            (0.3, 0.1, 0.1),
            (-0.9, 1.4, -0.7),
            (2.5, -3.0, 2.0),
            (40.0, 0.0, 0.0),
        ] {
            let d = model.delta(&Pose2::IDENTITY, &Pose2::new(x, y, th));
            let mut sub_whole = SubCell::centred(&whole);
            let mut out_whole = vec![0.0f32; whole.len()];
            shift(&whole, &d, &mut sub_whole, &src_whole, &mut out_whole, None);
            let mut sub_win = SubCell::centred(&win);
            let mut out_win = vec![7.0f32; win.len()];
            let edge = Edge {
                whole: &whole,
                at: [r.i0, r.j0],
                value: background,
            };
            let tally = shift(
                &win,
                &d,
                &mut sub_win,
                &window_of(&src_whole),
                &mut out_win,
                Some(edge),
            );
            // the window's free cells as the whole lattice's; its other cells untouched
            let want = window_of(&out_whole);
            for (c, (a, b)) in out_win.iter().zip(&want).enumerate() {
                if win.free[c % win.layer()] {
                    assert_eq!(a.to_bits(), b.to_bits(), "cell {c} after {x} {y} {th}");
                }
            }
            assert_eq!(sub_win, sub_whole);
            let free_sum: f64 = out_win
                .iter()
                .enumerate()
                .filter(|(c, _)| win.free[c % win.layer()])
                .map(|(_, &v)| v as f64)
                .sum();
            assert!((tally.sum() - free_sum).abs() <= 1e-9 * free_sum.max(1.0));
        }
    }
}
