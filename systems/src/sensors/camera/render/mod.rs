//! The camera's render kernel: every pixel below the horizon looks up the road surface under
//! its ground ray (pinhole model, [`super::GroundRays`]) and becomes that surface's colour;
//! pixels above the horizon are sky. Colours imitate a park in daylight as the thesis's USB
//! camera saw it ([Park thesis §5.2]: grey asphalt and light gravel among green grass).
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
//! Whole images render row by row; with AVX2 (detected at run time) eight pixels at a time
//! (`render/avx2.rs`), with the same bytes. A plain function over slices: no allocation, no ECS.

#[cfg(target_arch = "x86_64")]
mod avx2;

use super::pinhole::GroundRays;
use super::shade::{self, Rgb};
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

/// The ground-fixed mottle of cell (ix, iy), in [-0.5, 0.5): hashes of the 0.4 m and 0.1 m
/// cells it lies in.
#[inline(always)]
fn mottle(ix: i32, iy: i32) -> f32 {
    0.65 * cell_hash(ix >> 3, iy >> 3) + 0.35 * cell_hash(ix >> 1, iy >> 1) - 0.5
}

/// Whether cell (ix, iy) lies on a joint between paving stones (every 0.2 m).
#[inline(always)]
fn joint(ix: i32, iy: i32) -> bool {
    (ix & 3) == 0 || (iy & 3) == 0
}

/// Standard deviation of the sum of two independent uniform bytes minus 255.
const TRIANGULAR_STD: f32 = 104.52;

/// One frame of the view from a robot pose: any pixel can be computed on its own
/// ([`FrameView::pixel`]), or the whole image at once ([`FrameView::render`]); both give the
/// same bytes, since a pixel depends only on the pose, the frame's draws and its own index.
/// The road recognizer reads about a tenth of a frame, so a run computes only those pixels
/// and renders whole frames only for recordings.
#[derive(Clone, Copy, Debug)]
pub struct FrameView<'a> {
    rays: &'a GroundRays,
    raster: &'a SurfaceRaster,
    palette: &'a Palette,
    frame: FrameParams,
    /// Ray offsets (robot frame, m) to raster cells: rotation (scaled by 1 / resolution) ...
    r: [f32; 4],
    /// ... and the pose's cell position.
    o: [f32; 2],
    noise_scale: f32,
    /// Per surface class: base colour and mottle amplitude ...
    base: [Rgb; CLASSES],
    mottle: [Rgb; CLASSES],
    /// ... and the same per channel, for eight lanes of classes, with the joint factors.
    tables: ClassTables,
    /// Render whole rows with AVX2 (detected at run time; `render/avx2.rs`).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    avx2: bool,
}

/// Colours by class, one table per channel: `base[channel][class]`.
#[derive(Clone, Copy, Debug)]
struct ClassTables {
    base: [[f32; CLASSES]; 3],
    mottle: [[f32; CLASSES]; 3],
    joint: [f32; CLASSES],
}

impl<'a> FrameView<'a> {
    pub fn new(
        rays: &'a GroundRays,
        pose: Pose2,
        raster: &'a SurfaceRaster,
        palette: &'a Palette,
        frame: FrameParams,
    ) -> Self {
        let inv = 1.0 / raster.resolution;
        let (s, c) = pose.theta.sin_cos();
        FrameView {
            rays,
            raster,
            palette,
            frame,
            r: [
                (c * inv) as f32,
                (-s * inv) as f32,
                (s * inv) as f32,
                (c * inv) as f32,
            ],
            o: [
                ((pose.x - raster.origin[0]) * inv) as f32,
                ((pose.y - raster.origin[1]) * inv) as f32,
            ],
            noise_scale: frame.noise_std / TRIANGULAR_STD,
            base: std::array::from_fn(|k| shade::rgb(palette.classes[k].base)),
            mottle: std::array::from_fn(|k| shade::rgb(palette.classes[k].mottle)),
            tables: ClassTables {
                base: std::array::from_fn(|c| std::array::from_fn(|k| palette.classes[k].base[c])),
                mottle: std::array::from_fn(|c| {
                    std::array::from_fn(|k| palette.classes[k].mottle[c])
                }),
                joint: std::array::from_fn(|k| palette.classes[k].joints),
            },
            avx2: crate::core::cpu::has_avx2() && raster.cells.len() < i32::MAX as usize,
        }
    }

