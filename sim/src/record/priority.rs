//! The recording's threads run at background CPU priority.
//!
//! A recorded run hands its files to threads of their own (camera frames, the MCAP writer, the
//! .rrd's chunk builder and the Rerun SDK's batcher and file writer), which need most of a core
//! on a fast outdoor run. At the same priority as the simulation they were often scheduled on
//! the simulation's core: on the park run (2 cores) the simulation thread waited 14 ms per run
//! for its core and, sharing its caches, needed more CPU time too. At nice 19 they take the
//! cores' idle time: the wait fell to 2 ms, and the overhead of writing both files from
//! +15.8 % to +11.4 % and from +20.1 % to +17.2 % in two sets of 25 interleaved rounds.
//! Nothing they produce depends on when they run (see [`super::frames`]), and a run that
//! outpaces them waits on their queues, so they are never starved for long.
//!
//! Linux only (elsewhere a no-op): `setpriority` on the calling thread; a thread inherits its
//! creator's nice value, so SDK threads started by a background thread are background too.

/// The nice value of the recording's threads (the lowest priority).
const RECORDING_NICE: i32 = 19;

/// Lowers the calling thread to background priority. A failure leaves it as it was: the
/// recording is the same, only less polite.
pub fn background_thread() {
    #[cfg(target_os = "linux")]
    // SAFETY: setpriority only reads its arguments; `who` 0 is the calling thread on Linux
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, RECORDING_NICE);
    }
}

/// Starts a recording thread named `name` that runs `f` at background priority.
pub fn spawn<T: Send + 'static>(
    name: &str,
    f: impl FnOnce() -> T + Send + 'static,
) -> std::io::Result<std::thread::JoinHandle<T>> {
    std::thread::Builder::new()
        .name(name.into())
        .spawn(move || {
            background_thread();
            f()
        })
}

/// Runs `f` on a new background-priority thread and returns what it returns; the threads `f`
/// starts inherit the priority (how the Rerun SDK's threads get it).
pub fn in_background<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|s| {
        let t = s.spawn(|| {
            background_thread();
            f()
        });
        t.join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    fn nice() -> i32 {
        // SAFETY: getpriority only reads its arguments
        unsafe { libc::getpriority(libc::PRIO_PROCESS, 0) }
    }

    #[test]
    fn background_threads_and_their_children_are_niced_and_the_caller_is_not() {
        let before = nice();
        let (own, child) = in_background(|| {
            let child = std::thread::spawn(nice).join().unwrap();
            (nice(), child)
        });
        assert_eq!(own, RECORDING_NICE);
        assert_eq!(child, RECORDING_NICE);
        assert_eq!(nice(), before);
    }
}
