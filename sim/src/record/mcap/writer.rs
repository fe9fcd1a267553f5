//! Writing MCAP files of ROS 2 messages (MCAP spec: <https://mcap.dev/spec>, `ros2` profile:
//! schema encoding `ros2msg`, message encoding `cdr`), through the `mcap` crate's chunked,
//! indexed writer with lz4 chunk compression.
//!
//! Streaming: messages go into a chunk that is compressed as it fills and written straight to
//! the file; a chunk ends when it holds 1 MiB (uncompressed), at [`McapRecorder::flush`], and
//! automatically once the log time has moved on by the flush period (10 s by default) since
//! the last flush. Every ended chunk is on disk, so a run that dies leaves a file whose
//! complete chunks [`super::McapRecording::open_recovering`] reads back. [`McapRecorder::finish`]
//! writes the summary (schemas, channels, statistics, chunk and attachment indexes) and the
//! footer; dropping the recorder without it does the same, ignoring errors.

use super::cdr;
use super::schema::{RosMessage, SCHEMA_ENCODING};
use anyhow::anyhow;
use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

/// The MCAP profile of ROS 2 recordings.
pub const ROS2_PROFILE: &str = "ros2";
/// The message encoding of the `ros2` profile.
pub const MESSAGE_ENCODING: &str = "cdr";
/// Default automatic flush period (ns of log time).
pub const DEFAULT_FLUSH_PERIOD_NS: u64 = 10_000_000_000;

/// A registered topic whose messages are of type `T`.
pub struct Channel<T> {
    id: u16,
    _type: PhantomData<fn(&T)>,
}

impl<T> Clone for Channel<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Channel<T> {}

impl<T> Channel<T> {
    /// The MCAP channel id.
    pub fn id(&self) -> u16 {
        self.id
    }
}

/// What [`McapRecorder::finish`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct McapStats {
    pub messages: u64,
    pub channels: usize,
    pub chunks: usize,
    pub attachments: usize,
}

/// An MCAP file being written. See the module doc.
pub struct McapRecorder {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    /// Schema id per schema name.
    schemas: HashMap<&'static str, u16>,
    /// (channel id, schema name) per topic.
    topics: HashMap<String, (u16, &'static str)>,
    /// Next sequence number per channel id.
    sequences: HashMap<u16, u32>,
    buf: Vec<u8>,
    flush_period_ns: Option<u64>,
    last_flush_ns: Option<u64>,
    latest_ns: u64,
}

impl McapRecorder {
    /// Creates (truncates) `path` and writes the MCAP header with `profile` (use
    /// [`ROS2_PROFILE`]).
    pub fn create(path: &Path, profile: &str) -> anyhow::Result<Self> {
        let file = File::create(path)
            .map_err(|e| anyhow!("{}: cannot create the MCAP file: {e}", path.display()))?;
        let options = mcap::WriteOptions::new()
            .profile(profile)
            .library(format!(
                "sim {} (mcap-rust {})",
                env!("CARGO_PKG_VERSION"),
                mcap::VERSION
            ))
            .compression(Some(mcap::Compression::Lz4));
        let writer = options
            .create(BufWriter::with_capacity(1 << 16, file))
            .map_err(|e| anyhow!("{}: cannot start the MCAP file: {e}", path.display()))?;
        Ok(McapRecorder {
            path: path.to_path_buf(),
            writer,
            schemas: HashMap::new(),
            topics: HashMap::new(),
            sequences: HashMap::new(),
            buf: Vec::new(),
            flush_period_ns: Some(DEFAULT_FLUSH_PERIOD_NS),
            last_flush_ns: None,
            latest_ns: 0,
        })
    }

