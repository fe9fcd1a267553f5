//! MCAP recordings of ROS 2 messages (DESIGN.md, "Formats to speak": replays), without a ROS
//! installation: serde mirrors of the messages ([`messages`]), their `ros2msg` schemas
//! ([`schema`]), CDR payloads ([`cdr`]), an MCAP writer ([`writer`]) and reader ([`reader`]),
//! and the rule of its time stamps ([`sim_time`]). What a run records: [`crate::mcap_out`].
//! Specs: MCAP <https://mcap.dev/spec> and its `ros2` profile; rosbag2's
//! `docs/message_definition_encoding.md`; the ROS 2 `.msg` definitions (Humble/Jazzy).

pub mod cdr;
pub mod messages;
pub mod reader;
mod scan;
pub mod schema;
pub mod sim_time;
pub mod writer;

pub use cdr::{CdrError, decode, decode_prefix, encode};
pub use reader::{Attachment, ChannelInfo, McapRecording, RecordedMessage};
pub use schema::RosMessage;
pub use sim_time::{stamp_ns, time_on_grid};
pub use writer::{Channel, McapRecorder, McapStats, ROS2_PROFILE};

#[cfg(test)]
mod samples;
#[cfg(test)]
mod tests;
