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
//! done by [`super::rrd::close_recording`] at the end of a run, also an interrupted one). A full
//! set of columns goes to a thread of the stream that serializes them, builds the chunk and
//! hands it to the SDK, then sends the emptied columns back: the entity's next rows fill them,
//! so a column does not grow again from nothing (copying itself over and over, on fresh
//! pages) for every chunk.
//!
//! Rows carry only the `sim_time` timeline (no wall-clock `log_time`/`log_tick`), so two runs
//! of a scenario give the same rows and the viewer opens on simulated time.

use re_chunk::{Chunk, ChunkComponents, ChunkId, TimeColumn};
use rerun::external::arrow;
use rerun::{
    AsComponents, ComponentDescriptor, EntityPath, Loggable, RecordingStream,
    RecordingStreamResult, SerializedComponentColumn,
};
use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, mpsc};
use std::thread::JoinHandle;

/// Rows per chunk at most.
pub const CHUNK_ROWS: usize = 4096;
/// Component data per chunk at most (bytes, approximately).
pub const CHUNK_BYTES: usize = 1 << 20;
/// Simulated time (s) from a chunk's first row to its last at most.
pub const CHUNK_SPAN_S: f64 = 30.0;
/// Full column sets waiting for the chunk thread at most (the caller waits when there are more).
const QUEUED_CHUNKS: usize = 64;

/// The values of one component column, kept as they came until the chunk is built.
trait ColumnValues: Any + Send + Sync {
    /// All values, flat (the rows' lengths are kept by [`Column`]).
    fn to_arrow(&self) -> Result<arrow::array::ArrayRef, String>;
    /// Drops the values, keeping the allocation.
    fn clear(&mut self);
}

/// Plain component values ([`RrdStream::row`]).
impl<C: Loggable> ColumnValues for Vec<C> {
    fn to_arrow(&self) -> Result<arrow::array::ArrayRef, String> {
        C::to_arrow(self.iter().map(std::borrow::Cow::Borrowed)).map_err(|e| e.to_string())
    }
    fn clear(&mut self) {
        Vec::clear(self);
    }
}

/// Arrays of rows already serialized ([`RrdStream::log`]).
#[derive(Default)]
struct Serialized(Vec<arrow::array::ArrayRef>);

impl ColumnValues for Serialized {
    fn to_arrow(&self) -> Result<arrow::array::ArrayRef, String> {
        let parts: Vec<&dyn arrow::array::Array> = self.0.iter().map(|a| a.as_ref()).collect();
        arrow::compute::concat(&parts).map_err(|e| e.to_string())
    }
    fn clear(&mut self) {
        self.0.clear();
    }
}

/// One component of an entity's pending rows.
struct Column {
    descriptor: ComponentDescriptor,
    /// Values per row, for the rows up to the last one that has this component (a row
    /// without it reads as null: nothing logged). Empty: no row has it (a column of an earlier
    /// chunk, kept for its allocation), and the chunk leaves it out.
    lengths: Vec<Option<u32>>,
    values: Box<dyn ColumnValues>,
}

/// The rows being gathered for one entity.
struct Columns {
    /// The entity's index in [`RrdStream::pending`].
    entity: usize,
    path: EntityPath,
    /// `sim_time` of each row (ns).
    times: Vec<i64>,
    columns: Vec<Column>,
    bytes: usize,
}

impl Columns {
    fn new(entity: usize, path: EntityPath) -> Self {
        Columns {
            entity,
            path,
            times: Vec::new(),
            columns: Vec::new(),
            bytes: 0,
        }
    }

    /// The row lengths and values of the column of `descriptor` (created holding `V` when
    /// new); `None` when it holds another type.
    fn column<V: ColumnValues + Default>(
        &mut self,
        descriptor: &ComponentDescriptor,
    ) -> Option<(&mut Vec<Option<u32>>, &mut V)> {
        let k = match self
            .columns
            .iter()
            .position(|c| c.descriptor == *descriptor)
        {
            Some(k) => {
                // a column kept from an earlier chunk takes whatever type this chunk gives it
                let c = &mut self.columns[k];
                if c.lengths.is_empty() && !(c.values.as_ref() as &dyn Any).is::<V>() {
                    c.values = Box::new(V::default());
                }
                k
            }
            None => {
                self.columns.push(Column {
                    descriptor: descriptor.clone(),
                    lengths: Vec::new(),
                    values: Box::new(V::default()),
                });
                self.columns.len() - 1
            }
        };
        let c = &mut self.columns[k];
        let values = (c.values.as_mut() as &mut dyn Any).downcast_mut::<V>()?;
        Some((&mut c.lengths, values))
    }

