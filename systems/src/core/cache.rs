//! On-disk cache of structures that are pure functions of their inputs. The ray caster's distance
//! field and faces, the likelihood field, the navigation costmaps and the road-surface raster take
//! most of a world's start-up and depend on the map alone, so a second start of the same map
//! reads them instead of computing them again.
//!
//! Each structure is stored under a [`CacheKey`]: a BLAKE3 hash of everything it is computed from
//! (the grid's cells, resolution and origin, every parameter), of its type's format version
//! ([`Cached::FORMAT`]) and of the code version (this crate's version and a digest of its source,
//! compiler and target, made by the build script), so a changed map, parameter or program never
//! reads an old entry.
//!
//! An entry is one file: a header (magic, key, payload length, BLAKE3 hash of the payload) and
//! the payload, the structure's fields as little-endian bytes ([`Encoder`], [`Decoder`]). It is
//! written to a temporary file and renamed into place, so a reader sees a whole entry or none;
//! one that is truncated, corrupt or not for its key is rebuilt and replaced. The cache never
//! fails a build: a folder that cannot be read or written only costs the time of building.
//!
//! A cache can also share ([`MapCache::sharing`]): worlds built through it hold one copy of a
//! read-only structure ([`MapCache::get_or_build_shared`]) instead of one each, so many worlds of
//! one map side by side keep a single ray map in the processor's caches.

use std::any::Any;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// First bytes of every entry (and of every key's hash input).
const MAGIC: &[u8; 8] = b"SIMCACH1";
/// Magic, key, payload length, payload hash.
const HEADER: usize = 8 + 32 + 8 + 32;
/// File name extension of entries.
pub const ENTRY_EXTENSION: &str = "bin";
/// This crate's code version: see the module documentation.
const CODE_VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "+", env!("SYSTEMS_CODE_DIGEST"));

/// A structure the cache can hold.
pub trait Cached: Sized {
    /// Short name of the type; entries' file names start with it.
    const KIND: &'static str;
    /// Version of the encoding: bumped whenever the encoded fields or their meaning change.
    const FORMAT: u32;
    /// Appends the structure's fields.
    fn encode(&self, out: &mut Encoder);
    /// The structure [`Cached::encode`] wrote; an error for bytes it cannot have written.
    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed>;
}

/// Bytes that are not an encoding of the type asked for.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("malformed cache entry: {0}")]
pub struct Malformed(pub &'static str);

/// The key of one entry: what a structure is computed from, fed in field by field.
#[derive(Clone)]
pub struct CacheKey {
    kind: &'static str,
    hasher: blake3::Hasher,
}

impl CacheKey {
    /// The key of a `T` computed from the inputs fed next.
    pub fn new<T: Cached>() -> Self {
        let mut hasher = blake3::Hasher::new();
        hasher.update(MAGIC);
        CacheKey {
            kind: T::KIND,
            hasher,
        }
        .str(T::KIND)
        .u64(T::FORMAT.into())
        .str(CODE_VERSION)
    }

    pub fn u64(mut self, v: u64) -> Self {
        self.hasher.update(&v.to_le_bytes());
        self
    }

    /// A float by its bits (so 0.0 and −0.0 differ, as their results may).
    pub fn f64(self, v: f64) -> Self {
        self.u64(v.to_bits())
    }

    pub fn bytes(mut self, b: &[u8]) -> Self {
        self = self.u64(b.len() as u64);
        self.hasher.update(b);
        self
    }

    pub fn str(self, s: &str) -> Self {
        self.bytes(s.as_bytes())
    }

    /// The hash of everything fed in.
    pub fn digest(&self) -> [u8; 32] {
        *self.hasher.finalize().as_bytes()
    }

    /// The entry's file name: `<kind>-<hash in hex>.bin`.
    pub fn file_name(&self) -> String {
        let hex: String = self.digest().iter().map(|b| format!("{b:02x}")).collect();
        format!("{}-{hex}.{ENTRY_EXTENSION}", self.kind)
    }
}

/// How often a cache was used (shared by its clones).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    /// Structures read from an entry.
    pub hits: u64,
    /// Structures built (no entry, or a rejected one).
    pub misses: u64,
    /// Entries that were there but truncated, corrupt or not for their key.
    pub rejected: u64,
    /// Entries that could not be written.
    pub write_failures: u64,
}

