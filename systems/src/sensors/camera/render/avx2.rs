//! The AVX2 twin of [`FrameView`]'s whole-row rendering: eight pixels per step, one per lane.
//! Every lane performs the scalar code's f32 and integer operations in the same order
//! ([`super::cell_hash`], [`super::mottle`], [`super::joint`], [`super::shade`]), so the bytes
//! are those of [`FrameView::pixel`]; only the noise words are hashed one by one.
//!
//! A step falls back to the scalar code for its eight pixels when a lane's raster position is
//! not a finite value within `i32` (the scalar code's saturating conversion would differ from
//! the vector one) or its cell is one of the raster's last three (a 4-byte gather there would
//! read past the cells); so does a row's last `width % 8`.
//!
//! Only built for x86-64; [`FrameView::new`] detects AVX2 at run time.

use super::{CLASSES, FrameView, GRASS, shade};
use std::arch::x86_64::*;

/// Pixels per step.
const LANES: usize = 8;

// a class indexes its colours in a table of eight lanes
const _: () = assert!(CLASSES == LANES);

impl FrameView<'_> {
    /// A sky row of colour `colour` into `line`, its first pixel having index `i`.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn sky_row_avx2(&self, line: &mut [u8], colour: [f32; 3], i: usize) {
        let col = colour.map(|c| _mm256_set1_ps(c));
        let steps = line.len() / (3 * LANES);
        for s in 0..steps {
            let j = s * LANES;
            self.shade_store(col, i + j, &mut line[3 * j..]);
        }
        let c = shade::rgb(colour);
        for j in steps * LANES..line.len() / 3 {
            line[3 * j..3 * j + 3].copy_from_slice(&self.shade(c, i + j));
        }
    }

    /// A ground row into `line` from its rays (`rays.len()` pixels), its first pixel having
    /// index `i`.
    ///
    /// # Safety
    /// The CPU must support AVX2, and the raster must have fewer than `i32::MAX` cells.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn ground_row_avx2(&self, line: &mut [u8], rays: &[[f32; 2]], i: usize) {
        let steps = rays.len() / LANES;
        for s in 0..steps {
            let j = s * LANES;
            let group = &rays[j..j + LANES];
            if !self.ground_step(group, i + j, &mut line[3 * j..]) {
                for (p, ray) in group.iter().enumerate() {
                    let k = 3 * (j + p);
                    line[k..k + 3].copy_from_slice(&self.ground(ray, i + j + p));
                }
            }
        }
        for j in steps * LANES..rays.len() {
            line[3 * j..3 * j + 3].copy_from_slice(&self.ground(&rays[j], i + j));
        }
    }

    /// Eight ground pixels (rays `rays`, first index `i`) into `out`; false, with nothing
    /// written, when a lane needs the scalar code (module doc).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn ground_step(&self, rays: &[[f32; 2]], i: usize, out: &mut [u8]) -> bool {
        debug_assert_eq!(rays.len(), LANES);
        // SAFETY: `rays` holds 8 pairs of f32, 64 bytes, read as two unaligned 32-byte loads
        let (a, b) = unsafe {
            let p = rays.as_ptr().cast::<f32>();
            (_mm256_loadu_ps(p), _mm256_loadu_ps(p.add(8)))
        };
        // [x0 y0 x1 y1 | x2 y2 x3 y3] and [x4 y4 .. | ..] to x0..x7 and y0..y7
        let order = |v: __m256| {
            _mm256_castpd_ps(_mm256_permute4x64_pd::<0b11_01_10_00>(_mm256_castps_pd(v)))
        };
        let x = order(_mm256_shuffle_ps::<0b10_00_10_00>(a, b));
        let y = order(_mm256_shuffle_ps::<0b11_01_11_01>(a, b));
        let [r00, r01, r10, r11] = self.r.map(|v| _mm256_set1_ps(v));
        let fx = _mm256_add_ps(
            _mm256_add_ps(_mm256_set1_ps(self.o[0]), _mm256_mul_ps(r00, x)),
            _mm256_mul_ps(r01, y),
        );
        let fy = _mm256_add_ps(
            _mm256_add_ps(_mm256_set1_ps(self.o[1]), _mm256_mul_ps(r10, x)),
            _mm256_mul_ps(r11, y),
        );
        let in_i32 = |f: __m256| {
            let lo = _mm256_cmp_ps::<_CMP_GE_OQ>(f, _mm256_set1_ps(-2_147_483_648.0));
            let hi = _mm256_cmp_ps::<_CMP_LT_OQ>(f, _mm256_set1_ps(2_147_483_648.0));
            _mm256_movemask_ps(_mm256_and_ps(lo, hi)) == 0xff
        };
        if !in_i32(fx) || !in_i32(fy) {
            return false;
        }
        // floor: truncate, then one less where that rounded up
        let floor = |f: __m256| {
            let t = _mm256_cvttps_epi32(f);
            let up = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(t), f);
            _mm256_add_epi32(t, _mm256_castps_si256(up))
        };
        let (ix, iy) = (floor(fx), floor(fy));
        let Some(class) = self.classes(ix, iy) else {
            return false;
        };
        // mottle and paving joints
        let m = _mm256_sub_ps(
            _mm256_add_ps(
                _mm256_mul_ps(
                    _mm256_set1_ps(0.65),
                    cell_hash(_mm256_srai_epi32::<3>(ix), _mm256_srai_epi32::<3>(iy)),
                ),
                _mm256_mul_ps(
                    _mm256_set1_ps(0.35),
                    cell_hash(_mm256_srai_epi32::<1>(ix), _mm256_srai_epi32::<1>(iy)),
                ),
            ),
            _mm256_set1_ps(0.5),
        );
        let three = _mm256_set1_epi32(3);
        let zero = _mm256_setzero_si256();
        let on_joint = _mm256_or_si256(
            _mm256_cmpeq_epi32(_mm256_and_si256(ix, three), zero),
            _mm256_cmpeq_epi32(_mm256_and_si256(iy, three), zero),
        );
        let one = _mm256_set1_ps(1.0);
        let table = |t: &[f32; CLASSES]| {
            // SAFETY: a table holds 8 f32, 32 bytes
            _mm256_permutevar8x32_ps(unsafe { _mm256_loadu_ps(t.as_ptr()) }, class)
        };
        let joints = table(&self.tables.joint);
        let darker = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_NEQ_UQ>(joints, one),
            _mm256_castsi256_ps(on_joint),
        );
        let j_factor = _mm256_blendv_ps(one, joints, darker);
        // surface colour: (base + 2 m · mottle) · joint
        let twice_m = _mm256_mul_ps(_mm256_set1_ps(2.0), m);
        let col: [__m256; 3] = std::array::from_fn(|c| {
            let (base, amp) = (table(&self.tables.base[c]), table(&self.tables.mottle[c]));
            _mm256_mul_ps(_mm256_add_ps(base, _mm256_mul_ps(twice_m, amp)), j_factor)
        });
        self.shade_store(col, i, out);
        true
    }

    /// The surface classes of cells (ix, iy) ([`GRASS`] outside the raster); `None` when one
    /// lies in the raster's last three cells.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn classes(&self, ix: __m256i, iy: __m256i) -> Option<__m256i> {
        let r = self.raster;
        let minus_one = _mm256_set1_epi32(-1);
        let inside = _mm256_and_si256(
            _mm256_and_si256(
                _mm256_cmpgt_epi32(ix, minus_one),
                _mm256_cmpgt_epi32(iy, minus_one),
            ),
            _mm256_and_si256(
                _mm256_cmpgt_epi32(_mm256_set1_epi32(r.width as i32), ix),
                _mm256_cmpgt_epi32(_mm256_set1_epi32(r.height as i32), iy),
            ),
        );
        let index = _mm256_add_epi32(
            _mm256_mullo_epi32(iy, _mm256_set1_epi32(r.width as i32)),
            ix,
        );
        let last_load = _mm256_set1_epi32(r.cells.len() as i32 - 4);
        let past = _mm256_and_si256(inside, _mm256_cmpgt_epi32(index, last_load));
        if _mm256_movemask_epi8(past) != 0 {
            return None;
        }
        // SAFETY: only lanes inside the raster are read, each 4 bytes at a cell index at most
        // `cells.len() - 4`
        let words = unsafe {
            _mm256_mask_i32gather_epi32::<1>(
                _mm256_set1_epi32(GRASS as i32),
                r.cells.as_ptr().cast::<i32>(),
                index,
                inside,
            )
        };
        Some(_mm256_and_si256(words, _mm256_set1_epi32(0xff)))
    }

    /// Shades colours `col` (per channel, eight pixels from index `i`) with the frame's
    /// brightness and the pixels' noise, into the first 24 bytes of `out`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn shade_store(&self, col: [__m256; 3], i: usize, out: &mut [u8]) {
        // noise words of pixels 0, 2, 4, 6 and of 1, 3, 5, 7, so that joining the halves
        // below puts the pixels in order
        let words: [u64; LANES] = std::array::from_fn(|l| self.noise_word(i + 2 * (l % 4) + l / 4));
        // SAFETY: `words` holds 64 bytes, read as two unaligned 32-byte loads
        let (even, odd) = unsafe {
            let p = words.as_ptr().cast::<__m256i>();
            (_mm256_loadu_si256(p), _mm256_loadu_si256(p.add(1)))
        };
        // per pixel, the sums of bytes 2k and 2k + 1 in 16-bit lanes k = 0..3
        let ones = _mm256_set1_epi8(1);
        let (even, odd) = (
            _mm256_maddubs_epi16(even, ones),
            _mm256_maddubs_epi16(odd, ones),
        );
        let low16 = _mm256_set1_epi64x(0xffff);
        let sums = [
            join(even, odd, low16),
            join(
                _mm256_srli_epi64::<16>(even),
                _mm256_srli_epi64::<16>(odd),
                low16,
            ),
            join(
                _mm256_srli_epi64::<32>(even),
                _mm256_srli_epi64::<32>(odd),
                low16,
            ),
        ];
        let brightness = _mm256_set1_ps(self.frame.brightness);
        let scale = _mm256_set1_ps(self.noise_scale);
        let bytes: [__m256i; 3] = std::array::from_fn(|c| {
            let noise = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_cvtepi32_ps(sums[c]), _mm256_set1_ps(255.0)),
                scale,
            );
            let v = _mm256_add_ps(_mm256_mul_ps(col[c], brightness), noise);
            let v = _mm256_min_ps(_mm256_max_ps(v, _mm256_setzero_ps()), _mm256_set1_ps(255.0));
            _mm256_cvttps_epi32(v)
        });
        // per 128-bit half: R0-3 G0-3 B0-3 B0-3 as bytes, then interleaved R G B per pixel
        let rg = _mm256_packs_epi32(bytes[0], bytes[1]);
        let bb = _mm256_packs_epi32(bytes[2], bytes[2]);
        let planar = _mm256_packus_epi16(rg, bb);
        let interleave = _mm256_setr_epi8(
            0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1, //
            0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1,
        );
        let packed = _mm256_permutevar8x32_epi32(
            _mm256_shuffle_epi8(planar, interleave),
            _mm256_setr_epi32(0, 1, 2, 4, 5, 6, 3, 7),
        );
        if out.len() >= 32 {
            // SAFETY: `out` has room for the 32 bytes (the last 8 are overwritten later)
            unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast::<__m256i>(), packed) };
        } else {
            let mut tmp = [0u8; 32];
            // SAFETY: `tmp` holds 32 bytes
            unsafe { _mm256_storeu_si256(tmp.as_mut_ptr().cast::<__m256i>(), packed) };
            out[..3 * LANES].copy_from_slice(&tmp[..3 * LANES]);
        }
    }
}

