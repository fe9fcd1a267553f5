//! Which estimate a robot navigates by. Without a [`NavSource`] the belief is the wheel
//! odometry. With one, it is the chosen localizer's latest estimate carried forward by the
//! odometry since that estimate's scan — the map → odom correction AMCL publishes (ROS
//! `amcl`, "map → odom transform"): belief = (estimate ⊖ odometry at the scan) ⊕ odometry now.
//! So the controller sees a pose at every tick, not only at scan times, and one that does not
//! drift between scans.

use super::localizer::Localizers;
use super::odometry::{NavBelief, WheelOdometry};
use crate::core::Pose2;
use bevy_ecs::prelude::*;

#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct NavSource {
    /// Index into the robot's [`Localizers`].
    pub localizer: usize,
    /// The latest map → odom correction.
    pub correction: Pose2,
    /// Stamp of the estimate the correction comes from (−∞ before the first one).
    pub stamp: f64,
}

impl NavSource {
    pub fn new(localizer: usize) -> Self {
        NavSource {
            localizer,
            correction: Pose2::IDENTITY,
            stamp: f64::NEG_INFINITY,
        }
    }
}

/// Estimate (after the localizers): the navigation belief from the chosen localizer.
pub fn fuse_nav_belief(
    mut robots: Query<(&Localizers, &WheelOdometry, &mut NavSource, &mut NavBelief)>,
) {
    for (locs, odom, mut src, mut belief) in robots.iter_mut() {
        if let Some(latest) = locs.items.get(src.localizer).and_then(|l| l.latest)
            && latest.stamp > src.stamp
        {
            let at = odom.pose_at(latest.stamp);
            src.correction = latest.estimate.pose.compose(&at.inverse());
            src.stamp = latest.stamp;
        }
        belief.pose = src.correction.compose(&odom.pose);
        belief.stamp = odom.stamp;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_correction_carries_the_estimate_forward() {
        // odometry says (1, 0, 0) at the scan; the localizer says (1.2, 0.1, 0.05)
        let odom_at = Pose2::new(1.0, 0.0, 0.0);
        let est = Pose2::new(1.2, 0.1, 0.05);
        let corr = est.compose(&odom_at.inverse());
        // the robot then drives 1 m straight on by odometry
        let odom_now = odom_at.compose(&Pose2::new(1.0, 0.0, 0.0));
        let b = corr.compose(&odom_now);
        let want = est.compose(&Pose2::new(1.0, 0.0, 0.0));
        assert!((b.x - want.x).abs() < 1e-12 && (b.y - want.y).abs() < 1e-12);
        assert!((b.theta - want.theta).abs() < 1e-12);
    }
}
