//! Road recognition in the camera image ([Park thesis §5.2]), after the thesis:
//!
//! - **Learning**: the road colours are learned from the first `learn_frames` frames, from a
//!   window at the bottom centre of the image that the robot, set down on a road, sees as road
//!   (the thesis learns "the colour of the road" before driving and does not say where from;
//!   this window is the usual choice). Every sampled pixel whose colour the table does not yet
//!   hold becomes a learned colour ([`colour_table`]: ΔE in HSV, cached in a 64³ RGB table),
//!   up to `max_colours`.
//! - **Scanning**: from the bottom row up with a row step (2), each row from its start column
//!   outwards with a pixel step (4) until the image edge or more than `max_misses` consecutive
//!   non-road samples; the last road sample on each side gives the row's edges, hence its centre
//!   and width. Going up stops at the first row without road (at the latest, the sky).
//! - The thesis starts every row at the image centre; it adapted its sources "with small
//!   changes", and so does this: by default a row starts at the centre of the row below
//!   ([`ScanStart::PreviousCentre`]), so a road that bends out of the image centre is followed
//!   up the image. [`ScanStart::ImageCentre`] is the thesis's rule.
//!
//! Output: one [`RoadRow`] per scanned row with road, bottom first, in pixels; the road
//! follower ([`super::road_follow`]) turns them into ground points.

pub mod colour_table;
mod learning;

use crate::sensors::camera::{Camera, CameraImage, CameraImages, Pixels, surface_or_grass};
use crate::world::roads::{RoadSurface, SurfaceRaster};
use bevy_ecs::prelude::*;
pub use colour_table::ColourTable;

/// At most this many background colours are kept.
pub(crate) const BACKGROUND_COLOURS: usize = 32;
/// Frames a relearning looks for the new road in.
pub(crate) const RELEARN_BUDGET: u32 = 50;

/// Where each row's scan starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanStart {
    /// The image's centre column (the thesis).
    ImageCentre,
    /// The centre of the road found in the row below (the image centre for the bottom row).
    PreviousCentre,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RecognitionConfig {
    /// Frames the road colours are learned from.
    pub learn_frames: u32,
    /// Learning window as fractions of the image: [left, top, right, bottom].
    pub window: [f64; 4],
    /// Pixel step inside the learning window.
    pub learn_step: u32,
    /// ΔE threshold of a road colour.
    pub threshold: f64,
    /// At most this many learned colours.
    pub max_colours: usize,
    /// Step between the pixels tested in a row (the thesis: 4).
    pub pixel_step: u32,
    /// Step between the rows scanned (the thesis: 2).
    pub row_step: u32,
    /// A row's scan ends after more than this many consecutive non-road samples.
    pub max_misses: u32,
    pub scan_from: ScanStart,
    /// The road's lowest row is looked for in this bottom fraction of the image (with
    /// `PreviousCentre`; the thesis's rule ends at the first row without road).
    pub search_fraction: f64,
}

impl Default for RecognitionConfig {
    fn default() -> Self {
        RecognitionConfig {
            learn_frames: 5,
            window: [0.4, 0.8, 0.6, 1.0],
            learn_step: 2,
            threshold: 20.0,
            max_colours: 64,
            pixel_step: 4,
            row_step: 2,
            max_misses: 2,
            scan_from: ScanStart::PreviousCentre,
            search_fraction: 0.75,
        }
    }
}

/// The road in one image row. Columns are continuous pixel positions (column i spans
/// [i, i + 1)); an edge lies halfway between the last road sample and the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadRow {
    /// Image row (0 at the top).
    pub v: u32,
    pub left: f64,
    pub right: f64,
    pub centre: f64,
    pub width: f64,
    /// Whether the scan ended at a road edge on that side (false: at the image border, the
    /// road goes on beyond the view).
    pub left_edge: bool,
    pub right_edge: bool,
}

