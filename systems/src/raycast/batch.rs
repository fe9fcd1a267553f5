//! Many independent rays at once ("ray streams"): a single ray on the distance field is a chain of
//! dependent memory loads — each leap needs the byte at the cell the previous leap landed in — so
//! one ray leaves the core idle most of the time. Here several rays advance in turn, one leap or
//! cell step each per round, so the loads of different rays overlap; a lane whose ray ends takes
//! the next one. Every step is the one [`Lane::advance`] takes (crossing times from the cell
//! indices, never accumulated), so results agree with the cell walk of [`super::cast_dda`].
//!
//! Two kernels with the same answers: with AVX2 (detected at run time) 32 rays in four
//! vectors (`batch_avx2`), otherwise `LANES` rays one after another.
//!
//! This is what a particle filter needs (every particle's beams at once: the `calc_range_many`
//! of range_libc, Walsh & Karaman 2018) and what scans fall back to when the sweep does not apply.

use super::feed::Feed;
use super::leap::{Bounds, Lane};
use super::raymap::RayMap;

/// Rays in flight in the scalar kernel. Eight is enough to hide an L2/L3 load behind the other
/// lanes' arithmetic.
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
        let feed = Feed::new(ray, n, &b, self.origin(), max_range);
        #[cfg(target_arch = "x86_64")]
        if self.stream_avx2() {
            // SAFETY: AVX2 was detected; the padded field fits `i32` indices (`stream_avx2`)
            unsafe {
                super::batch_avx2::cast_stream_avx2(
                    self.dist_padded(),
                    self.tiles_per_row(),
                    &b,
                    max_range,
                    feed,
                    out,
                )
            };
            return;
        }
        self.cast_stream_scalar(&b, max_range, feed, out);
    }

    /// The scalar stream kernel.
    pub(super) fn cast_stream_scalar(
        &self,
        b: &Bounds,
        max_range: f32,
        mut feed: Feed<impl Fn(usize) -> ([f32; 2], f32, f32)>,
        out: &mut [f32],
    ) {
        let dist = self.dist();
        let mut lanes = [Lane::default(); LANES];
        let mut active = 0;
        while active < LANES {
            match feed.next(out) {
                Some(l) => lanes[active] = l,
                None => break,
            }
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
                } else if !l.advance(k, b, max_range) {
                    out[l.id] = f32::INFINITY;
                    true
                } else {
                    false
                };
                if done {
                    match feed.next(out) {
                        Some(l) => lanes[j] = l,
                        None => {
                            active -= 1;
                            lanes[j] = lanes[active];
                            continue;
                        }
                    }
                }
                j += 1;
            }
        }
    }
}
