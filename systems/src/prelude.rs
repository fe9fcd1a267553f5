//! The names most programs that use `systems` need: `use systems::prelude::*;`.

pub use crate::body::{DriveCommand, Footprint, Kinematics, TruePose, TrueTwist};
pub use crate::core::{Pose2, RobotId, RobotIndex, SimClock, SimPlugin, SimSet};
pub use crate::localization::{
    Localizers, MapLocalizer, PoseEstimate, ScanEstimator, WheelOdometry,
};
pub use crate::navigation::{Behaviour, HeldCommand, Navigator};
pub use crate::robot::RobotBundle;
pub use crate::sensors::{LaserScan, LaserScans, LaserTruth};
