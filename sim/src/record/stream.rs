//! The .rrd's rows gathered into Rerun chunks by the recorder itself.
//!
//! `RecordingStream::log` hands every row to the SDK's batcher thread (a channel send and, as
//! the batcher sleeps between rows, a thread wake-up per row), which then groups rows of an
//! entity into chunks. A fast run logs tens of thousands of rows per simulated minute, so that
//! per-row hand-over cost more than the simulation of an outdoor run. [`RrdStream`] keeps one
//! [`rerun::log::Chunk`] builder per entity instead and sends a chunk when it holds
//! [`CHUNK_ROWS`] rows or [`CHUNK_BYTES`] of data, and every builder when the recording is
//! flushed ([`RrdStream::flush_blocking`], done by [`super::rrd::close_recording`] at the end
//! of a run, also an interrupted one). A full builder goes to a thread of the stream that
//! builds the chunk (concatenating the rows' arrays) and hands it to the SDK, so the
//! simulation thread only serializes rows.
//!
//! Rows carry only the `sim_time` timeline (no wall-clock `log_time`/`log_tick`), so two runs
//! of a scenario give the same rows and the viewer opens on simulated time.

use re_chunk::{Chunk, ChunkBuilder, RowId};
use rerun::{AsComponents, EntityPath, RecordingStream, RecordingStreamResult, TimeCell};
use std::collections::HashMap;
use std::sync::mpsc;
use std::thread::JoinHandle;

/// Rows per chunk at most.
pub const CHUNK_ROWS: usize = 4096;
/// Component data per chunk at most (bytes, approximately).
pub const CHUNK_BYTES: usize = 1 << 20;
/// Full builders waiting for the chunk thread at most (the caller waits when there are more).
const QUEUED_CHUNKS: usize = 64;

/// The rows being gathered for one entity.
struct Pending {
    path: EntityPath,
    builder: Option<ChunkBuilder>,
    rows: usize,
    bytes: usize,
}

/// A Rerun recording whose temporal rows are chunked here (see the module doc); static rows go
/// straight to the SDK.
pub struct RrdStream {
    rec: RecordingStream,
    /// The `sim_time` of the rows logged next.
    time: rerun::TimePoint,
    /// Per entity, in the order of their first row.
    pending: Vec<Pending>,
    index: HashMap<EntityPath, usize>,
    /// The chunk thread: builds chunks and sends them to the SDK; ends with its first error.
    chunks: Option<mpsc::SyncSender<ChunkBuilder>>,
    chunker: Option<JoinHandle<Option<String>>>,
}

impl RrdStream {
    pub fn new(rec: RecordingStream) -> Self {
        let (chunks, queue) = mpsc::sync_channel::<ChunkBuilder>(QUEUED_CHUNKS);
        let sdk = rec.clone();
        // without the thread, chunks are built on the caller's thread
        let chunker = std::thread::Builder::new()
            .name("rrd chunks".into())
            .spawn(move || {
                let mut error = None;
                for builder in queue {
                    match builder.build() {
                        Ok(chunk) => sdk.send_chunk(chunk),
                        Err(e) => {
                            error.get_or_insert_with(|| e.to_string());
                        }
                    }
                }
                error
            })
            .ok();
        RrdStream {
            rec,
            time: sim_time(0.0),
            pending: Vec::new(),
            index: HashMap::new(),
            chunks: chunker.as_ref().map(|_| chunks),
            chunker,
        }
    }

    /// Sets the `sim_time` (s) of the rows logged next (`timeline` must be `sim_time`, the
    /// recording's only timeline).
    pub fn set_duration_secs(&mut self, timeline: &str, secs: f64) {
        debug_assert_eq!(timeline, "sim_time");
        self.time = sim_time(secs);
    }

    /// Adds a row of `arch` at `path` at the current time.
    pub fn log(
        &mut self,
        path: impl Into<EntityPath>,
        arch: &(impl AsComponents + ?Sized),
    ) -> RecordingStreamResult<()> {
        let path = path.into();
        let batches = arch.as_serialized_batches();
        if batches.is_empty() {
            return Ok(());
        }
        let bytes: usize = batches
            .iter()
            .map(|b| rerun::external::arrow::array::Array::get_array_memory_size(&*b.array))
            .sum();
        let k = match self.index.get(&path) {
            Some(&k) => k,
            None => {
                self.index.insert(path.clone(), self.pending.len());
                self.pending.push(Pending {
                    path,
                    builder: None,
                    rows: 0,
                    bytes: 0,
                });
                self.pending.len() - 1
            }
        };
        let p = &mut self.pending[k];
        let builder = p
            .builder
            .take()
            .unwrap_or_else(|| Chunk::builder(p.path.clone()));
        p.builder = Some(builder.with_serialized_batches(RowId::new(), self.time.clone(), batches));
        p.rows += 1;
        p.bytes += bytes;
        if p.rows >= CHUNK_ROWS || p.bytes >= CHUNK_BYTES {
            return self.send(k);
        }
        Ok(())
    }

