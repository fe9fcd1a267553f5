//! Test support shared by the localizers' tests: the [`super::fixtures`], an error metric, and
//! the global-initialisation drive of the DE localizers' tests.

use super::OdometryMotionModel;
pub use super::fixtures::*;
use super::mcl::{BeamSubset, PoseEstimate};
use crate::core::{Pose2, wrap_angle};

pub fn error(e: &PoseEstimate, truth: &Pose2) -> (f64, f64) {
    (
        e.pose.distance(truth),
        wrap_angle(e.pose.theta - truth.theta).abs(),
    )
}

/// The motion model of the DE localizers' convergence tests.
pub fn de_motion() -> OdometryMotionModel {
    OdometryMotionModel {
        alpha1: 0.05,
        alpha2: 0.05,
        alpha3: 0.05,
        alpha4: 0.05,
    }
}

/// The errors (position, heading) of a localizer's estimates along the hospital's corridor
/// drive: `step` takes 60 beams of each scan and the odometry, and returns the new estimate if
/// it made one.
pub fn corridor_errors(
    mut step: impl FnMut(&BeamSubset, &Pose2) -> Option<PoseEstimate>,
) -> Vec<(f64, f64)> {
    let map = hospital();
    let mut errors = Vec::new();
    drive(&map, &CORRIDOR, 0.0, 4, |truth, odom, scan| {
        let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
        if let Some(e) = step(&beams, odom) {
            errors.push(error(&e, truth));
        }
    });
    errors
}

/// (first update from which five in a row are within 0.2 m / 5°, share right after it, count).
pub fn convergence(errors: &[(f64, f64)]) -> (Option<usize>, f64, usize) {
    let ok = |e: &(f64, f64)| e.0 < 0.2 && e.1 < 5f64.to_radians();
    let since = (0..errors.len().saturating_sub(5)).find(|&i| errors[i..i + 5].iter().all(ok));
    let tracked = since.map_or(0.0, |s| {
        errors[s..].iter().filter(|e| ok(e)).count() as f64 / (errors.len() - s) as f64
    });
    (since, tracked, errors.len())
}
