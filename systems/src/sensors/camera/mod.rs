//! Forward-looking colour camera over the road surface ([Park thesis §4.1.2, §5.2]: a USB camera,
//! 640×480 frames halved to 320×240 for the road recognition). An ideal pinhole camera (no lens
//! distortion) at `mount_height` above the flat ground, `mount_x` ahead of the robot origin,
//! looking forward and pitched down by `pitch`; it sees the rasterized road surface
//! ([`RoadSurface`]) and sky above the horizon.
//!
//! Pinhole model: focal length f = (width / 2) / tan(hfov / 2) pixels, principal point at the
//! image centre, square pixels; pixel (u, v) is a continuous position (u right, v down; pixel
//! column i spans [i, i + 1)). Its ray in the robot frame (x forward, y left, z up) is
//! d = f̂ + a·r̂ + b·d̂ with a = (u − cx)/f, b = (v − cy)/f, f̂ = (cos p, 0, −sin p),
//! r̂ = (0, −1, 0) and d̂ = (−sin p, 0, −cos p); it meets the ground after
//! t = h / (sin p + b·cos p), where the denominator is positive (below the horizon).
//!
//! The rays of all pixels are computed once per spec ([`GroundRays`]); each frame only rotates
//! them to the robot's pose ([`render::render_ground`]). The default spec is the thesis's
//! camera at the halved resolution, 60° wide, on a short mast of the 520 × 400 mm RC car:
//! 0.5 m up, 0.2 m ahead of the origin, pitched 15° down, so the ground from 0.8 m ahead to
//! the horizon (a third of the image from the top) is in view.

pub mod render;
mod shade;

use crate::body::TruePose;
use crate::core::clock::RateTimer;
use crate::core::{Pose2, SimClock, SimRng};
use crate::world::roads::{RoadSurface, SurfaceRaster};
use bevy_ecs::prelude::*;
use rand::RngExt;
use rand_distr::StandardNormal;
pub use render::{FrameParams, FrameView, Palette, render_ground};
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct CameraSpec {
    /// Image size (pixels).
    pub width: u32,
    pub height: u32,
    /// Horizontal field of view (rad).
    pub hfov: f64,
    /// Position of the camera ahead of the robot origin (m).
    pub mount_x: f64,
    /// Height of the camera above the ground (m).
    pub mount_height: f64,
    /// Downward tilt of the optical axis (rad, down positive).
    pub pitch: f64,
    /// Frames per second.
    pub rate: f64,
    /// Standard deviation of the frame-to-frame brightness factor (1 nominal).
    pub brightness_std: f64,
    /// Standard deviation of the per-pixel noise (0–255 units).
    pub noise_std: f64,
}

impl Default for CameraSpec {
    fn default() -> Self {
        CameraSpec {
            width: 320,
            height: 240,
            hfov: 60f64.to_radians(),
            mount_x: 0.2,
            mount_height: 0.5,
            pitch: 15f64.to_radians(),
            rate: 10.0,
            brightness_std: 0.08,
            noise_std: 6.0,
        }
    }
}

impl CameraSpec {
    /// Focal length (pixels).
    pub fn focal(&self) -> f64 {
        0.5 * self.width as f64 / (0.5 * self.hfov).tan()
    }

    /// Principal point (pixels).
    pub fn centre(&self) -> [f64; 2] {
        [0.5 * self.width as f64, 0.5 * self.height as f64]
    }

    /// Image row of the horizon (pixels from the top; rays below it hit the ground).
    pub fn horizon_v(&self) -> f64 {
        self.centre()[1] - self.focal() * self.pitch.tan()
    }

    /// The ground point seen at pixel position (u, v), in the robot frame (m); `None` at or
    /// above the horizon.
    pub fn ground_point(&self, u: f64, v: f64) -> Option<[f64; 2]> {
        let f = self.focal();
        let [cx, cy] = self.centre();
        let (a, b) = ((u - cx) / f, (v - cy) / f);
        let (sp, cp) = self.pitch.sin_cos();
        let down = sp + b * cp;
        if down <= 1e-9 {
            return None;
        }
        let t = self.mount_height / down;
        Some([self.mount_x + t * (cp - b * sp), -t * a])
    }