    /// Serializes the columns into a chunk (rows in time order) and empties them, keeping
    /// their allocations.
    fn build(&mut self) -> Result<Chunk, String> {
        let chunk = self.chunk();
        self.times.clear();
        self.bytes = 0;
        for c in &mut self.columns {
            c.lengths.clear();
            c.values.clear();
        }
        chunk
    }

    fn chunk(&mut self) -> Result<Chunk, String> {
        use arrow::array::ListArray;
        use arrow::buffer::{NullBuffer, OffsetBuffer};
        let rows = self.times.len();
        let mut components = ChunkComponents::default();
        for c in self.columns.iter_mut().filter(|c| !c.lengths.is_empty()) {
            let values = c.values.to_arrow()?;
            let lengths = &mut c.lengths;
            lengths.resize(rows, None);
            let nulls = lengths
                .iter()
                .any(Option::is_none)
                .then(|| NullBuffer::from_iter(lengths.iter().map(Option::is_some)));
            let offsets =
                OffsetBuffer::<i32>::from_lengths(lengths.iter().map(|l| l.unwrap_or(0) as usize));
            let field = Arc::new(arrow::datatypes::Field::new_list_field(
                values.data_type().clone(),
                true,
            ));
            let list = ListArray::try_new(field, offsets, values, nulls)
                .map_err(|e| format!("{}: {e}", c.descriptor))?;
            components.insert(SerializedComponentColumn::new(list, c.descriptor.clone()));
        }
        let time = TimeColumn::new(
            None,
            rerun::Timeline::new_duration("sim_time"),
            self.times.clone().into(),
        );
        Chunk::from_auto_row_ids(
            ChunkId::new(),
            self.path.clone(),
            std::iter::once((*time.timeline().name(), time)).collect(),
            components,
        )
        .map_err(|e| e.to_string())
    }
}

/// A row of an entity being filled ([`RrdStream::row`]): component values added with
/// [`Row::with`].
pub struct Row<'a> {
    columns: &'a mut Columns,
    row: usize,
    error: &'a mut Option<String>,
}

impl Row<'_> {
    /// Sets component `descriptor` of the row to `values` (e.g.
    /// `Points3D::descriptor_positions()` and `[Position3D::new(x, y, 0.0)]`). A descriptor
    /// must keep the component type it was first given in a chunk; a row giving another is
    /// left out of the column and the mismatch reported at the end of the run.
    pub fn with<C: Loggable>(
        mut self,
        descriptor: ComponentDescriptor,
        values: impl IntoIterator<Item = C>,
    ) -> Self {
        self.put(&descriptor, |vec: &mut Vec<C>| {
            let before = vec.len();
            // `extend` reserves for the whole row at once (a particle set is a thousand values)
            vec.extend(values);
            let row = &vec[before..];
            let heap: u64 = row.iter().map(|v| v.heap_size_bytes()).sum();
            (row.len(), std::mem::size_of_val(row) + heap as usize)
        });
        self
    }

    /// Adds this row's entry of column `descriptor` (holding `V`): `fill` appends the values
    /// and returns (how many, bytes). A column of another type, or one this row has already
    /// set, is left alone and the problem reported at the end of the run.
    fn put<V: ColumnValues + Default>(
        &mut self,
        descriptor: &ComponentDescriptor,
        fill: impl FnOnce(&mut V) -> (usize, usize),
    ) {
        let problem = match self.columns.column::<V>(descriptor) {
            None => "logged after another type in this chunk",
            Some((lengths, _)) if lengths.len() > self.row => "given twice in one row",
            Some((lengths, values)) => {
                let (n, bytes) = fill(values);
                lengths.resize(self.row, None);
                lengths.push(Some(n as u32));
                self.columns.bytes += bytes;
                return;
            }
        };
        self.error
            .get_or_insert_with(|| format!("{}: {descriptor} {problem}", self.columns.path));
    }
}

/// A Rerun recording whose temporal rows are chunked here (see the module doc); static rows go
/// straight to the SDK.
pub struct RrdStream {
    rec: RecordingStream,
    /// The `sim_time` of the rows logged next (ns).
    time: i64,
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
}