    /// Logs `arch` at `path` as static data (timeless), straight to the SDK.
    pub fn log_static(
        &self,
        path: impl Into<EntityPath>,
        arch: &(impl AsComponents + ?Sized),
    ) -> RecordingStreamResult<()> {
        self.rec.log_static(path, arch)
    }

    /// Sends the chunk gathered for entity `k` (to the chunk thread while it runs).
    fn send(&mut self, k: usize) -> RecordingStreamResult<()> {
        let p = &mut self.pending[k];
        p.rows = 0;
        p.bytes = 0;
        let Some(builder) = p.builder.take() else {
            return Ok(());
        };
        let builder = match &self.chunks {
            Some(chunks) => match chunks.send(builder) {
                Ok(()) => return Ok(()),
                Err(mpsc::SendError(builder)) => builder,
            },
            None => builder,
        };
        self.rec.send_chunk(builder.build()?);
        Ok(())
    }

    /// Sends every chunk being gathered, ends the chunk thread and waits until the SDK has
    /// written everything; the first error, if any. Rows logged afterwards are chunked on the
    /// caller's thread.
    pub fn flush_blocking(&mut self) -> Result<(), String> {
        let mut first: Option<String> = None;
        for k in 0..self.pending.len() {
            if let Err(e) = self.send(k) {
                first.get_or_insert_with(|| e.to_string());
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
}

/// A time point on the `sim_time` timeline (s), as `RecordingStream::set_duration_secs` makes
/// it.
fn sim_time(secs: f64) -> rerun::TimePoint {
    let d = std::time::Duration::try_from_secs_f64(secs).unwrap_or_default();
    rerun::TimePoint::from([("sim_time", TimeCell::from(d))])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rerun::log::LogMsg;

    /// (entity, rows, timelines) of every data chunk of `msgs`, in order.
    fn chunks(msgs: &[LogMsg]) -> Vec<(String, usize, Vec<String>)> {
        msgs.iter()
            .filter_map(|m| match m {
                LogMsg::ArrowMsg(_, a) => Some(Chunk::from_arrow_msg(a).unwrap()),
                _ => None,
            })
            .filter(|c| !c.entity_path().to_string().starts_with("/__"))
            .map(|c| {
                let mut t: Vec<String> = c.timelines().keys().map(|k| k.to_string()).collect();
                t.sort();
                (c.entity_path().to_string(), c.num_rows(), t)
            })
            .collect()
    }

    #[test]
    fn rows_become_one_chunk_per_entity_on_sim_time_and_full_chunks_go_early() {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        let n = CHUNK_ROWS + 10;
        for k in 0..n {
            s.set_duration_secs("sim_time", k as f64 * 0.1);
            s.log("a", &rerun::Scalars::single(k as f64)).unwrap();
            if k % 2 == 0 {
                s.log("b", &rerun::Points3D::new([[k as f32, 0.0, 0.0]]))
                    .unwrap();
            }
        }
        s.flush_blocking().unwrap();
        let got = chunks(&storage.take());
        let t = vec!["sim_time".to_string()];
        assert_eq!(
            got,
            [
                ("/a".to_string(), CHUNK_ROWS, t.clone()),
                ("/a".to_string(), 10, t.clone()),
                ("/b".to_string(), n.div_ceil(2), t),
            ]
        );
    }

    #[test]
    fn the_times_are_those_of_set_duration_secs() {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        for t in [0.05, 1.0, 2.5] {
            s.set_duration_secs("sim_time", t);
            s.log("x", &rerun::Scalars::single(t)).unwrap();
        }
        s.flush_blocking().unwrap();
        let msgs = storage.take();
        let chunk = msgs
            .iter()
            .find_map(|m| match m {
                LogMsg::ArrowMsg(_, a) => Chunk::from_arrow_msg(a)
                    .ok()
                    .filter(|c| c.entity_path().to_string() == "/x"),
                _ => None,
            })
            .unwrap();
        let times: Vec<i64> = chunk.timelines()[&"sim_time".into()].times_raw().to_vec();
        assert_eq!(times, [50_000_000, 1_000_000_000, 2_500_000_000]);
    }
}