#[derive(Default)]
struct Counters {
    hits: AtomicU64,
    misses: AtomicU64,
    rejected: AtomicU64,
    write_failures: AtomicU64,
}

/// Structures handed out by a sharing cache, by key digest.
type Shared = Mutex<HashMap<[u8; 32], Arc<dyn Any + Send + Sync>>>;

/// The cache: a folder of entries, or none (every structure is built); with or without a copy in
/// memory shared by every world built through it and its clones ([`MapCache::sharing`]).
#[derive(Clone, Default)]
pub struct MapCache {
    dir: Option<Arc<Path>>,
    counters: Arc<Counters>,
    shared: Option<Arc<Shared>>,
}

impl std::fmt::Debug for MapCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MapCache")
            .field("dir", &self.dir)
            .field("stats", &self.stats())
            .finish()
    }
}

/// Entries written by this process, for unique temporary names.
static WRITES: AtomicU64 = AtomicU64::new(0);

impl MapCache {
    /// No cache: every structure is built.
    pub fn disabled() -> Self {
        MapCache::default()
    }

    /// Entries in `dir` (created when the first entry is written).
    pub fn in_dir(dir: impl Into<PathBuf>) -> Self {
        MapCache {
            dir: Some(Arc::from(dir.into())),
            counters: Arc::default(),
            shared: None,
        }
    }

    /// This cache, keeping in memory each structure it hands out through
    /// [`MapCache::get_or_build_shared`] and handing the same copy to every later world built
    /// through it or its clones (a vectorized simulation's worlds). A world that edits its copy
    /// (a door) edits a copy of its own.
    pub fn sharing(self) -> Self {
        MapCache {
            shared: Some(Arc::default()),
            ..self
        }
    }

    /// [`MapCache::get_or_build`] for a read-only structure: with [`MapCache::sharing`], the
    /// copy an earlier world of this cache got, if any; else a copy of its own.
    pub fn get_or_build_shared<T: Cached + Send + Sync + 'static>(
        &self,
        key: &CacheKey,
        build: impl FnOnce() -> T,
    ) -> Arc<T> {
        let Some(shared) = &self.shared else {
            return Arc::new(self.get_or_build(key, build));
        };
        let digest = key.digest();
        let held = shared
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&digest)
            .cloned();
        if let Some(v) = held.and_then(|v| v.downcast::<T>().ok()) {
            return v;
        }
        // built outside the lock (worlds are built in parallel); the first one stored is kept
        let built = Arc::new(self.get_or_build(key, build));
        let mut map = shared.lock().unwrap_or_else(|e| e.into_inner());
        let kept = map.entry(digest).or_insert_with(|| built.clone()).clone();
        kept.downcast::<T>().unwrap_or(built)
    }

    /// The folder, if the cache is on.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    pub fn stats(&self) -> CacheStats {
        let c = &self.counters;
        CacheStats {
            hits: c.hits.load(Ordering::Relaxed),
            misses: c.misses.load(Ordering::Relaxed),
            rejected: c.rejected.load(Ordering::Relaxed),
            write_failures: c.write_failures.load(Ordering::Relaxed),
        }
    }

    /// Where the entry of `key` lives, if the cache is on.
    pub fn entry_path(&self, key: &CacheKey) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join(key.file_name()))
    }

    /// The structure stored under `key`, or `build()`'s, which is then stored.
    pub fn get_or_build<T: Cached>(&self, key: &CacheKey, build: impl FnOnce() -> T) -> T {
        let Some(path) = self.entry_path(key) else {
            return build();
        };
        let digest = key.digest();
        match std::fs::read(&path) {
            Ok(bytes) => match read_entry::<T>(&bytes, &digest) {
                Ok(v) => {
                    self.counters.hits.fetch_add(1, Ordering::Relaxed);
                    return v;
                }
                Err(e) => {
                    self.counters.rejected.fetch_add(1, Ordering::Relaxed);
                    tracing::warn!("cache entry {} rebuilt: {e}", path.display());
                }
            },
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => tracing::debug!("cache entry {} unreadable: {e}", path.display()),
        }
        self.counters.misses.fetch_add(1, Ordering::Relaxed);
        let value = build();
        if let Err(e) = write_entry(&path, &digest, &value) {
            self.counters.write_failures.fetch_add(1, Ordering::Relaxed);
            tracing::debug!("cache entry {} not written: {e}", path.display());
        }
        value
    }
}

