//! Reading MCAP files of ROS 2 messages back (for `sim replay`): one pass over the whole file
//! in memory with the `mcap` crate's linear reader (MCAP spec: <https://mcap.dev/spec>), which
//! decompresses chunks and checks every CRC the file has (chunks before any of their messages
//! are used, the data section, the summary section).
//!
//! [`McapRecording::open`] accepts only a complete, undamaged file. A recording cut short (the
//! simulator died) or damaged is an error naming the file, what is wrong and how many messages
//! came before; [`McapRecording::open_recovering`] instead keeps the schemas, channels,
//! messages and attachments that precede the damage (the messages of every complete chunk) and
//! says what it stopped at in [`McapRecording::damage`].

use super::cdr;
use super::recording::{Attachment, ChannelInfo, McapRecording, RecordedMessage};
use super::scan::ReadState;
use super::schema::RosMessage;
use super::writer::MESSAGE_ENCODING;
use anyhow::anyhow;
use std::path::Path;
use systems::core::input::{MAX_DATA_BYTES, read_bounded};

impl McapRecording {
    /// Reads a complete MCAP file; any damage is an error.
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        Self::from_bytes(path, &read(path)?, false)
    }

    /// Reads what precedes any damage; an error only if the file cannot be read or is not
    /// MCAP at all.
    pub fn open_recovering(path: &Path) -> anyhow::Result<Self> {
        Self::from_bytes(path, &read(path)?, true)
    }

    /// Reads `bytes` (the content of `path`, which names the file in errors).
    pub fn from_bytes(path: &Path, bytes: &[u8], recover: bool) -> anyhow::Result<Self> {
        let mut rec = McapRecording {
            path: path.to_path_buf(),
            ..Default::default()
        };
        let mut state = ReadState::default();
        if let Err(what) = state.scan(&mut rec, bytes) {
            let n = rec.messages.len();
            if state.records == 0 || !recover {
                return Err(anyhow!(
                    "{}: {what} (after {n} messages{})",
                    path.display(),
                    if n == 0 {
                        ""
                    } else {
                        "; `sim replay --recover` replays them"
                    }
                ));
            }
            rec.damage = Some(what);
        }
        rec.messages.sort_by_key(|m| m.log_time);
        Ok(rec)
    }

    /// The channel of `topic`.
    pub fn channel(&self, topic: &str) -> Option<&ChannelInfo> {
        self.channels.iter().find(|c| c.topic == topic)
    }

    /// The attachment called `name`.
    pub fn attachment(&self, name: &str) -> Option<&Attachment> {
        self.attachments.iter().find(|a| a.name == name)
    }

    /// Decodes `msg` as a `T`, checking that its channel carries `T` in CDR.
    pub fn decode<T: RosMessage>(&self, msg: &RecordedMessage) -> anyhow::Result<T> {
        let ch = &self.channels[msg.channel];
        if ch.schema_name != T::NAME || ch.message_encoding != MESSAGE_ENCODING {
            return Err(anyhow!(
                "{}: topic {} carries `{}` in `{}`, not {} in {MESSAGE_ENCODING}",
                self.path.display(),
                ch.topic,
                ch.schema_name,
                ch.message_encoding,
                T::NAME
            ));
        }
        cdr::decode(&msg.data).map_err(|e| {
            anyhow!(
                "{}: message {} on {} at {} ns: {e}",
                self.path.display(),
                msg.sequence,
                ch.topic,
                msg.log_time
            )
        })
    }

    /// The messages of `topic` decoded as `T`, with their log times, in log-time order.
    pub fn decode_topic<T: RosMessage>(&self, topic: &str) -> anyhow::Result<Vec<(u64, T)>> {
        let Some(index) = self.channels.iter().position(|c| c.topic == topic) else {
            return Err(anyhow!("{}: no topic {topic}", self.path.display()));
        };
        self.messages
            .iter()
            .filter(|m| m.channel == index)
            .map(|m| Ok((m.log_time, self.decode(m)?)))
            .collect()
    }
}

fn read(path: &Path) -> anyhow::Result<Vec<u8>> {
    read_bounded(path, MAX_DATA_BYTES).map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))
}
