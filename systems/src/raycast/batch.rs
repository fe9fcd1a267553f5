//! Many independent rays at once ("ray streams"): a single ray on the distance field is a chain of
//! dependent memory loads — each leap needs the byte at the cell the previous leap landed in — so
//! one ray leaves the core idle most of the time. Here `LANES` rays advance in turn, one leap or
//! cell step each per round, so the loads of different rays overlap; a lane whose ray ends takes
//! the next one. Every step is the one [`RayMap::cast`] takes (crossing times from the cell
//! indices, never accumulated), so results agree with the cell walk of [`super::cast_dda`].
//!
//! This is what a particle filter needs (every particle's beams at once: the `calc_range_many`
//! of range_libc, Walsh & Karaman 2018) and what scans fall back to when the sweep does not apply.

use super::leap::{Bounds, Lane};
use super::raymap::RayMap;

/// Rays in flight. Eight is enough to hide an L2/L3 load behind the other lanes' arithmetic.
const LANES: usize = 8;

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
        let b = Bounds::new(self.width(), self.height(), self.resolution());
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
                match Lane::start(gx, gy, dx, dy, &b, max_range) {
                    Ok(l) => *lane = l,
                    Err(answer) => {
                        out[i] = answer;
                        continue;
                    }
                }
                lane.id = i;
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
                } else if !l.advance(k, &b, max_range) {
                    out[l.id] = f32::INFINITY;
                    true
                } else {
                    false
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
