//! The per-pixel colour arithmetic of [`super::render`]: a pixel's three channels in the lanes
//! of one SSE2 register (part of every x86-64 CPU) or, on other targets, in a plain array.
//! Every lane performs the scalar formula's f32 operations in the same order, so the bytes do
//! not depend on the target:
//! - surface colour: `(base + 2 m · mottle) · joint` ([`mottled`]);
//! - shading: `clamp(c · brightness + (a + b − 255) · noise_scale, 0, 255)` truncated to a
//!   byte, where `a` and `b` are bytes 2k and 2k + 1 of the pixel's noise word for channel k
//!   ([`shade`]).

// SAFETY (every `unsafe` below): the module is compiled only where SSE2 is enabled, and the
// intrinsics it calls need nothing else (no memory is read or written through pointers).
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod lanes {
    use std::arch::x86_64::*;

    /// The three channels (and an unused fourth lane).
    #[derive(Clone, Copy, Debug)]
    pub struct Rgb(__m128);

    #[inline(always)]
    pub fn rgb(c: [f32; 3]) -> Rgb {
        Rgb(unsafe { _mm_setr_ps(c[0], c[1], c[2], 0.0) })
    }

    #[inline(always)]
    pub fn mottled(base: Rgb, mottle: Rgb, m: f32, joint: f32) -> Rgb {
        unsafe {
            let t = _mm_mul_ps(_mm_set1_ps(2.0 * m), mottle.0);
            Rgb(_mm_mul_ps(_mm_add_ps(base.0, t), _mm_set1_ps(joint)))
        }
    }

    #[inline(always)]
    pub fn shade(c: Rgb, n: u64, brightness: f32, noise_scale: f32) -> [u8; 3] {
        let bytes = unsafe {
            let zero = _mm_setzero_si128();
            // bytes 2k and 2k + 1 of the noise word, summed per channel k
            let words = _mm_unpacklo_epi8(_mm_cvtsi64_si128(n as i64), zero);
            let sums = _mm_madd_epi16(words, _mm_set1_epi16(1));
            let noise = _mm_mul_ps(
                _mm_sub_ps(_mm_cvtepi32_ps(sums), _mm_set1_ps(255.0)),
                _mm_set1_ps(noise_scale),
            );
            let v = _mm_add_ps(_mm_mul_ps(c.0, _mm_set1_ps(brightness)), noise);
            let v = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(255.0));
            let i = _mm_cvttps_epi32(v);
            let bytes = _mm_packus_epi16(_mm_packs_epi32(i, zero), zero);
            _mm_cvtsi128_si32(bytes)
        };
        let [r, g, b, _] = bytes.to_le_bytes();
        [r, g, b]
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
mod lanes {
    /// The three channels.
    #[derive(Clone, Copy, Debug)]
    pub struct Rgb([f32; 3]);

    #[inline(always)]
    pub fn rgb(c: [f32; 3]) -> Rgb {
        Rgb(c)
    }

    #[inline(always)]
    pub fn mottled(base: Rgb, mottle: Rgb, m: f32, joint: f32) -> Rgb {
        Rgb(std::array::from_fn(|k| {
            (base.0[k] + 2.0 * m * mottle.0[k]) * joint
        }))
    }

    #[inline(always)]
    pub fn shade(c: Rgb, n: u64, brightness: f32, noise_scale: f32) -> [u8; 3] {
        std::array::from_fn(|k| {
            let a = ((n >> (16 * k)) & 0xff) as f32;
            let b = ((n >> (16 * k + 8)) & 0xff) as f32;
            let v = c.0[k] * brightness + (a + b - 255.0) * noise_scale;
            v.clamp(0.0, 255.0) as u8
        })
    }
}

pub use lanes::{Rgb, mottled, rgb, shade};

#[cfg(test)]
mod tests {
    use super::*;

    /// The formulas of the module doc, one channel at a time.
    fn reference(c: [f32; 3], m: f32, joint: f32, n: u64, brightness: f32, scale: f32) -> [u8; 3] {
        std::array::from_fn(|k| {
            let col = (c[k] + 2.0 * m * (c[k] * 0.1)) * joint;
            let a = ((n >> (16 * k)) & 0xff) as f32;
            let b = ((n >> (16 * k + 8)) & 0xff) as f32;
            let v = col * brightness + (a + b - 255.0) * scale;
            v.clamp(0.0, 255.0) as u8
        })
    }

    #[test]
    fn lanes_give_the_bytes_of_the_scalar_formula() {
        let mut n = 0x9e37_79b9_7f4a_7c15u64;
        let mut checked = 0;
        for base in [
            [0.0, 0.0, 0.0],
            [72.0, 116.0, 42.0],
            [205.0, 220.0, 235.0],
            [255.0; 3],
        ] {
            for m in [-0.5, -0.13, 0.0, 0.27, 0.4999] {
                for joint in [1.0, 0.82] {
                    for (brightness, scale) in [(1.0, 0.0), (0.8, 0.05), (1.3, 0.2), (2.0, 1.0)] {
                        for _ in 0..50 {
                            n = n
                                .wrapping_mul(6364136223846793005)
                                .wrapping_add(1442695040888963407);
                            let mottle: [f32; 3] = std::array::from_fn(|k| base[k] * 0.1);
                            let got = shade(
                                mottled(rgb(base), rgb(mottle), m, joint),
                                n,
                                brightness,
                                scale,
                            );
                            assert_eq!(got, reference(base, m, joint, n, brightness, scale));
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(checked, 4 * 5 * 2 * 4 * 50);
    }
}
