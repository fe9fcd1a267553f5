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

mod pinhole;
pub mod render;
mod shade;

use crate::body::TruePose;
use crate::core::clock::RateTimer;
use crate::core::{Pose2, SimClock, SimRng};
use crate::world::roads::{RoadSurface, SurfaceRaster};
use bevy_ecs::prelude::*;
pub use pinhole::{CameraSpec, GroundRays};
use rand::RngExt;
use rand_distr::StandardNormal;
pub use render::{FrameParams, FrameView, Palette, render_ground};
use std::sync::Arc;

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
