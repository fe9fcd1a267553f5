//! `tf2_msgs/msg/TFMessage` (ros2/geometry2 `tf2_msgs/msg/TFMessage.msg`), the message of the
//! `/tf` and `/tf_static` topics.

use super::geometry_msgs::TransformStamped;
use serde::{Deserialize, Serialize};

/// `tf2_msgs/msg/TFMessage`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct TFMessage {
    pub transforms: Vec<TransformStamped>,
}
