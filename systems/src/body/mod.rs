//! Robot bodies: kinematics (differential drive, Ackermann), footprints and the rapier2d bridge
//! that turns drive commands into ground-truth motion with contacts; walking people, the other
//! bodies that bridge moves.

pub mod footprint;
pub mod kinematics;
pub mod people;
pub mod physics;
pub mod truth;

pub use footprint::Footprint;
pub use kinematics::{Ackermann, DiffDrive, DriveCommand, DriveState, Kinematics};
pub use people::{PeoplePlugin, Person, PersonId, PersonIndex, Walker};
pub use physics::{Collisions, Physics, PhysicsBody, PhysicsPlugin};
pub use truth::{TruePose, TrueTwist};
