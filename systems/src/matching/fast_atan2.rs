//! A branch-light `atan2` approximation for the improved matcher's hot loops (orientation
//! histograms, visibility checks), where bins of 0.5°–1° make full precision pointless. Octant
//! reduction plus the minimax polynomial for atan on [0, 1] (Abramowitz & Stegun 4.4.47 family,
//! degree 7, max error ≈ 1e-5 rad).

use std::f32::consts::{FRAC_PI_2, PI};

/// `atan2(y, x)` in (−π, π], |error| < 2e-5 rad; 0 for (0, 0).
#[inline(always)]
pub(crate) fn fast_atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (num, den) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if den == 0.0 {
        return 0.0;
    }
    let t = num / den;
    let t2 = t * t;
    // atan(t) on [0, 1]
    let mut a = t
        * (0.999_866
            + t2 * (-0.330_299_5 + t2 * (0.180_141 + t2 * (-0.085_133 + t2 * 0.020_835_1))));
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 { -a } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_to_std_atan2() {
        let mut worst = 0f32;
        for k in 0..10_000 {
            let a = -PI + 2.0 * PI * k as f32 / 10_000.0;
            for r in [0.3f32, 1.0, 17.0] {
                let (y, x) = (r * a.sin(), r * a.cos());
                let d = (fast_atan2(y, x) - y.atan2(x)).abs();
                let d = d.min(2.0 * PI - d);
                worst = worst.max(d);
            }
        }
        assert!(worst < 2e-5, "{worst}");
        assert_eq!(fast_atan2(0.0, 0.0), 0.0);
    }
}