    /// The same view rendering whole rows without AVX2 (tests: both give the same bytes).
    #[cfg(test)]
    pub(crate) fn without_avx2(mut self) -> Self {
        self.avx2 = false;
        self
    }

    pub fn width(&self) -> u32 {
        self.rays.width
    }

    pub fn height(&self) -> u32 {
        self.rays.height
    }

    /// The colour of pixel (u, v) (u < width, v < height).
    #[inline]
    pub fn pixel(&self, u: u32, v: u32) -> [u8; 3] {
        let w = self.rays.width as usize;
        let i = v as usize * w + u as usize;
        let first = self.rays.first_ground_row;
        if v < first {
            self.shade(shade::rgb(self.sky(v)), i)
        } else {
            self.ground(&self.rays.offsets[i - first as usize * w], i)
        }
    }

    /// The whole image into `out`: RGB8, row-major, row 0 at the top,
    /// `width × height × 3` bytes. Rows render in parallel on the caller's rayon pool; the
    /// image does not depend on the thread count.
    pub fn render(&self, out: &mut [u8]) {
        self.render_rows(out, true);
    }

    /// [`FrameView::render`] on the calling thread alone (for a thread of its own, such as a
    /// recorder's): the same bytes.
    pub fn render_here(&self, out: &mut [u8]) {
        self.render_rows(out, false);
    }

    fn render_rows(&self, out: &mut [u8], parallel: bool) {
        let (w, h) = (self.rays.width as usize, self.rays.height as usize);
        assert_eq!(out.len(), w * h * 3, "output buffer size");
        let first = (self.rays.first_ground_row as usize).min(h);
        let (sky, ground) = out.split_at_mut(3 * first * w);
        for (v, line) in sky.chunks_exact_mut(3 * w).enumerate() {
            self.sky_row(line, self.sky(v as u32), v * w);
        }
        let render_row = |(row, (line, offsets)): (usize, (&mut [u8], &[[f32; 2]]))| {
            self.ground_row(line, offsets, (first + row) * w);
        };
        if parallel {
            ground
                .par_chunks_mut(3 * w)
                .zip(self.rays.offsets.par_chunks(w))
                .enumerate()
                .with_min_len(ROWS_PER_TASK)
                .for_each(render_row);
        } else {
            ground
                .chunks_mut(3 * w)
                .zip(self.rays.offsets.chunks(w))
                .enumerate()
                .for_each(render_row);
        }
    }

