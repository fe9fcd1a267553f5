//! `sim scans` and `sim match` as a user runs them: the scans CSV of a short bundled scenario
//! parses, a known pair is recovered (within 0.1 m and 2° of the true transform), `--json` has
//! the documented fields, and every bad input the commands check ends with a clear message and a
//! non-zero exit code (one test per case); absurd sizes are refused before the file is read.

use crate::common::{self, run_ok, sim as sim_command};
use sim::formats::scans::{SCANS_HEADER, ScanRecord, read_scans};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

/// The scans of the first 4 s of the bundled maze run (41 scans of `scout`, 0.1 s apart),
/// written by `sim scans` once per test process. Every process writes its own file and renames
/// it over `maze_4s.csv` in cargo's scratch folder for integration tests, so parallel test
/// processes never read a half-written file and nothing piles up between runs.
fn maze_scans() -> &'static Path {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
        let own = format!("maze_4s.{}.csv", std::process::id());
        let out = sim_command(
            &[
                "scans",
                "maze_run",
                "--duration",
                "4",
                "--out",
                &own,
                "--quiet",
            ],
            &dir,
        );
        assert!(
            out.status.success(),
            "sim scans failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let file = dir.join("maze_4s.csv");
        std::fs::rename(dir.join(&own), &file).unwrap();
        file
    })
}

/// Runs `args`, expects a non-zero exit without a panic and every fragment in the message.
fn expect_failure(args: &[&str], cwd: &Path, fragments: &[&str]) -> Output {
    let out = sim_command(args, cwd);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "{args:?} should fail; stderr:\n{err}"
    );
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("error: "), "{err}");
    for f in fragments {
        assert!(err.contains(f), "{args:?}: expected `{f}` in: {err}");
    }
    out
}

