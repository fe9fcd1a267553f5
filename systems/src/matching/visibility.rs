//! Free-space consistency of an alignment: a reference scan does not only say where surfaces
//! are, it also says that the space between the sensor and each end point is empty. A correctly
//! moved current point may fall where the reference saw nothing (occluded or outside its field
//! of view), but never well *in front of* what the reference measured along the same bearing.
//! Counting such violations separates a right alignment from a wrong one that happens to lay
//! many points on some other, similar wall — the "chybné natočení" (wrong rotation) and
//! symmetric-room failures of [Hospital thesis §6.2, §7.3], which its correlation
//! fitness cannot see. (The same negative information is what beam models in Probabilistic
//! Robotics §6.3 use.)
//!
//! The reference is summarised as a polar range image: the smallest range per 0.5° bearing bin.
//! A point at bearing φ and range ρ violates if every bin within ±1 bin of φ holds a range
//! larger than `ρ + margin` — conservative at depth edges, and bins without a return (no
//! reading, outside the field of view) never produce violations.

use super::fast_atan2::fast_atan2;
use std::f32::consts::PI;

/// Bearing bins over the full circle (0.5° each).
const BINS: usize = 720;

#[derive(Clone, Debug)]
pub(crate) struct RangeImage {
    min_range: Vec<f32>,
}

impl RangeImage {
    /// The range image of points in their sensor's frame (sensor at the origin).
    pub fn build(points: &[[f32; 2]]) -> RangeImage {
        let mut min_range = vec![f32::INFINITY; BINS];
        for p in points {
            let b = bin(fast_atan2(p[1], p[0]));
            let r = p[0].hypot(p[1]);
            if r < min_range[b] {
                min_range[b] = r;
            }
        }
        // the ±1-bin minimum, so lookups are one read; no reading (∞) becomes 0, which no
        // point can be in front of
        let near = (0..BINS)
            .map(|b| {
                let r = min_range[(b + BINS - 1) % BINS]
                    .min(min_range[b])
                    .min(min_range[(b + 1) % BINS]);
                if r.is_finite() { r } else { 0.0 }
            })
            .collect();
        RangeImage { min_range: near }
    }

    /// Whether `q` (in the image's sensor frame) lies more than `margin` in front of what the
    /// sensor measured around its bearing. Bins with no reading never count.
    #[inline]
    pub fn violates(&self, q: [f32; 2], margin: f32) -> bool {
        (q[0] * q[0] + q[1] * q[1]).sqrt() + margin < self.min_range[bin(fast_atan2(q[1], q[0]))]
    }
}

#[inline(always)]
fn bin(angle: f32) -> usize {
    let u = (angle + PI) * (BINS as f32 / (2.0 * PI));
    (u as usize).min(BINS - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_in_front_of_a_wall_violate_behind_do_not() {
        // a wall at x = 4 seen over ±45°
        let wall: Vec<[f32; 2]> = (0..200).map(|k| [4.0, -4.0 + 0.04 * k as f32]).collect();
        let img = RangeImage::build(&wall);
        assert!(img.violates([2.0, 0.3], 0.2));
        assert!(!img.violates([3.9, 0.3], 0.2));
        assert!(!img.violates([6.0, 0.3], 0.2));
        // behind the sensor: no reading, never a violation
        assert!(!img.violates([-1.0, 0.0], 0.2));
    }
}
