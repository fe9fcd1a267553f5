//! The `sim` command line: exit codes, error messages, default file names, the summary JSON.

mod batch_limits;
mod bounds_match_loc;
mod carmen;
mod interrupt;
mod matching;
mod option_limits;
mod replay;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `sim` binary with `args` in `cwd`.
pub fn sim(args: &[&str], cwd: &Path) -> Output {
    sim_env(args, cwd, &[])
}

/// [`sim`] with extra environment variables.
pub fn sim_env(args: &[&str], cwd: &Path, env: &[(&str, &Path)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sim"))
        .args(args)
        .current_dir(cwd)
        .envs(env.iter().copied())
        .output()
        .expect("sim runs")
}

/// Runs `sim` and returns its standard output, failing with its standard error.
pub fn run_ok(args: &[&str], cwd: &Path) -> String {
    let out = sim(args, cwd);
    assert!(
        out.status.success(),
        "{args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

const ROOM: &str = r#"
name = "tiny"
seed = 3
duration = 2.0
walls = [
  { from = [0.0, 0.0], to = [6.0, 0.0], thickness = 0.2 },
  { from = [0.0, 6.0], to = [6.0, 6.0], thickness = 0.2 },
  { from = [0.0, 0.0], to = [0.0, 6.0], thickness = 0.2 },
  { from = [6.0, 0.0], to = [6.0, 6.0], thickness = 0.2 },
]
[[robots]]
name = "r1"
start = [2.0, 2.0, 0.0]
behaviour = { type = "waypoints", points = [[4.0, 2.0]], speed = 0.5 }
[robots.sensors.laser]
preset = "hokuyo_urg04lx"
[robots.sensors.encoder]
"#;

#[test]
fn run_writes_default_rrd_and_summary_json() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let out = sim(
        &[
            "run",
            "tiny.toml",
            "--seed",
            "5",
            "--summary",
            "s.json",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        dir.path().join("tiny-seed5.rrd").exists(),
        "default .rrd name"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(s["scenario"], "tiny");
    assert_eq!(s["seed"], 5);
    assert!((s["sim_time_s"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    for key in ["wall_time_s", "real_time_factor"] {
        assert!(s[key].as_f64().unwrap() > 0.0, "{key}");
    }
    let r = &s["robots"][0];
    assert_eq!(r["name"], "r1");
    for key in ["distance_m", "collisions", "odometry_drift_m"] {
        assert!(r[key].is_number(), "{key} in {r}");
    }
    assert!(r["distance_m"].as_f64().unwrap() > 0.3);
}

#[test]
fn no_rrd_writes_nothing_and_prints_the_table() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let out = sim(
        &["run", "tiny.toml", "--no-rrd", "--duration", "0.5"],
        dir.path(),
    );
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("r1") && stdout.contains("odom drift"),
        "{stdout}"
    );
    let rrds = std::fs::read_dir(dir.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "rrd")
        })
        .count();
    assert_eq!(rrds, 0);
}

pub fn expect_failure(args: &[&str], cwd: &Path, fragments: &[&str]) {
    let out = sim(args, cwd);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    for f in fragments {
        assert!(err.contains(f), "expected `{f}` in: {err}");
    }
}

#[test]
fn without_the_assets_folder_bundled_names_fail_and_say_why() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no_assets");
    let run = |args: &[&str]| sim_env(args, dir.path(), &[("SIM_ASSETS", &missing)]);
    for args in [&["run", "hospital_patrol"][..], &["scenarios"][..]] {
        let out = run(args);
        assert!(!out.status.success(), "{args:?} should fail");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        for f in [
            "no_assets",
            "cannot read the bundled scenarios",
            "SIM_ASSETS",
        ] {
            assert!(err.contains(f), "{args:?}: expected `{f}` in: {err}");
        }
    }
    // a scenario file needs no bundled folder
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let out = run(&[
        "run",
        "tiny.toml",
        "--duration",
        "0.1",
        "--no-rrd",
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_input_exits_non_zero_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["run", "nowhere.toml"],
        dir.path(),
        &["nowhere.toml", "no such file"],
    );
    std::fs::write(
        dir.path().join("bad.toml"),
        ROOM.replace("seed = 3", "seed = 3\nspeed = 2"),
    )
    .unwrap();
    expect_failure(&["run", "bad.toml"], dir.path(), &["bad.toml:4:", "speed"]);
    std::fs::write(
        dir.path().join("bad2.toml"),
        ROOM.replace(
            "[robots.sensors.encoder]",
            "[robots.sensors.encoder]\nticks_per_rev = -5",
        ),
    )
    .unwrap();
    expect_failure(
        &["run", "bad2.toml"],
        dir.path(),
        &["bad2.toml:", "ticks_per_rev"],
    );
    std::fs::write(dir.path().join("bad3.toml"), "duration = [").unwrap();
    expect_failure(&["run", "bad3.toml"], dir.path(), &["bad3.toml:1:"]);
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    expect_failure(
        &["run", "tiny.toml", "--duration", "-1"],
        dir.path(),
        &["--duration"],
    );
    expect_failure(
        &[
            "run",
            "tiny.toml",
            "--rrd",
            "no/such/dir/x.rrd",
            "--duration",
            "0.1",
        ],
        dir.path(),
        &["x.rrd"],
    );
}

#[test]
fn scenarios_lists_the_bundled_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(&["scenarios"], dir.path());
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(
        s.contains("hospital_patrol") && s.contains("maze_run"),
        "{s}"
    );
    assert!(!s.contains("invalid"), "{s}");
}

/// Parses every line of a `--json` bench output and checks the fields each row must have.
/// Output into a pipe nobody reads (`sim scenarios | head -0`): the process ends by SIGPIPE, as
/// Unix tools do, not with a panic about a failed print.
#[cfg(unix)]
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_sim"))
        .arg("scenarios")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        out.status.signal(),
        Some(libc::SIGPIPE),
        "{:?} {stderr}",
        out.status
    );
}

