//! Rotation pre-search by cross-correlating orientation histograms of surface normals, the
//! "histogram correlation" method the thesis surveys ([Hospital thesis §3.8, eq. 12]; angle
//! histograms after [Weiß 1994]): `c(j) = Σ_i h₁(i) · h₂((i + j) mod n)`. The angle histogram does
//! not depend on translation, so its correlation peaks give rotation hypotheses before any
//! translation is known.
//!
//! Each point with a normal adds its local surface length (half the distance between its two
//! neighbours, capped) to the bin of its normal's direction, so a histogram peak measures how
//! much wall faces that way. Bins are 1°, the histogram is smoothed circularly, and the
//! correlation's local maxima (refined by a parabola through the peak and its neighbours) are the
//! hypotheses, best first. A normal at angle α in the current frame is at α + ω in the reference
//! frame, so peak shift j is the rotation ω. In rectilinear buildings the true rotation and its
//! 90° siblings all score high: the matcher tests several hypotheses.

use super::fast_atan2::fast_atan2;
use std::f64::consts::TAU;

/// Histogram bins (1° each).
pub(crate) const BINS: usize = 360;
/// Cap on the surface length one point stands for (m), so isolated far points do not dominate.
const MAX_WEIGHT: f32 = 0.25;
/// Circular Gaussian smoothing, in bins.
const SMOOTH_SIGMA: f32 = 1.0;

/// The orientation histogram of points with normals (see the module docs).
pub(crate) fn orientation_histogram(points: &[[f32; 2]], normals: &[Option<[f32; 2]>]) -> Vec<f32> {
    let mut h = vec![0f32; BINS];
    let n = points.len();
    let bin_per_rad = BINS as f32 / std::f32::consts::TAU;
    for k in 0..n {
        let Some(nr) = normals[k] else { continue };
        let (prev, next) = (points[k.saturating_sub(1)], points[(k + 1).min(n - 1)]);
        let span = (next[0] - prev[0]).hypot(next[1] - prev[1]);
        let w = (0.5 * span).min(MAX_WEIGHT);
        let mut u = fast_atan2(nr[1], nr[0]) * bin_per_rad;
        if u < 0.0 {
            u += BINS as f32;
        }
        // linear split between the two nearest bins
        let b0 = (u.floor() as usize) % BINS;
        let f = u - u.floor();
        h[b0] += w * (1.0 - f);
        h[(b0 + 1) % BINS] += w * f;
    }
    smooth(&h)
}

fn smooth(h: &[f32]) -> Vec<f32> {
    let r = (3.0 * SMOOTH_SIGMA).ceil() as usize;
    let kernel: Vec<f32> = (0..=2 * r)
        .map(|i| {
            let x = i as f32 - r as f32;
            (-0.5 * x * x / (SMOOTH_SIGMA * SMOOTH_SIGMA)).exp()
        })
        .collect();
    (0..BINS)
        .map(|b| {
            kernel
                .iter()
                .enumerate()
                .map(|(i, k)| k * h[(b + BINS + i - r) % BINS])
                .sum()
        })
        .collect()
}

/// Rotation hypotheses `ω` (radians, in (−π, π]) with their correlation scores, best first, at
/// most `max`, keeping only `|ω| ≤ max_theta` (+ half a bin).
pub(crate) fn rotation_hypotheses(
    reference: &[f32],
    current: &[f32],
    max: usize,
    max_theta: f64,
) -> Vec<(f64, f32)> {
    // c(j) = Σ_i h_cur(i) · h_ref(i + j): h_ref doubled so every shift is one contiguous dot product
    let mut doubled = Vec::with_capacity(2 * BINS);
    doubled.extend_from_slice(reference);
    doubled.extend_from_slice(reference);
    let corr: Vec<f32> = (0..BINS)
        .map(|j| dot(current, &doubled[j..j + BINS]))
        .collect();
    let mut peaks: Vec<(f64, f32)> = Vec::new();
    for j in 0..BINS {
        let (l, c, r) = (corr[(j + BINS - 1) % BINS], corr[j], corr[(j + 1) % BINS]);
        if !(c > l && c >= r && c > 0.0) {
            continue;
        }
        let denom = l - 2.0 * c + r;
        let delta = if denom < 0.0 {
            0.5 * (l - r) / denom
        } else {
            0.0
        };
        let omega = crate::core::wrap_angle((j as f64 + delta as f64) * TAU / BINS as f64);
        if omega.abs() <= max_theta + 0.5 * TAU / BINS as f64 {
            peaks.push((omega, c));
        }
    }
    // best first; equal scores keep the smaller shift first (stable sort on the scan order)
    peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
    peaks.truncate(max);
    peaks
}

#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    // eight partial sums: vectorises, and the order is fixed, so results are reproducible
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for i in 0..8 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s: f32 = acc.iter().sum();
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matching::normals::estimate_normals;

    /// An L-shaped corner plus a short wall, rotated by `rot`.
    fn shape(rot: f32) -> Vec<[f32; 2]> {
        let mut p = Vec::new();
        for k in 0..60 {
            p.push([3.0, -2.0 + 0.05 * k as f32]);
        }
        for k in 0..40 {
            p.push([3.0 - 0.05 * k as f32, 1.0]);
        }
        for k in 0..20 {
            p.push([-2.0, 0.5 - 0.05 * k as f32]);
        }
        let (s, c) = rot.sin_cos();
        p.iter()
            .map(|q| [c * q[0] - s * q[1], s * q[0] + c * q[1]])
            .collect()
    }

    #[test]
    fn the_best_hypothesis_is_the_rotation() {
        let reference = shape(0.0);
        let h_ref = orientation_histogram(&reference, &estimate_normals(&reference, 0.3, 0.3));
        for deg in [-170.0f32, -57.0, 0.0, 33.3, 120.0, 179.0] {
            // the current scan is the reference seen rotated by −ω, so ω maps it back
            let current = shape(-deg.to_radians());
            let h_cur = orientation_histogram(&current, &estimate_normals(&current, 0.3, 0.3));
            let hyp = rotation_hypotheses(&h_ref, &h_cur, 4, std::f64::consts::PI);
            let err = crate::core::wrap_angle(hyp[0].0 - deg.to_radians() as f64).to_degrees();
            assert!(err.abs() < 0.6, "{deg}: {hyp:?}");
        }
    }

    #[test]
    fn window_limits_hypotheses() {
        let reference = shape(0.0);
        let current = shape(-2.0);
        let h_ref = orientation_histogram(&reference, &estimate_normals(&reference, 0.3, 0.3));
        let h_cur = orientation_histogram(&current, &estimate_normals(&current, 0.3, 0.3));
        let hyp = rotation_hypotheses(&h_ref, &h_cur, 8, 0.5);
        assert!(hyp.iter().all(|h| h.0.abs() <= 0.51));
    }
}
