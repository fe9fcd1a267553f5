//! The linear pass of the MCAP reader over an MCAP file in memory (MCAP spec:
//! <https://mcap.dev/spec>, "Reading"): the `mcap` crate's sans-io linear reader with every CRC
//! check on, the records collected into a [`McapRecording`], and its errors put in words.

use super::recording::{Attachment, ChannelInfo, McapRecording, RecordedMessage};
use mcap::McapError;
use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::HashMap;
use std::collections::hash_map::Entry;

/// What an error of the linear reader means for the file.
fn describe(e: &McapError, records: usize, len: usize) -> String {
    match e {
        McapError::BadMagic if records == 0 => {
            "not an MCAP file (no MCAP magic at the start)".into()
        }
        McapError::UnexpectedEof if len < mcap::MAGIC.len() => {
            format!("not an MCAP file ({len} bytes, too short for the MCAP magic)")
        }
        McapError::UnexpectedEof if records == 0 => {
            "truncated MCAP file: it ends before its header record".into()
        }
        McapError::UnexpectedEof => {
            "truncated MCAP file: it ends in the middle of a record (the writer did not finish)"
                .into()
        }
        McapError::BadMagic => "corrupt MCAP file: no MCAP magic at the end".into(),
        McapError::UnsupportedCompression(c) => format!(
            "its chunks are compressed with `{c}`, which this reader does not support (it \
             reads uncompressed, lz4 and zstd chunks)"
        ),
        other => format!("corrupt MCAP file: {other}"),
    }
}

/// Whether the file holds a chunk whose header still has the writer's placeholder length
/// (all ones): the chunk being written when the writer stopped.
fn has_unfinished_chunk(bytes: &[u8]) -> bool {
    const PLACEHOLDER: [u8; 9] = [0x06, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff];
    bytes.windows(PLACEHOLDER.len()).any(|w| w == PLACEHOLDER)
}

/// The length an Attachment record's body needs for its header (log time, create time, name,
/// media type, data length) and the CRC after it, when it is shorter than that. The `mcap`
/// crate (0.26) slices past the end of such a body instead of returning an error, so it is
/// checked first.
fn short_attachment(body: &[u8]) -> Option<u64> {
    let len_at = |at: usize| -> u64 {
        body.get(at..at + 4)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64)
    };
    let name_end = 16 + 4 + len_at(16);
    let media_end = name_end + 4 + len_at(name_end as usize);
    let needed = media_end + 8 + 4;
    (needed > body.len() as u64).then_some(needed)
}

/// Largest decompressed chunk accepted (the writer's are about 1 MiB), so a corrupt length
/// cannot make the reader allocate more.
const MAX_CHUNK: usize = 1 << 28;

/// Schemas seen so far and where the reader is.
#[derive(Default)]
pub(super) struct ReadState {
    /// Schema id → (name, encoding).
    schemas: HashMap<u16, (String, String)>,
    /// Channel id → index into the recording's channels.
    channels: HashMap<u16, usize>,
    /// Records read (the header counts: past it, the file is MCAP).
    pub(super) records: usize,
    past_data_end: bool,
}

impl ReadState {
    /// Reads `bytes` into `rec`; on damage, says what it is.
    pub(super) fn scan(&mut self, rec: &mut McapRecording, bytes: &[u8]) -> Result<(), String> {
        let stats = self.records_of(rec, bytes).map_err(|e| {
            if !self.past_data_end && has_unfinished_chunk(bytes) {
                "truncated MCAP file: it ends in a chunk the writer never finished (the \
                 recording was interrupted)"
                    .into()
            } else {
                describe(&e, self.records, bytes.len())
            }
        })?;
        match stats {
            Some(n) if n != rec.messages.len() as u64 => Err(format!(
                "corrupt MCAP file: its statistics count {n} messages, its chunks hold {}",
                rec.messages.len()
            )),
            _ => Ok(()),
        }
    }

    /// The linear pass; returns the message count of the statistics record, if any.
    fn records_of(
        &mut self,
        rec: &mut McapRecording,
        bytes: &[u8],
    ) -> Result<Option<u64>, McapError> {
        let options = LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(bytes.len().max(MAX_CHUNK));
        let mut reader = LinearReader::new_with_options(options);
        let mut rest = bytes;
        let mut stats = None;
        while let Some(event) = reader.next_event() {
            match event? {
                LinearReadEvent::ReadRequest(need) => {
                    let n = need.min(rest.len());
                    reader.insert(n).copy_from_slice(&rest[..n]);
                    reader.notify_read(n);
                    rest = &rest[n..];
                }
                LinearReadEvent::Record { opcode, data } => {
                    if opcode == mcap::records::op::ATTACHMENT
                        && let Some(needed) = short_attachment(data)
                    {
                        return Err(McapError::BadAttachmentLength {
                            header: needed,
                            available: data.len() as u64,
                        });
                    }
                    let record = mcap::parse_record(opcode, data)?;
                    self.records += 1;
                    if let Record::Statistics(s) = &record {
                        stats = Some(s.message_count);
                    }
                    self.add(rec, record)?;
                }
            }
        }
        Ok(stats)
    }

    fn add(&mut self, rec: &mut McapRecording, record: Record<'_>) -> Result<(), McapError> {
        if self.past_data_end {
            return Ok(()); // the summary repeats schemas and channels
        }
        match record {
            Record::Header(h) => rec.profile = h.profile,
            Record::Schema { header, .. } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(c) => {
                let (schema_name, schema_encoding) = match c.schema_id {
                    0 => Default::default(),
                    id => self
                        .schemas
                        .get(&id)
                        .cloned()
                        .ok_or_else(|| McapError::UnknownSchema(c.topic.clone(), id))?,
                };
                if let Entry::Vacant(slot) = self.channels.entry(c.id) {
                    slot.insert(rec.channels.len());
                    rec.channels.push(ChannelInfo {
                        id: c.id,
                        topic: c.topic,
                        schema_name,
                        schema_encoding,
                        message_encoding: c.message_encoding,
                        message_count: 0,
                    });
                }
            }
            Record::Message { header, data } => {
                let &channel =
                    self.channels
                        .get(&header.channel_id)
                        .ok_or(McapError::UnknownChannel(
                            header.sequence,
                            header.channel_id,
                        ))?;
                rec.channels[channel].message_count += 1;
                rec.messages.push(RecordedMessage {
                    channel,
                    sequence: header.sequence,
                    log_time: header.log_time,
                    publish_time: header.publish_time,
                    data: data.into_owned(),
                });
            }
            Record::Attachment { header, data, .. } => rec.attachments.push(Attachment {
                name: header.name,
                media_type: header.media_type,
                log_time: header.log_time,
                data: data.into_owned(),
            }),
            Record::DataEnd(_) => self.past_data_end = true,
            _ => {}
        }
        Ok(())
    }
}
