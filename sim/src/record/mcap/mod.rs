//! MCAP recordings of ROS 2 messages (the replay format of the recordings documentation), without a ROS
//! installation: serde mirrors of the messages ([`messages`]), their `ros2msg` schemas
//! ([`schema`]), CDR payloads ([`cdr`]), an MCAP writer ([`writer`]) and reader ([`reader`]),
//! and the rule of its time stamps ([`sim_time`]). What a run records: [`crate::record::topics`].
//! Specs: MCAP <https://mcap.dev/spec> and its `ros2` profile; rosbag2's
//! `docs/message_definition_encoding.md`; the ROS 2 `.msg` definitions (Humble/Jazzy).

pub mod cdr;
pub mod messages;
pub mod reader;
pub mod recording;
mod scan;
pub mod schema;
pub mod sim_time;
pub mod writer;

pub use cdr::{CdrError, decode, decode_prefix, encode};
pub use recording::{Attachment, ChannelInfo, McapRecording, RecordedMessage};
pub use schema::RosMessage;
pub use sim_time::{stamp_ns, time_on_grid};
pub use writer::{Channel, McapRecorder, McapStats, ROS2_PROFILE};

#[cfg(test)]
mod samples;
#[cfg(test)]
mod tests;