impl RrdStream {
    pub fn new(rec: RecordingStream) -> Self {
        let (chunks, queue) = mpsc::sync_channel::<Columns>(QUEUED_CHUNKS);
        let (done, emptied) = mpsc::channel();
        let sdk = rec.clone();
        // without the thread, chunks are built on the caller's thread
        let chunker = std::thread::Builder::new()
            .name("rrd chunks".into())
            .spawn(move || {
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
            pending: Vec::new(),
            index: HashMap::new(),
            error: None,
            chunks: chunker.as_ref().map(|_| chunks),
            chunker,
            emptied: std::sync::Mutex::new(emptied),
            spare: Vec::new(),
            out: 0,
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
        &self,
        path: impl Into<EntityPath>,
        arch: &(impl AsComponents + ?Sized),
    ) -> RecordingStreamResult<()> {
        self.rec.log_static(path, arch)
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
mod tests {
    use super::*;
    use arrow::array::Array;
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

    /// The data chunks of entity `path` in `msgs`.
    fn entity_chunks(msgs: &[LogMsg], path: &str) -> Vec<Chunk> {
        msgs.iter()
            .filter_map(|m| match m {
                LogMsg::ArrowMsg(_, a) => Chunk::from_arrow_msg(a).ok(),
                _ => None,
            })
            .filter(|c| c.entity_path().to_string() == path)
            .collect()
    }

    #[test]
    fn plain_values_give_the_columns_of_the_archetypes() {
        use rerun::components::{Color, LineStrip3D, Position3D, Radius, Text};
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        let c = Color::from_rgb(1, 2, 3);
        for k in 0..5 {
            let x = k as f32;
            s.set_duration_secs("sim_time", 0.5 * k as f64);
            // the same rows as archetypes ...
            s.log(
                "arch",
                &rerun::Points3D::new([[x, 1.0, 0.0], [x, 2.0, 0.0]])
                    .with_radii([0.3])
                    .with_colors([c])
                    .with_labels([format!("p{k}")]),
            )
            .unwrap();
            // ... and as plain values
            s.row("plain")
                .with(
                    rerun::Points3D::descriptor_positions(),
                    [Position3D::new(x, 1.0, 0.0), Position3D::new(x, 2.0, 0.0)],
                )
                .with(rerun::Points3D::descriptor_radii(), [Radius::from(0.3)])
                .with(rerun::Points3D::descriptor_colors(), [c])
                .with(
                    rerun::Points3D::descriptor_labels(),
                    [Text::from(format!("p{k}"))],
                );
            // every other row without the strip: a null there, not an empty list
            if k % 2 == 0 {
                s.log(
                    "arch",
                    &rerun::LineStrips3D::new([[[x, 0.0, 0.0], [0.0, x, 0.0]]]),
                )
                .unwrap();
                s.row("plain").with(
                    rerun::LineStrips3D::descriptor_strips(),
                    [LineStrip3D::from([[x, 0.0, 0.0], [0.0, x, 0.0]])],
                );
            }
        }
        s.flush_blocking().unwrap();
        let msgs = storage.take();
        let (arch, plain) = (
            entity_chunks(&msgs, "/arch"),
            entity_chunks(&msgs, "/plain"),
        );
        assert_eq!((arch.len(), plain.len()), (1, 1));
        let (a, p) = (&arch[0], &plain[0]);
        assert_eq!((a.num_rows(), p.num_rows()), (8, 8));
        assert_eq!(
            a.timelines()[&"sim_time".into()].times_raw(),
            p.timelines()[&"sim_time".into()].times_raw()
        );
        let mut descriptors: Vec<_> = p.components().component_descriptors().cloned().collect();
        descriptors.sort_by_key(|d| d.to_string());
        let mut expected: Vec<_> = a.components().component_descriptors().cloned().collect();
        expected.sort_by_key(|d| d.to_string());
        assert_eq!(descriptors, expected);
        for d in &descriptors {
            let (x, y) = (
                a.components().get_array(d.component).unwrap(),
                p.components().get_array(d.component).unwrap(),
            );
            assert_eq!(x.to_data(), y.to_data(), "{d}");
        }
    }

    #[test]
    fn a_component_given_twice_or_with_another_type_is_reported_and_left_out() {
        use rerun::components::{Radius, Scalar};
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        s.row("x")
            .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(1.0)])
            .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(2.0)]);
        s.row("x")
            .with(rerun::Scalars::descriptor_scalars(), [Radius::from(3.0)]);
        let e = s.flush_blocking().unwrap_err();
        assert!(e.contains("/x") && e.contains("twice in one row"), "{e}");
        let msgs = storage.take();
        let chunk = &entity_chunks(&msgs, "/x")[0];
        let values = chunk
            .components()
            .get_array(rerun::Scalars::descriptor_scalars().component)
            .unwrap();
        // the first value of the first row; the second row has none
        assert_eq!(
            (values.len(), values.value_length(0), values.is_null(1)),
            (2, 1, true)
        );
        // the type mismatch alone is reported too
        let (rec, _storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        s.row("x")
            .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(1.0)]);
        s.row("x")
            .with(rerun::Scalars::descriptor_scalars(), [Radius::from(3.0)]);
        let e = s.flush_blocking().unwrap_err();
        assert!(e.contains("after another type"), "{e}");
    }

    #[test]
    fn rows_become_one_chunk_per_entity_on_sim_time_and_full_chunks_go_early() {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        let n = CHUNK_ROWS + 10;
        for k in 0..n {
            // well within CHUNK_SPAN_S
            s.set_duration_secs("sim_time", k as f64 * 0.005);
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

    /// Later chunks of an entity fill the columns its earlier chunks emptied: each chunk holds
    /// its own rows' values only, a component no row of a chunk has is not in it, and a
    /// component may change type from one chunk to the next.
    #[test]
    fn later_chunks_reuse_the_emptied_columns_and_hold_only_their_rows() {
        use rerun::components::{Radius, Scalar};
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        let scalars = rerun::Scalars::descriptor_scalars();
        let radii = rerun::Points3D::descriptor_radii();
        let chunks = 4;
        for k in 0..chunks * CHUNK_ROWS {
            let c = k / CHUNK_ROWS;
            if k % CHUNK_ROWS == 0 {
                // the chunk before last is back: this row's send hands its columns over
                s.take_emptied(true);
            }
            s.set_duration_secs("sim_time", k as f64 * 0.001);
            let row = s.row("x");
            // chunk 0: scalars and radii; chunk 1: scalars only; chunk 2: the radii
            // descriptor with scalar values; chunk 3: both again, three values a row
            match c {
                0 => row
                    .with(scalars.clone(), [Scalar::from(k as f64)])
                    .with(radii.clone(), [Radius::from(k as f32)]),
                1 => row.with(scalars.clone(), [Scalar::from(k as f64)]),
                2 => row.with(radii.clone(), [Scalar::from(-(k as f64))]),
                _ => row
                    .with(scalars.clone(), [Scalar::from(k as f64); 3])
                    .with(radii.clone(), [Radius::from(k as f32); 3]),
            };
        }
        s.flush_blocking().unwrap();
        let msgs = storage.take();
        let got = entity_chunks(&msgs, "/x");
        assert_eq!(got.len(), chunks);
        let values = |chunk: &Chunk, d: &ComponentDescriptor| {
            chunk.components().get_array(d.component).map(|a| {
                let inner = a.values();
                (a.len(), inner.len(), inner.data_type().clone())
            })
        };
        let (rows, n) = (CHUNK_ROWS, CHUNK_ROWS);
        let f64s = arrow::datatypes::DataType::Float64;
        let f32s = arrow::datatypes::DataType::Float32;
        assert_eq!(values(&got[0], &scalars), Some((rows, n, f64s.clone())));
        assert_eq!(values(&got[0], &radii), Some((rows, n, f32s.clone())));
        assert_eq!(values(&got[1], &scalars), Some((rows, n, f64s.clone())));
        assert_eq!(values(&got[1], &radii), None);
        assert_eq!(values(&got[2], &scalars), None);
        assert_eq!(values(&got[2], &radii), Some((rows, n, f64s.clone())));
        assert_eq!(values(&got[3], &scalars), Some((rows, 3 * n, f64s)));
        assert_eq!(values(&got[3], &radii), Some((rows, 3 * n, f32s)));
        // the last chunk's first scalar is its first row's, not a left-over
        let first = got[3]
            .components()
            .get_array(scalars.component)
            .unwrap()
            .value(0);
        let first = first
            .as_any()
            .downcast_ref::<arrow::array::Float64Array>()
            .unwrap();
        assert_eq!(first.value(0), (3 * CHUNK_ROWS) as f64);
    }

    #[test]
    fn a_chunk_spans_at_most_chunk_span_s_of_sim_time() {
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
        let mut s = RrdStream::new(rec);
        let n = 100;
        for k in 0..n {
            s.set_duration_secs("sim_time", k as f64 * CHUNK_SPAN_S / 30.0);
            s.log("a", &rerun::Scalars::single(k as f64)).unwrap();
        }
        s.flush_blocking().unwrap();
        let rows: Vec<usize> = chunks(&storage.take()).iter().map(|c| c.1).collect();
        // a row more than the span after the chunk's first starts the next chunk
        assert_eq!(rows, [31, 31, 31, 7]);
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
