//! What the recorder hands its writer thread: batches of operations (messages, schemas,
//! channels, attachments, flushes), the constants both sides share, and the statistics the
//! thread returns. A leaf, so the recorder and the thread import it and not each other.

use crate::record::mcap::cdr;
use crate::record::mcap::schema::RosMessage;
use std::sync::mpsc;

/// The message encoding of the `ros2` profile.
pub const MESSAGE_ENCODING: &str = "cdr";
/// Default automatic flush period (ns of log time).
pub const DEFAULT_FLUSH_PERIOD_NS: u64 = 10_000_000_000;

/// Where an MCAP file goes: a file, or a test's stand-in.
pub(crate) trait Output: std::io::Write + std::io::Seek + Send {}
impl<T: std::io::Write + std::io::Seek + Send> Output for T {}

/// What `McapRecorder::finish` wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct McapStats {
    pub messages: u64,
    pub channels: usize,
    pub chunks: usize,
    pub attachments: usize,
}

/// Operations for the writer thread, in order; message payloads lie in [`Batch::data`].
#[derive(Default)]
pub(super) struct Batch {
    pub(super) ops: Vec<Op>,
    pub(super) data: Vec<u8>,
}

pub(super) type Reply<T> = mpsc::Sender<anyhow::Result<T>>;

pub(super) enum Op {
    /// A message whose payload ends at `end` in the batch's data (and starts where the
    /// previous message's ended, or at 0).
    Message {
        channel: u16,
        log_time: u64,
        end: usize,
    },
    /// A message the writer thread encodes ([`McapRecorder::write_owned`]).
    Owned {
        channel: u16,
        log_time: u64,
        msg: Box<dyn Encode>,
    },
    Schema {
        id: u16,
        name: &'static str,
        definition: &'static str,
    },
    Channel {
        id: u16,
        schema: u16,
        topic: String,
    },
    Attach {
        name: String,
        media_type: String,
        data: Vec<u8>,
    },
    FlushPeriod(Option<u64>),
    Flush(Reply<()>),
    /// Stop as a dying process would: no summary, buffered bytes lost (tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Abandon,
}

/// A message to encode later, on the writer thread.
pub(super) trait Encode: Send + Sync {
    /// Its CDR payload, into `out` (cleared first).
    fn encode_into(&self, out: &mut Vec<u8>);
}

impl<T: RosMessage + Send + Sync> Encode for T {
    fn encode_into(&self, out: &mut Vec<u8>) {
        cdr::encode_into(out, self);
    }
}
