//! Prediction of the grid by the odometry motion model (Probabilistic Robotics §8.2, Table 8.1
//! line 3, with the motion of Table 5.5): the mass of every cell (x, y, θ) moves by the odometry
//! motion (δrot1, δtrans, δrot2) as seen from that cell's heading, split trilinearly over the
//! eight cells around its destination (which is itself a blur of a fraction of a cell), then a
//! separable Gaussian blur adds what is left of the motion noise. Mass that lands in occupied
//! or unknown cells is dropped; the caller renormalises.

use super::layout::Layout;
use crate::localization::motion_model::OdometryDelta;

/// Moves `src` (all θ layers) by `d` into `dst` (cleared first).
pub fn shift(layout: &Layout, d: &OdometryDelta, src: &[f32], dst: &mut [f32]) {
    dst.iter_mut().for_each(|v| *v = 0.0);
    let (nx, ny, nt) = (layout.nx as isize, layout.ny as isize, layout.n_theta);
    let layer = layout.layer();
    let step = layout.theta_step();
    // heading change in bins, the same for every layer
    let dk = (d.rot1 + d.rot2) / step;
    let dk0 = dk.floor();
    let wk = (dk - dk0) as f32;
    // a shift past the grid's extent drops all the mass, as any longer one: clamped there so
    // the cell arithmetic stays within integers
    let beyond = (layout.nx + layout.ny + 2) as f64;
    for k in 0..nt {
        let th = layout.theta(k) + d.rot1;
        let sx = (d.trans * th.cos() / layout.resolution).clamp(-beyond, beyond);
        let sy = (d.trans * th.sin() / layout.resolution).clamp(-beyond, beyond);
        let (ix, iy) = (sx.floor(), sy.floor());
        let (fx, fy) = ((sx - ix) as f32, (sy - iy) as f32);
        let (ix, iy) = (ix as isize, iy as isize);
        let weights = [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ];
        let k0 = (k as isize + dk0 as isize).rem_euclid(nt as isize) as usize;
        let k1 = (k0 + 1) % nt;
        let from = &src[k * layer..(k + 1) * layer];
        // the whole layer moves by the same (ix + ox, iy + oy): contiguous row slices; mass
        // that lands on a cell outside free space is dropped below
        for s in &layout.spans {
            let j = s.j as isize;
            for &(ox, oy, w) in &weights {
                let tj = j + iy + oy;
                if w == 0.0 || tj < 0 || tj >= ny {
                    continue;
                }
                let (i0, i1) = (s.i0 as isize, (s.i0 + s.len) as isize);
                let dx = ix + ox;
                let (a, b) = ((i0 + dx).max(0), (i1 + dx).min(nx));
                if a >= b {
                    continue;
                }
                let src_row = &from[(j * nx + a - dx) as usize..(j * nx + b - dx) as usize];
                let t = (tj * nx + a) as usize..(tj * nx + b) as usize;
                let (w0, w1) = (w * (1.0 - wk), w * wk);
                for (d, &m) in dst[k0 * layer..][t.clone()].iter_mut().zip(src_row) {
                    *d += m * w0;
                }
                for (d, &m) in dst[k1 * layer..][t].iter_mut().zip(src_row) {
                    *d += m * w1;
                }
            }
        }
    }
    for layer_cells in dst.chunks_mut(layer) {
        for (v, &f) in layer_cells.iter_mut().zip(&layout.free) {
            if !f {
                *v = 0.0;
            }
        }
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