/// `sim match` on the maze scans with extra arguments.
fn match_maze(extra: &[&str]) -> Vec<String> {
    let file = maze_scans().display().to_string();
    let mut args: Vec<String> = ["match", &file, "--reference", "20", "--current", "30"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

fn refs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

/// A folder with a SCANS file of the given body (after the header).
fn scans_file(name: &str, body: &str) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{}\n{body}", SCANS_HEADER.join(","));
    std::fs::write(dir.path().join(name), text).unwrap();
    (dir, name.to_string())
}

#[test]
fn scans_writes_a_csv_that_parses() {
    let path = maze_scans();
    let text = std::fs::read_to_string(path).unwrap();
    assert_eq!(text.lines().next(), Some(SCANS_HEADER.join(",").as_str()));
    let scans: Vec<ScanRecord> = read_scans(path).unwrap();
    assert_eq!(scans.len(), 41, "one scan every 0.1 s over 0 ..= 4 s");
    for (k, s) in scans.iter().enumerate() {
        assert_eq!(s.index, k as u64);
        assert_eq!(s.robot, "scout");
        assert!((s.stamp - 0.1 * k as f64).abs() < 1e-9, "{}", s.stamp);
        assert_eq!(s.ranges.len(), 1081, "SICK LMS100 scans");
        assert!((s.angle_increment.to_degrees() - 0.25).abs() < 1e-4);
        assert!(s.points().len() > 500, "scan {k} sees the maze");
    }
    // the robot drives: the true poses move
    assert!(scans[0].pose.distance(&scans[40].pose) > 1.0);
}

#[test]
fn match_recovers_a_known_pair() {
    let dir = tempfile::tempdir().unwrap();
    let text = run_ok(&refs(&match_maze(&[])), dir.path());
    assert!(text.contains("method: improved matcher"), "{text}");
    assert!(text.contains("→ right (within 0.1 m and 2°)"), "{text}");
}

#[test]
fn match_json_has_the_fields() {
    let dir = tempfile::tempdir().unwrap();
    let text = run_ok(&refs(&match_maze(&["--json"])), dir.path());
    assert_eq!(text.lines().count(), 1, "one JSON object: {text}");
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(j["reference"], 20);
    assert_eq!(j["current"], 30);
    assert_eq!(j["reference_robot"], "scout");
    assert_eq!(j["method"], "improved");
    assert_eq!(j["right"], true, "{j}");
    assert!(j["evaluations"].as_u64().unwrap() > 0);
    assert!(j["time_ms"].as_f64().unwrap() > 0.0);
    assert!(j["strategy"].is_null() && j["passes_thesis_filter"].is_null());
    // the true transform is P_ref⁻¹ ⊕ P_cur of the file's poses
    let scans = read_scans(maze_scans()).unwrap();
    let truth = scans[20].pose.between(&scans[30].pose);
    let t = &j["true_transform"];
    assert!((t["x_m"].as_f64().unwrap() - truth.x).abs() < 1e-9);
    assert!((t["y_m"].as_f64().unwrap() - truth.y).abs() < 1e-9);
    assert!((t["theta_rad"].as_f64().unwrap() - truth.theta).abs() < 1e-9);
    let found = &j["transform"];
    let (dx, dy) = (
        found["x_m"].as_f64().unwrap() - truth.x,
        found["y_m"].as_f64().unwrap() - truth.y,
    );
    let dtheta = found["theta_deg"].as_f64().unwrap() - truth.theta.to_degrees();
    assert!(dx.hypot(dy) <= 0.1 && dtheta.abs() <= 2.0, "{j}");
    let e = &j["error"];
    assert!((e["distance_m"].as_f64().unwrap() - dx.hypot(dy)).abs() < 1e-9);
    for k in ["x_mm", "y_mm", "theta_deg"] {
        assert!(found[k].is_number(), "{k} in {found}");
    }
}

#[test]
fn match_json_of_the_thesis_de() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&[
        "--json",
        "--fitness",
        "correlation",
        "--strategy",
        "rand/1",
        "--pop",
        "20",
        "--gens",
        "300",
        "-F",
        "0.5",
        "-C",
        "0.9",
        "--seed",
        "3",
    ]);
    let text = run_ok(&refs(&args), dir.path());
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(j["method"], "correlation");
    assert_eq!(j["strategy"], "rand1");
    assert_eq!(j["population"], 20);
    assert_eq!(j["generations"], 300);
    assert_eq!(j["f"], 0.5);
    assert_eq!(j["seed"], 3);
    assert!(j["passes_thesis_filter"].is_boolean());
    // same seed, same answer
    let again: serde_json::Value = serde_json::from_str(&run_ok(&refs(&args), dir.path())).unwrap();
    assert_eq!(j["transform"], again["transform"]);
    assert_eq!(j["evaluations"], again["evaluations"]);
}

// ---- sim match: bad input ----

#[test]
fn match_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["match", "nowhere.csv", "--reference", "0", "--current", "1"],
        dir.path(),
        &["nowhere.csv", "cannot read the scans file"],
    );
}

#[test]
fn match_unknown_reference_index() {
    let dir = tempfile::tempdir().unwrap();
    let file = maze_scans().display().to_string();
    expect_failure(
        &["match", &file, "--reference", "999", "--current", "1"],
        dir.path(),
        &[
            "--reference 999",
            "no scan with index 999",
            "indices 0..=40",
        ],
    );
}

#[test]
fn match_unknown_current_index() {
    let dir = tempfile::tempdir().unwrap();
    let file = maze_scans().display().to_string();
    expect_failure(
        &["match", &file, "--reference", "0", "--current", "41"],
        dir.path(),
        &["--current 41", "no scan with index 41"],
    );
}

#[test]
fn match_malformed_field_names_line_and_column() {
    let (dir, f) = scans_file(
        "bad.csv",
        "0,r1,0,0,0,0,-2.35,0.004,0.5,20,1,2,3\n1,r1,zz,0,0,0,-2.35,0.004,0.5,20,1,2,3\n",
    );
    expect_failure(
        &["match", &f, "--reference", "0", "--current", "1"],
        dir.path(),
        &[
            "bad.csv:3:3: field `stamp_s`",
            "expected a finite number, found `zz`",
        ],
    );
}

