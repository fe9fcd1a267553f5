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

use super::layout::Layout;
use crate::localization::motion_model::OdometryDelta;

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

/// Moves `src` (all θ layers, at the offsets `sub`) by `d` into `dst` (cleared first), and
/// `sub` to the offsets of the moved mass.
pub fn shift(layout: &Layout, d: &OdometryDelta, sub: &mut SubCell, src: &[f32], dst: &mut [f32]) {
    dst.iter_mut().for_each(|v| *v = 0.0);
    let (nx, ny, nt) = (layout.nx as isize, layout.ny as isize, layout.n_theta);
    let layer = layout.layer();
    // heading change in bins, the same for every layer: whole bins, the rest carried
    let turn = sub.theta + (d.rot1 + d.rot2) / layout.theta_step();
    let dk = turn.round();
    // a shift past the grid's extent drops all the mass, as any longer one: clamped there so
    // the cell arithmetic stays within integers
    let beyond = (layout.nx + layout.ny + 2) as f64;
    let mut moved = vec![[0.0; 2]; nt];
    for (k, sub_k) in sub.xy.iter().enumerate() {
        let th = sub.heading(layout, k) + d.rot1;
        let sx = (sub_k[0] + d.trans * th.cos() / layout.resolution).clamp(-beyond, beyond);
        let sy = (sub_k[1] + d.trans * th.sin() / layout.resolution).clamp(-beyond, beyond);
        let (ix, iy) = (sx.round(), sy.round());
        let to = (k as isize + dk as isize).rem_euclid(nt as isize) as usize;
        moved[to] = [sx - ix, sy - iy];
        let (ix, iy) = (ix as isize, iy as isize);
        let from = &src[k * layer..(k + 1) * layer];
        let into = &mut dst[to * layer..(to + 1) * layer];
        // the whole layer moves by the same (ix, iy): contiguous row slices; mass that lands
        // on a cell outside free space is dropped below
        for s in &layout.spans {
            let tj = s.j as isize + iy;
            if tj < 0 || tj >= ny {
                continue;
            }
            let (i0, i1) = (s.i0 as isize, (s.i0 + s.len) as isize);
            let (a, b) = ((i0 + ix).max(0), (i1 + ix).min(nx));
            if a >= b {
                continue;
            }
            let j = s.j as isize;
            into[(tj * nx + a) as usize..(tj * nx + b) as usize]
                .copy_from_slice(&from[(j * nx + a - ix) as usize..(j * nx + b - ix) as usize]);
        }
    }
    sub.xy = moved;
    sub.theta = turn - dk;
    for layer_cells in dst.chunks_mut(layer) {
        for (v, &f) in layer_cells.iter_mut().zip(&layout.free) {
            if !f {
                *v = 0.0;
            }
        }
    }
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

/// Blurs every θ layer of `p` along x and y with `k` (`tmp` is scratch of one layer); mass that
/// leaves free space is dropped.
pub fn blur_xy(layout: &Layout, k: &[f32], p: &mut [f32], tmp: &mut Vec<f32>) {
    let (nx, ny) = (layout.nx, layout.ny);
    let r = (k.len() / 2) as isize;
    tmp.resize(layout.layer(), 0.0);
    for layer in p.chunks_mut(layout.layer()) {
        // along x into tmp
        for j in 0..ny {
            let row = &layer[j * nx..(j + 1) * nx];
            let out = &mut tmp[j * nx..(j + 1) * nx];
            for (i, o) in out.iter_mut().enumerate() {
                let mut acc = 0.0;
                for (t, &w) in k.iter().enumerate() {
                    let s = i as isize + t as isize - r;
                    if s >= 0 && (s as usize) < nx {
                        acc += w * row[s as usize];
                    }
                }
                *o = acc;
            }
        }
        // along y back into the layer
        for j in 0..ny {
            for i in 0..nx {
                let c = j * nx + i;
                if !layout.free[c] {
                    layer[c] = 0.0;
                    continue;
                }
                let mut acc = 0.0;
                for (t, &w) in k.iter().enumerate() {
                    let s = j as isize + t as isize - r;
                    if s >= 0 && (s as usize) < ny {
                        acc += w * tmp[s as usize * nx + i];
                    }
                }
                layer[c] = acc;
            }
        }
    }
}

/// Blurs `p` across θ layers (circularly) with `k`, into `dst`.
pub fn blur_theta(layout: &Layout, k: &[f32], p: &[f32], dst: &mut [f32]) {
    let layer = layout.layer();
    let nt = layout.n_theta as isize;
    let r = (k.len() / 2) as isize;
    dst.iter_mut().for_each(|v| *v = 0.0);
    for kk in 0..nt {
        let out = kk as usize * layer;
        for (t, &w) in k.iter().enumerate() {
            let s = (kk + t as isize - r).rem_euclid(nt) as usize * layer;
            for sp in &layout.spans {
                let a = sp.j as usize * layout.nx + sp.i0 as usize;
                let b = a + sp.len as usize;
                for (o, &v) in dst[out + a..out + b].iter_mut().zip(&p[s + a..s + b]) {
                    *o += w * v;
                }
            }
        }
    }
}
