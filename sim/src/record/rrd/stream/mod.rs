//! The .rrd's rows gathered into Rerun chunks by the recorder itself, column by column.
//!
//! `RecordingStream::log` hands every row to the SDK's batcher thread (a channel send and, as
//! the batcher sleeps between rows, a thread wake-up per row), and a Rerun archetype serializes
//! each of its components to a small Arrow array when it is built (about 5 µs for a row of a
//! few components, most of it allocating those arrays). A fast run logs tens of thousands of
//! rows per simulated minute, so both cost more than the simulation of an outdoor run.
//! [`RrdStream`] keeps the rows of each entity as columns instead:
//! - [`RrdStream::row`] appends plain component values (`Position3D`, `Color`, `Scalar`, …) to
//!   one `Vec` per component; the whole column is serialized once per chunk, so a row costs a
//!   few pushes;
//! - [`RrdStream::log`] takes any archetype (serialized as usual) for the rarer rows.
//!
//! An entity's rows go out as one chunk when they reach [`CHUNK_ROWS`] rows or [`CHUNK_BYTES`]
//! of data or span [`CHUNK_SPAN_S`] of simulated time (so that little is left to build when
//! the run ends), and every entity's when the recording is flushed ([`RrdStream::flush_blocking`],
//! done by `close_recording` at the end of a run, also an interrupted one). A full
//! set of columns goes to a thread of the stream that serializes them, builds the chunk and
//! hands it to the SDK, then sends the emptied columns back: the entity's next rows fill them,
//! so a column does not grow again from nothing (copying itself over and over, on fresh
//! pages) for every chunk.
//!
//! Rows carry only the `sim_time` timeline (no wall-clock `log_time`/`log_tick`), so two runs
//! of a scenario give the same rows and the viewer opens on simulated time.

use rerun::{AsComponents, EntityPath, RecordingStream, RecordingStreamResult};
use std::collections::HashMap;
use std::sync::mpsc;
use std::thread::JoinHandle;

mod columns;
pub mod file_sink;

pub use columns::Row;
use columns::{Columns, Serialized};

/// Rows per chunk at most.
pub const CHUNK_ROWS: usize = 4096;
/// Component data per chunk at most (bytes, approximately).
pub const CHUNK_BYTES: usize = 1 << 20;
/// Simulated time (s) from a chunk's first row to its last at most.
pub const CHUNK_SPAN_S: f64 = 30.0;
/// Full column sets waiting for the chunk thread at most (the caller waits when there are more).
const QUEUED_CHUNKS: usize = 64;

/// A Rerun recording whose temporal rows are chunked here (see the module doc); static rows go
/// straight to the SDK.
pub struct RrdStream {
    rec: RecordingStream,
    /// The `sim_time` of the rows logged next (ns).
    time: i64,
    /// The latest `sim_time` set (ns).
    latest: i64,
    /// Per entity, in the order of their first row.
    pending: Vec<Columns>,
    index: HashMap<String, usize>,
    /// The first error of a row (reported by [`RrdStream::flush_blocking`]).
    error: Option<String>,
    /// The chunk thread: builds chunks and sends them to the SDK; ends with its first error.
    chunks: Option<mpsc::SyncSender<Columns>>,
    chunker: Option<JoinHandle<Option<String>>>,
    /// Columns the chunk thread has emptied, back for their entity's next rows. In a mutex
    /// only because the recorder must be `Sync`; reached through `&mut`.
    emptied: std::sync::Mutex<mpsc::Receiver<Columns>>,
    /// Per entity: emptied columns waiting to be filled.
    spare: Vec<Option<Columns>>,
    /// Column sets with the chunk thread (sent and not back yet).
    out: usize,
    /// Entities logged as static data, in the order of their first row.
    statics: Vec<String>,
    /// The file the SDK writes to, finished by [`RrdStream::close`] (None: another sink).
    file: Option<file_sink::RrdFile>,
}