/// The road found in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadDetection {
    pub stamp: f64,
    pub width: u32,
    pub height: u32,
    /// Whether the frame was also used for learning.
    pub learning: bool,
    /// Rows with road, bottom first.
    pub rows: Vec<RoadRow>,
}

/// Learns the road colours, then finds the road in each frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadRecognizer {
    pub config: RecognitionConfig,
    pub table: ColourTable,
    /// Colours seen beside the recognized road (grass, verge): never learned as road.
    pub background: ColourTable,
    frames_learned: u32,
    /// Frames still to learn a new surface from, and frames left to find them in.
    relearn_frames: u32,
    relearn_budget: u32,
}

/// One half-row scan: the nearest and the farthest road sample, and whether it ended at the
/// image border without a miss.
struct Side {
    first: Option<i64>,
    last: Option<i64>,
    open: bool,
}

impl RoadRecognizer {
    pub fn new(config: RecognitionConfig) -> Self {
        RoadRecognizer {
            table: ColourTable::new(config.threshold as f32, config.max_colours),
            background: ColourTable::new(config.threshold as f32, BACKGROUND_COLOURS),
            config,
            frames_learned: 0,
            relearn_frames: 0,
            relearn_budget: 0,
        }
    }

    /// Learns from the frame while learning, then finds the road in it.
    pub fn process(&mut self, image: &impl Pixels) -> RoadDetection {
        let learning = self.learning();
        if learning {
            self.learn(image);
        } else if self.relearning() {
            self.relearn_from(image);
        }
        let mut det = self.recognize(image);
        if !learning {
            self.learn_background(image, &det);
        }
        det.learning = learning;
        det
    }

    /// Finds the road in `image` with the colours learned so far.
    pub fn recognize(&self, image: &impl Pixels) -> RoadDetection {
        let c = &self.config;
        let (w, h) = (image.width() as i64, image.height() as i64);
        let step = c.pixel_step.max(1) as i64;
        let mut rows = Vec::new();
        let mut start = w / 2;
        let mut v = h - 1;
        // rows without road below the first row with road are skipped (the robot beside the
        // road sees it further up, off to one side); after that the road ends at the first
        // row without it
        let lowest = if c.scan_from == ScanStart::PreviousCentre {
            (h as f64 * (1.0 - c.search_fraction)) as i64
        } else {
            h
        };
        while v >= 0 {
            let Some(row) = self.scan_row(image, v as u32, start.clamp(0, w - 1), step) else {
                if rows.is_empty() && v > lowest {
                    v -= c.row_step.max(1) as i64;
                    continue;
                }
                break;
            };
            if c.scan_from == ScanStart::PreviousCentre {
                start = row.centre.floor() as i64;
            }
            rows.push(row);
            v -= c.row_step.max(1) as i64;
        }
        RoadDetection {
            stamp: image.stamp(),
            width: image.width(),
            height: image.height(),
            learning: false,
            rows,
        }
    }

    /// Scans one half-row outwards from `start`. With `seek` (the start is off the road) the
    /// misses before the first road sample do not count: the scan looks for the nearest road
    /// across the whole half-row.
    fn scan_side(
        &self,
        image: &impl Pixels,
        v: u32,
        start: i64,
        dir: i64,
        step: i64,
        seek: bool,
    ) -> Side {
        let w = image.width() as i64;
        let mut side = Side {
            first: None,
            last: None,
            open: false,
        };
        let mut misses = 0;
        let mut c = start + dir * step;
        loop {
            if c < 0 || c >= w {
                side.open = misses == 0;
                return side;
            }
            if self.table.is_road(image.pixel(c as u32, v)) {
                side.first.get_or_insert(c);
                side.last = Some(c);
                misses = 0;
            } else if !(seek && side.first.is_none()) {
                misses += 1;
                if misses > self.config.max_misses {
                    return side;
                }
            }
            c += dir * step;
        }
    }

