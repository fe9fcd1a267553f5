//! The AVX2 twin of the ray-stream kernel (`batch`): eight rays per vector, one per lane, and
//! [`GROUPS`] vectors in flight. Each round a group gathers the eight distance bytes its rays
//! stand on and makes every lane's move of [`Lane::advance`] without branches: the leap and the
//! cell step are both computed and the lane's distance value picks one. A lane whose ray ends
//! (a hit, or the ray leaves the grid or passes `max_range`) writes its answer and takes the next
//! ray from the feed.
//!
//! Why: in the scalar stream the branch between leap and cell step depends on the loaded byte,
//! so it mispredicts often, and each misprediction throws away the loads of the other rays in
//! flight. Here nothing waits on a loaded byte but the arithmetic that uses it, so the gathers of
//! different groups overlap.
//!
//! Every lane performs the scalar code's f32 and integer operations in the same order (no fused
//! multiply-adds), so each ray's answer is the one [`super::RayMap::cast_many`]'s scalar kernel
//! gives (tests: `stream_avx2_matches_scalar`).
//!
//! Only built for x86-64; `batch` detects AVX2 at run time and needs the distance field padded
//! by three bytes (a 4-byte gather at its last cell) and indexable by `i32`.

use super::feed::Feed;
use super::leap::{Bounds, Lane};
use std::arch::x86_64::*;

/// Rays per vector.
const W: usize = 8;
/// Vectors in flight: while one waits for its gather, the others compute.
const GROUPS: usize = 4;

/// One vector of rays, lane by lane (see [`Lane`]).
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
struct Group {
    gx: [f32; W],
    gy: [f32; W],
    dx: [f32; W],
    dy: [f32; W],
    idx: [f32; W],
    idy: [f32; W],
    leap: [f32; W],
    t: [f32; W],
    sx: [i32; W],
    sy: [i32; W],
    cx: [i32; W],
    cy: [i32; W],
    /// Lanes holding a ray (all ones) or idle (zero: the feed ran dry).
    live: [i32; W],
    id: [usize; W],
    /// Live lanes.
    n: usize,
}

impl Group {
    fn put(&mut self, j: usize, l: &Lane) {
        self.gx[j] = l.gx;
        self.gy[j] = l.gy;
        self.dx[j] = l.dx;
        self.dy[j] = l.dy;
        self.idx[j] = l.idx;
        self.idy[j] = l.idy;
        self.leap[j] = l.leap;
        self.t[j] = l.t;
        self.sx[j] = l.sx;
        self.sy[j] = l.sy;
        self.cx[j] = l.cx;
        self.cy[j] = l.cy;
        self.live[j] = -1;
        self.id[j] = l.id;
    }

    /// Lane `j` takes the feed's next ray, or goes idle on cell (0, 0).
    fn refill(
        &mut self,
        j: usize,
        feed: &mut Feed<impl Fn(usize) -> ([f32; 2], f32, f32)>,
        out: &mut [f32],
    ) -> bool {
        match feed.next(out) {
            Some(l) => {
                self.n += (self.live[j] == 0) as usize;
                self.put(j, &l);
                true
            }
            None => {
                self.n -= (self.live[j] != 0) as usize;
                self.live[j] = 0;
                self.cx[j] = 0;
                self.cy[j] = 0;
                false
            }
        }
    }
}