    /// Sets the automatic flush period in ns of log time (`None`: only explicit flushes).
    pub fn set_flush_period(&mut self, period_ns: Option<u64>) {
        self.flush_period_ns = period_ns;
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn error(&self, what: &str, e: impl std::fmt::Display) -> anyhow::Error {
        anyhow!("{}: cannot {what}: {e}", self.path.display())
    }

    /// Registers `topic` for messages of type `T` (the schema is written once per type).
    /// Asking again for the same topic and type gives the same channel; another type is an
    /// error.
    pub fn channel<T: RosMessage>(&mut self, topic: &str) -> anyhow::Result<Channel<T>> {
        if let Some(&(id, name)) = self.topics.get(topic) {
            if name != T::NAME {
                return Err(anyhow!(
                    "{}: topic {topic} already carries {name}, not {}",
                    self.path.display(),
                    T::NAME
                ));
            }
            return Ok(Channel {
                id,
                _type: PhantomData,
            });
        }
        let schema = match self.schemas.get(T::NAME) {
            Some(&id) => id,
            None => {
                let id = self
                    .writer
                    .add_schema(T::NAME, SCHEMA_ENCODING, T::DEFINITION.as_bytes())
                    .map_err(|e| self.error(&format!("add the schema {}", T::NAME), e))?;
                self.schemas.insert(T::NAME, id);
                id
            }
        };
        // The `ros2` profile requires this key; empty means "no recorded QoS", which rosbag2
        // reads as its default profile.
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), String::new())]);
        let id = self
            .writer
            .add_channel(schema, topic, MESSAGE_ENCODING, &metadata)
            .map_err(|e| self.error(&format!("add the channel {topic}"), e))?;
        self.topics.insert(topic.to_string(), (id, T::NAME));
        Ok(Channel {
            id,
            _type: PhantomData,
        })
    }

    /// Writes `msg` on `channel` at `log_time_ns` (also its publish time). Messages may come in
    /// any time order; readers sort them.
    pub fn write<T: RosMessage>(
        &mut self,
        channel: Channel<T>,
        log_time_ns: u64,
        msg: &T,
    ) -> anyhow::Result<()> {
        cdr::encode_into(&mut self.buf, msg);
        let seq = self.sequences.entry(channel.id).or_insert(0);
        let header = mcap::records::MessageHeader {
            channel_id: channel.id,
            sequence: *seq,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        *seq = seq.wrapping_add(1);
        self.writer
            .write_to_known_channel(&header, &self.buf)
            .map_err(|e| anyhow!("{}: cannot write a message: {e}", self.path.display()))?;
        self.latest_ns = self.latest_ns.max(log_time_ns);
        let last = *self.last_flush_ns.get_or_insert(log_time_ns);
        if self
            .flush_period_ns
            .is_some_and(|p| log_time_ns.saturating_sub(last) >= p)
        {
            self.flush()?;
        }
        Ok(())
    }

    /// Adds an attachment (e.g. the resolved scenario, `application/toml`), stamped with the
    /// latest log time written so far. Ends the current chunk.
    pub fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> anyhow::Result<()> {
        let attachment = mcap::Attachment {
            log_time: self.latest_ns,
            create_time: self.latest_ns,
            name: name.to_string(),
            media_type: media_type.to_string(),
            data: std::borrow::Cow::Borrowed(data),
        };
        self.writer
            .attach(&attachment)
            .map_err(|e| self.error(&format!("attach {name}"), e))
    }

    /// Ends the current chunk and hands everything written to the OS, so the file is readable
    /// up to here even if the process dies next.
    pub fn flush(&mut self) -> anyhow::Result<()> {
        self.last_flush_ns = Some(self.latest_ns);
        self.writer.flush().map_err(|e| self.error("flush", e))
    }

    /// Writes the summary and the footer and closes the file.
    pub fn finish(mut self) -> anyhow::Result<McapStats> {
        let summary = self
            .writer
            .finish()
            .map_err(|e| self.error("finish the MCAP file", e))?;
        let McapRecorder { path, writer, .. } = self;
        writer.into_inner().into_inner().map_err(|e| {
            anyhow!(
                "{}: cannot write the MCAP file: {}",
                path.display(),
                e.error()
            )
        })?;
        let stats = summary.stats.unwrap_or_default();
        Ok(McapStats {
            messages: stats.message_count,
            channels: stats.channel_count as usize,
            chunks: summary.chunk_indexes.len(),
            attachments: summary.attachment_indexes.len(),
        })
    }
}
