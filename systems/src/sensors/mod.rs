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

use crate::core::{Chained, SimPlugin, SimSet, any_with};
use bevy_ecs::prelude::*;

pub struct SensorsPlugin;

impl SimPlugin for SensorsPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.init_resource::<others::RobotOutlines>();
        let lasers = any_with::<Laser>(world);
        let sonars = any_with::<Sonars>(world);
        Chained::new()
            // the outlines of the others are what lasers and sonars see besides walls
            .add(lasers || sonars, others::update_robot_outlines)
            .add(lasers, laser::sample_lasers)
            .add(sonars, sonar::sample_sonars)
            .add(any_with::<Encoder>(world), encoder::sample_encoders)
            .add(any_with::<Gps>(world), gps::sample_gps)
            .add(any_with::<Compass>(world), compass::sample_compasses)
            .add(any_with::<Camera>(world), camera::sample_cameras)
            .add_to(schedule, SimSet::Sense);
    }
}
