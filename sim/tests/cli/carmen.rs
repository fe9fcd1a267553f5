//! `sim slam --carmen`, `sim run --carmen-out` and `--save-map` through the binary: exit codes,
//! messages, printed counts and default file names, and I/O errors that say what failed once.

use crate::common::{ROOM, expect_failure, run_ok, sim};

fn fixture(name: &str) -> String {
    systems::core::source::source_path("tests/fixtures/carmen")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn slam_on_a_malformed_log_exits_non_zero_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["slam", "--carmen", &fixture("malformed.log"), "--no-rrd"],
        dir.path(),
        &["malformed.log:5: FLASER", "expected 5 range readings"],
    );
    expect_failure(
        &["slam", "--carmen", "nowhere.log"],
        dir.path(),
        &["nowhere.log", "cannot read"],
    );
}

#[test]
fn slam_prints_skipped_types_and_writes_the_default_recording() {
    let dir = tempfile::tempdir().unwrap();
    let text = run_ok(
        &["slam", "--carmen", &fixture("unknown_types.log")],
        dir.path(),
    );
    for want in [
        "1 scans used",
        "BUMP 1",
        "NMEAGGA 1",
        "POSITIONLASER 1",
        "RAWLASER1 2",
        "SONAR 1",
        "SYNC 2",
        "no TRUEPOS lines",
        "real time",
    ] {
        assert!(text.contains(want), "expected `{want}` in:\n{text}");
    }
    assert!(dir.path().join("unknown_types-slam.rrd").exists());
}

#[test]
fn slam_rejects_bad_options_with_the_flag_or_file_line() {
    let dir = tempfile::tempdir().unwrap();
    let log = fixture("flaser_odom.log");
    let base = ["slam", "--carmen", log.as_str(), "--no-rrd"];
    fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        base.iter().chain(extra).copied().collect()
    }
    expect_failure(
        &with(&base, &["--slam", "nope"]),
        dir.path(),
        &["--slam", "unknown variant `nope`"],
    );
    expect_failure(&with(&base, &["--fov", "0"]), dir.path(), &["--fov"]);
    expect_failure(
        &with(&base, &["--max-range", "-2"]),
        dir.path(),
        &["--max-range"],
    );
    std::fs::write(dir.path().join("s.toml"), "# ok\nlevels = 9\n").unwrap();
    expect_failure(
        &with(&base, &["--slam-config", "s.toml"]),
        dir.path(),
        &["s.toml:2:", "`levels`"],
    );
    std::fs::write(dir.path().join("u.toml"), "\nspeed = 9\n").unwrap();
    expect_failure(
        &with(&base, &["--slam-config", "u.toml"]),
        dir.path(),
        &["u.toml:2:", "unknown field `speed`"],
    );
}

#[test]
fn run_exports_a_log_and_a_map_that_slam_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let text = run_ok(
        &[
            "run",
            "tiny.toml",
            "--no-rrd",
            "--carmen-out",
            "tiny.log",
            "--save-map",
            "room",
        ],
        dir.path(),
    );
    assert!(text.contains("CARMEN log written to tiny.log"), "{text}");
    assert!(
        text.contains("map of r1/known_poses written to room.yaml"),
        "{text}"
    );
    assert!(text.contains("precision"), "{text}");
    for f in ["tiny.log", "room.yaml", "room.pgm"] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
    run_ok(
        &[
            "slam",
            "--carmen",
            "tiny.log",
            "--no-rrd",
            "--summary",
            "s.json",
            "--save-map",
            "slam.yaml",
        ],
        dir.path(),
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    // the Hokuyo fires at 10 Hz for 2 s
    assert!(s["scans"].as_u64().unwrap() >= 19, "{s}");
    assert!(
        s["slam_metrics"]["ate_rmse_m"].as_f64().unwrap() < 0.05,
        "{s}"
    );
    assert!(dir.path().join("slam.pgm").exists());
}

#[test]
fn slam_rates_must_not_be_negative() {
    let dir = tempfile::tempdir().unwrap();
    let log = fixture("flaser_odom.log");
    expect_failure(
        &["slam", "--carmen", &log, "--slam-rate", "-1"],
        dir.path(),
        &["--slam-rate"],
    );
    std::fs::write(
        dir.path().join("r.toml"),
        format!("{ROOM}[record]\nslam_rate = -1\n"),
    )
    .unwrap();
    expect_failure(
        &["run", "r.toml"],
        dir.path(),
        &[
            "r.toml:",
            "`record.slam_rate`: expected a number of at least 0",
        ],
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

/// A log whose poses jump 58 km: every SLAM system maps both places without the space between
/// (the RBPF's tile table grew to hold it and ran out of memory).
#[test]
fn a_log_whose_poses_jump_kilometres_maps_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let line = |x: f64, y: f64, t: f64| {
        let ranges = vec!["3.0"; 181].join(" ");
        format!("FLASER 181 {ranges} {x} {y} 0.0 {x} {y} 0.0 {t} host {t}\n")
    };
    let log = [
        line(0.0, 0.0, 1.0),
        line(0.1, 0.0, 1.1),
        line(50_000.0, 30_000.0, 1.2),
        line(50_000.1, 30_000.0, 1.3),
    ]
    .concat();
    std::fs::write(dir.path().join("far.log"), log).unwrap();
    for slam in ["scan_to_map", "rbpf", "graph"] {
        let out = run_ok(
            &["slam", "--carmen", "far.log", "--slam", slam, "--no-rrd"],
            dir.path(),
        );
        let map = out.lines().find(|l| l.starts_with("map ")).unwrap_or("");
        let cells: Vec<usize> = map
            .split(|c: char| !c.is_ascii_digit())
            .filter_map(|w| w.parse().ok())
            .take(2)
            .collect();
        assert!(
            cells.len() == 2 && cells[0] * cells[1] <= 1_000_000,
            "{slam}: {map}"
        );
    }
}
