//! [`RobotBundle`]: the components every simulated robot carries, so a program can spawn one
//! into a world of its own, without the `sim` crate's scenario files. Sensors (laser, encoder,
//! sonar, …), localizers and a navigator are added to the entity as their own components.

use crate::body::{
    DriveCommand, DriveState, Footprint, Kinematics, PhysicsBody, TruePose, TrueTwist,
};
use crate::core::{Pose2, RobotId, RobotIndex};
use crate::eval::RobotMetrics;
use crate::localization::NavBelief;
use crate::navigation::{Behaviour, HeldCommand};
use bevy_ecs::prelude::*;

/// A robot's body, drive and bookkeeping: what the physics, the drivers (behaviour, held
/// commands), the navigation belief and the evaluation of every tick read and write.
#[derive(Bundle)]
pub struct RobotBundle {
    pub id: RobotId,
    /// Its place in the world's robot list (the physics and the recordings order by it).
    pub index: RobotIndex,
    pub truth: TruePose,
    pub twist: TrueTwist,
    pub footprint: Footprint,
    pub kinematics: Kinematics,
    pub command: DriveCommand,
    pub held: HeldCommand,
    pub drive: DriveState,
    /// Its rigid body in the world's [`crate::body::Physics`] (`Physics::add_robot`).
    pub body: PhysicsBody,
    pub behaviour: Behaviour,
    /// What the navigation believes the pose is (the start until a localizer says otherwise).
    pub belief: NavBelief,
    pub metrics: RobotMetrics,
}

impl RobotBundle {
    /// Robot `name`, number `index`, standing still at `start`, its `body` already added to the
    /// physics at that pose.
    pub fn new(
        name: impl Into<String>,
        index: u32,
        start: Pose2,
        footprint: Footprint,
        kinematics: Kinematics,
        body: PhysicsBody,
        behaviour: Behaviour,
    ) -> Self {
        RobotBundle {
            id: RobotId(name.into()),
            index: RobotIndex(index),
            truth: TruePose::at(start),
            twist: TrueTwist::default(),
            footprint,
            kinematics,
            command: DriveCommand::default(),
            held: HeldCommand::default(),
            drive: DriveState::default(),
            body,
            behaviour,
            belief: NavBelief {
                pose: start,
                stamp: 0.0,
            },
            metrics: RobotMetrics::default(),
        }
    }
}

#[cfg(test)]
mod faults;
#[cfg(test)]
mod tests;
