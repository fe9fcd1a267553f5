//! `nav_msgs/msg/Odometry` (ros2/common_interfaces `nav_msgs/msg/Odometry.msg`).

use super::geometry_msgs::{PoseWithCovariance, TwistWithCovariance};
use super::std_msgs::Header;
use serde::{Deserialize, Serialize};

/// `nav_msgs/msg/Odometry`: the pose in `header.frame_id`, the twist in `child_frame_id`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct Odometry {
    pub header: Header,
    pub child_frame_id: String,
    pub pose: PoseWithCovariance,
    pub twist: TwistWithCovariance,
}
