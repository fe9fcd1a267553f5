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
//!
//! Threads: the caller only encodes messages (CDR) into a batch; compression, checksums and
//! file writes happen on a writer thread of the recorder ([`file`]), which takes the batches
//! in order (at most [`QUEUED_BATCHES`] waiting, so memory stays bounded). A large message (a
//! camera image) is better handed over whole ([`McapRecorder::write_owned`]): the writer
//! thread encodes it, so the caller does not copy its payload. The file is the same as if
//! written on the caller's thread. A write error is reported by the next
//! [`McapRecorder::flush`] or by [`McapRecorder::finish`]; nothing is written after it.

use super::cdr;
use super::schema::RosMessage;
use anyhow::anyhow;
use std::collections::HashMap;
use std::fs::File;
use std::io::BufWriter;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, mpsc};
use std::thread::JoinHandle;

mod file;
mod ops;

use file::FileWriter;
pub(crate) use ops::Output;
use ops::{Batch, Op, Reply};
pub use ops::{DEFAULT_FLUSH_PERIOD_NS, MESSAGE_ENCODING, McapStats};

/// The MCAP profile of ROS 2 recordings.
pub const ROS2_PROFILE: &str = "ros2";
/// A batch goes to the writer thread when its payloads reach this size (bytes) ...
const BATCH_BYTES: usize = 256 * 1024;
/// ... or it holds this many operations.
const BATCH_OPS: usize = 2048;
/// Batches waiting for the writer thread at most (the caller waits when there are more).
pub const QUEUED_BATCHES: usize = 8;

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

/// An MCAP file being written. See the module doc.
pub struct McapRecorder {
    path: PathBuf,
    /// Schema id per schema name.
    schemas: HashMap<&'static str, u16>,
    /// (channel id, schema name) per topic.
    topics: HashMap<String, (u16, &'static str)>,
    /// What is gathered for the writer thread.
    batch: Batch,
    jobs: Option<mpsc::SyncSender<Batch>>,
    /// Batches the writer thread is done with, emptied, for their allocations (a batch that
    /// grew from nothing each time would copy its data over and over as it grew). In a mutex
    /// only because a resource must be `Sync`; reached through `&mut`.
    spare: Mutex<mpsc::Receiver<Batch>>,
    worker: Option<JoinHandle<anyhow::Result<McapStats>>>,
}

impl McapRecorder {
    /// Creates (truncates) `path` and writes the MCAP header with `profile` (use
    /// [`ROS2_PROFILE`]).
    pub fn create(path: &Path, profile: &str) -> anyhow::Result<Self> {
        let file = File::create(path)
            .map_err(|e| anyhow!("{}: cannot create the MCAP file: {e}", path.display()))?;
        Self::create_on(path, Box::new(file), profile)
    }

    /// [`McapRecorder::create`] writing to `out` (`path` names it in messages).
    pub(crate) fn create_on(
        path: &Path,
        out: Box<dyn Output>,
        profile: &str,
    ) -> anyhow::Result<Self> {
        let options = mcap::WriteOptions::new()
            .profile(profile)
            .library(format!(
                "sim {} (mcap-rust {})",
                env!("CARGO_PKG_VERSION"),
                mcap::VERSION
            ))
            .compression(Some(mcap::Compression::Lz4));
        let writer = options
            .create(BufWriter::with_capacity(1 << 16, out))
            .map_err(|e| anyhow!("{}: cannot start the MCAP file: {e}", path.display()))?;
        let file = FileWriter::new(path.to_path_buf(), writer);
        let (jobs, queue) = mpsc::sync_channel(QUEUED_BATCHES);
        let (done, spare) = mpsc::channel();
        let worker =
            crate::record::priority::spawn("mcap writer", move || file.run(queue, done))
                .map_err(|e| anyhow!("{}: cannot start the writer thread: {e}", path.display()))?;
        Ok(McapRecorder {
            path: path.to_path_buf(),
            schemas: HashMap::new(),
            topics: HashMap::new(),
            batch: Batch::default(),
            jobs: Some(jobs),
            spare: Mutex::new(spare),
            worker: Some(worker),
        })
    }

    /// Sets the automatic flush period in ns of log time (`None`: only explicit flushes).
    pub fn set_flush_period(&mut self, period_ns: Option<u64>) {
        self.batch.ops.push(Op::FlushPeriod(period_ns));
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Hands the batch to the writer thread; an error if the thread has ended (its own error).
    fn send(&mut self) -> anyhow::Result<()> {
        if self.batch.ops.is_empty() {
            return Ok(());
        }
        let spare = self.spare.get_mut().unwrap_or_else(|e| e.into_inner());
        let next = spare.try_recv().unwrap_or_default();
        let batch = std::mem::replace(&mut self.batch, next);
        let sent = self.jobs.as_ref().is_some_and(|j| j.send(batch).is_ok());
        if sent { Ok(()) } else { Err(self.stopped()) }
    }

    /// Tells the writer thread that nothing more comes and waits for it: what it returned
    /// (the file's statistics or its first error).
    fn hang_up(&mut self) -> anyhow::Result<McapStats> {
        self.jobs = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(anyhow!(
                "{}: the MCAP writer thread panicked",
                self.path.display()
            )),
            None => Err(anyhow!(
                "{}: the MCAP writer has stopped",
                self.path.display()
            )),
        }
    }