    /// A sky row of colour `colour` into `line`, its first pixel having index `i`.
    fn sky_row(&self, line: &mut [u8], colour: [f32; 3], i: usize) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: AVX2 was detected in `new`
            unsafe { self.sky_row_avx2(line, colour, i) };
            return;
        }
        let c = shade::rgb(colour);
        for (u, px) in line.chunks_exact_mut(3).enumerate() {
            px.copy_from_slice(&self.shade(c, i + u));
        }
    }

    /// A ground row into `line` from its rays, its first pixel having index `i`.
    fn ground_row(&self, line: &mut [u8], rays: &[[f32; 2]], mut i: usize) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: AVX2 was detected in `new`, which checked the raster's size
            unsafe { self.ground_row_avx2(line, rays, i) };
            return;
        }
        // in blocks: first every pixel's cell (independent raster reads the CPU overlaps),
        // then the colours
        let mut cells = [(0, 0, 0); BLOCK];
        // neighbouring pixels near the camera see the same cell: its mottle once
        let mut last = (i32::MIN, i32::MIN, 0.0);
        for (px, rays) in line.chunks_mut(3 * BLOCK).zip(rays.chunks(BLOCK)) {
            for (c, ray) in cells.iter_mut().zip(rays) {
                *c = self.cell(ray);
            }
            for (px, &(ix, iy, class)) in px.chunks_exact_mut(3).zip(&cells) {
                if (ix, iy) != (last.0, last.1) {
                    last = (ix, iy, mottle(ix, iy));
                }
                px.copy_from_slice(&self.coloured(class, last.2, joint(ix, iy), i));
                i += 1;
            }
        }
    }

    /// The sky's colour in row `v` (above the horizon): a gradient down to the horizon.
    fn sky(&self, v: u32) -> [f32; 3] {
        let first = self.rays.first_ground_row;
        let t = if first > 1 {
            v as f32 / (first - 1) as f32
        } else {
            1.0
        };
        let p = self.palette;
        std::array::from_fn(|k| p.sky_top[k] + t * (p.sky_horizon[k] - p.sky_top[k]))
    }

    /// The ground colour under ray `ray` (robot frame offset, m), for pixel index `i`.
    #[inline(always)]
    fn ground(&self, ray: &[f32; 2], i: usize) -> [u8; 3] {
        self.colour(self.cell(ray), i)
    }

    /// The raster cell under ray `ray` and its surface class.
    #[inline(always)]
    fn cell(&self, ray: &[f32; 2]) -> (i32, i32, u8) {
        let [r00, r01, r10, r11] = self.r;
        let fx = self.o[0] + r00 * ray[0] + r01 * ray[1];
        let fy = self.o[1] + r10 * ray[0] + r11 * ray[1];
        let (ix, iy) = (floor_i32(fx), floor_i32(fy));
        let class = if fx.is_finite() && fy.is_finite() {
            self.raster.class_at_cell(ix as i64, iy as i64)
        } else {
            GRASS
        };
        (ix, iy, class)
    }

    /// The colour of pixel index `i` seeing cell (ix, iy) of class `class`.
    #[inline(always)]
    fn colour(&self, (ix, iy, class): (i32, i32, u8), i: usize) -> [u8; 3] {
        self.coloured(class, mottle(ix, iy), joint(ix, iy), i)
    }

    /// The colour of pixel index `i` seeing a cell of class `class` with mottle `m`
    /// ([`mottle`]) on a paving joint or not ([`joint`]).
    #[inline(always)]
    fn coloured(&self, class: u8, m: f32, on_joint: bool, i: usize) -> [u8; 3] {
        let k = class as usize;
        let joints = self.tables.joint[k];
        let j_factor = if joints != 1.0 && on_joint {
            joints
        } else {
            1.0
        };
        self.shade(shade::mottled(self.base[k], self.mottle[k], m, j_factor), i)
    }

    /// Colour `c` of pixel index `i` with the frame's brightness and the pixel's own noise.
    #[inline(always)]
    fn shade(&self, c: Rgb, i: usize) -> [u8; 3] {
        shade::shade(
            c,
            self.noise_word(i),
            self.frame.brightness,
            self.noise_scale,
        )
    }

    /// The noise word of pixel index `i`: a hash of the frame's seed and `i`.
    #[inline(always)]
    fn noise_word(&self, i: usize) -> u64 {
        mix64(self.frame.seed ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }
}

/// Renders the view from robot pose `pose` (world frame) into `out`: RGB8, row-major, row 0 at
/// the top, `rays.width × rays.height × 3` bytes ([`FrameView::render`]).
pub fn render_ground(
    rays: &GroundRays,
    pose: Pose2,
    raster: &SurfaceRaster,
    palette: &Palette,
    frame: &FrameParams,
    out: &mut [u8],
) {
    FrameView::new(rays, pose, raster, palette, *frame).render(out);
}

/// Pixels whose cells are looked up before their colours are computed.
const BLOCK: usize = 32;

/// Image rows rendered per rayon task.
const ROWS_PER_TASK: usize = 8;
