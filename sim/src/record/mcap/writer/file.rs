//! The writer thread of the MCAP recorder: takes the batches in order and writes them
//! through the `mcap` crate's writer (lz4 chunks, checksums, file writes), then the summary.

use super::ops::{Batch, DEFAULT_FLUSH_PERIOD_NS, MESSAGE_ENCODING, McapStats, Op, Output};
use crate::record::mcap::schema::SCHEMA_ENCODING;
use anyhow::anyhow;
use std::collections::{BTreeMap, HashMap};
use std::io::BufWriter;
use std::path::PathBuf;
use std::sync::mpsc;

/// The writer thread's side: the `mcap` writer and what the flush period needs.
pub(super) struct FileWriter {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<Box<dyn Output>>>,
    /// Next sequence number per channel id.
    sequences: HashMap<u16, u32>,
    flush_period_ns: Option<u64>,
    last_flush_ns: Option<u64>,
    latest_ns: u64,
}

impl FileWriter {
    /// The thread's side of a file whose header `writer` has written.
    pub(super) fn new(path: PathBuf, writer: mcap::Writer<BufWriter<Box<dyn Output>>>) -> Self {
        FileWriter {
            path,
            writer,
            sequences: HashMap::new(),
            flush_period_ns: Some(DEFAULT_FLUSH_PERIOD_NS),
            last_flush_ns: None,
            latest_ns: 0,
        }
    }

    /// The writer thread: the batches in order until the recorder hangs up, then the summary.
    /// Each batch done goes back emptied through `done`.
    pub(super) fn run(
        mut self,
        queue: mpsc::Receiver<Batch>,
        done: mpsc::Sender<Batch>,
    ) -> anyhow::Result<McapStats> {
        let mut error: Option<anyhow::Error> = None;
        let mut payload = Vec::new();
        for mut batch in queue {
            let mut start = 0;
            for op in batch.ops.drain(..) {
                match op {
                    Op::Message {
                        channel,
                        log_time,
                        end,
                    } => {
                        let data = &batch.data[start..end];
                        start = end;
                        if error.is_none() {
                            error = self.message(channel, log_time, data).err();
                        }
                    }
                    Op::Owned {
                        channel,
                        log_time,
                        msg,
                    } => {
                        if error.is_none() {
                            msg.encode_into(&mut payload);
                            error = self.message(channel, log_time, &payload).err();
                        }
                    }
                    Op::Abandon => {
                        std::mem::forget(self);
                        return Err(anyhow!("abandoned"));
                    }
                    Op::FlushPeriod(p) => self.flush_period_ns = p,
                    Op::Attach {
                        name,
                        media_type,
                        data,
                    } => {
                        if error.is_none() {
                            error = self.attach(&name, &media_type, &data).err();
                        }
                    }
                    Op::Flush(reply) => {
                        let r = match &error {
                            Some(e) => Err(anyhow!("{e:#}")),
                            None => self.flush(),
                        };
                        if let (None, Err(e)) = (&error, &r) {
                            error = Some(anyhow!("{e:#}"));
                        }
                        let _ = reply.send(r);
                    }
                    Op::Schema {
                        id,
                        name,
                        definition,
                    } => {
                        if error.is_none() {
                            error = self
                                .writer
                                .add_schema_with_id(
                                    id,
                                    name,
                                    SCHEMA_ENCODING,
                                    definition.as_bytes(),
                                )
                                .map_err(|e| self.error(&format!("add the schema {name}"), e))
                                .err();
                        }
                    }
                    Op::Channel { id, schema, topic } => {
                        // The `ros2` profile requires this key; empty means "no recorded QoS",
                        // which rosbag2 reads as its default profile.
                        let metadata =
                            BTreeMap::from([("offered_qos_profiles".to_string(), String::new())]);
                        if error.is_none() {
                            error = self
                                .writer
                                .add_channel_with_id(
                                    id,
                                    schema,
                                    &topic,
                                    MESSAGE_ENCODING,
                                    &metadata,
                                )
                                .map_err(|e| self.error(&format!("add the channel {topic}"), e))
                                .err();
                        }
                    }
                }
            }
            batch.data.clear();
            // the recorder may be gone already (its last batch)
            let _ = done.send(batch);
        }
        match error {
            Some(e) => Err(e),
            None => self.finish(),
        }
    }

    /// The error of `what`, with its causes (the OS error under the mcap crate's I/O error).
    fn error(&self, what: &str, e: impl Into<anyhow::Error>) -> anyhow::Error {
        anyhow!("{}: cannot {what}: {:#}", self.path.display(), e.into())
    }

    fn message(&mut self, channel: u16, log_time: u64, data: &[u8]) -> anyhow::Result<()> {
        let seq = self.sequences.entry(channel).or_insert(0);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: *seq,
            log_time,
            publish_time: log_time,
        };
        *seq = seq.wrapping_add(1);
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(|e| self.error("write a message", e))?;
        self.latest_ns = self.latest_ns.max(log_time);
        let last = *self.last_flush_ns.get_or_insert(log_time);
        if self
            .flush_period_ns
            .is_some_and(|p| log_time.saturating_sub(last) >= p)
        {
            self.flush()?;
        }
        Ok(())
    }

    fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> anyhow::Result<()> {
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

    fn flush(&mut self) -> anyhow::Result<()> {
        self.last_flush_ns = Some(self.latest_ns);
        self.writer.flush().map_err(|e| self.error("flush", e))
    }

    fn finish(mut self) -> anyhow::Result<McapStats> {
        let summary = self
            .writer
            .finish()
            .map_err(|e| self.error("finish the MCAP file", e))?;
        let FileWriter { path, writer, .. } = self;
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
