//! Many independent rays at once ("ray streams"): a single ray on the distance field is a chain of
//! dependent memory loads — each leap needs the byte at the cell the previous leap landed in — so
//! one ray leaves the core idle most of the time. Here `LANES` rays advance in turn, one leap or
//! cell step each per round, so the loads of different rays overlap; a lane whose ray ends takes
//! the next one. Every step is the one [`RayMap::cast`] takes (crossing times from the cell
//! indices, never accumulated), so results agree with the cell walk of [`super::cast_dda`].
//!
//! This is what a particle filter needs (every particle's beams at once: the `calc_range_many`
//! of range_libc, Walsh & Karaman 2018) and what scans fall back to when the sweep does not apply.

use super::dda::{enter_grid, step_sign};
use super::raymap::RayMap;

/// Rays in flight. Eight is enough to hide an L2/L3 load behind the other lanes' arithmetic.
const LANES: usize = 8;

/// One ray's constants and position, in grid-relative metres.
#[derive(Clone, Copy, Default)]
struct Lane {
    gx: f32,
    gy: f32,
    dx: f32,
    dy: f32,
    /// 1/dx, 1/dy (finite: only used when the step sign is non-zero).
    idx: f32,
    idy: f32,
    /// Cell steps and the offsets (0 or 1) of the next boundary.
    sx: i32,
    sy: i32,
    bx: i32,
    by: i32,
    /// Length of one cell of L∞ travel along the ray.
    leap: f32,
    cx: i32,
    cy: i32,
    t: f32,
    /// Output slot.
    id: usize,
}

impl RayMap {
    /// Casts rays `(origin, angle)` into `out` (same length): `out[i]` is what
    /// [`RayMap::cast`] returns for ray i, computed several rays at a time.
    pub fn cast_many(&self, rays: &[([f32; 2], f32)], max_range: f32, out: &mut [f32]) {
        assert_eq!(rays.len(), out.len(), "one output per ray");
        self.cast_stream(
            rays.len(),
            |i| {
                let (p, a) = rays[i];
                let (dy, dx) = a.sin_cos();
                (p, dx, dy)
            },
            max_range,
            out,
        );
    }

    /// The stream kernel: ray i starts at `ray(i).0` with unit direction (`.1`, `.2`).
    pub(super) fn cast_stream(
        &self,
        n: usize,
        ray: impl Fn(usize) -> ([f32; 2], f32, f32),
        max_range: f32,
        out: &mut [f32],
    ) {
        let (w, h) = (self.width() as i32, self.height() as i32);
        let res = self.resolution();
        let inv_res = 1.0 / res;
        let (wf, hf) = (w as f32 * res, h as f32 * res);
        let origin = self.origin();
        let dist = self.dist();
        let mut lanes = [Lane::default(); LANES];
        let mut next = 0usize;
        // starts ray `next` (or later ones) in `lane`; rays that begin outside the grid or in an
        // occupied cell are answered at once. Returns false when no rays are left.
        let start = |lane: &mut Lane, next: &mut usize, out: &mut [f32]| -> bool {
            while *next < n {
                let i = *next;
                *next += 1;
                let (p, dx, dy) = ray(i);
                let (gx, gy) = (p[0] - origin[0], p[1] - origin[1]);
                if !(gx.is_finite() && gy.is_finite() && dx.is_finite() && dy.is_finite()) {
                    // no defined ray (a NaN or infinite pose): nothing to walk along
                    out[i] = f32::NAN;
                    continue;
                }
                let mut t = 0.0;
                if !(gx >= 0.0 && gy >= 0.0 && gx < wf && gy < hf) {
                    match enter_grid(gx, gy, dx, dy, wf, hf, max_range) {
                        Some(t0) => t = t0,
                        None => {
                            out[i] = f32::INFINITY;
                            continue;
                        }
                    }
                }
                let (sx, sy) = (step_sign(dx), step_sign(dy));
                *lane = Lane {
                    gx,
                    gy,
                    dx,
                    dy,
                    idx: if sx != 0 { 1.0 / dx } else { 0.0 },
                    idy: if sy != 0 { 1.0 / dy } else { 0.0 },
                    sx,
                    sy,
                    bx: (sx > 0) as i32,
                    by: (sy > 0) as i32,
                    leap: res / dx.abs().max(dy.abs()),
                    cx: (((gx + dx * t) * inv_res) as i32).clamp(0, w - 1),
                    cy: (((gy + dy * t) * inv_res) as i32).clamp(0, h - 1),
                    t,
                    id: i,
                };
                return true;
            }
            false
        };
        let mut active = 0;
        while active < LANES && start(&mut lanes[active], &mut next, out) {
            active += 1;
        }
        while active > 0 {
            let mut j = 0;
            while j < active {
                let l = &mut lanes[j];
                let k = dist[self.idx(l.cx as usize, l.cy as usize)];
                let done = if k == 0 {
                    out[l.id] = l.t;
                    true
                } else if k >= 2 {
                    // leap: every cell within L∞ distance k − 1 is free
                    let t = l.t + (k - 1) as f32 * l.leap;
                    let (px, py) = (l.gx + l.dx * t, l.gy + l.dy * t);
                    if t > max_range || px < 0.0 || py < 0.0 || px >= wf || py >= hf {
                        out[l.id] = f32::INFINITY;
                        true
                    } else {
                        l.t = t;
                        l.cx = ((px * inv_res) as i32).min(w - 1);
                        l.cy = ((py * inv_res) as i32).min(h - 1);
                        false
                    }
                } else {
                    // next to an obstacle: one cell step
                    let tx = if l.sx != 0 {
                        ((l.cx + l.bx) as f32 * res - l.gx) * l.idx
                    } else {
                        f32::INFINITY
                    };
                    let ty = if l.sy != 0 {
                        ((l.cy + l.by) as f32 * res - l.gy) * l.idy
                    } else {
                        f32::INFINITY
                    };
                    // never back along the ray: a ray running along a cell boundary can find
                    // the boundary it crosses a rounding error behind it, and leaping on from
                    // there could cycle between two cells for ever
                    if tx < ty {
                        l.t = tx.max(l.t);
                        l.cx += l.sx;
                    } else {
                        l.t = ty.max(l.t);
                        l.cy += l.sy;
                    }
                    if l.t > max_range || l.cx < 0 || l.cy < 0 || l.cx >= w || l.cy >= h {
                        out[l.id] = f32::INFINITY;
                        true
                    } else {
                        false
                    }
                };
                if done && !start(&mut lanes[j], &mut next, out) {
                    active -= 1;
                    lanes[j] = lanes[active];
                    continue;
                }
                j += 1;
            }
        }
    }
}