    /// Why the writer thread is gone.
    fn stopped(&mut self) -> anyhow::Error {
        match self.hang_up() {
            Err(e) => e,
            Ok(_) => anyhow!("{}: the MCAP writer has stopped", self.path.display()),
        }
    }

    /// Sends `op` with the batch and waits for the writer thread's answer.
    fn ask<T>(&mut self, op: impl FnOnce(Reply<T>) -> Op) -> anyhow::Result<T> {
        let (reply, answer) = mpsc::channel();
        self.batch.ops.push(op(reply));
        self.send()?;
        match answer.recv() {
            Ok(result) => result,
            Err(_) => Err(self.stopped()),
        }
    }

    /// Registers `topic` for messages of type `T` (the schema is written once per type).
    /// Asking again for the same topic and type gives the same channel; another type is an
    /// error. The records are written by the writer thread, which reports a failure like a
    /// write error (at the next [`McapRecorder::flush`] or at [`McapRecorder::finish`]).
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
        // ids are given here, as `mcap`'s own allocator would give them (from 1, in order of
        // registration), so registering never waits for the writer thread
        let schema = match self.schemas.get(T::NAME) {
            Some(&id) => id,
            None => {
                let id = u16::try_from(self.schemas.len() + 1)
                    .map_err(|_| anyhow!("{}: too many schemas", self.path.display()))?;
                self.batch.ops.push(Op::Schema {
                    id,
                    name: T::NAME,
                    definition: T::DEFINITION,
                });
                self.schemas.insert(T::NAME, id);
                id
            }
        };
        let id = u16::try_from(self.topics.len() + 1)
            .map_err(|_| anyhow!("{}: too many channels", self.path.display()))?;
        self.batch.ops.push(Op::Channel {
            id,
            schema,
            topic: topic.to_string(),
        });
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
        cdr::encode_append(&mut self.batch.data, msg);
        self.batch.ops.push(Op::Message {
            channel: channel.id,
            log_time: log_time_ns,
            end: self.batch.data.len(),
        });
        if self.batch.data.len() >= BATCH_BYTES || self.batch.ops.len() >= BATCH_OPS {
            self.send()?;
        }
        Ok(())
    }

    /// [`McapRecorder::write`] for a message taken whole: it is encoded on the writer thread,
    /// so a large payload (an image) is neither copied nor encoded by the caller. The file is
    /// the same as with [`McapRecorder::write`].
    pub fn write_owned<T: RosMessage + Send + Sync + 'static>(
        &mut self,
        channel: Channel<T>,
        log_time_ns: u64,
        msg: T,
    ) -> anyhow::Result<()> {
        self.batch.ops.push(Op::Owned {
            channel: channel.id,
            log_time: log_time_ns,
            msg: Box::new(msg),
        });
        if self.batch.ops.len() >= BATCH_OPS {
            self.send()?;
        }
        Ok(())
    }

    /// Adds an attachment (e.g. the resolved scenario, `application/toml`), stamped with the
    /// latest log time written so far. Ends the current chunk.
    pub fn attach(&mut self, name: &str, media_type: &str, data: &[u8]) -> anyhow::Result<()> {
        self.batch.ops.push(Op::Attach {
            name: name.to_string(),
            media_type: media_type.to_string(),
            data: data.to_vec(),
        });
        Ok(())
    }

    /// Ends the current chunk and hands everything written to the OS, so the file is readable
    /// up to here even if the process dies next; the first write error so far, if any.
    pub fn flush(&mut self) -> anyhow::Result<()> {
        self.ask(Op::Flush)
    }

    /// Writes the summary and the footer and closes the file.
    pub fn finish(mut self) -> anyhow::Result<McapStats> {
        self.send()?;
        self.hang_up()
    }

    /// Stops writing as a process that dies here would: what the writer thread had ended
    /// (flushed chunks) stays, the rest is lost, and there is no summary.
    #[cfg(test)]
    pub(crate) fn abandon(mut self) {
        self.batch.ops.push(Op::Abandon);
        let _ = self.send();
        let _ = self.hang_up();
    }
}

impl Drop for McapRecorder {
    /// Finishes the file as [`McapRecorder::finish`] does, ignoring errors.
    fn drop(&mut self) {
        if self.worker.is_some() {
            let _ = self.send();
            let _ = self.hang_up();
        }
    }
}