fn bench_rows(args: &[&str], fields: &[&str]) -> Vec<serde_json::Value> {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(args, dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    for row in &rows {
        // the processor, so figures from different machines are not compared unawares
        let machine = row["machine"].as_str().unwrap_or_default();
        assert!(machine.contains("CPU"), "no machine in {row}");
        for f in fields {
            let x = row[f].as_f64().unwrap_or_else(|| panic!("no {f} in {row}"));
            assert!(x.is_finite() && x > 0.0, "{f} = {x} in {row}");
        }
    }
    rows
}

#[test]
fn bench_mcl_prints_json_lines() {
    let rows = bench_rows(
        &["bench", "mcl", "--json", "--reps", "1"],
        &["particles", "beams", "ms_per_update", "evals_per_s"],
    );
    let counts: Vec<u64> = rows
        .iter()
        .map(|r| r["particles"].as_u64().unwrap())
        .collect();
    assert_eq!(counts, [1000, 5000, 20000]);
    assert!(rows.iter().all(|r| r["beams"] == 60), "{rows:?}");
}

/// Lists take commas or spaces, and each row reports the population and laser asked for.
#[test]
fn bench_swarm_prints_one_row_per_population_and_laser() {
    let fields = [
        "robots",
        "beams",
        "real_time_factor",
        "rays_per_s",
        "sim_time_s",
    ];
    let spaced = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "1",
            "3",
            "--beams",
            "30",
            "--duration",
            "0.3",
        ],
        &fields,
    );
    let commas = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "1,3",
            "--beams",
            "30,45",
            "--duration",
            "0.3",
        ],
        &fields,
    );
    let asked = |rows: &[serde_json::Value]| -> Vec<(u64, u64)> {
        rows.iter()
            .map(|r| (r["robots"].as_u64().unwrap(), r["beams"].as_u64().unwrap()))
            .collect()
    };
    assert_eq!(asked(&spaced), [(1, 30), (3, 30)]);
    assert_eq!(asked(&commas), [(1, 30), (3, 30), (1, 45), (3, 45)]);
    let ran = |r: &serde_json::Value| (r["sim_time_s"].as_f64().unwrap() - 0.3).abs() < 1e-9;
    assert!(commas.iter().all(ran), "{commas:?}");
}

/// Options the swarm benchmark cannot honour are refused before anything runs, naming the
/// option, instead of being clamped or running forever.
#[test]
fn bench_swarm_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    for (args, expected) in [
        (
            &["--duration", "-5"][..],
            &["--duration", "positive", "-5"][..],
        ),
        (&["--duration=0"], &["--duration", "positive"]),
        (&["--duration", "nan"], &["--duration", "positive"]),
        (&["--duration", "inf"], &["--duration", "positive"]),
        (&["--beams", "1"], &["--beams", "2 to 20000", "got 1"]),
        (&["--beams", "180,20001"], &["--beams", "got 20001"]),
        (&["--robots", "10,0"], &["--robots", "at least 1", "got 0"]),
        (
            &["--robots", "1000000"],
            &["--robots 1000000", "free floor"],
        ),
    ] {
        let mut all = vec!["bench", "swarm", "--json"];
        all.extend_from_slice(args);
        expect_failure(&all, dir.path(), expected);
    }
}

#[test]
fn bench_markov_grid_prints_json_lines() {
    let rows = bench_rows(
        &["bench", "markov-grid", "--json", "--reps", "1"],
        &["particles", "cells", "beams", "ms_per_update"],
    );
    let modes: Vec<&str> = rows.iter().map(|r| r["mode"].as_str().unwrap()).collect();
    assert_eq!(modes, ["global", "selective"]);
}

#[test]
fn slam_experiment_and_bench_refuse_bad_options_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &[
            "experiment",
            "maze-slam",
            "--methods",
            "scan_to_map,gmapping",
        ],
        dir.path(),
        &["--methods", "unknown method `gmapping`"],
    );
    expect_failure(
        &["bench", "slam", "--modes", "hector"],
        dir.path(),
        &["--modes", "hector"],
    );
    expect_failure(
        &["bench", "slam", "--duration", "-5"],
        dir.path(),
        &["--duration", "positive"],
    );
}
