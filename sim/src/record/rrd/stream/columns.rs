//! The pending rows of an entity as columns of component values ([`Columns`]), filled a row
//! at a time through [`Row`] and serialized into a Rerun chunk by [`Columns::build`], which
//! empties them for reuse.

use re_chunk::{Chunk, ChunkComponents, ChunkId, TimeColumn};
use rerun::external::arrow;
use rerun::{ComponentDescriptor, EntityPath, Loggable, SerializedComponentColumn};
use std::any::Any;
use std::sync::Arc;

/// The values of one component column, kept as they came until the chunk is built.
pub(super) trait ColumnValues: Any + Send + Sync {
    /// All values, flat (the rows' lengths are kept by [`Column`]).
    fn to_arrow(&self) -> Result<arrow::array::ArrayRef, String>;
    /// Drops the values, keeping the allocation.
    fn clear(&mut self);
}

/// Plain component values ([`super::RrdStream::row`]).
impl<C: Loggable> ColumnValues for Vec<C> {
    fn to_arrow(&self) -> Result<arrow::array::ArrayRef, String> {
        C::to_arrow(self.iter().map(std::borrow::Cow::Borrowed)).map_err(|e| e.to_string())
    }
    fn clear(&mut self) {
        Vec::clear(self);
    }
}

/// Arrays of rows already serialized ([`super::RrdStream::log`]).
#[derive(Default)]
pub(super) struct Serialized(pub(super) Vec<arrow::array::ArrayRef>);

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
pub(super) struct Column {
    descriptor: ComponentDescriptor,
    /// Values per row, for the rows up to the last one that has this component (a row
    /// without it reads as null: nothing logged). Empty: no row has it (a column of an earlier
    /// chunk, kept for its allocation), and the chunk leaves it out.
    lengths: Vec<Option<u32>>,
    values: Box<dyn ColumnValues>,
}

/// The rows being gathered for one entity.
pub(super) struct Columns {
    /// The entity's index in `RrdStream::pending`.
    pub(super) entity: usize,
    pub(super) path: EntityPath,
    /// `sim_time` of each row (ns).
    pub(super) times: Vec<i64>,
    columns: Vec<Column>,
    pub(super) bytes: usize,
}

impl Columns {
    pub(super) fn new(entity: usize, path: EntityPath) -> Self {
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
    pub(super) fn build(&mut self) -> Result<Chunk, String> {
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

/// A row of an entity being filled ([`super::RrdStream::row`]): component values added with
/// [`Row::with`].
pub struct Row<'a> {
    pub(super) columns: &'a mut Columns,
    pub(super) row: usize,
    pub(super) error: &'a mut Option<String>,
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
    pub(super) fn put<V: ColumnValues + Default>(
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