    /// The pixel position (u, v) where ground point `p` (robot frame, m) appears; `None` when
    /// it is behind the camera. The position may lie outside the image.
    pub fn pixel_of(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let (dx, h) = (p[0] - self.mount_x, self.mount_height);
        let (sp, cp) = self.pitch.sin_cos();
        let z = dx * cp + h * sp; // along the optical axis
        if z <= 1e-9 {
            return None;
        }
        let f = self.focal();
        let [cx, cy] = self.centre();
        Some([cx - f * p[1] / z, cy + f * (h * cp - dx * sp) / z])
    }
}

/// The ground offset (robot frame, m) of every pixel centre below the horizon, for one spec.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundRays {
    pub width: u32,
    pub height: u32,
    /// The first image row whose pixel centres all see the ground; rows above are sky.
    pub first_ground_row: u32,
    /// Row-major offsets of rows `first_ground_row..height`, f32 (cm-level is plenty).
    pub offsets: Vec<[f32; 2]>,
}

impl GroundRays {
    pub fn new(spec: &CameraSpec) -> Self {
        let (w, h) = (spec.width, spec.height);
        let first = (0..h)
            .find(|&v| spec.ground_point(0.5, v as f64 + 0.5).is_some())
            .unwrap_or(h);
        let mut offsets = Vec::with_capacity(((h - first) * w) as usize);
        for v in first..h {
            for u in 0..w {
                let g = spec
                    .ground_point(u as f64 + 0.5, v as f64 + 0.5)
                    // the horizon depends on the row only; a pixel at the limit sees far grass
                    .unwrap_or([1.0e4, 0.0]);
                offsets.push([g[0] as f32, g[1] as f32]);
            }
        }
        GroundRays {
            width: w,
            height: h,
            first_ground_row: first,
            offsets,
        }
    }
}

/// One frame: RGB8, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraImage {
    pub stamp: f64,
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl CameraImage {
    pub fn new(width: u32, height: u32) -> Self {
        CameraImage {
            stamp: 0.0,
            width,
            height,
            rgb: vec![0; (width * height * 3) as usize],
        }
    }

    /// The colour of pixel (u, v).
    #[inline]
    pub fn pixel(&self, u: u32, v: u32) -> [u8; 3] {
        let i = 3 * (v * self.width + u) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

#[derive(Component, Clone, Debug)]
pub struct Camera {
    pub spec: CameraSpec,
    pub rng: SimRng,
    pub timer: RateTimer,
    pub enabled: bool,
    pub palette: Palette,
    /// Derived from `spec` by [`Camera::new`]; rebuild with [`GroundRays::new`] if the spec
    /// changes. Shared, so recorders can render frames on another thread.
    pub rays: Arc<GroundRays>,
}

impl Camera {
    pub fn new(spec: CameraSpec, rng: SimRng) -> Self {
        Camera {
            timer: RateTimer::new(spec.rate, 0.0),
            rays: Arc::new(GroundRays::new(&spec)),
            palette: Palette::default(),
            spec,
            rng,
            enabled: true,
        }
    }

    /// Takes a frame at robot pose `pose` (world frame): draws its brightness and noise seed.
    /// No pixel is computed until asked for ([`Camera::view`], [`Camera::render`]).
    pub fn take(&mut self, stamp: f64, pose: Pose2) -> CameraFrame {
        let n: f64 = self.rng.sample(StandardNormal);
        CameraFrame {
            stamp,
            pose,
            params: FrameParams {
                brightness: (1.0 + self.spec.brightness_std * n).max(0.05) as f32,
                noise_std: self.spec.noise_std as f32,
                seed: self.rng.random(),
            },
        }
    }

    /// The pixels of `frame` over the road surface `raster`, computed one by one on request.
    pub fn view<'a>(&'a self, frame: &CameraFrame, raster: &'a SurfaceRaster) -> CameraView<'a> {
        CameraView {
            stamp: frame.stamp,
            pixels: FrameView::new(&self.rays, frame.pose, raster, &self.palette, frame.params),
        }
    }

    /// Renders the whole of `frame` into `out` (resized if needed); rows in parallel on the
    /// caller's rayon pool.
    pub fn render_into(&self, frame: &CameraFrame, raster: &SurfaceRaster, out: &mut CameraImage) {
        out.stamp = frame.stamp;
        out.width = self.spec.width;
        out.height = self.spec.height;
        out.rgb
            .resize((self.spec.width * self.spec.height * 3) as usize, 0);
        self.view(frame, raster).pixels.render(&mut out.rgb);
    }

    /// The whole image of `frame`.
    pub fn render(&self, frame: &CameraFrame, raster: &SurfaceRaster) -> CameraImage {
        let mut img = CameraImage::new(self.spec.width, self.spec.height);
        self.render_into(frame, raster, &mut img);
        img
    }

    /// Takes a frame at robot pose `pose` (world frame) and renders it into `out`.
    pub fn capture(
        &mut self,
        stamp: f64,
        pose: Pose2,
        raster: &SurfaceRaster,
        out: &mut CameraImage,
    ) {
        let frame = self.take(stamp, pose);
        self.render_into(&frame, raster, out);
    }

    /// A new image of this camera's size, taken at `pose`.
    pub fn shoot(&mut self, stamp: f64, pose: Pose2, raster: &SurfaceRaster) -> CameraImage {
        let frame = self.take(stamp, pose);
        self.render(&frame, raster)
    }
}

/// What makes a frame: when and where it was taken and its random draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    pub stamp: f64,
    /// The robot's true pose (world frame) when it was taken.
    pub pose: Pose2,
    pub params: FrameParams,
}

/// A frame whose pixels are computed when read: what the road recognizer looks at.
#[derive(Clone, Copy, Debug)]
pub struct CameraView<'a> {
    pub stamp: f64,
    pub pixels: FrameView<'a>,
}

