//! `sim batch`, `sim batch-merge` and `sim bench batch` with bad input: bad seeds, `--set`
//! keys, shards and durations are clear errors naming the option, absurd `--jobs` and batches
//! too large to plan are refused before anything is allocated or spawned, empty sweep values
//! name their key, and batch-merge refuses to overwrite a shard, to take one twice, to mix
//! shards of different batches and to merge a batch with shards missing.

use crate::common::{ROOM, expect_failure, run_ok, sim};
use std::path::Path;

/// A folder with `tiny.toml` (the 2 s room of the CLI tests) and `other.toml` (the same room
/// under another name).
fn room() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let other = ROOM.replace("name = \"tiny\"", "name = \"other\"");
    std::fs::write(dir.path().join("other.toml"), other).unwrap();
    dir
}

/// Runs `sim batch SCENARIO --seeds 0..3 --duration DURATION --shard SHARD --out OUT --quiet`.
fn shard(dir: &Path, scenario: &str, duration: &str, shard: &str, out: &str) {
    run_ok(
        &[
            "batch",
            scenario,
            "--seeds",
            "0..3",
            "--duration",
            duration,
            "--shard",
            shard,
            "--jobs",
            "1",
            "--out",
            out,
            "--quiet",
        ],
        dir,
    );
}

#[test]
fn batch_refuses_absurd_jobs() {
    let dir = room();
    expect_failure(
        &["batch", "tiny.toml", "--seeds", "0..1", "--jobs", "5000"],
        dir.path(),
        &["--jobs", "5000 is not in 0..=1024"],
    );
}

#[test]
fn batch_never_starts_more_workers_than_runs() {
    let dir = room();
    let out = sim(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..1",
            "--duration",
            "0.1",
            "--jobs",
            "1024",
            "--out",
            "b",
        ],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains(": 1 runs, 1 at a time"), "{err}");
}

#[test]
fn batch_refuses_too_many_seeds() {
    let dir = room();
    expect_failure(
        &["batch", "tiny.toml", "--seeds", "0..18446744073709551615"],
        dir.path(),
        &[
            "--seeds 0..18446744073709551615 makes 18446744073709551615 runs",
            "more than the 1000000 a batch may have",
        ],
    );
    assert!(
        !dir.path()
            .join("batch-tiny-0-18446744073709551615")
            .exists()
    );
}

#[test]
fn batch_refuses_sweeps_that_overflow_the_run_count() {
    let dir = room();
    expect_failure(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..6148914691236517206",
            "--sweep",
            "k=a,b,c",
        ],
        dir.path(),
        &[
            "--seeds 0..6148914691236517206 × 3 parameter sets (--sweep/--zip) makes 18446744073709551618 runs",
        ],
    );
    expect_failure(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..9223372036854775808",
            "--sweep",
            "k=a,b",
        ],
        dir.path(),
        &["× 2 parameter sets (--sweep/--zip) makes 18446744073709551616 runs"],
    );
}

#[test]
fn bench_batch_refuses_too_many_seeds() {
    let dir = room();
    expect_failure(
        &["bench", "batch", "--seeds", "4294967296"],
        dir.path(),
        &["--seeds", "4294967296 is not in 1..=1000000"],
    );
}

#[test]
fn bench_batch_help_gives_the_duration_it_uses() {
    let dir = room();
    let help = run_ok(&["bench", "batch", "--help"], dir.path());
    assert!(!help.contains("(default: the scenario"), "{help}");
    assert!(
        help.contains("in place of the scenario's own duration"),
        "{help}"
    );
    assert!(help.contains("[default: 30]"), "{help}");
}

#[test]
fn empty_sweep_and_zip_values_name_the_key() {
    let dir = room();
    for flag in ["--sweep", "--zip"] {
        for (arg, i) in [("k=", 1), ("k=,", 1), ("k=0.5,", 2)] {
            let want = format!("{flag} {arg}: value {i} of the list is empty");
            expect_failure(
                &["batch", "tiny.toml", "--seeds", "0..1", flag, arg],
                dir.path(),
                &[&want],
            );
        }
    }
}

#[test]
fn merge_refuses_to_overwrite_a_shard() {
    let dir = room();
    shard(dir.path(), "tiny.toml", "0.1", "0/2", "s0");
    shard(dir.path(), "tiny.toml", "0.1", "1/2", "s1");
    let before = std::fs::read_to_string(dir.path().join("s0/runs.jsonl")).unwrap();
    expect_failure(
        &["batch-merge", "s0", "s0", "s1"],
        dir.path(),
        &[
            "s0: the output folder is also given as a shard",
            "another folder",
        ],
    );
    // also when the same folder is spelled differently
    expect_failure(
        &["batch-merge", "./s1/", "s0", "s1"],
        dir.path(),
        &["the output folder is also given as a shard (s1)"],
    );
    let after = std::fs::read_to_string(dir.path().join("s0/runs.jsonl")).unwrap();
    assert_eq!(before, after);
    // a shard given twice
    expect_failure(
        &["batch-merge", "m", "s0", "s0"],
        dir.path(),
        &["job 0 is in both"],
    );
    // the shards merge into another folder, which is then a whole batch of its own
    run_ok(&["batch-merge", "m", "s0", "s1", "--quiet"], dir.path());
    let rows = std::fs::read_to_string(dir.path().join("m/runs.jsonl")).unwrap();
    assert_eq!(rows.lines().count(), 3);
    run_ok(&["batch-merge", "m2", "m", "--quiet"], dir.path());
}

