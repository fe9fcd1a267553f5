//! The likelihood-field scoring kernel (Probabilistic Robotics §6.4, Table 6.3, in AMCL's form
//! p = 1 + Σ pz³ with pz³ read from a per-distance table): for each particle, every beam
//! endpoint is moved into the map by the particle's pose, its distance-field cell is looked up
//! and the table value of that cell's quantised distance is summed.
//!
//! Two implementations compute bit-identical sums, so results never depend on the CPU:
//!
//! - [`score_scalar`]: one particle at a time (any target);
//! - an AVX2 path on x86-64, chosen at run time when the CPU has it: eight particles per vector,
//!   each lane doing exactly the scalar operations in the same order (separate multiplies and
//!   adds, no fused multiply-add, beams summed in order) with the two table look-ups as gathers.
//!
//! The cell of an endpoint is found by truncating its grid coordinates shifted by one cell to
//! `i32` and subtracting one (the floor for every coordinate that can land in the map, negative
//! below it) and one unsigned range test per axis: `f32::floor` is a libm call on baseline
//! x86-64 and float-to-`usize` casts are a branchy sequence each.

use crate::world::DistanceField;

/// A particle's pose in the distance field's grid: cell coordinates plus one, and the sine and
/// cosine of its heading divided by the resolution (so endpoints in metres land in cells).
#[derive(Clone, Copy, Debug)]
pub struct GridPose {
    pub gx: f32,
    pub gy: f32,
    pub sin: f32,
    pub cos: f32,
}

impl GridPose {
    pub fn new(field: &DistanceField, x: f64, y: f64, theta: f64) -> Self {
        let (s, c) = theta.sin_cos();
        Self::with_sin_cos(field, x, y, s, c)
    }

    /// [`GridPose::new`] from the heading's sine `s` and cosine `c`, already computed.
    pub fn with_sin_cos(field: &DistanceField, x: f64, y: f64, s: f64, c: f64) -> Self {
        let inv = 1.0 / field.resolution;
        GridPose {
            gx: ((x - field.origin[0]) * inv) as f32 + 1.0,
            gy: ((y - field.origin[1]) * inv) as f32 + 1.0,
            sin: (s * inv) as f32,
            cos: (c * inv) as f32,
        }
    }
}

/// The table value of the cell under the endpoint at shifted grid coordinates (`x`, `y`), or
/// `far` outside the map.
#[inline(always)]
fn lookup(field: &DistanceField, table: &[f32; 256], far: f32, x: f32, y: f32) -> f32 {
    let cx = (x as i32).wrapping_sub(1);
    let cy = (y as i32).wrapping_sub(1);
    if (cx as u32) < field.width as u32 && (cy as u32) < field.height as u32 {
        table[field.cells[cy as usize * field.width + cx as usize] as usize]
    } else {
        far
    }
}

/// 1 + Σ over `points` (beam endpoints in the robot frame, metres) of the table value under
/// each endpoint moved by `pose`; `far` is the value outside the map.
pub fn score_scalar(
    field: &DistanceField,
    table: &[f32; 256],
    far: f32,
    points: &[[f32; 2]],
    pose: &GridPose,
) -> f32 {
    let GridPose { gx, gy, sin, cos } = *pose;
    let mut p = 1.0f32;
    for &[bx, by] in points {
        p += lookup(
            field,
            table,
            far,
            gx + cos * bx - sin * by,
            gy + sin * bx + cos * by,
        );
    }
    p
}

/// Scores every pose of `poses` into `out` (same length), with the fastest implementation the
/// CPU supports; the results are identical whichever runs.
pub fn score_all(
    field: &DistanceField,
    table: &[f32; 256],
    far: f32,
    points: &[[f32; 2]],
    poses: &[GridPose],
    out: &mut [f32],
) {
    assert_eq!(poses.len(), out.len());
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && avx2::fits(field) {
        // SAFETY: the CPU supports AVX2 (checked just above).
        unsafe { avx2::score_all(field, table, far, points, poses, out) };
        return;
    }
    score_all_scalar(field, table, far, points, poses, out);
}

