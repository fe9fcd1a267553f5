//! The odometry motion model of Thrun, Burgard & Fox, Probabilistic Robotics (2005), §5.4: a
//! motion between two odometry poses is decomposed into a rotation δrot1, a translation δtrans
//! and a rotation δrot2, each perturbed by zero-mean noise whose variance mixes the motion's own
//! rotation and translation with four parameters α1..α4 (Table 5.5, `motion_model_odometry`, the
//! probability form; Table 5.6, `sample_motion_model_odometry`, the sampling form).
//!
//! Two refinements follow ROS AMCL's `diff` model (amcl_odom.cpp): for (nearly) pure rotations
//! δrot1 is set to 0, because the heading of a few-millimetre translation is noise; and the
//! rotation noise is computed from the rotations folded to [0, π/2], so driving backwards is not
//! mistaken for two half turns.

use crate::core::{Pose2, wrap_angle};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

/// Below this translation (m) a motion counts as a rotation in place (AMCL uses 1 cm).
const MIN_TRANS_FOR_HEADING: f64 = 0.01;

/// The four noise parameters (ROS AMCL's `odom_alpha1..4`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometryMotionModel {
    /// Rotation noise from rotation (rad²/rad²).
    pub alpha1: f64,
    /// Rotation noise from translation (rad²/m²).
    pub alpha2: f64,
    /// Translation noise from translation (m²/m²).
    pub alpha3: f64,
    /// Translation noise from rotation (m²/rad²).
    pub alpha4: f64,
}

impl Default for OdometryMotionModel {
    /// AMCL's defaults.
    fn default() -> Self {
        OdometryMotionModel {
            alpha1: 0.2,
            alpha2: 0.2,
            alpha3: 0.2,
            alpha4: 0.2,
        }
    }
}

/// A motion decomposed as (δrot1, δtrans, δrot2) with the standard deviations of each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometryDelta {
    pub rot1: f64,
    pub trans: f64,
    pub rot2: f64,
    pub sd_rot1: f64,
    pub sd_trans: f64,
    pub sd_rot2: f64,
}

impl OdometryDelta {
    /// The motion's spread at its end, to first order: position (m, from the translation's
    /// noise and the first rotation's noise swung over the translation) and heading (rad).
    pub fn end_sd(&self) -> [f64; 2] {
        [
            self.sd_trans.hypot(self.trans * self.sd_rot1),
            self.sd_rot1.hypot(self.sd_rot2),
        ]
    }
}

/// |a| folded to [0, π/2]: a rotation of almost π is treated like a small one (reversing).
fn folded(a: f64) -> f64 {
    let a = wrap_angle(a).abs();
    a.min(PI - a)
}

/// (δrot1, δtrans, δrot2) of the motion from `a` to `b` (Table 5.5 lines 2–4).
fn decompose(a: &Pose2, b: &Pose2) -> (f64, f64, f64) {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let trans = dx.hypot(dy);
    let rot1 = if trans < MIN_TRANS_FOR_HEADING {
        0.0
    } else {
        wrap_angle(dy.atan2(dx) - a.theta)
    };
    let rot2 = wrap_angle(b.theta - a.theta - rot1);
    (rot1, trans, rot2)
}

/// Normal density of `x` with standard deviation `sd`.
fn normal_pdf(x: f64, sd: f64) -> f64 {
    (-0.5 * (x / sd).powi(2)).exp() / (sd * (2.0 * PI).sqrt())
}

/// The update trigger of the filters (AMCL's `update_min_d` / `update_min_a`): true once the
/// odometry has moved at least `min_d` (m) or turned at least `min_a` (rad) since `last`.
pub fn moved_enough(last: &Pose2, odom: &Pose2, min_d: f64, min_a: f64) -> bool {
    last.distance(odom) >= min_d || wrap_angle(odom.theta - last.theta).abs() >= min_a
}

impl OdometryMotionModel {
    /// The decomposed motion between odometry poses `from` and `to`, with its noise.
    pub fn delta(&self, from: &Pose2, to: &Pose2) -> OdometryDelta {
        let (rot1, trans, rot2) = decompose(from, to);
        let (r1, r2) = (folded(rot1), folded(rot2));
        OdometryDelta {
            rot1,
            trans,
            rot2,
            sd_rot1: (self.alpha1 * r1 * r1 + self.alpha2 * trans * trans).sqrt(),
            sd_trans: (self.alpha3 * trans * trans + self.alpha4 * (r1 * r1 + r2 * r2)).sqrt(),
            sd_rot2: (self.alpha1 * r2 * r2 + self.alpha2 * trans * trans).sqrt(),
        }
    }

    /// Sampling form (Table 5.6): a pose drawn from p(x' | u, x) for the motion `d`.
    pub fn sample(&self, d: &OdometryDelta, x: &Pose2, rng: &mut impl Rng) -> Pose2 {
        let mut n = || -> f64 { StandardNormal.sample(rng) };
        let rot1 = d.rot1 - d.sd_rot1 * n();
        let trans = d.trans - d.sd_trans * n();
        let rot2 = d.rot2 - d.sd_rot2 * n();
        let heading = x.theta + rot1;
        Pose2::new(
            x.x + trans * heading.cos(),
            x.y + trans * heading.sin(),
            wrap_angle(heading + rot2),
        )
    }

