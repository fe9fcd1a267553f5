//! Test support shared by the localizers' tests: the [`super::fixtures`] and an error metric.

pub use super::fixtures::*;
use super::mcl::PoseEstimate;
use crate::core::{Pose2, wrap_angle};

pub fn error(e: &PoseEstimate, truth: &Pose2) -> (f64, f64) {
    (
        e.pose.distance(truth),
        wrap_angle(e.pose.theta - truth.theta).abs(),
    )
}
