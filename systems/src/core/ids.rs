//! Robot identity.

use bevy_ecs::prelude::Component;

/// A robot's scenario name (unique) — also the key of its random streams and recording paths.
#[derive(Component, Clone, Debug, PartialEq, Eq, Hash)]
pub struct RobotId(pub String);

/// A robot's spawn index: the stable order in which robots are iterated wherever order reaches
/// an output.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RobotIndex(pub u32);
