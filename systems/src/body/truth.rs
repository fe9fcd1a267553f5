//! Ground truth of a body's motion, the components physics writes every tick and sensors,
//! people and evaluation read. A leaf of its own so that physics (which moves people) and
//! people (who read everyone's pose) both use it without importing each other.

use crate::core::Pose2;
use bevy_ecs::prelude::Component;

/// Ground-truth pose (never read by estimators, planners or controllers). `prev` is the pose at
/// the start of the current tick, so sensors firing between ticks can interpolate.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct TruePose {
    pub pose: Pose2,
    pub prev: Pose2,
}

impl TruePose {
    pub fn at(pose: Pose2) -> Self {
        TruePose { pose, prev: pose }
    }

    /// Pose at fraction `f` ∈ [0, 1] of the current tick.
    pub fn interpolate(&self, f: f64) -> Pose2 {
        self.prev.lerp(&self.pose, f)
    }
}

/// Ground-truth body twist over the last tick (m/s, rad/s).
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct TrueTwist {
    pub v: f64,
    pub w: f64,
}
