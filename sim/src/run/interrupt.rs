//! Ctrl-C and SIGTERM during a run: the first asks every run of the process to stop at the end
//! of its current tick, after which the runner finishes the recordings (.rrd, MCAP) and the
//! command writes its other files and exits with [`EXIT_CODE`]; a second one ends the process
//! at once (files may then be incomplete; the MCAP chunks already written stay readable with
//! [`crate::record::mcap::McapRecording::open_recovering`]).

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the handler; read by the run loop once per tick.
static STOP: AtomicBool = AtomicBool::new(false);

/// The exit code of an interrupted command (128 + SIGINT, as shells report it).
pub const EXIT_CODE: u8 = 130;

/// Installs the handler of SIGINT, SIGTERM and SIGHUP (the `ctrlc` crate, `termination`
/// feature). Call once, from `main`.
pub fn install_handler() -> anyhow::Result<()> {
    ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            // the second signal: stop now
            std::process::exit(i32::from(EXIT_CODE));
        }
        eprintln!("\nstopping at the end of this tick (signal again to stop at once)");
    })
    .map_err(|e| anyhow::anyhow!("cannot install the Ctrl-C handler: {e}"))
}

/// Makes a file-size limit (`ulimit -f`, `prlimit --fsize`) an error of the write that passes
/// it, which names its file, instead of SIGXFSZ killing the process with every other output
/// unwritten. Call once, from `main`.
pub fn ignore_file_size_signal() {
    // SAFETY: setting SIGXFSZ's disposition to SIG_IGN installs no handler code; writes past
    // the limit then fail with EFBIG (POSIX `write`).
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// True once a stop was asked for.
pub fn requested() -> bool {
    STOP.load(Ordering::Relaxed)
}

/// The error a command returns when it was interrupted: `main` prints it and exits with
/// [`EXIT_CODE`] instead of 1.
#[derive(Debug, thiserror::Error)]
#[error("interrupted at t = {sim_time_s:.2} s (files written for the partial run)")]
pub struct Interrupted {
    /// Simulated time when the run stopped (s).
    pub sim_time_s: f64,
}
