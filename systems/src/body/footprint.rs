//! Robot footprints (the outline physics and other robots' lasers see).

use crate::core::Pose2;
use bevy_ecs::prelude::Component;

#[derive(Component, Clone, Debug, PartialEq)]
pub enum Footprint {
    Circle {
        radius: f64,
    },
    /// A rectangle centred on the base frame, `length` along x, `width` along y.
    Rectangle {
        length: f64,
        width: f64,
    },
}

impl Footprint {
    /// Radius of the smallest disc around the base frame containing the footprint.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Footprint::Circle { radius } => *radius,
            Footprint::Rectangle { length, width } => (length / 2.0).hypot(width / 2.0),
        }
    }

    /// Outline vertices in the world for a pose (a 16-gon for circles).
    pub fn outline(&self, pose: &Pose2) -> Vec<[f64; 2]> {
        match self {
            Footprint::Circle { radius } => (0..16)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / 16.0;
                    pose.transform_point([radius * a.cos(), radius * a.sin()])
                })
                .collect(),
            Footprint::Rectangle { length, width } => {
                let (hx, hy) = (length / 2.0, width / 2.0);
                [[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]]
                    .iter()
                    .map(|p| pose.transform_point(*p))
                    .collect()
            }
        }
    }
}
