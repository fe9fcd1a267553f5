//! Trajectory error metrics with the definitions of the evo tool (systems/ARCHITECTURE.md,
//! "Metrics"; [Grupp 2017]):
//!
//! - ATE = `evo_ape tum TRUTH EST --align_origin`, translation RMSE: the estimate is moved by
//!   the rigid transform that puts its first pose on the first true pose, then
//!   √(mean ‖t_est,i − t_true,i‖²).
//! - RPE = `evo_rpe tum TRUTH EST --delta 1 --delta_unit f`: for consecutive pairs,
//!   E_i = (Q_i⁻¹ Q_{i+1})⁻¹ (P_i⁻¹ P_{i+1}) with Q the truth and P the estimate; the mean of
//!   ‖trans(E_i)‖ (`--pose_relation trans_part`) and of |angle(E_i)| (`angle_rad`), as in
//!   [Kümmerle 2009] and [SLAM thesis §4.3.1].
//! - Tracking: a sample is tracked when its position error is under 0.2 m and its heading error
//!   under 5° (map frame, no alignment). Global localization has converged at the first sample
//!   from which every sample of the following `hold` seconds (or to the end of the run, if that
//!   is sooner but at least one sample) is tracked.

use crate::core::{Pose2, wrap_angle};

/// Tracking thresholds.
pub const TRACKED_POSITION_M: f64 = 0.2;
pub const TRACKED_HEADING_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// One estimate with the true pose at its timestamp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub estimate: Pose2,
    pub truth: Pose2,
    /// The position spread the estimator reported with it, √(σ²ₓ + σ²ᵧ) (m); 0 when it reports
    /// none. How a localizer says it is unsure: it is never compared with the truth.
    pub spread_m: f64,
}

impl Sample {
    pub fn position_error(&self) -> f64 {
        self.estimate.distance(&self.truth)
    }

    pub fn heading_error(&self) -> f64 {
        wrap_angle(self.estimate.theta - self.truth.theta).abs()
    }

    pub fn tracked(&self) -> bool {
        self.position_error() < TRACKED_POSITION_M && self.heading_error() < TRACKED_HEADING_RAD
    }
}

/// ATE translation RMSE after aligning the first estimate onto the first true pose.
pub fn ate_align_origin(samples: &[Sample]) -> Option<f64> {
    let first = samples.first()?;
    let align = first.truth.compose(&first.estimate.inverse());
    let sum: f64 = samples
        .iter()
        .map(|s| {
            let e = align.compose(&s.estimate);
            (e.x - s.truth.x).powi(2) + (e.y - s.truth.y).powi(2)
        })
        .sum();
    Some((sum / samples.len() as f64).sqrt())
}

/// ATE translation RMSE without alignment (map frame).
pub fn ate_unaligned(samples: &[Sample]) -> Option<f64> {
    if samples.is_empty() {
        return None;
    }
    let sum: f64 = samples.iter().map(|s| s.position_error().powi(2)).sum();
    Some((sum / samples.len() as f64).sqrt())
}

/// RPE over consecutive pairs: (mean translation error (m), mean rotation error (rad)).
pub fn rpe_consecutive(samples: &[Sample]) -> Option<(f64, f64)> {
    if samples.len() < 2 {
        return None;
    }
    let (mut st, mut sr) = (0.0, 0.0);
    for w in samples.windows(2) {
        let q = w[0].truth.between(&w[1].truth);
        let p = w[0].estimate.between(&w[1].estimate);
        let e = q.inverse().compose(&p);
        st += e.x.hypot(e.y);
        sr += wrap_angle(e.theta).abs();
    }
    let n = (samples.len() - 1) as f64;
    Some((st / n, sr / n))
}

/// Fraction of samples tracked.
pub fn tracked_fraction(samples: &[Sample]) -> Option<f64> {
    if samples.is_empty() {
        return None;
    }
    Some(samples.iter().filter(|s| s.tracked()).count() as f64 / samples.len() as f64)
}

/// Index of the first sample from which tracking holds for `hold` seconds (see the module
/// docs), or None.
pub fn convergence_index(samples: &[Sample], hold: f64) -> Option<usize> {
    let mut start: Option<usize> = None;
    for (i, s) in samples.iter().enumerate() {
        if !s.tracked() {
            start = None;
            continue;
        }
        let b = *start.get_or_insert(i);
        if s.t - samples[b].t >= hold {
            return Some(b);
        }
    }
    start
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(t: f64, e: (f64, f64, f64), g: (f64, f64, f64)) -> Sample {
        Sample {
            t,
            estimate: Pose2::new(e.0, e.1, e.2),
            truth: Pose2::new(g.0, g.1, g.2),
            spread_m: 0.0,
        }
    }

    #[test]
    fn ate_by_hand() {
        // estimate = truth shifted by (1, 0): origin alignment removes it entirely
        let shifted = [
            s(0.0, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
            s(1.0, (2.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
        ];
        assert!(ate_align_origin(&shifted).unwrap() < 1e-12);
        assert!((ate_unaligned(&shifted).unwrap() - 1.0).abs() < 1e-12);
        // first poses agree; then errors 0.3 and 0.4 → RMSE √((0 + 0.09 + 0.16)/3)
        let v = [
            s(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
            s(1.0, (1.0, 0.3, 0.0), (1.0, 0.0, 0.0)),
            s(2.0, (2.0, -0.4, 0.0), (2.0, 0.0, 0.0)),
        ];
        let want = (0.25f64 / 3.0).sqrt();
        assert!((ate_align_origin(&v).unwrap() - want).abs() < 1e-12);
        // a first estimate rotated by 90°: the alignment rotates the whole estimate back
        let r = std::f64::consts::FRAC_PI_2;
        let rot = [
            s(0.0, (0.0, 0.0, r), (0.0, 0.0, 0.0)),
            s(1.0, (0.0, 1.0, r), (1.0, 0.0, 0.0)),
        ];
        assert!(ate_align_origin(&rot).unwrap() < 1e-12);
    }

    #[test]
    fn rpe_by_hand() {
        // truth moves 1 m forward per step; the estimate 1.1 m then turns 0.1 rad extra
        let v = [
            s(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
            s(1.0, (1.1, 0.0, 0.0), (1.0, 0.0, 0.0)),
            s(2.0, (2.1, 0.0, 0.1), (2.0, 0.0, 0.0)),
        ];
        let (t, r) = rpe_consecutive(&v).unwrap();
        // pair 1: E = (0.1, 0, 0); pair 2: E = (0, 0, 0.1)
        assert!((t - 0.05).abs() < 1e-12, "{t}");
        assert!((r - 0.05).abs() < 1e-12, "{r}");
    }

    #[test]
    fn tracking_and_convergence() {
        let mut v = Vec::new();
        for i in 0..20 {
            let err = if i < 5 || i == 8 { 1.0 } else { 0.05 };
            v.push(s(i as f64, (err, 0.0, 0.0), (0.0, 0.0, 0.0)));
        }
        assert!((tracked_fraction(&v).unwrap() - 14.0 / 20.0).abs() < 1e-12);
        // tracked from 5 to 7, broken at 8, then from 9 on: holds 5 s from index 9
        assert_eq!(convergence_index(&v, 5.0), Some(9));
        assert_eq!(
            convergence_index(&v, 50.0),
            Some(9),
            "to the end of the run"
        );
        assert_eq!(convergence_index(&v[..5], 1.0), None);
    }
}
