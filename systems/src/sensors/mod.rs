//! Sensors: each is a component holding its parameters, its own random stream and rate timer, and
//! a sampling system in [`SimSet::Sense`] that reads ground truth and
//! writes readings shaped like the ROS messages they are recorded as.

pub mod camera;
pub mod compass;
pub mod encoder;
pub mod gps;
pub mod laser;
pub mod others;
pub mod sonar;

pub use camera::{Camera, CameraImage, CameraImages, CameraSpec};
pub use compass::{Compass, CompassReading, CompassReadings, CompassSpec};
pub use encoder::{Encoder, EncoderReading, EncoderReadings, EncoderSpec};
pub use gps::{Gps, GpsFix, GpsReadings, GpsSpec};
pub use laser::{Laser, LaserScan, LaserScans, LaserSpec, LaserTruth};
pub use sonar::{SonarReadings, SonarSpec, SonarTruth, Sonars};

use crate::core::{SimPlugin, SimSet};
use bevy_ecs::prelude::*;

pub struct SensorsPlugin;

impl SimPlugin for SensorsPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.init_resource::<others::RobotOutlines>();
        schedule.add_systems(
            (
                others::update_robot_outlines,
                laser::sample_lasers,
                sonar::sample_sonars,
                encoder::sample_encoders,
                gps::sample_gps,
                compass::sample_compasses,
                camera::sample_cameras,
            )
                .chain()
                .in_set(SimSet::Sense),
        );
    }
}
