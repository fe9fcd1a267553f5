//! `--threads` of every command: more than 1024 is refused before any work, naming the option;
//! 1024 runs.

use crate::common::{ROOM, expect_failure, run_ok};

/// Every command with `--threads`, with what else it needs to get past argument parsing.
const THREADS_COMMANDS: [&[&str]; 11] = [
    &[
        "run",
        "tiny.toml",
        "--no-rrd",
        "--quiet",
        "--duration",
        "0.1",
    ],
    &["replay", "r.mcap", "--no-rrd", "--quiet"],
    &["scans", "tiny.toml", "--out", "s.csv", "--quiet"],
    &["batch", "tiny.toml", "--seeds", "0..1", "--quiet"],
    &["slam", "--carmen", "c.log", "--no-rrd", "--quiet"],
    &["experiment", "park", "--runs", "1"],
    &["experiment", "de-match", "--pairs", "1"],
    &["experiment", "maze-slam", "--methods", "wheel_odometry"],
    &["bench", "record", "--reps", "1"],
    &["bench", "swarm", "--robots", "1"],
    &["bench", "slam", "--duration", "1"],
];

#[test]
fn every_threads_option_refuses_more_than_1024_before_starting_any() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    for cmd in THREADS_COMMANDS {
        for bad in ["5000", "4294967296", "-5", ""] {
            let flag = format!("--threads={bad}");
            let args: Vec<&str> = cmd.iter().copied().chain([flag.as_str()]).collect();
            let started = std::time::Instant::now();
            expect_failure(
                &args,
                dir.path(),
                &["--threads", "0 (one per core)", "1024"],
            );
            assert!(started.elapsed().as_secs_f64() < 2.0, "{args:?} was slow");
        }
    }
}

#[test]
fn the_most_threads_allowed_still_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    run_ok(
        &[
            "run",
            "tiny.toml",
            "--no-rrd",
            "--quiet",
            "--duration",
            "0.1",
            "--threads",
            "1024",
        ],
        dir.path(),
    );
}
