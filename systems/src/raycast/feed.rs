//! The rays of a stream, fed to the lanes of both stream kernels: the scalar one (`batch`) and
//! its AVX2 twin (`batch_avx2`). A leaf of its own so that neither kernel imports the other
//! for it.

use super::leap::{Bounds, Lane};

/// The rays of a stream in order, placed where they enter the grid; rays with nothing to walk
/// (starting outside the grid and missing it, or undefined) are answered on the way.
pub(super) struct Feed<'a, F> {
    ray: F,
    n: usize,
    next: usize,
    b: &'a Bounds,
    origin: [f32; 2],
    max_range: f32,
}

impl<'a, F: Fn(usize) -> ([f32; 2], f32, f32)> Feed<'a, F> {
    /// Rays `0..n`: ray i starts at `ray(i).0` (world frame) with unit direction (`.1`, `.2`),
    /// on a grid of bounds `b` whose lower-left corner is at `origin`.
    #[inline]
    pub fn new(ray: F, n: usize, b: &'a Bounds, origin: [f32; 2], max_range: f32) -> Self {
        Feed {
            ray,
            n,
            next: 0,
            b,
            origin,
            max_range,
        }
    }

    /// The next ray to walk, its `id` set to its index, or None when the stream is done.
    #[inline]
    pub fn next(&mut self, out: &mut [f32]) -> Option<Lane> {
        while self.next < self.n {
            let i = self.next;
            self.next += 1;
            let (p, dx, dy) = (self.ray)(i);
            let (gx, gy) = (p[0] - self.origin[0], p[1] - self.origin[1]);
            match Lane::start(gx, gy, dx, dy, self.b, self.max_range) {
                Ok(mut l) => {
                    l.id = i;
                    return Some(l);
                }
                Err(answer) => out[i] = answer,
            }
        }
        None
    }
}