#[test]
fn merge_refuses_shards_of_different_batches() {
    let dir = room();
    shard(dir.path(), "tiny.toml", "0.1", "0/2", "s0");
    shard(dir.path(), "other.toml", "0.1", "1/2", "o1");
    shard(dir.path(), "tiny.toml", "0.2", "1/2", "d1");
    shard(dir.path(), "tiny.toml", "0.1", "1/3", "n1");
    expect_failure(
        &["batch-merge", "m", "s0", "o1"],
        dir.path(),
        &["s0 and o1 are not shards of the same batch: the scenario is tiny in s0 but other in o1"],
    );
    expect_failure(
        &["batch-merge", "m", "s0", "d1"],
        dir.path(),
        &["s0 and d1 are not shards of the same batch: --duration is 0.1 in s0 but 0.2 in d1"],
    );
    expect_failure(
        &["batch-merge", "m", "s0", "n1"],
        dir.path(),
        &["the number of shards N (--shard K/N) is 2 in s0 but 3 in n1"],
    );
    assert!(!dir.path().join("m").exists());
}

#[test]
fn merge_refuses_missing_shards() {
    let dir = room();
    shard(dir.path(), "tiny.toml", "0.1", "0/3", "s0");
    expect_failure(
        &["batch-merge", "m", "s0"],
        dir.path(),
        &[
            "shards 1/3, 2/3 of the batch are missing",
            "--shard K/3 for K from 0 to 2",
        ],
    );
    // a folder without batch.json is not taken for a whole batch
    std::fs::remove_file(dir.path().join("s0/batch.json")).unwrap();
    expect_failure(
        &["batch-merge", "m", "s0"],
        dir.path(),
        &["batch.json: cannot read"],
    );
    assert!(!dir.path().join("m").exists());
}

/// A row whose parameter set is far beyond the batch's (found by fuzzing: the merge then
/// aggregated 54 billion empty sets and never ended) is an error naming the file.
#[test]
fn merge_refuses_rows_outside_the_batch() {
    let dir = room();
    shard(dir.path(), "tiny.toml", "0.1", "0/2", "s0");
    shard(dir.path(), "tiny.toml", "0.1", "1/2", "s1");
    let rows = dir.path().join("s1/runs.jsonl");
    let text = std::fs::read_to_string(&rows).unwrap();
    assert!(text.contains("\"set\":0,"), "{text}");
    std::fs::write(&rows, text.replace("\"set\":0,", "\"set\":54505553469,")).unwrap();
    expect_failure(
        &["batch-merge", "m", "s0", "s1"],
        dir.path(),
        &[
            "s1/runs.jsonl",
            "parameter set 54505553469",
            "batch of 3 runs",
        ],
    );
}

/// `sim batch ARGS` fails without a panic; the message after `error: `.
fn batch_error(args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let all: Vec<&str> = ["batch"].iter().chain(args).copied().collect();
    let out = sim(&all, dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "sim batch {args:?} should fail: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    match err.split_once("error: ") {
        Some((_, e)) => e.to_string(),
        None => panic!("no error in: {err}"),
    }
}

#[test]
fn bad_arguments_give_clear_errors() {
    let e = batch_error(&["maze_run", "--seeds", "5..2"]);
    assert!(e.contains("--seeds 5..2: the range is empty"), "{e}");
    let e = batch_error(&["maze_run", "--seeds", "0-3"]);
    assert!(e.contains("--seeds 0-3: expected a range A..B"), "{e}");
    let e = batch_error(&["maze_run", "--seeds", "0..2", "--set", "duration"]);
    assert!(e.contains("--set duration: expected KEY=VALUE"), "{e}");
    let e = batch_error(&[
        "maze_run",
        "--seeds",
        "0..2",
        "--set",
        "robots.0.sensors.laser.rte=5",
    ]);
    assert!(e.starts_with("--set robots.0.sensors.laser.rte=5: "), "{e}");
    assert!(
        e.contains("`robots[0].sensors.laser.rte`: unknown field `rte`"),
        "{e}"
    );
    let e = batch_error(&["maze_run", "--seeds", "0..2", "--set", "duration=abc"]);
    assert!(e.starts_with("--set duration=abc: "), "{e}");
    assert!(e.contains("maze_run.toml:9"), "{e}");
    let e = batch_error(&[
        "maze_run",
        "--seeds",
        "0..2",
        "--set",
        "robots[name=r9].speed=1",
    ]);
    assert!(
        e.contains("`robots` has no item with name = r9 (its items' name: scout)"),
        "{e}"
    );
    let e = batch_error(&["maze_run", "--seeds", "0..2", "--shard", "2/2"]);
    assert!(e.contains("--shard 2/2: K must be below N"), "{e}");
    let e = batch_error(&["maze_run", "--seeds", "0..2", "--duration", "-1"]);
    assert!(
        e.contains("--duration: expected a positive number of seconds, got -1"),
        "{e}"
    );
    let e = batch_error(&["no_such_scenario", "--seeds", "0..2"]);
    assert!(
        e.contains("no_such_scenario: no such file and no bundled scenario"),
        "{e}"
    );
}

