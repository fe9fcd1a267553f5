//! Bad values of `--threads`, `sim experiment park`, `sim bench slam`, `sim experiment
//! maze-slam` and the CARMEN export: refused before any work with a message naming the option
//! that was given, and I/O errors that say what failed once.

use super::{ROOM, expect_failure, run_ok, sim};

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

#[test]
fn park_refuses_absurd_run_counts_and_repeated_routes() {
    let dir = tempfile::tempdir().unwrap();
    for runs in ["100001", "4294967296"] {
        expect_failure(
            &["experiment", "park", "--runs", runs],
            dir.path(),
            &["--runs", "100000", runs],
        );
    }
    // commas and spaces both separate routes; the same route twice is refused
    for routes in [
        &["park_route_short,park_route_short"][..],
        &["park_route_short", "park_route_short"][..],
    ] {
        let mut args = vec!["experiment", "park", "--runs", "1", "--routes"];
        args.extend(routes);
        expect_failure(
            &args,
            dir.path(),
            &["--routes", "park_route_short", "twice"],
        );
    }
}

#[test]
fn park_per_run_needs_json() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["experiment", "park", "--runs", "1", "--per-run"],
        dir.path(),
        &["--per-run", "--json"],
    );
}

/// A bad scenario or duration stops `bench record` before its table's header is printed.
#[test]
fn bench_record_checks_its_options_before_printing() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["bench", "record", "--duration", "-1"][..],
        &["bench", "record", "--scenario", "hospital_patrol,nowhere"],
    ] {
        let out = sim(args, dir.path());
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(out.stdout.is_empty(), "{args:?} printed: {:?}", out.stdout);
    }
}

#[test]
fn bench_slam_refuses_long_durations_and_unknown_modes_naming_its_own_options() {
    let dir = tempfile::tempdir().unwrap();
    for d in ["700", "1e12"] {
        expect_failure(
            &["bench", "slam", "--duration", d],
            dir.path(),
            &["--duration", "hospital_loop lasts 600 s"],
        );
    }
    for m in ["nosuch", ""] {
        let out = sim(
            &["bench", "slam", "--duration", "1", "--modes", m],
            dir.path(),
        );
        assert!(!out.status.success(), "--modes {m:?} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--modes") && err.contains("scan_to_map, graph, rbpf"),
            "{err}"
        );
        assert!(!err.contains("--slam"), "{err}");
    }
}

#[test]
fn bench_slam_prints_the_thread_count_it_ran_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_ok(
        &[
            "bench",
            "slam",
            "--json",
            "--modes",
            "scan_to_map",
            "--duration",
            "1",
            "--threads",
            "0",
        ],
        dir.path(),
    );
    let row: serde_json::Value = serde_json::from_str(out.lines().next().unwrap()).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(row["threads"], cores as u64, "{row}");
}

#[test]
fn maze_slam_names_scenarios_when_one_has_nothing_to_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(
        &[
            "experiment",
            "maze-slam",
            "--scenarios",
            "park_route_short",
            "--methods",
            "wheel_odometry",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--scenarios") && err.contains("park_route_short"),
        "{err}"
    );
    assert!(!err.contains("--carmen-out"), "{err}");
    assert!(
        !err.contains("simulating"),
        "checked before simulating: {err}"
    );
}

#[test]
fn carmen_io_errors_say_read_or_write_and_give_the_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    std::fs::write(dir.path().join("afile"), "").unwrap();
    let err = |args: &[&str], cause: &str| {
        let out = sim(args, dir.path());
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(err.matches(cause).count(), 1, "{err}");
        err
    };
    let e = err(
        &[
            "run",
            "tiny.toml",
            "--no-rrd",
            "--quiet",
            "--duration",
            "0.1",
            "--carmen-out",
            "afile/c",
        ],
        "Not a directory",
    );
    assert!(e.contains("afile/c: cannot write"), "{e}");
    let e = err(
        &["slam", "--carmen", "nosuch", "--no-rrd", "--quiet"],
        "No such file",
    );
    assert!(e.contains("nosuch: cannot read"), "{e}");
}