/// The low 32 bits of each 64-bit lane of `even` (pixels 0, 2, 4, 6), masked by `mask`, and
/// those of `odd` (1, 3, 5, 7) as eight 32-bit lanes in pixel order.
#[inline]
#[target_feature(enable = "avx2")]
fn join(even: __m256i, odd: __m256i, mask: __m256i) -> __m256i {
    _mm256_or_si256(
        _mm256_and_si256(even, mask),
        _mm256_slli_epi64::<32>(_mm256_and_si256(odd, mask)),
    )
}

/// [`super::cell_hash`] of eight cells.
#[inline]
#[target_feature(enable = "avx2")]
fn cell_hash(ix: __m256i, iy: __m256i) -> __m256 {
    let mul = |a: __m256i, k: u32| _mm256_mullo_epi32(a, _mm256_set1_epi32(k as i32));
    let mut h = _mm256_xor_si256(mul(ix, 0x9e37_79b1), mul(iy, 0x85eb_ca77));
    h = _mm256_xor_si256(h, _mm256_srli_epi32::<16>(h));
    h = mul(h, 0x85eb_ca6b);
    h = _mm256_xor_si256(h, _mm256_srli_epi32::<13>(h));
    h = mul(h, 0xc2b2_ae35);
    h = _mm256_xor_si256(h, _mm256_srli_epi32::<16>(h));
    _mm256_mul_ps(
        _mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(h)),
        _mm256_set1_ps(1.0 / (1u32 << 24) as f32),
    )
}