/// The rows of `dir`'s runs.jsonl without their wall-clock fields, one string per row.
fn rows_without_timing(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("runs.jsonl")).unwrap();
    text.lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            let o = v.as_object_mut().unwrap();
            for k in ["job_wall_s", "wall_time_s", "real_time_factor"] {
                o.remove(k);
            }
            v.to_string()
        })
        .collect()
}

/// A shard killed mid-way keeps the rows of the runs it finished; batch-merge refuses the
/// folder and says how to finish it; `--resume` runs only the missing jobs, and the merged
/// batch equals the batch run whole, row for row (apart from wall-clock fields).
#[test]
fn a_killed_shard_resumes_and_merges_to_the_whole_batch() {
    use std::os::unix::process::ExitStatusExt;
    let dir = room();
    let args = |shard: &'static str, out: &'static str| {
        let mut a = vec![
            "batch",
            "tiny.toml",
            "--seeds",
            "0..40",
            "--duration",
            "200",
        ];
        a.extend(["--jobs", "1", "--out", out, "--quiet"]);
        if !shard.is_empty() {
            a.extend(["--shard", shard]);
        }
        a
    };
    run_ok(&args("0/2", "s0"), dir.path());
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sim"))
        .args(args("1/2", "s1"))
        .current_dir(dir.path())
        .spawn()
        .unwrap();
    let rows = dir.path().join("s1/runs.jsonl");
    let started = std::time::Instant::now();
    while std::fs::read_to_string(&rows).map_or(0, |t| t.lines().count()) < 3 {
        assert!(started.elapsed().as_secs() < 120, "no rows appear");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(
        status.signal(),
        Some(9),
        "the shard ended before it was killed"
    );
    let done_before = std::fs::read_to_string(&rows).unwrap().lines().count();
    assert!((3..20).contains(&done_before), "{done_before} rows");
    expect_failure(
        &["batch-merge", "m", "s0", "s1"],
        dir.path(),
        &["s1/runs.jsonl", "incomplete", "--resume"],
    );
    let mut resume = args("1/2", "s1");
    resume.retain(|a| *a != "--quiet");
    resume.push("--resume");
    let out = crate::common::sim(&resume, dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(&format!(
            "resuming: {done_before} of 20 runs are done, {} to run",
            20 - done_before
        )),
        "{err}"
    );
    run_ok(&["batch-merge", "m", "s0", "s1", "--quiet"], dir.path());
    run_ok(&args("", "whole"), dir.path());
    let (merged, whole) = (
        rows_without_timing(&dir.path().join("m")),
        rows_without_timing(&dir.path().join("whole")),
    );
    assert_eq!(merged.len(), 40);
    assert_eq!(merged, whole);
}

/// A batch whose runs partly fail (a parameter value the scenario refuses) reports them, exits
/// with 2, and `--resume` runs only those again; a folder of another batch is not resumed.
#[test]
fn resume_runs_only_the_failed_runs_and_refuses_another_batch() {
    let dir = room();
    let args = |extra: &[&'static str]| {
        let mut a = vec!["batch", "tiny.toml", "--seeds", "0..2", "--duration", "1"];
        a.extend([
            "--sweep",
            "robots.0.behaviour.speed=0.5,-1,0.7",
            "--jobs",
            "1",
        ]);
        a.extend(["--out", "o"]);
        a.extend_from_slice(extra);
        a
    };
    let out = crate::common::sim(&args(&["--quiet"]), dir.path());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("set 1 (robots.0.behaviour.speed=-1) does not load"),
        "{err}"
    );
    let ok_lines = || {
        let text = std::fs::read_to_string(dir.path().join("o/runs.jsonl")).unwrap();
        let ok: Vec<String> = text
            .lines()
            .filter(|l| l.contains("\"status\":\"ok\""))
            .map(String::from)
            .collect();
        ok
    };
    let (first, first_ok) = (rows_without_timing(&dir.path().join("o")), ok_lines());
    assert_eq!(first.len(), 6);
    let out = crate::common::sim(&args(&["--resume"]), dir.path());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("resuming: 4 of 6 runs are done, 2 to run"),
        "{err}"
    );
    assert!(err.contains("2 of 6 runs failed"), "{err}");
    assert_eq!(rows_without_timing(&dir.path().join("o")), first);
    // the successful runs were not run again: their rows are kept, wall times included
    assert_eq!(ok_lines(), first_ok);
    let mut other = args(&["--resume"]);
    other[5] = "2";
    expect_failure(
        &other,
        dir.path(),
        &[
            "--resume",
            "holds another batch: --duration is 1 there, 2 here",
        ],
    );
    expect_failure(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..2",
            "--out",
            "new",
            "--resume",
        ],
        dir.path(),
        &["new holds no batch"],
    );
}