    /// The road in row `v`, scanning out from column `start`.
    fn scan_row(&self, image: &impl Pixels, v: u32, start: i64, step: i64) -> Option<RoadRow> {
        let w = image.width() as f64;
        let half = 0.5 * step as f64;
        let on_road = self.table.is_road(image.pixel(start as u32, v));
        // the thesis gives up on a row whose start is off the road; we look along it
        let seek = !on_road && self.config.scan_from == ScanStart::PreviousCentre;
        let left = self.scan_side(image, v, start, -1, step, seek);
        let right = self.scan_side(image, v, start, 1, step, seek);
        // the extent of road samples, and whether each end is open (image border)
        let (lo, lo_open, hi, hi_open) = if on_road {
            (
                left.last.unwrap_or(start),
                left.open,
                right.last.unwrap_or(start),
                right.open,
            )
        } else {
            // the start is off the road: take the side whose road is nearer
            let dl = left.first.map(|f| start - f);
            let dr = right.first.map(|f| f - start);
            match (dl, dr) {
                (None, None) => return None,
                (Some(a), Some(b)) if b < a => (right.first?, false, right.last?, right.open),
                (Some(_), _) => (left.last?, left.open, left.first?, false),
                (None, Some(_)) => (right.first?, false, right.last?, right.open),
            }
        };
        let l = if lo_open {
            0.0
        } else {
            (lo as f64 + 0.5 - half).max(0.0)
        };
        let r = if hi_open {
            w
        } else {
            (hi as f64 + 0.5 + half).min(w)
        };
        Some(RoadRow {
            v,
            left: l,
            right: r,
            centre: 0.5 * (l + r),
            width: r - l,
            left_edge: !lo_open,
            right_edge: !hi_open,
        })
    }
}

/// Paints the detection into `image` (for recording): found edges red, the centre yellow.
pub fn draw_detection(image: &mut CameraImage, det: &RoadDetection) {
    let (w, h) = (image.width, image.height);
    let mut put = |u: f64, v: u32, c: [u8; 3]| {
        let u0 = (u.floor() as i64).clamp(0, w as i64 - 1);
        for du in -1..=1 {
            let u = (u0 + du).clamp(0, w as i64 - 1) as u32;
            if v < h {
                let i = 3 * (v * w + u) as usize;
                image.rgb[i..i + 3].copy_from_slice(&c);
            }
        }
    };
    for row in &det.rows {
        if row.left_edge {
            put(row.left, row.v, [255, 0, 0]);
        }
        if row.right_edge {
            put(row.right, row.v, [255, 0, 0]);
        }
        put(row.centre, row.v, [255, 230, 0]);
    }
}

/// A robot's road recognizer and its latest result.
#[derive(Component, Clone, Debug)]
pub struct RoadDetector {
    pub recognizer: RoadRecognizer,
    pub detection: Option<RoadDetection>,
    /// True only in the tick a new detection was made.
    pub fresh: bool,
}

impl RoadDetector {
    pub fn new(config: RecognitionConfig) -> Self {
        RoadDetector {
            recognizer: RoadRecognizer::new(config),
            detection: None,
            fresh: false,
        }
    }
}

/// Recognizes the road in every fresh camera frame, computing only the pixels it reads.
pub fn detect_roads(
    surface: Option<Res<RoadSurface>>,
    mut detectors: Query<(&Camera, &CameraImages, &mut RoadDetector)>,
) {
    let empty = SurfaceRaster::empty();
    let raster = surface_or_grass(surface.as_deref(), &empty);
    for (camera, images, mut det) in detectors.iter_mut() {
        det.fresh = false;
        if !images.fresh {
            continue;
        }
        if let Some(frame) = &images.frame {
            let d = det.recognizer.process(&camera.view(frame, raster));
            det.detection = Some(d);
            det.fresh = true;
        }
    }
}

#[cfg(test)]
mod tests;
