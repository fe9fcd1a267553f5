//! The .rrd file: the SDK's encoder writing to a buffered file on the SDK's forwarding thread,
//! keeping the first write error for the end of the run.
//!
//! Why not the SDK's `FileSink`: when a write fails (disk full, a file size limit), its writer
//! thread ends with a flush request still in its queue, so the flush at the end of the run
//! waits forever and the error is only logged. Here a failed write ends the file (nothing more
//! is written to it) and every later flush, and [`RrdFile::finish`], return the error.

use rerun::external::re_log_encoding::{CrateVersion, Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

/// The writing end the SDK holds ([`LogSink`]).
pub struct RrdFileSink(Arc<Mutex<FileState>>);

/// The recorder's handle on the same file: its path, and [`RrdFile::finish`].
pub struct RrdFile {
    state: Arc<Mutex<FileState>>,
    path: PathBuf,
}

struct FileState {
    /// None once finished or failed.
    encoder: Option<Encoder<BufWriter<File>>>,
    /// The first write error.
    error: Option<String>,
}

impl FileState {
    /// Keeps the first error and closes the file without a footer: after a failed write the
    /// stream is cut, and the end marker would follow a partial message.
    fn fail(&mut self, e: impl std::fmt::Display) {
        self.error.get_or_insert_with(|| e.to_string());
        if let Some(mut enc) = self.encoder.take() {
            enc.do_not_emit_footer();
            // the writer's own flush on drop would repeat the failing write
            if let Ok(w) = enc.into_inner() {
                let (_file, _unwritten) = w.into_parts();
            }
        }
    }

    fn result(&self) -> Result<(), String> {
        self.error.clone().map_or(Ok(()), Err)
    }
}

fn lock(state: &Mutex<FileState>) -> MutexGuard<'_, FileState> {
    state.lock().unwrap_or_else(|p| p.into_inner())
}

/// Creates `path` and writes the stream header (the SDK's on-disk options: protobuf, LZ4).
pub fn create(path: &Path) -> anyhow::Result<(RrdFileSink, RrdFile)> {
    let file = File::create(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the recording: {e}", path.display()))?;
    let encoder = Encoder::new_eager(
        CrateVersion::LOCAL,
        EncodingOptions::PROTOBUF_COMPRESSED,
        BufWriter::new(file),
    )
    .map_err(|e| anyhow::anyhow!("{}: cannot write the recording: {e}", path.display()))?;
    let state = Arc::new(Mutex::new(FileState {
        encoder: Some(encoder),
        error: None,
    }));
    Ok((
        RrdFileSink(state.clone()),
        RrdFile {
            state,
            path: path.to_path_buf(),
        },
    ))
}

impl LogSink for RrdFileSink {
    fn send(&self, msg: LogMsg) {
        let mut s = lock(&self.0);
        if let Some(enc) = s.encoder.as_mut()
            && let Err(e) = enc.append(&msg)
        {
            s.fail(e);
        }
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        let mut s = lock(&self.0);
        if let Some(enc) = s.encoder.as_mut()
            && let Err(e) = enc.flush_blocking()
        {
            s.fail(e);
        }
        s.result().map_err(SinkFlushError::failed)
    }
}

impl RrdFile {
    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the footer (the index Rerun's tools read the file by) and closes the file; the
    /// first write error, if any. Call after the stream's last flush; later messages are
    /// dropped.
    pub fn finish(&self) -> Result<(), String> {
        let mut s = lock(&self.state);
        if let Some(mut enc) = s.encoder.take() {
            let ended = enc.finish().map_err(|e| e.to_string()).and_then(|()| {
                let w = enc.into_inner().map_err(|e| e.to_string())?;
                w.into_inner().map(drop).map_err(|e| e.error().to_string())
            });
            if let Err(e) = ended {
                s.error.get_or_insert(e);
            }
        }
        s.result()
    }
}
