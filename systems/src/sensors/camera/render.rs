//! The camera's render kernel: every pixel below the horizon looks up the road surface under
//! its ground ray (pinhole model, [`super::GroundRays`]) and becomes that surface's colour;
//! pixels above the horizon are sky. Colours imitate a park in daylight as the thesis's USB
//! camera saw it (004_95e533f2514531b8.txt §5.2: grey asphalt and light gravel among green
//! grass; SEEDS.md "Camera road recognition").
//!
//! Texture, so the recognizer does not face flat colours:
//! - **mottle**: a value-noise pattern fixed to the ground (hashes of the raster cell at 0.4 m
//!   and 0.1 m), strong on grass, gravel and dirt, weak on asphalt and concrete; paving gets
//!   darker joints every 0.2 m;
//! - **per-pixel noise**: independent per channel, a triangular distribution of standard
//!   deviation `noise_std`, from a hash of (frame seed, pixel index) — one random draw per
//!   frame, yet deterministic;
//! - **brightness**: one factor per frame scales the whole image (clouds, auto-exposure).
//!
//! A plain function over slices: no allocation, no ECS.

use super::GroundRays;
use crate::core::Pose2;
use crate::world::roads::surface_raster::{CLASSES, GRASS, SurfaceRaster};
use rayon::prelude::*;

/// Colour of one surface class (RGB, 0–255).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassColour {
    pub base: [f32; 3],
    /// Amplitude of the ground-fixed mottle per channel (± this).
    pub mottle: [f32; 3],
    /// Brightness factor of the joints between paving stones (1: no joints).
    pub joints: f32,
}

const fn colour(base: [f32; 3], mottle: [f32; 3]) -> ClassColour {
    ClassColour {
        base,
        mottle,
        joints: 1.0,
    }
}

/// Colours of the surface classes (indexed by class) and the sky.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    pub classes: [ClassColour; CLASSES],
    /// Sky colour at the top of the image ...
    pub sky_top: [f32; 3],
    /// ... and at the horizon.
    pub sky_horizon: [f32; 3],
}

impl Default for Palette {
    fn default() -> Self {
        Palette {
            classes: [
                colour([72.0, 116.0, 42.0], [16.0, 24.0, 8.0]), // grass
                colour([92.0, 92.0, 96.0], [5.0, 5.0, 5.0]),    // asphalt
                colour([168.0, 156.0, 132.0], [14.0, 13.0, 12.0]), // gravel
                ClassColour {
                    joints: 0.82,
                    ..colour([150.0, 118.0, 102.0], [9.0, 8.0, 7.0])
                }, // paving
                colour([176.0, 176.0, 170.0], [6.0, 6.0, 6.0]), // concrete
                colour([124.0, 96.0, 66.0], [14.0, 11.0, 8.0]), // dirt
                colour([132.0, 126.0, 116.0], [10.0, 10.0, 10.0]), // unknown
                colour([92.0, 76.0, 46.0], [10.0, 9.0, 6.0]),   // verge
            ],
            sky_top: [150.0, 185.0, 230.0],
            sky_horizon: [205.0, 220.0, 235.0],
        }
    }
}

/// What varies from frame to frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// Global brightness factor (1: nominal).
    pub brightness: f32,
    /// Per-pixel noise standard deviation (0–255 units).
    pub noise_std: f32,
    /// Seed of the per-pixel noise.
    pub seed: u64,
}

