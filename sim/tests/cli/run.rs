//! `sim run` and `sim scenarios`: the default file names, the summary JSON and the table, bad
//! input and a missing assets folder, and output into a closed pipe.

use crate::common::{ROOM, expect_failure, sim, sim_env};
use std::process::Command;

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
fn set_overrides_scenario_keys_and_names_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let run = |sets: &[&str]| {
        let mut args = vec![
            "run",
            "tiny.toml",
            "--no-rrd",
            "--quiet",
            "--summary",
            "s.json",
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = sim(&args, dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s = std::fs::read_to_string(dir.path().join("s.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&s).unwrap()
    };
    let plain = run(&[]);
    let faster = run(&["robots.0.behaviour.speed=1.0", "duration=1.5"]);
    assert!((faster["sim_time_s"].as_f64().unwrap() - 1.5).abs() < 1e-9);
    let distance = |s: &serde_json::Value| s["robots"][0]["distance_m"].as_f64().unwrap();
    // twice the speed for three quarters of the time: further
    assert!(
        distance(&faster) > 1.2 * distance(&plain),
        "{faster} {plain}"
    );
    // by name, as batch keys are
    let named = run(&["robots[name=r1].behaviour.speed=1.0", "duration=1.5"]);
    assert_eq!(distance(&named), distance(&faster));
    expect_failure(
        &[
            "run",
            "tiny.toml",
            "--no-rrd",
            "--set",
            "robots.0.sensors.laser.rate=-1",
        ],
        dir.path(),
        &["robots.0.sensors.laser.rate"],
    );
    expect_failure(
        &["run", "tiny.toml", "--no-rrd", "--set", "robots.0.speed"],
        dir.path(),
        &["--set robots.0.speed", "KEY=VALUE"],
    );
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
    // a run that would never end is refused before its first tick: in the file (with its
    // line), or from --duration
    std::fs::write(
        dir.path().join("endless.toml"),
        ROOM.replace("seed = 3", "seed = 3\ndt = 1e-9"),
    )
    .unwrap();
    expect_failure(
        &["run", "endless.toml"],
        dir.path(),
        &[
            "endless.toml:5:",
            "dt = 1e-9 s",
            "2.000e9 ticks",
            "at most 1e8",
        ],
    );
    expect_failure(
        &["run", "tiny.toml", "--duration", "1e12", "--no-rrd"],
        dir.path(),
        &["duration", "2.000e13 ticks"],
    );
    // a file that is not UTF-8: where the first bad byte is
    std::fs::write(
        dir.path().join("latin1.toml"),
        b"duration = 1.0\n# caf\xe9\n",
    )
    .unwrap();
    expect_failure(
        &["run", "latin1.toml"],
        dir.path(),
        &["latin1.toml:2:6:", "not UTF-8"],
    );
    // every estimate of what? --all-estimates qualifies --trajectories
    expect_failure(
        &["run", "tiny.toml", "--all-estimates", "--no-rrd"],
        dir.path(),
        &["--all-estimates", "--trajectories"],
    );
}

/// Inputs with no end (a stream of zeros, a file without line ends) or no sensible size are
/// refused at a stated bound, never read until memory runs out.
#[test]
fn endless_or_oversized_inputs_are_refused_at_their_bound() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &["run", "/dev/zero", "--no-rrd"],
        dir.path(),
        &["/dev/zero: cannot read: larger than 64 MiB"],
    );
    expect_failure(
        &["match", "/dev/zero", "--reference", "0", "--current", "1"],
        dir.path(),
        &["/dev/zero", "a line longer than 64 MiB"],
    );
    // one line of 65 MiB in a regular file
    std::fs::write(dir.path().join("one.scans"), vec![b'7'; 65 << 20]).unwrap();
    expect_failure(
        &["match", "one.scans", "--reference", "0", "--current", "1"],
        dir.path(),
        &["one.scans", "a line longer than 64 MiB"],
    );
    // a --set key thousands of parts deep overflowed the stack when applied
    let deep = format!("{}=1", vec!["a"; 5000].join("."));
    expect_failure(
        &[
            "batch", "maze_run", "--seeds", "0..1", "--set", &deep, "--out", "deep",
        ],
        dir.path(),
        &["--set a.a.a", "5000 parts", "at most 32"],
    );
}

/// A run asked to save maps of a world with nothing to map fails before its first tick, not
/// after the whole run.
#[test]
fn save_map_without_a_laser_fails_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let no_laser = ROOM.replace("[robots.sensors.laser]\npreset = \"hokuyo_urg04lx\"\n", "");
    assert_ne!(no_laser, ROOM);
    std::fs::write(dir.path().join("blind.toml"), no_laser).unwrap();
    // a day of simulated time: a check after the run would keep this test busy for minutes
    expect_failure(
        &[
            "run",
            "blind.toml",
            "--no-rrd",
            "--save-map",
            "map",
            "--duration",
            "86400",
        ],
        dir.path(),
        &["--save-map", "blind.toml", "no robot with a laser"],
    );
    assert!(!dir.path().join("map.pgm").exists());
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

/// Outputs that cannot be written: a full disk (`/dev/full`) and a file-size limit reached
/// mid-run (`ulimit -f`, which would otherwise kill the process with SIGXFSZ) end the command
/// with an error naming the file and the OS's reason, and a non-zero exit code.
#[test]
fn a_full_disk_or_a_file_size_limit_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    for flag in ["--mcap", "--rrd", "--carmen-out"] {
        let mut args = vec!["run", "tiny.toml", flag, "/dev/full"];
        if flag != "--rrd" {
            args.push("--no-rrd");
        }
        expect_failure(&args, dir.path(), &["/dev/full", "No space left on device"]);
    }
    // 100 blocks of 512 bytes: the MCAP of a 20 s run passes it mid-run
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -f 100 && exec {} run tiny.toml --duration 20 --no-rrd --quiet --mcap big.mcap",
            env!("CARGO_BIN_EXE_sim")
        ))
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("big.mcap") && err.contains("File too large") && !err.contains("panicked"),
        "{err}"
    );
}
