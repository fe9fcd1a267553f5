//! A scan's beams as a fan of angles `start + k·inc`, k < n: which beam indices an arc of
//! directions covers. Shared by the face sweep and the moving-obstacle overlays; the reciprocal of
//! the increment is taken once per scan, so mapping an arc costs two multiplications. The arcs
//! themselves come from [`atan2_approx`], widened by its [`MARGIN`].

use std::f32::consts::TAU;

/// Wraps an angle to [0, 2π) (arguments are within a few turns: no libm fmod).
#[inline]
pub(crate) fn wrap_tau(mut a: f32) -> f32 {
    while a < 0.0 {
        a += TAU;
    }
    while a >= TAU {
        a -= TAU;
    }
    a
}

/// atan2 by a minimax polynomial (max error about 1e-5 rad), without branches so that loops
/// over faces vectorise: intervals are taken with a [`MARGIN`] and every hit is then computed
/// exactly, so the approximation never changes a range. atan2(0, 0) = 0.
#[inline]
pub(crate) fn atan2_approx(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (mn, mx) = (ax.min(ay), ax.max(ay));
    let a = mn / mx.max(f32::MIN_POSITIVE);
    let s = a * a;
    let mut r =
        a * (0.999_866 + s * (-0.330_299_5 + s * (0.180_141 + s * (-0.085_133 + s * 0.020_835_1))));
    r = if ay > ax { FRAC_PI_2 - r } else { r };
    r = if x < 0.0 { PI - r } else { r };
    if y < 0.0 { -r } else { r }
}

/// Margin of an angular interval found with [`atan2_approx`] (radians): wider than its error.
pub(crate) const MARGIN: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub(crate) struct Fan {
    start: f32,
    inv_inc: f32,
    /// Angle of the last beam relative to the first.
    span: f32,
    n: usize,
}

impl Fan {
    pub fn new(start: f32, inc: f32, n: usize) -> Fan {
        Fan {
            start,
            inv_inc: 1.0 / inc,
            span: n.saturating_sub(1) as f32 * inc,
            n,
        }
    }

    pub fn span(&self) -> f32 {
        self.span
    }

    /// The beam indices whose angle lies in the arc [lo, lo + width] (radians, any lo;
    /// width < 2π), as at most two inclusive ranges (k0, k1): the arc may wrap past the start.
    #[inline]
    pub fn ranges(&self, lo: f32, width: f32) -> [Option<(usize, usize)>; 2] {
        if self.n == 0 {
            return [None, None];
        }
        let rel = wrap_tau(lo - self.start);
        let one = |a: f32| {
            let b = a + width;
            if b < 0.0 || a > self.span + 1e-6 {
                return None;
            }
            // b ≥ 0, so truncation is floor; ceil by hand (no SSE4.1 rounding, libm is slow)
            let k0 = if a <= 0.0 {
                0
            } else {
                let q = a * self.inv_inc;
                let i = q as usize;
                i + ((i as f32) < q) as usize
            };
            let k1 = ((b * self.inv_inc) as usize).min(self.n - 1);
            (k1 >= k0).then_some((k0, k1))
        };
        // the second range only exists when the arc crosses 2π back into the fan
        let second = if rel + width >= TAU {
            one(rel - TAU)
        } else {
            None
        };
        [one(rel), second]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn arcs_map_to_beam_ranges_with_wrap_around() {
        // 360 beams, one per degree from -180°
        let fan = Fan::new(-PI, PI / 180.0, 360);
        let deg = |d: f32| d.to_radians();
        assert_eq!(fan.ranges(deg(0.5), deg(2.0)), [Some((181, 182)), None]);
        // an arc across ±180° covers the last beams and the first ones
        assert_eq!(
            fan.ranges(deg(178.5), deg(3.0)),
            [Some((359, 359)), Some((0, 1))]
        );
        // an arc outside a narrow fan covers nothing
        let narrow = Fan::new(0.0, deg(1.0), 91);
        assert_eq!(narrow.ranges(deg(100.0), deg(50.0)), [None, None]);
        let r = narrow.ranges(deg(-10.0), deg(12.5));
        assert_eq!(r.into_iter().flatten().collect::<Vec<_>>(), vec![(0, 2)]);
        // no beams, no ranges
        assert_eq!(Fan::new(0.0, 0.1, 0).ranges(0.0, 1.0), [None, None]);
        assert_eq!(fan.ranges(deg(-1.5), deg(2.0)), [Some((179, 180)), None]);
    }
}