#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A hash of an integer cell in [0, 1) (the 32-bit MurmurHash3 finaliser).
#[inline]
fn cell_hash(ix: i32, iy: i32) -> f32 {
    let mut h = (ix as u32).wrapping_mul(0x9e37_79b1) ^ (iy as u32).wrapping_mul(0x85eb_ca77);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^= h >> 16;
    (h >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[inline]
fn floor_i32(v: f32) -> i32 {
    let i = v as i32;
    if (i as f32) > v { i - 1 } else { i }
}

/// Standard deviation of the sum of two independent uniform bytes minus 255.
const TRIANGULAR_STD: f32 = 104.52;

/// Renders the view from robot pose `pose` (world frame) into `out`: RGB8, row-major, row 0 at
/// the top, `rays.width × rays.height × 3` bytes.
pub fn render_ground(
    rays: &GroundRays,
    pose: Pose2,
    raster: &SurfaceRaster,
    palette: &Palette,
    frame: &FrameParams,
    out: &mut [u8],
) {
    let (w, h) = (rays.width as usize, rays.height as usize);
    assert_eq!(out.len(), w * h * 3, "output buffer size");
    let noise_scale = frame.noise_std / TRIANGULAR_STD;
    let gain = frame.brightness;
    let put = |px: &mut [u8], c: [f32; 3], n: u64| {
        for (k, o) in px.iter_mut().enumerate() {
            let a = ((n >> (16 * k)) & 0xff) as f32;
            let b = ((n >> (16 * k + 8)) & 0xff) as f32;
            let v = c[k] * gain + (a + b - 255.0) * noise_scale;
            *o = v.clamp(0.0, 255.0) as u8;
        }
    };
    let pixel_noise = |i: usize| mix64(frame.seed ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));

    // sky
    let first = (rays.first_ground_row as usize).min(h);
    for v in 0..first {
        let t = if first > 1 {
            v as f32 / (first - 1) as f32
        } else {
            1.0
        };
        let c: [f32; 3] = std::array::from_fn(|k| {
            palette.sky_top[k] + t * (palette.sky_horizon[k] - palette.sky_top[k])
        });
        for u in 0..w {
            let i = v * w + u;
            put(&mut out[3 * i..3 * i + 3], c, pixel_noise(i));
        }
    }

    // ground: the ray offsets (robot frame, m) rotated and translated into raster cells
    let inv = 1.0 / raster.resolution;
    let (s, c) = pose.theta.sin_cos();
    let (r00, r01, r10, r11) = (
        (c * inv) as f32,
        (-s * inv) as f32,
        (s * inv) as f32,
        (c * inv) as f32,
    );
    let ox = ((pose.x - raster.origin[0]) * inv) as f32;
    let oy = ((pose.y - raster.origin[1]) * inv) as f32;
    let ground = &mut out[3 * first * w..];
    // rows in parallel on the caller's rayon pool: a pixel's noise depends only on its index,
    // so the image does not depend on the thread count
    let ground_pixel = |px: &mut [u8], ray: &[f32; 2], j: usize| {
        let fx = ox + r00 * ray[0] + r01 * ray[1];
        let fy = oy + r10 * ray[0] + r11 * ray[1];
        let (ix, iy) = (floor_i32(fx), floor_i32(fy));
        let class = if fx.is_finite() && fy.is_finite() {
            raster.class_at_cell(ix as i64, iy as i64)
        } else {
            GRASS
        };
        let cc = &palette.classes[class as usize];
        let m = 0.65 * cell_hash(ix >> 3, iy >> 3) + 0.35 * cell_hash(ix >> 1, iy >> 1) - 0.5;
        let j_factor = if cc.joints != 1.0 && ((ix & 3) == 0 || (iy & 3) == 0) {
            cc.joints
        } else {
            1.0
        };
        let col: [f32; 3] =
            std::array::from_fn(|k| (cc.base[k] + 2.0 * m * cc.mottle[k]) * j_factor);
        put(px, col, pixel_noise(first * w + j));
    };
    let render_row = |(row, (line, offsets)): (usize, (&mut [u8], &[[f32; 2]]))| {
        for (u, (px, ray)) in line.chunks_exact_mut(3).zip(offsets).enumerate() {
            ground_pixel(px, ray, row * w + u);
        }
    };
    ground
        .par_chunks_mut(3 * w)
        .zip(rays.offsets.par_chunks(w))
        .enumerate()
        .with_min_len(ROWS_PER_TASK)
        .for_each(render_row);
}

/// Image rows rendered per rayon task.
const ROWS_PER_TASK: usize = 8;
