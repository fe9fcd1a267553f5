//! Judging a SLAM run on a CARMEN log against the log's ground truth (`TRUEPOS` lines), with the
//! localization metrics `sim run` reports ([`LocalizerMetrics`]: evo's ATE with
//! `--align_origin` and RPE over consecutive poses, `systems/ARCHITECTURE.md`, "Metrics").
//!
//! Each estimate is paired with the true pose at its timestamp: the `TRUEPOS` record of that
//! instant (logs written by `sim run --carmen-out` have one at every scan), else the pose
//! interpolated between the records around it when they are at most [`MAX_GAP_S`] apart;
//! estimates outside the truth's time span or in a wider gap are not judged.

use crate::formats::carmen::TruePosRecord;
use systems::core::Pose2;
use systems::eval::{LocalizerMetrics, Sample, TrajectoryMetrics};

/// Widest gap between two `TRUEPOS` records an estimate is interpolated in (s).
pub const MAX_GAP_S: f64 = 1.0;

/// A log's ground truth in time order.
#[derive(Clone, Debug, Default)]
pub struct TruthTrack {
    stamps: Vec<f64>,
    poses: Vec<Pose2>,
}

impl TruthTrack {
    pub fn new(records: &[TruePosRecord]) -> Self {
        let mut r: Vec<&TruePosRecord> = records.iter().collect();
        r.sort_by(|a, b| a.timestamp.total_cmp(&b.timestamp));
        TruthTrack {
            stamps: r.iter().map(|r| r.timestamp).collect(),
            poses: r.iter().map(|r| r.truth).collect(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.stamps.is_empty()
    }

    /// The true pose at `t`, if the track covers it.
    pub fn at(&self, t: f64) -> Option<Pose2> {
        let i = self.stamps.partition_point(|&s| s < t);
        if self.stamps.get(i) == Some(&t) {
            return Some(self.poses[i]);
        }
        if i == 0 || i == self.stamps.len() {
            return None;
        }
        let (t0, t1) = (self.stamps[i - 1], self.stamps[i]);
        if t1 - t0 > MAX_GAP_S {
            return None;
        }
        Some(self.poses[i - 1].lerp(&self.poses[i], (t - t0) / (t1 - t0)))
    }

    /// Each (stamp, estimate) paired with the truth at its stamp (uncovered ones dropped).
    pub fn samples(&self, estimates: &[(f64, Pose2)]) -> Vec<Sample> {
        estimates
            .iter()
            .filter_map(|&(t, estimate)| {
                self.at(t).map(|truth| Sample {
                    t,
                    estimate,
                    truth,
                    spread_m: 0.0,
                })
            })
            .collect()
    }

    /// The metrics of `estimates` (None when no estimate falls in the truth's span).
    pub fn metrics(&self, kind: &str, estimates: &[(f64, Pose2)]) -> Option<LocalizerMetrics> {
        let samples = self.samples(estimates);
        (!samples.is_empty()).then(|| LocalizerMetrics::from_samples(kind, &samples))
    }

    /// A SLAM system's metrics as `sim run` reports them: those of the estimates it published
    /// scan by scan (`online`), with `final_trajectory` judging the trajectory it holds at the
    /// end (for graph SLAM, after the last optimization).
    pub fn slam_metrics(
        &self,
        kind: &str,
        online: &[(f64, Pose2)],
        trajectory: &[(f64, Pose2)],
    ) -> Option<LocalizerMetrics> {
        let mut m = self.metrics(kind, online)?;
        let samples = self.samples(trajectory);
        m.final_trajectory =
            (!samples.is_empty()).then(|| TrajectoryMetrics::from_samples(&samples));
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(t: f64, x: f64, th: f64) -> TruePosRecord {
        TruePosRecord {
            timestamp: t,
            truth: Pose2::new(x, 0.0, th),
            odom: Pose2::default(),
        }
    }

    #[test]
    fn exact_interpolated_or_not_covered() {
        let track = TruthTrack::new(&[rec(2.0, 2.0, 3.0), rec(1.0, 1.0, -3.0), rec(5.0, 5.0, 0.0)]);
        assert_eq!(track.at(1.0), Some(Pose2::new(1.0, 0.0, -3.0)));
        let mid = track.at(1.5).unwrap();
        assert!((mid.x - 1.5).abs() < 1e-12);
        // the heading goes the short way round through ±π
        assert!(mid.theta.abs() > 3.0, "{mid:?}");
        assert_eq!(track.at(0.5), None);
        assert_eq!(track.at(3.0), None, "a 3 s gap is not interpolated");
        assert_eq!(track.at(5.0), Some(Pose2::new(5.0, 0.0, 0.0)));
        assert_eq!(
            track
                .samples(&[(0.0, Pose2::default()), (2.0, Pose2::default())])
                .len(),
            1
        );
    }

    #[test]
    fn metrics_of_a_shifted_trajectory_are_its_drift() {
        let truth: Vec<TruePosRecord> = (0..11).map(|k| rec(k as f64, k as f64, 0.0)).collect();
        let track = TruthTrack::new(&truth);
        // an estimate that starts right and drifts 1 cm per step sideways
        let est: Vec<(f64, Pose2)> = (0..11)
            .map(|k| (k as f64, Pose2::new(k as f64, 0.01 * k as f64, 0.0)))
            .collect();
        let m = track.metrics("x", &est).unwrap();
        assert_eq!(m.estimates, 11);
        assert!((m.rpe_trans_m.unwrap() - 0.01).abs() < 1e-9, "{m:?}");
        let rms = ((0..11).map(|k| (0.01 * k as f64).powi(2)).sum::<f64>() / 11.0).sqrt();
        assert!((m.ate_rmse_m.unwrap() - rms).abs() < 1e-9, "{m:?}");
        assert!(track.metrics("x", &[(20.0, Pose2::default())]).is_none());
        // the final trajectory is judged on its own: here the drift smoothed away
        let straight: Vec<(f64, Pose2)> = (0..11)
            .map(|k| (k as f64, Pose2::new(k as f64, 0.0, 0.0)))
            .collect();
        let m = track.slam_metrics("x", &est, &straight).unwrap();
        assert!(m.ate_rmse_m.unwrap() > 0.01);
        let f = m.final_trajectory.unwrap();
        assert_eq!((f.poses, f.ate_rmse_m), (11, Some(0.0)));
    }
}