    /// Sampling form over particle arrays: moves every (x, y, θ) by its own draw.
    pub fn sample_slices(
        &self,
        d: &OdometryDelta,
        xs: &mut [f64],
        ys: &mut [f64],
        ths: &mut [f64],
        rng: &mut impl Rng,
    ) {
        for ((x, y), th) in xs.iter_mut().zip(ys.iter_mut()).zip(ths.iter_mut()) {
            let p = self.sample(d, &Pose2::new(*x, *y, *th), rng);
            (*x, *y, *th) = (p.x, p.y, p.theta);
        }
    }

    /// Probability form (Table 5.5): the density of ending at `x1` from `x0` when odometry
    /// reported the motion from `odom0` to `odom1`. Standard deviations are floored at
    /// `min_sd` = (m, rad) so a motionless odometry does not make the density a Dirac.
    pub fn probability(
        &self,
        odom0: &Pose2,
        odom1: &Pose2,
        x0: &Pose2,
        x1: &Pose2,
        min_sd: (f64, f64),
    ) -> f64 {
        let d = self.delta(odom0, odom1);
        let (rot1, trans, rot2) = decompose(x0, x1);
        normal_pdf(wrap_angle(d.rot1 - rot1), d.sd_rot1.max(min_sd.1))
            * normal_pdf(d.trans - trans, d.sd_trans.max(min_sd.0))
            * normal_pdf(wrap_angle(d.rot2 - rot2), d.sd_rot2.max(min_sd.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;

    #[test]
    fn noiseless_model_reproduces_odometry_motion() {
        let m = OdometryMotionModel {
            alpha1: 0.0,
            alpha2: 0.0,
            alpha3: 0.0,
            alpha4: 0.0,
        };
        let o0 = Pose2::new(1.0, 2.0, 0.3);
        let o1 = Pose2::new(1.8, 2.5, 1.1);
        let d = m.delta(&o0, &o1);
        // applied to another start pose, the motion is the same in the robot frame
        let x0 = Pose2::new(-4.0, 7.0, -2.0);
        let x1 = m.sample(&d, &x0, &mut stream_rng(1, "t", "m"));
        let want = x0.compose(&o0.between(&o1));
        assert!(x1.distance(&want) < 1e-12 && wrap_angle(x1.theta - want.theta).abs() < 1e-12);
    }

    #[test]
    fn sample_spread_matches_the_variances() {
        let m = OdometryMotionModel::default();
        let o0 = Pose2::IDENTITY;
        let o1 = Pose2::new(1.0, 0.0, 0.0);
        let d = m.delta(&o0, &o1);
        // straight 1 m: sd_trans = sqrt(α3), sd_rot = sqrt(α2)
        assert!((d.sd_trans - 0.2f64.sqrt()).abs() < 1e-12);
        let mut rng = stream_rng(2, "t", "m");
        let n = 20_000;
        let mut xs = vec![0.0; n];
        let mut ys = vec![0.0; n];
        let mut ths = vec![0.0; n];
        m.sample_slices(&d, &mut xs, &mut ys, &mut ths, &mut rng);
        let mean_th = ths.iter().sum::<f64>() / n as f64;
        let var_th = ths.iter().map(|t| (t - mean_th).powi(2)).sum::<f64>() / n as f64;
        // θ' = rot1 + rot2 noise: two independent draws of variance α2
        assert!((var_th - 2.0 * 0.2).abs() < 0.03, "{var_th}");
        let mean_r = xs.iter().zip(&ys).map(|(x, y)| x.hypot(*y)).sum::<f64>() / n as f64;
        assert!((mean_r - 1.0).abs() < 0.05, "{mean_r}");
    }

    #[test]
    fn reversing_is_not_two_half_turns() {
        let m = OdometryMotionModel::default();
        let d = m.delta(&Pose2::IDENTITY, &Pose2::new(-0.5, 0.0, 0.0));
        // rot1 = π, rot2 = −π; the folded rotations are 0, so rotation noise comes from translation
        assert!((d.sd_rot1 - (0.2f64 * 0.25).sqrt()).abs() < 1e-9, "{d:?}");
    }

    #[test]
    fn probability_peaks_at_the_odometry_motion() {
        let m = OdometryMotionModel {
            alpha1: 0.05,
            alpha2: 0.05,
            alpha3: 0.05,
            alpha4: 0.05,
        };
        let o0 = Pose2::new(0.0, 0.0, 0.0);
        let o1 = Pose2::new(1.0, 0.2, 0.3);
        let x0 = Pose2::new(5.0, 5.0, 1.0);
        let exact = x0.compose(&o0.between(&o1));
        let p_exact = m.probability(&o0, &o1, &x0, &exact, (0.01, 0.01));
        for off in [0.05, 0.2] {
            let moved = Pose2::new(exact.x + off, exact.y, exact.theta);
            assert!(m.probability(&o0, &o1, &x0, &moved, (0.01, 0.01)) < p_exact);
        }
        // no motion, no odometry change: the floor keeps it finite and peaked at x0
        let p0 = m.probability(&o0, &o0, &x0, &x0, (0.01, 0.01));
        assert!(p0.is_finite() && p0 > 0.0);
    }
}