impl RrdStream {
    pub fn new(rec: RecordingStream) -> Self {
        let (chunks, queue) = mpsc::sync_channel::<Columns>(QUEUED_CHUNKS);
        let (done, emptied) = mpsc::channel();
        let sdk = rec.clone();
        // without the thread, chunks are built on the caller's thread
        let chunker = crate::record::priority::spawn("rrd chunks", move || {
            let mut error = None;
            for mut columns in queue {
                match columns.build() {
                    Ok(chunk) => sdk.send_chunk(chunk),
                    Err(e) => {
                        error.get_or_insert(e);
                    }
                }
                // the stream may be flushing already
                let _ = done.send(columns);
            }
            error
        })
        .ok();
        RrdStream {
            rec,
            time: 0,
            latest: 0,
            pending: Vec::new(),
            index: HashMap::new(),
            error: None,
            chunks: chunker.as_ref().map(|_| chunks),
            chunker,
            emptied: std::sync::Mutex::new(emptied),
            spare: Vec::new(),
            out: 0,
            statics: Vec::new(),
            file: None,
        }
    }

    /// A stream whose recording writes to `file` (see [`file_sink::create`]).
    pub fn writing_to(rec: RecordingStream, file: file_sink::RrdFile) -> Self {
        RrdStream {
            file: Some(file),
            ..RrdStream::new(rec)
        }
    }

    /// Keeps the columns the chunk thread has emptied so far (with `wait`, all of them: waits
    /// until every set sent is back).
    fn take_emptied(&mut self, wait: bool) {
        let emptied = self.emptied.get_mut().unwrap_or_else(|e| e.into_inner());
        while self.out > 0 {
            let next = if wait {
                emptied.recv().ok()
            } else {
                emptied.try_recv().ok()
            };
            let Some(c) = next else { break };
            self.out -= 1;
            let k = c.entity;
            if self.spare.len() <= k {
                self.spare.resize_with(k + 1, || None);
            }
            self.spare[k] = Some(c);
        }
    }

    /// Sets the `sim_time` (s) of the rows logged next (`timeline` must be `sim_time`, the
    /// recording's only timeline).
    pub fn set_duration_secs(&mut self, timeline: &str, secs: f64) {
        debug_assert_eq!(timeline, "sim_time");
        self.time = sim_time_nanos(secs);
        self.latest = self.latest.max(self.time);
    }

    /// The latest `sim_time` rows were logged at (s).
    pub fn latest_secs(&self) -> f64 {
        self.latest as f64 * 1e-9
    }