/// A structure's encoding (what an entry's payload holds): two structures with the same bytes
/// are the same.
pub fn to_bytes<T: Cached>(value: &T) -> Vec<u8> {
    let mut e = Encoder { buf: Vec::new() };
    value.encode(&mut e);
    e.buf
}

/// The structure in an entry's bytes, after checking its header and payload.
fn read_entry<T: Cached>(bytes: &[u8], digest: &[u8; 32]) -> Result<T, Malformed> {
    if bytes.len() < HEADER || &bytes[..8] != MAGIC {
        return Err(Malformed("not a cache entry"));
    }
    if &bytes[8..40] != digest {
        return Err(Malformed("the entry is for another key"));
    }
    let len = u64::from_le_bytes(bytes[40..48].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER..];
    if len != payload.len() as u64 {
        return Err(Malformed("truncated or extended"));
    }
    if blake3::hash(payload).as_bytes() != &bytes[48..80] {
        return Err(Malformed("checksum mismatch"));
    }
    let mut d = Decoder::new(payload);
    let v = T::decode(&mut d)?;
    d.finish()?;
    Ok(v)
}

/// Writes the entry of `value` to a temporary file beside `path` and renames it into place.
fn write_entry<T: Cached>(path: &Path, digest: &[u8; 32], value: &T) -> std::io::Result<()> {
    let mut e = Encoder {
        buf: vec![0; HEADER],
    };
    value.encode(&mut e);
    let mut bytes = e.buf;
    let len = (bytes.len() - HEADER) as u64;
    let hash = blake3::hash(&bytes[HEADER..]);
    bytes[..8].copy_from_slice(MAGIC);
    bytes[8..40].copy_from_slice(digest);
    bytes[40..48].copy_from_slice(&len.to_le_bytes());
    bytes[48..80].copy_from_slice(hash.as_bytes());
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(
        ".{}.{}-{}.tmp",
        path.file_name().and_then(|n| n.to_str()).unwrap_or("entry"),
        std::process::id(),
        WRITES.fetch_add(1, Ordering::Relaxed)
    ));
    let written = std::fs::write(&tmp, &bytes).and_then(|()| std::fs::rename(&tmp, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// A structure's fields as little-endian bytes.
pub struct Encoder {
    buf: Vec<u8>,
}

impl Encoder {
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn u32(&mut self, v: u32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    pub fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    pub fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    /// A grid's frame: width and height in cells, metres per cell, origin.
    pub fn grid_frame(&mut self, width: usize, height: usize, resolution: f64, origin: [f64; 2]) {
        self.usize(width);
        self.usize(height);
        self.f64(resolution);
        self.f64(origin[0]);
        self.f64(origin[1]);
    }
    /// A length, then the bytes.
    pub fn bytes(&mut self, b: &[u8]) {
        self.usize(b.len());
        self.buf.extend_from_slice(b);
    }
    /// A length, then runs of equal bytes (value, count): compact for class rasters.
    pub fn byte_runs(&mut self, b: &[u8]) {
        self.usize(b.len());
        for run in b.chunk_by(|x, y| x == y) {
            for part in run.chunks(u32::MAX as usize) {
                self.u8(part[0]);
                self.u32(part.len() as u32);
            }
        }
    }
    /// A length, then each float's bits.
    pub fn f32s(&mut self, v: &[f32]) {
        self.usize(v.len());
        self.buf.reserve(4 * v.len());
        v.iter().for_each(|x| self.f32(*x));
    }
    /// A length, then each value.
    pub fn u32s(&mut self, v: &[u32]) {
        self.usize(v.len());
        self.buf.reserve(4 * v.len());
        v.iter().for_each(|x| self.u32(*x));
    }
}

/// Reads what an [`Encoder`] wrote, in the same order.
pub struct Decoder<'a> {
    rest: &'a [u8],
}

impl<'a> Decoder<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Decoder { rest: bytes }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], Malformed> {
        if n > self.rest.len() {
            return Err(Malformed("shorter than its fields"));
        }
        let (head, rest) = self.rest.split_at(n);
        self.rest = rest;
        Ok(head)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], Malformed> {
        Ok(self.take(N)?.try_into().expect("N bytes"))
    }

    pub fn u8(&mut self) -> Result<u8, Malformed> {
        Ok(self.take(1)?[0])
    }
    pub fn u32(&mut self) -> Result<u32, Malformed> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub fn u64(&mut self) -> Result<u64, Malformed> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    pub fn usize(&mut self) -> Result<usize, Malformed> {
        usize::try_from(self.u64()?).map_err(|_| Malformed("a length beyond this machine"))
    }
    pub fn bool(&mut self) -> Result<bool, Malformed> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(Malformed("a flag is neither 0 nor 1")),
        }
    }
    pub fn f32(&mut self) -> Result<f32, Malformed> {
        Ok(f32::from_bits(self.u32()?))
    }
    pub fn f64(&mut self) -> Result<f64, Malformed> {
        Ok(f64::from_bits(self.u64()?))
    }
    /// What [`Encoder::grid_frame`] wrote: (width, height, resolution, origin).
    pub fn grid_frame(&mut self) -> Result<(usize, usize, f64, [f64; 2]), Malformed> {
        Ok((
            self.usize()?,
            self.usize()?,
            self.f64()?,
            [self.f64()?, self.f64()?],
        ))
    }
    /// A length of items of `size` bytes, checked against what is left.
    fn len_of(&mut self, size: usize) -> Result<usize, Malformed> {
        let n = self.usize()?;
        if n.checked_mul(size).is_none_or(|b| b > self.rest.len()) {
            return Err(Malformed("a length beyond the entry"));
        }
        Ok(n)
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], Malformed> {
        let n = self.len_of(1)?;
        self.take(n)
    }
    /// What [`Encoder::byte_runs`] wrote.
    pub fn byte_runs(&mut self) -> Result<Vec<u8>, Malformed> {
        let n = self.usize()?;
        // every run takes 5 bytes of the entry and stands for at most u32::MAX bytes
        if n / u32::MAX as usize > self.rest.len() / 5 {
            return Err(Malformed("a length beyond the entry"));
        }
        // zeroed memory comes from the system as it is: runs of zeros cost nothing
        let mut out = vec![0u8; n];
        let mut at = 0;
        while at < n {
            let v = self.u8()?;
            let len = self.u32()? as usize;
            if len == 0 || len > n - at {
                return Err(Malformed("a run beyond its length"));
            }
            if v != 0 {
                out[at..at + len].fill(v);
            }
            at += len;
        }
        Ok(out)
    }
    pub fn f32s(&mut self) -> Result<Vec<f32>, Malformed> {
        let n = self.len_of(4)?;
        Ok(self
            .take(4 * n)?
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
    pub fn u32s(&mut self) -> Result<Vec<u32>, Malformed> {
        let n = self.len_of(4)?;
        Ok(self
            .take(4 * n)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
    /// A length for items of at least `min_size` bytes each (checked against what is left).
    pub fn count(&mut self, min_size: usize) -> Result<usize, Malformed> {
        self.len_of(min_size.max(1))
    }
    /// Errs unless every byte was read.
    pub fn finish(&self) -> Result<(), Malformed> {
        if self.rest.is_empty() {
            Ok(())
        } else {
            Err(Malformed("bytes after its fields"))
        }
    }
}

#[cfg(test)]
mod tests;