/// Casts the feed's rays on the tiled distance field `dist` (`tw` tiles per row), writing
/// `out[i]` for ray i.
///
/// # Safety
/// The CPU must support AVX2; `dist` must hold every cell of the `b.w` × `b.h` grid in tiled
/// order plus three bytes, and its length must fit in an `i32`.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn cast_stream_avx2(
    dist: &[u8],
    tw: usize,
    b: &Bounds,
    max_range: f32,
    mut feed: Feed<impl Fn(usize) -> ([f32; 2], f32, f32)>,
    out: &mut [f32],
) {
    let mut groups = [Group::default(); GROUPS];
    for g in groups.iter_mut() {
        for j in 0..W {
            g.refill(j, &mut feed, out);
        }
    }
    let mut live: usize = groups.iter().map(|g| g.n).sum();
    let zero = _mm256_setzero_si256();
    let one = _mm256_set1_epi32(1);
    let seven = _mm256_set1_epi32(7);
    let byte = _mm256_set1_epi32(0xff);
    let tws = _mm256_set1_epi32(tw as i32);
    let w1 = _mm256_set1_epi32(b.w - 1);
    let h1 = _mm256_set1_epi32(b.h - 1);
    let res = _mm256_set1_ps(b.res);
    let inv_res = _mm256_set1_ps(b.inv_res);
    let wf = _mm256_set1_ps(b.wf);
    let hf = _mm256_set1_ps(b.hf);
    let maxr = _mm256_set1_ps(max_range);
    let fzero = _mm256_setzero_ps();
    let inf = _mm256_set1_ps(f32::INFINITY);
    while live > 0 {
        // once the feed runs dry, groups empty one by one and are skipped
        for g in groups.iter_mut().filter(|g| g.n > 0) {
            // SAFETY: `Group` is 32-byte aligned and its arrays are eight lanes wide
            let ld = |a: &[i32; W]| unsafe { _mm256_load_si256(a.as_ptr().cast()) };
            let ldf = |a: &[f32; W]| unsafe { _mm256_load_ps(a.as_ptr()) };
            let (cx, cy, t) = (ld(&g.cx), ld(&g.cy), ldf(&g.t));
            // the tiled index of `RayMap::idx`
            let tile = _mm256_add_epi32(
                _mm256_mullo_epi32(_mm256_srai_epi32::<3>(cy), tws),
                _mm256_srai_epi32::<3>(cx),
            );
            let at = _mm256_add_epi32(
                _mm256_slli_epi32::<6>(tile),
                _mm256_add_epi32(
                    _mm256_slli_epi32::<3>(_mm256_and_si256(cy, seven)),
                    _mm256_and_si256(cx, seven),
                ),
            );
            // SAFETY: every lane's cell is inside the grid (live lanes by the walk's bounds
            // checks, idle ones on cell 0), and the field is padded for the 4-byte reads
            let k = _mm256_and_si256(
                unsafe { _mm256_i32gather_epi32::<1>(dist.as_ptr().cast(), at) },
                byte,
            );
            let hit = _mm256_cmpeq_epi32(k, zero);
            let is_leap = _mm256_cmpgt_epi32(k, one);
            let (gx, gy, dx, dy) = (ldf(&g.gx), ldf(&g.gy), ldf(&g.dx), ldf(&g.dy));

            // the leap: k − 1 cells of L∞ travel
            let tl = _mm256_add_ps(
                t,
                _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_sub_epi32(k, one)), ldf(&g.leap)),
            );
            let px = _mm256_add_ps(gx, _mm256_mul_ps(dx, tl));
            let py = _mm256_add_ps(gy, _mm256_mul_ps(dy, tl));
            let leap_out = _mm256_or_ps(
                _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_GT_OQ>(tl, maxr),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(px, fzero),
                ),
                _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(py, fzero),
                    _mm256_or_ps(
                        _mm256_cmp_ps::<_CMP_GE_OQ>(px, wf),
                        _mm256_cmp_ps::<_CMP_GE_OQ>(py, hf),
                    ),
                ),
            );
            let lcx = _mm256_min_epi32(_mm256_cvttps_epi32(_mm256_mul_ps(px, inv_res)), w1);
            let lcy = _mm256_min_epi32(_mm256_cvttps_epi32(_mm256_mul_ps(py, inv_res)), h1);

            // the cell step: the nearer of the next boundaries on each axis
            let (sx, sy) = (ld(&g.sx), ld(&g.sy));
            // boundary index: the cell's + 1 when the step is positive
            let bcx = _mm256_sub_epi32(cx, _mm256_cmpgt_epi32(sx, zero));
            let bcy = _mm256_sub_epi32(cy, _mm256_cmpgt_epi32(sy, zero));
            let tx = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(bcx), res), gx),
                ldf(&g.idx),
            );
            let ty = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(bcy), res), gy),
                ldf(&g.idy),
            );
            // no boundary on an axis the ray does not move along
            let tx = _mm256_blendv_ps(tx, inf, _mm256_castsi256_ps(_mm256_cmpeq_epi32(sx, zero)));
            let ty = _mm256_blendv_ps(ty, inf, _mm256_castsi256_ps(_mm256_cmpeq_epi32(sy, zero)));
            let x_first = _mm256_cmp_ps::<_CMP_LT_OQ>(tx, ty);
            let ts = _mm256_max_ps(_mm256_blendv_ps(ty, tx, x_first), t);
            let xf = _mm256_castps_si256(x_first);
            let scx = _mm256_add_epi32(cx, _mm256_and_si256(sx, xf));
            let scy = _mm256_add_epi32(cy, _mm256_andnot_si256(xf, sy));
            let step_out = _mm256_or_si256(
                _mm256_or_si256(
                    _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GT_OQ>(ts, maxr)),
                    _mm256_or_si256(_mm256_cmpgt_epi32(zero, scx), _mm256_cmpgt_epi32(zero, scy)),
                ),
                _mm256_or_si256(_mm256_cmpgt_epi32(scx, w1), _mm256_cmpgt_epi32(scy, h1)),
            );

            let leap_f = _mm256_castsi256_ps(is_leap);
            let nt = _mm256_blendv_ps(ts, tl, leap_f);
            // idle lanes stay on cell 0
            let lv = ld(&g.live);
            let ncx = _mm256_and_si256(_mm256_blendv_epi8(scx, lcx, is_leap), lv);
            let ncy = _mm256_and_si256(_mm256_blendv_epi8(scy, lcy, is_leap), lv);
            let gone = _mm256_andnot_si256(
                hit,
                _mm256_blendv_epi8(step_out, _mm256_castps_si256(leap_out), is_leap),
            );
            let done = _mm256_and_si256(_mm256_or_si256(hit, gone), lv);
            // SAFETY: as for the loads
            unsafe {
                _mm256_store_si256(g.cx.as_mut_ptr().cast(), ncx);
                _mm256_store_si256(g.cy.as_mut_ptr().cast(), ncy);
                _mm256_store_ps(g.t.as_mut_ptr(), nt);
            }
            let mut mask = _mm256_movemask_ps(_mm256_castsi256_ps(done)) as u32;
            if mask != 0 {
                let mut answer = [0f32; W];
                // SAFETY: an eight-lane array
                unsafe {
                    _mm256_storeu_ps(
                        answer.as_mut_ptr(),
                        _mm256_blendv_ps(inf, t, _mm256_castsi256_ps(hit)),
                    )
                };
                while mask != 0 {
                    let j = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    out[g.id[j]] = answer[j];
                    if !g.refill(j, &mut feed, out) {
                        live -= 1;
                    }
                }
            }
        }
    }
}
