//! Per-robot, per-localizer accuracy against ground truth: every published estimate is paired
//! with the true pose at its timestamp (interpolated within the tick), and the metrics of
//! [`super::trajectory`] are computed at the end of the run.
//!
//! ATE and RPE cover the samples from convergence on (global localization is not judged on its
//! search); a localizer that never converges is judged on all its samples. The trajectories
//! written for evo hold exactly those samples, so `evo_ape`/`evo_rpe` reproduce the figures.

use super::trajectory::{self, Sample};
use crate::body::TruePose;
use crate::core::SimClock;
use crate::localization::Localizers;
use bevy_ecs::prelude::*;
use serde::Serialize;

/// Seconds of continuous tracking that count as converged.
pub const CONVERGENCE_HOLD_S: f64 = 5.0;

/// The samples of every localizer of a robot, in the order of its `Localizers`.
#[derive(Component, Clone, Debug, Default)]
pub struct LocalizationSamples {
    pub per_localizer: Vec<(String, Vec<Sample>)>,
}

/// The summary figures of one localizer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocalizerMetrics {
    pub kind: String,
    pub estimates: usize,
    pub ate_rmse_m: Option<f64>,
    /// Translation RMSE in the map frame, without alignment.
    pub ate_map_rmse_m: Option<f64>,
    pub rpe_trans_m: Option<f64>,
    pub rpe_rot_rad: Option<f64>,
    /// Simulated time of convergence (s), None if it never converged.
    pub converged_after_s: Option<f64>,
    pub tracked_fraction: Option<f64>,
    /// Position error of the last estimate (m).
    pub final_error_m: Option<f64>,
    /// For SLAM systems: ATE and RPE of the trajectory the system holds at the end of the run
    /// (for graph SLAM, after its last optimization; for filters, the poses they published).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_trajectory: Option<TrajectoryMetrics>,
    /// Whether the estimator localizes in the scenario's map (its error is judged in the map
    /// frame) rather than integrating odometry or building its own map (judged aligned at the
    /// first pose). Set by whoever knows the estimator; false by default.
    #[serde(skip)]
    pub in_map: bool,
}

impl LocalizerMetrics {
    /// The ATE a table shows: the map-frame error for an estimator in the map (aligning its
    /// first pose would turn a half-degree heading error of the first estimate into
    /// decimetres), the origin-aligned one for odometry and SLAM [Grupp 2017].
    pub fn headline_ate(&self) -> Option<f64> {
        if self.in_map {
            self.ate_map_rmse_m
        } else {
            self.ate_rmse_m
        }
    }
}

/// ATE/RPE of a whole trajectory (same definitions as [`LocalizerMetrics`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TrajectoryMetrics {
    pub poses: usize,
    pub ate_rmse_m: Option<f64>,
    pub rpe_trans_m: Option<f64>,
    pub rpe_rot_rad: Option<f64>,
}

impl TrajectoryMetrics {
    pub fn from_samples(samples: &[Sample]) -> Self {
        let rpe = trajectory::rpe_consecutive(samples);
        TrajectoryMetrics {
            poses: samples.len(),
            ate_rmse_m: trajectory::ate_align_origin(samples),
            rpe_trans_m: rpe.map(|r| r.0),
            rpe_rot_rad: rpe.map(|r| r.1),
        }
    }
}

/// `trajectory` (stamp, pose) paired with the true poses of `samples` at the same stamps (the
/// online samples of the same estimator, which hold the truth at every scan it consumed);
/// stamps without a sample are left out.
pub fn pair_with_truth(
    samples: &[Sample],
    trajectory: &[(f64, crate::core::Pose2)],
) -> Vec<Sample> {
    trajectory
        .iter()
        .filter_map(|&(t, pose)| {
            let i = samples.partition_point(|s| s.t < t - 1e-9);
            let s = samples.get(i).filter(|s| (s.t - t).abs() <= 1e-9)?;
            Some(Sample {
                t,
                estimate: pose,
                truth: s.truth,
                spread_m: 0.0,
            })
        })
        .collect()
}

/// The samples the ATE/RPE figures (and the written trajectories) use.
pub fn judged_samples(samples: &[Sample]) -> &[Sample] {
    match trajectory::convergence_index(samples, CONVERGENCE_HOLD_S) {
        Some(i) => &samples[i..],
        None => samples,
    }
}

impl LocalizerMetrics {
    pub fn from_samples(kind: &str, samples: &[Sample]) -> Self {
        let conv = trajectory::convergence_index(samples, CONVERGENCE_HOLD_S);
        let judged = judged_samples(samples);
        let rpe = trajectory::rpe_consecutive(judged);
        LocalizerMetrics {
            kind: kind.to_string(),
            estimates: samples.len(),
            ate_rmse_m: trajectory::ate_align_origin(judged),
            ate_map_rmse_m: trajectory::ate_unaligned(judged),
            rpe_trans_m: rpe.map(|r| r.0),
            rpe_rot_rad: rpe.map(|r| r.1),
            converged_after_s: conv.map(|i| samples[i].t),
            tracked_fraction: trajectory::tracked_fraction(samples),
            final_error_m: samples.last().map(Sample::position_error),
            final_trajectory: None,
            in_map: false,
        }
    }
}

/// Evaluate: pair this tick's estimates with the true pose at their timestamps.
pub fn sample_localization(
    clock: Res<SimClock>,
    mut robots: Query<(&Localizers, &TruePose, &mut LocalizationSamples)>,
) {
    let (start, dt) = (clock.start(), clock.dt);
    for (locs, truth, mut out) in robots.iter_mut() {
        if out.per_localizer.len() != locs.items.len() {
            out.per_localizer = locs
                .items
                .iter()
                .map(|l| (l.name.clone(), Vec::new()))
                .collect();
        }
        for (l, (_, samples)) in locs.items.iter().zip(out.per_localizer.iter_mut()) {
            for e in &l.fresh {
                let f = ((e.stamp - start) / dt).clamp(0.0, 1.0);
                samples.push(Sample {
                    t: e.stamp,
                    estimate: e.estimate.pose,
                    truth: truth.interpolate(f),
                    spread_m: e.estimate.position_spread(),
                });
            }
        }
    }
}
