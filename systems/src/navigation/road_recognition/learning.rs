//! Learning the road colours ([Park thesis §5.2]): from the learning window in the first frames, as
//! the thesis does, and — beyond it — again for a road of a new surface, guarded by the background
//! colours seen beside the road so a robot standing on the grass never learns grass as road.

use super::{BACKGROUND_COLOURS, RELEARN_BUDGET, RoadDetection, RoadRecognizer};
use crate::sensors::camera::Pixels;

impl RoadRecognizer {
    /// Whether frames are still being learned from.
    pub fn learning(&self) -> bool {
        self.frames_learned < self.config.learn_frames
    }

    /// Learns the colours in the learning window; returns how many were new.
    pub fn learn(&mut self, image: &impl Pixels) -> usize {
        let pixels: Vec<[u8; 3]> = self.window_pixels(image).collect();
        let added = pixels
            .into_iter()
            .map(|p| usize::from(self.table.learn(p)))
            .sum();
        self.frames_learned += 1;
        added
    }

    /// Learns a road of another surface from the next `frames` frames whose learning window
    /// shows a road (mostly colours that are not background), looking for them over
    /// at most `RELEARN_BUDGET` frames. The road already learned stays recognized meanwhile.
    pub fn relearn(&mut self, frames: u32) {
        self.relearn_frames = frames;
        self.relearn_budget = RELEARN_BUDGET;
    }

    /// Whether a relearning asked for is still looking for the new road.
    pub fn relearning(&self) -> bool {
        self.relearn_frames > 0 && self.relearn_budget > 0
    }

    /// The learning window's pixels (row-major, `learn_step` apart).
    pub(super) fn window_pixels(&self, image: &impl Pixels) -> impl Iterator<Item = [u8; 3]> {
        let (w, h) = (image.width() as f64, image.height() as f64);
        let [l, t, r, b] = self.config.window;
        let col = |f: f64, n: f64| ((f * n).round() as u32).min(n as u32);
        let (u0, u1) = (col(l, w), col(r, w));
        let (v0, v1) = (col(t, h), col(b, h));
        let step = self.config.learn_step.max(1) as usize;
        (v0..v1)
            .step_by(step)
            .flat_map(move |v| (u0..u1).step_by(step).map(move |u| image.pixel(u, v)))
    }

    /// One frame of relearning: learns the window's colours that are not background when
    /// most of them are not (the robot is on a road), else waits for a better frame.
    pub(super) fn relearn_from(&mut self, image: &impl Pixels) {
        self.relearn_budget -= 1;
        let pixels: Vec<[u8; 3]> = self.window_pixels(image).collect();
        let clear = pixels
            .iter()
            .filter(|&&p| !self.background.is_road(p))
            .count();
        if 2 * clear < pixels.len() {
            return;
        }
        for p in pixels {
            if !self.background.is_road(p) {
                self.table.learn(p);
            }
        }
        self.relearn_frames -= 1;
    }

    /// Learns colours beside a road recognized with both edges in the near rows: the
    /// background a new road must differ from.
    pub(super) fn learn_background(&mut self, image: &impl Pixels, det: &RoadDetection) {
        if self.background.learned().len() >= BACKGROUND_COLOURS {
            return;
        }
        let w = image.width() as f64;
        let gap = 2.0 * self.config.pixel_step as f64;
        for row in det
            .rows
            .iter()
            .filter(|r| r.left_edge && r.right_edge)
            .take(8)
        {
            for u in [
                row.left - gap,
                row.left - 3.0 * gap,
                row.right + gap,
                row.right + 3.0 * gap,
            ] {
                if (0.0..w).contains(&u) {
                    let p = image.pixel(u as u32, row.v);
                    if !self.table.is_road(p) {
                        self.background.learn(p);
                    }
                }
            }
        }
    }
}
