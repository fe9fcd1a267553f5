//! What an MCAP file holds once read: its channels, messages and attachments (filled by the
//! linear pass in `super::scan`, opened and decoded through [`super::reader`]).

use std::path::PathBuf;

/// A channel of the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    pub id: u16,
    pub topic: String,
    /// e.g. `sensor_msgs/msg/LaserScan` (empty for a channel without schema).
    pub schema_name: String,
    pub schema_encoding: String,
    pub message_encoding: String,
    /// Messages read on this channel.
    pub message_count: u64,
}

/// One message as stored: its channel (index into [`McapRecording::channels`]) and CDR bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordedMessage {
    pub channel: usize,
    pub sequence: u32,
    pub log_time: u64,
    pub publish_time: u64,
    pub data: Vec<u8>,
}

/// An attachment (e.g. the resolved scenario).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Attachment {
    pub name: String,
    pub media_type: String,
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// The content of an MCAP file, messages in log-time order (file order among equal times).
#[derive(Debug, Clone, Default)]
pub struct McapRecording {
    pub path: PathBuf,
    pub profile: String,
    /// In the order the file defines them.
    pub channels: Vec<ChannelInfo>,
    pub messages: Vec<RecordedMessage>,
    pub attachments: Vec<Attachment>,
    /// What a recovering read stopped at (`None`: the whole file was read).
    pub damage: Option<String>,
}
