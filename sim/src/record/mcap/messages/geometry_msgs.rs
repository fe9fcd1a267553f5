//! `geometry_msgs/msg/*` (ros2/common_interfaces `geometry_msgs/msg/*.msg`): points, rotations,
//! poses, velocities and transforms, with the 6×6 covariances as row-major `float64[36]` in
//! (x, y, z, rotation about X, about Y, about Z).

use super::fixed_array;
use super::std_msgs::Header;
use serde::{Deserialize, Serialize};

/// `geometry_msgs/msg/Point`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion` (the `.msg` defaults are the identity: w = 1).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

impl Quaternion {
    /// A rotation of `yaw` radians about z (a planar heading).
    pub fn from_yaw(yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The rotation about z (exact for planar rotations, the yaw of the ZYX Euler angles
    /// otherwise).
    pub fn yaw(&self) -> f64 {
        let Quaternion { x, y, z, w } = *self;
        (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
    }
}

/// `geometry_msgs/msg/Pose`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

impl Pose {
    /// A planar pose (z = 0, heading `theta` about z).
    pub fn planar(x: f64, y: f64, theta: f64) -> Self {
        Pose {
            position: Point { x, y, z: 0.0 },
            orientation: Quaternion::from_yaw(theta),
        }
    }
}

/// `geometry_msgs/msg/PoseWithCovariance`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct PoseWithCovariance {
    pub pose: Pose,
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        PoseWithCovariance {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/msg/Twist`: linear and angular velocity.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Twist {
    pub linear: Vector3,
    pub angular: Vector3,
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct TwistWithCovariance {
    pub twist: Twist,
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        TwistWithCovariance {
            twist: Twist::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/Transform`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Transform {
    pub translation: Vector3,
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`: the transform from `header.frame_id` to
/// `child_frame_id` at `header.stamp`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    pub transform: Transform,
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_round_trip() {
        for yaw in [0.0, 0.3, -2.0, 3.1] {
            assert!((Quaternion::from_yaw(yaw).yaw() - yaw).abs() < 1e-12);
        }
        assert_eq!(Quaternion::default(), Quaternion::from_yaw(0.0));
    }
}