#[test]
fn match_bad_range_names_the_beam() {
    let (dir, f) = scans_file("bad.csv", "0,r1,0,0,0,0,-2.35,0.004,0.5,20,1,x,3\n");
    expect_failure(
        &["match", &f, "--reference", "0", "--current", "0"],
        dir.path(),
        &["bad.csv:2:12: field `ranges[1]`", "found `x`"],
    );
}

#[test]
fn match_short_line() {
    let (dir, f) = scans_file("short.csv", "0,r1,0,0,0,0,-2.35,0.004,0.5,20,1\n1,r1,0,0\n");
    expect_failure(
        &["match", &f, "--reference", "0", "--current", "1"],
        dir.path(),
        &["short.csv:3: expected at least 11 fields", "found 4"],
    );
}

#[test]
fn match_duplicate_index() {
    let (dir, f) = scans_file(
        "dup.csv",
        "7,r1,0,0,0,0,-2.35,0.004,0.5,20,1\n7,r1,0,0,0,0,-2.35,0.004,0.5,20,1\n",
    );
    expect_failure(
        &["match", &f, "--reference", "7", "--current", "7"],
        dir.path(),
        &["dup.csv:3:1: field `index`", "first on line 2"],
    );
}

#[test]
fn match_bad_header() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("h.csv"), "index,robot,stamp,x\n").unwrap();
    expect_failure(
        &["match", "h.csv", "--reference", "0", "--current", "1"],
        dir.path(),
        &["h.csv:1:3: expected the header column `stamp_s`"],
    );
}

#[test]
fn match_empty_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("e.csv"), "").unwrap();
    expect_failure(
        &["match", "e.csv", "--reference", "0", "--current", "1"],
        dir.path(),
        &["e.csv:1: expected the header line", "empty file"],
    );
}

#[test]
fn match_scan_without_valid_readings() {
    let (dir, f) = scans_file(
        "inf.csv",
        "0,r1,0,0,0,0,-2.35,0.004,0.5,20,inf,nan,0.1\n1,r1,0,0,0,0,-2.35,0.004,0.5,20,1,1,1\n",
    );
    expect_failure(
        &["match", &f, "--reference", "0", "--current", "1"],
        dir.path(),
        &["--reference 0: scan 0 of inf.csv has no valid reading"],
    );
    expect_failure(
        &["match", &f, "--reference", "1", "--current", "0"],
        dir.path(),
        &["--current 0: scan 0 of inf.csv has no valid reading"],
    );
}

#[test]
fn match_population_below_the_strategy_minimum() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "correlation", "--pop", "3"]);
    expect_failure(
        &refs(&args),
        dir.path(),
        &["--pop:", "population size 3", "at least 4"],
    );
}

#[test]
fn match_bad_mutation_constant() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "euclidean", "-F", "0"]);
    expect_failure(&refs(&args), dir.path(), &["-F:", "F must be in (0, 2]"]);
}

#[test]
fn match_bad_crossover_rate() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "euclidean", "-C", "1.5"]);
    expect_failure(&refs(&args), dir.path(), &["-C:", "[0, 1]", "1.5"]);
}

#[test]
fn match_unknown_strategy() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "correlation", "--strategy", "best3"]);
    let out = sim_command(&refs(&args), dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    // a command-line usage error (clap's exit code 2)
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("rand1") && err.contains("best3"), "{err}");
}

#[test]
fn match_de_options_with_the_improved_matcher() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--gens", "10"]);
    expect_failure(
        &refs(&args),
        dir.path(),
        &["--gens sets the thesis's DE", "not with --fitness improved"],
    );
}

#[test]
fn match_bad_window() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &refs(&match_maze(&["--max-xy", "0"])),
        dir.path(),
        &["--max-xy: expected a positive distance"],
    );
    expect_failure(
        &refs(&match_maze(&["--max-theta", "200"])),
        dir.path(),
        &["--max-theta: expected an angle in (0, 180] degrees"],
    );
}

#[test]
fn match_zero_stall() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "correlation", "--stall", "0"]);
    expect_failure(&refs(&args), dir.path(), &["--stall: expected at least 1"]);
}