/// [`score_all`] one particle at a time.
pub fn score_all_scalar(
    field: &DistanceField,
    table: &[f32; 256],
    far: f32,
    points: &[[f32; 2]],
    poses: &[GridPose],
    out: &mut [f32],
) {
    for (o, pose) in out.iter_mut().zip(poses) {
        *o = score_scalar(field, table, far, points, pose);
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{GridPose, lookup, score_scalar};
    use crate::world::DistanceField;
    use std::arch::x86_64::*;

    /// The vector path indexes cells with `i32` (products y·width + x up to the cell count).
    pub fn fits(field: &DistanceField) -> bool {
        field.cells.len() < i32::MAX as usize && field.cells.len() == field.width * field.height
    }

    /// Eight particles per step; the remainder and any group that touches the last three cells
    /// of the map (a 4-byte gather there would read past the array) go through the scalar code.
    ///
    /// # Safety
    /// The CPU must support AVX2, and `fits(field)` must hold.
    #[target_feature(enable = "avx2")]
    pub unsafe fn score_all(
        field: &DistanceField,
        table: &[f32; 256],
        far: f32,
        points: &[[f32; 2]],
        poses: &[GridPose],
        out: &mut [f32],
    ) {
        let n = poses.len();
        let groups = n / 8;
        let cells = field.cells.as_ptr();
        // the last index a 4-byte load may start at
        let last_load = _mm256_set1_epi32(field.cells.len() as i32 - 4);
        let wu = _mm256_set1_epi32(field.width as i32);
        let hu = _mm256_set1_epi32(field.height as i32);
        let one_i = _mm256_set1_epi32(1);
        let byte = _mm256_set1_epi32(0xff);
        let far_v = _mm256_set1_ps(far);
        for g in 0..groups {
            let lanes = &poses[g * 8..g * 8 + 8];
            let gx = _mm256_set_ps(
                lanes[7].gx,
                lanes[6].gx,
                lanes[5].gx,
                lanes[4].gx,
                lanes[3].gx,
                lanes[2].gx,
                lanes[1].gx,
                lanes[0].gx,
            );
            let gy = _mm256_set_ps(
                lanes[7].gy,
                lanes[6].gy,
                lanes[5].gy,
                lanes[4].gy,
                lanes[3].gy,
                lanes[2].gy,
                lanes[1].gy,
                lanes[0].gy,
            );
            let sn = _mm256_set_ps(
                lanes[7].sin,
                lanes[6].sin,
                lanes[5].sin,
                lanes[4].sin,
                lanes[3].sin,
                lanes[2].sin,
                lanes[1].sin,
                lanes[0].sin,
            );
            let cs = _mm256_set_ps(
                lanes[7].cos,
                lanes[6].cos,
                lanes[5].cos,
                lanes[4].cos,
                lanes[3].cos,
                lanes[2].cos,
                lanes[1].cos,
                lanes[0].cos,
            );
            let mut p = _mm256_set1_ps(1.0);
            for &[bx, by] in points {
                let (bx, by) = (_mm256_set1_ps(bx), _mm256_set1_ps(by));
                // the scalar expression order: (g + c·bx) − s·by and (g + s·bx) + c·by
                let x = _mm256_sub_ps(
                    _mm256_add_ps(gx, _mm256_mul_ps(cs, bx)),
                    _mm256_mul_ps(sn, by),
                );
                let y = _mm256_add_ps(
                    _mm256_add_ps(gy, _mm256_mul_ps(sn, bx)),
                    _mm256_mul_ps(cs, by),
                );
                // truncation; NaN and out-of-range give i32::MIN, which wraps to i32::MAX
                // (outside) like the scalar saturating cast does
                let cx = _mm256_sub_epi32(_mm256_cvttps_epi32(x), one_i);
                let cy = _mm256_sub_epi32(_mm256_cvttps_epi32(y), one_i);
                // unsigned c < n  ⇔  max_u(c, n) ≠ c  — as signed: 0 ≤ c < n (n > 0)
                let inside = _mm256_and_si256(
                    _mm256_and_si256(
                        _mm256_cmpgt_epi32(cx, _mm256_set1_epi32(-1)),
                        _mm256_cmpgt_epi32(wu, cx),
                    ),
                    _mm256_and_si256(
                        _mm256_cmpgt_epi32(cy, _mm256_set1_epi32(-1)),
                        _mm256_cmpgt_epi32(hu, cy),
                    ),
                );
                let idx = _mm256_add_epi32(_mm256_mullo_epi32(cy, wu), cx);
                let tail = _mm256_and_si256(inside, _mm256_cmpgt_epi32(idx, last_load));
                if _mm256_movemask_epi8(tail) != 0 {
                    // a lane within 3 bytes of the end of the map: this beam, scalar
                    let mut xs = [0f32; 8];
                    let mut ys = [0f32; 8];
                    // SAFETY: 8 f32 stores into arrays of 8
                    unsafe {
                        _mm256_storeu_ps(xs.as_mut_ptr(), x);
                        _mm256_storeu_ps(ys.as_mut_ptr(), y);
                    }
                    let v: [f32; 8] =
                        std::array::from_fn(|k| lookup(field, table, far, xs[k], ys[k]));
                    // SAFETY: an 8-f32 load from an array of 8
                    p = _mm256_add_ps(p, unsafe { _mm256_loadu_ps(v.as_ptr()) });
                    continue;
                }
                // SAFETY: lanes with `inside` set load 4 bytes at idx ≤ len − 4 of `cells`;
                // the others are masked off and read nothing.
                let words = unsafe {
                    _mm256_mask_i32gather_epi32::<1>(
                        _mm256_setzero_si256(),
                        cells.cast::<i32>(),
                        idx,
                        inside,
                    )
                };
                let q = _mm256_and_si256(words, byte);
                // SAFETY: q ∈ [0, 255] indexes the 256-entry table; outside lanes are masked
                // and keep `far`.
                let v = unsafe {
                    _mm256_mask_i32gather_ps::<4>(
                        far_v,
                        table.as_ptr(),
                        q,
                        _mm256_castsi256_ps(inside),
                    )
                };
                p = _mm256_add_ps(p, v);
            }
            // SAFETY: 8 f32 stores into out[g·8 .. g·8 + 8], in bounds since g < n / 8
            unsafe { _mm256_storeu_ps(out.as_mut_ptr().add(g * 8), p) };
        }
        for (o, pose) in out[groups * 8..].iter_mut().zip(&poses[groups * 8..]) {
            *o = score_scalar(field, table, far, points, pose);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use rand::RngExt;

    fn field(width: usize, height: usize) -> DistanceField {
        let mut rng = stream_rng(1, "field", "cells");
        DistanceField {
            width,
            height,
            resolution: 0.05,
            origin: [-1.0, 2.0],
            max_dist: 2.0,
            step: 2.0 / 255.0,
            cells: (0..width * height).map(|_| rng.random()).collect(),
        }
    }

    /// Every implementation gives the same bits, for poses inside, across and outside the map
    /// (its last cells included), with particle counts that leave a remainder.
    #[test]
    fn vector_and_scalar_kernels_agree_bit_for_bit() {
        let f = field(97, 61);
        let mut rng = stream_rng(2, "poses", "k");
        let table: [f32; 256] = std::array::from_fn(|k| 0.001 * k as f32 + 0.25);
        let far = 0.125;
        let points: Vec<[f32; 2]> = (0..60)
            .map(|_| [rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0)])
            .collect();
        // the pose itself: poses near the far corner read the map's last cells
        let mut points = points;
        points.push([0.0, 0.0]);
        let (w, h) = (97.0 * 0.05, 61.0 * 0.05);
        let mut poses: Vec<GridPose> = (0..1003)
            .map(|_| {
                GridPose::new(
                    &f,
                    -1.0 + rng.random_range(-2.0..w + 2.0),
                    2.0 + rng.random_range(-2.0..h + 2.0),
                    rng.random_range(-4.0..4.0),
                )
            })
            .collect();
        // poses whose endpoints hit the last cells, and non-finite ones
        for k in 0..16 {
            poses.push(GridPose::new(
                &f,
                -1.0 + w - 0.01 * k as f64,
                2.0 + h - 0.01,
                0.0,
            ));
        }
        poses.push(GridPose::new(&f, f64::NAN, 3.0, 0.0));
        poses.push(GridPose::new(&f, 1e30, -1e30, 1.0));
        let mut fast = vec![0.0; poses.len()];
        let mut slow = vec![0.0; poses.len()];
        score_all(&f, &table, far, &points, &poses, &mut fast);
        score_all_scalar(&f, &table, far, &points, &poses, &mut slow);
        for (k, (a, b)) in fast.iter().zip(&slow).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "pose {k}: {a} vs {b}");
        }
        // the sums really mix inside and outside look-ups
        assert!(slow.iter().any(|&p| p > 1.0 + 61.0 * far + 1.0));
        let outside = score_scalar(&f, &table, far, &points, &poses[1020]);
        assert_eq!(outside, 1.0 + 61.0 * far);
    }

    /// The corner endpoints land in the right cells: a single point at the pose itself reads
    /// the cell under it, the floor of its grid coordinates, including negative fractions.
    #[test]
    fn endpoints_read_the_cell_under_them() {
        let f = field(10, 10);
        let table: [f32; 256] = std::array::from_fn(|k| k as f32);
        let at = |x: f64, y: f64| {
            score_scalar(
                &f,
                &table,
                -1.0,
                &[[0.0, 0.0]],
                &GridPose::new(&f, x, y, 0.0),
            ) - 1.0
        };
        let cell = |c: usize, r: usize| f.cells[r * 10 + c] as f32;
        assert_eq!(at(-1.0 + 0.025, 2.0 + 0.025), cell(0, 0));
        assert_eq!(at(-1.0 + 0.49, 2.0 + 0.26), cell(9, 5));
        assert_eq!(at(-1.0 - 0.001, 2.0 + 0.2), -1.0, "just left of the map");
        assert_eq!(at(-1.0 + 0.2, 2.0 - 0.001), -1.0, "just below the map");
        assert_eq!(at(-1.0 + 0.5, 2.0 + 0.2), -1.0, "right edge");
    }
}