/// An image the road recognizer can read: a rendered [`CameraImage`] or a [`CameraView`].
pub trait Pixels {
    fn stamp(&self) -> f64;
    fn width(&self) -> u32;
    fn height(&self) -> u32;
    /// The colour of pixel (u, v) (u < width, v < height).
    fn pixel(&self, u: u32, v: u32) -> [u8; 3];
}

impl Pixels for CameraImage {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    fn width(&self) -> u32 {
        self.width
    }
    fn height(&self) -> u32 {
        self.height
    }
    #[inline]
    fn pixel(&self, u: u32, v: u32) -> [u8; 3] {
        CameraImage::pixel(self, u, v)
    }
}

impl Pixels for CameraView<'_> {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    fn width(&self) -> u32 {
        self.pixels.width()
    }
    fn height(&self) -> u32 {
        self.pixels.height()
    }
    #[inline]
    fn pixel(&self, u: u32, v: u32) -> [u8; 3] {
        self.pixels.pixel(u, v)
    }
}

/// The latest frame of a camera. Pixels are computed on demand: the road recognizer reads a
/// few of them through [`Camera::view`], recorders render whole frames ([`Camera::render`])
/// at their own rate. Both see the same pixels.
#[derive(Component, Clone, Debug, Default)]
pub struct CameraImages {
    pub frame: Option<CameraFrame>,
    /// True only in the tick the frame was taken.
    pub fresh: bool,
}

/// Sense: the last frame due in this tick (earlier ones of the same tick are skipped).
pub fn sample_cameras(
    clock: Res<SimClock>,
    mut cameras: Query<(&TruePose, &mut Camera, &mut CameraImages)>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    let mut due = Vec::new();
    for (truth, mut camera, mut out) in cameras.iter_mut() {
        out.fresh = false;
        camera.timer.due(start, end, &mut due);
        let Some(&t) = due.last() else { continue };
        if !camera.enabled {
            continue;
        }
        let f = ((t - start) / dt).clamp(0.0, 1.0);
        out.frame = Some(camera.take(t, truth.interpolate(f)));
        out.fresh = true;
    }
}

/// The road surface cameras see: the scenario's, or grass everywhere without roads.
pub fn surface_or_grass<'a>(
    surface: Option<&'a RoadSurface>,
    empty: &'a SurfaceRaster,
) -> &'a SurfaceRaster {
    surface.map_or(empty, |s| &s.0)
}

#[cfg(test)]
mod tests;
