//! The camera's pinhole geometry (model in the [camera module](super) doc): the spec and the
//! ground offset of every pixel it derives. A leaf of its own so that the render kernel
//! ([`super::render`]), which reads the rays, does not import the camera systems that use it.

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