#[test]
fn match_bad_time_limit() {
    let dir = tempfile::tempdir().unwrap();
    let args = match_maze(&["--fitness", "correlation", "--time", "0"]);
    expect_failure(&refs(&args), dir.path(), &["--time: expected a positive"]);
}

// ---- sim scans: bad input ----

#[test]
fn scans_unknown_scenario() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["scans", "nowhere", "--out", "x.csv"],
        dir.path(),
        &["nowhere: no such file and no bundled scenario", "maze_run"],
    );
}

#[test]
fn scans_bad_period() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["scans", "maze_run", "--period", "0", "--out", "x.csv"],
        dir.path(),
        &["--period: expected a positive number of seconds"],
    );
}

#[test]
fn scans_bad_duration() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["scans", "maze_run", "--duration", "-1", "--out", "x.csv"],
        dir.path(),
        &["--duration: expected a positive number of seconds"],
    );
}

#[test]
fn scans_unknown_robot() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &[
            "scans", "maze_run", "--robot", "nobody", "--out", "x.csv", "--quiet",
        ],
        dir.path(),
        &["no robot named `nobody`", "robots: scout"],
    );
}

#[test]
fn scans_no_laser() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
name = "blind"
duration = 1.0
dt = 0.05
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0], thickness = 0.2 },
  { from = [0.0, 10.0], to = [10.0, 10.0], thickness = 0.2 },
  { from = [0.0, 0.0], to = [0.0, 10.0], thickness = 0.2 },
  { from = [10.0, 0.0], to = [10.0, 10.0], thickness = 0.2 },
]
[[robots]]
name = "r"
start = [3.0, 3.0, 0.0]
"#;
    std::fs::write(dir.path().join("blind.toml"), text).unwrap();
    expect_failure(
        &["scans", "blind.toml", "--out", "x.csv", "--quiet"],
        dir.path(),
        &["blind.toml", "no laser scans captured"],
    );
    assert!(!dir.path().join("x.csv").exists());
}

#[test]
fn scans_unwritable_output() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &[
            "scans",
            "maze_run",
            "--duration",
            "0.2",
            "--out",
            "no/such/dir/x.csv",
            "--quiet",
        ],
        dir.path(),
        &["no/such/dir/x.csv", "cannot create the scans file"],
    );
}

// ---- sim match: sizes beyond the limits, refused before the file is read (some by the
// argument parser, with its exit code 2) ----

/// `sim match` on a file that is never read: the options are checked first.
fn match_args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "match",
        "never-read.csv",
        "--reference",
        "0",
        "--current",
        "1",
    ];
    args.extend(extra);
    args
}

#[test]
fn match_refuses_a_population_or_generations_beyond_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    for pop in ["100001", "4294967296"] {
        common::expect_failure(
            &match_args(&["--fitness", "euclidean", "--pop", pop]),
            dir.path(),
            &["--pop", pop, "100000"],
        );
    }
    for gens in ["1000001", "4294967296"] {
        common::expect_failure(
            &match_args(&["--fitness", "euclidean", "--gens", gens]),
            dir.path(),
            &["--gens", gens, "1000000"],
        );
    }
}

#[test]
fn match_refuses_a_window_beyond_100_m() {
    let dir = tempfile::tempdir().unwrap();
    for max_xy in ["100.5", "1e4", "1e5", "1e9", "inf"] {
        common::expect_failure(
            &match_args(&["--max-xy", max_xy]),
            dir.path(),
            &["--max-xy: expected a positive distance", "at most 100"],
        );
    }
}

#[test]
fn match_refuses_a_mutation_constant_above_2() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["2.5", "1e12", "inf"] {
        common::expect_failure(
            &match_args(&["--fitness", "correlation", "-F", f]),
            dir.path(),
            &["-F:", "F must be in (0, 2]"],
        );
    }
}

#[test]
fn match_refuses_a_time_limit_too_long_for_a_duration() {
    let dir = tempfile::tempdir().unwrap();
    common::expect_failure(
        &match_args(&["--fitness", "correlation", "--time", "1e300"]),
        dir.path(),
        &["--time: 1e300 seconds is too long"],
    );
}