    /// Starts a row of entity `path` at the current time; its components are added with
    /// [`Row::with`].
    pub fn row(&mut self, path: &str) -> Row<'_> {
        let k = match self.index.get(path) {
            Some(&k) => k,
            None => {
                let k = self.pending.len();
                self.index.insert(path.to_string(), k);
                self.pending.push(Columns::new(k, EntityPath::from(path)));
                k
            }
        };
        let full = {
            let p = &self.pending[k];
            p.times.len() >= CHUNK_ROWS
                || p.bytes >= CHUNK_BYTES
                || p.times
                    .first()
                    .is_some_and(|&t0| self.time - t0 > chunk_span_ns())
        };
        if full && let Err(e) = self.send(k) {
            self.error.get_or_insert(e);
        }
        let columns = &mut self.pending[k];
        columns.times.push(self.time);
        Row {
            row: columns.times.len() - 1,
            columns,
            error: &mut self.error,
        }
    }

    /// Adds a row of `arch` at `path` at the current time.
    pub fn log(
        &mut self,
        path: impl AsRef<str>,
        arch: &(impl AsComponents + ?Sized),
    ) -> RecordingStreamResult<()> {
        let batches = arch.as_serialized_batches();
        if batches.is_empty() {
            return Ok(());
        }
        let mut row = self.row(path.as_ref());
        for b in batches {
            row.put(&b.descriptor, |values: &mut Serialized| {
                let (n, bytes) = (b.array.len(), b.array.get_array_memory_size());
                values.0.push(b.array);
                (n, bytes)
            });
        }
        Ok(())
    }

    /// Logs `arch` at `path` as static data (timeless), straight to the SDK.
    pub fn log_static(
        &mut self,
        path: impl AsRef<str>,
        arch: &(impl AsComponents + ?Sized),
    ) -> RecordingStreamResult<()> {
        let path = path.as_ref();
        if !self.statics.iter().any(|p| p == path) {
            self.statics.push(path.to_string());
        }
        self.rec.log_static(path, arch)
    }

    /// Every entity given rows so far (without a leading `/`): the temporal ones in the order
    /// of their first row, then the static ones.
    pub fn entity_paths(&self) -> Vec<String> {
        let temporal = self.pending.iter().map(|c| c.path.to_string());
        let statics = self
            .statics
            .iter()
            .map(|p| p.trim_start_matches('/').to_string());
        temporal
            .map(|p| p.trim_start_matches('/').to_string())
            .chain(statics)
            .collect()
    }

    /// Sends a blueprint (a store of its own, built by the caller) to the recording's sink.
    pub fn send_blueprint(
        &self,
        msgs: Vec<rerun::log::LogMsg>,
        activation: rerun::external::re_log_types::BlueprintActivationCommand,
    ) {
        self.rec.send_blueprint(msgs, activation);
    }

    /// The recording's application id ("sim").
    pub fn application_id(&self) -> Option<rerun::ApplicationId> {
        self.rec.store_info().map(|i| i.application_id().clone())
    }

    /// Sends the rows gathered for entity `k` (to the chunk thread while it runs).
    fn send(&mut self, k: usize) -> Result<(), String> {
        if self.pending[k].times.is_empty() {
            return Ok(());
        }
        self.take_emptied(false);
        let p = &mut self.pending[k];
        let next = match self.spare.get_mut(k).and_then(Option::take) {
            Some(spare) => spare,
            None => Columns::new(k, p.path.clone()),
        };
        let mut columns = std::mem::replace(p, next);
        if let Some(chunks) = &self.chunks {
            match chunks.send(columns) {
                Ok(()) => {
                    self.out += 1;
                    return Ok(());
                }
                Err(mpsc::SendError(back)) => columns = back,
            }
        }
        let chunk = columns.build();
        self.pending[k] = columns;
        self.rec.send_chunk(chunk?);
        Ok(())
    }

    /// Sends every entity's rows, ends the chunk thread and waits until the SDK has written
    /// everything; the first error, if any. Rows logged afterwards are chunked on the caller's
    /// thread.
    pub fn flush_blocking(&mut self) -> Result<(), String> {
        let mut first = self.error.take();
        for k in 0..self.pending.len() {
            if let Err(e) = self.send(k) {
                first.get_or_insert(e);
            }
        }
        self.chunks = None;
        if let Some(chunker) = self.chunker.take() {
            match chunker.join() {
                Ok(Some(e)) => {
                    first.get_or_insert(e);
                }
                Ok(None) => {}
                Err(_) => {
                    first.get_or_insert_with(|| "the chunk thread panicked".into());
                }
            }
        }
        if let Err(e) = self.rec.flush_blocking() {
            first.get_or_insert_with(|| e.to_string());
        }
        first.map_or(Ok(()), Err)
    }

    /// [`RrdStream::flush_blocking`], then the file's footer is written and the file closed;
    /// the first error, naming the file.
    pub fn close(&mut self) -> Result<(), String> {
        let flushed = self.flush_blocking();
        let Some(file) = self.file.take() else {
            return flushed;
        };
        flushed.and(file.finish()).map_err(|e| {
            format!(
                "{}: writing the recording failed: {e}",
                file.path().display()
            )
        })
    }
}

/// [`CHUNK_SPAN_S`] in ns.
fn chunk_span_ns() -> i64 {
    sim_time_nanos(CHUNK_SPAN_S)
}

/// Simulated time `secs` on the `sim_time` timeline (ns), as `RecordingStream::set_duration_secs`
/// makes it.
fn sim_time_nanos(secs: f64) -> i64 {
    let d = std::time::Duration::try_from_secs_f64(secs).unwrap_or_default();
    i64::try_from(d.as_nanos()).unwrap_or(i64::MAX)
}

#[cfg(test)]
mod tests;
