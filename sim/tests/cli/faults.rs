//! Faults during a run, made without privileges: a file size limit reached mid-run (`ulimit -f`),
//! an output that cannot be written, and SIGKILL. A failed output is an error naming its file,
//! the other outputs are still written and the exit code is non-zero; a killed run leaves an
//! MCAP file whose complete chunks Foxglove's reader and ours read, and an .rrd whose complete
//! part Rerun's tools take back.

use crate::common::sim;
use sim::record::mcap::McapRecording;
use sim::record::mcap::messages::LaserScan;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};
use systems::core::test_tools::{TestTool, test_tool};

#[test]
fn a_file_size_limit_mid_run_names_the_files_and_the_other_outputs_are_written() {
    let dir = tempfile::tempdir().unwrap();
    // 1000 blocks of 512 bytes (POSIX sh): both recordings pass it within a simulated minute
    let out = Command::new("sh")
        .args(["-c", "ulimit -f 1000; exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_sim"))
        .args(["run", "maze_run", "--duration", "120", "--rrd", "big.rrd"])
        .args([
            "--mcap",
            "run.mcap",
            "--summary",
            "s.json",
            "--log",
            "ev.log",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for f in ["big.rrd: writing the recording failed", "run.mcap: cannot"] {
        assert!(err.contains(f), "expected `{f}` in: {err}");
    }
    assert!(err.contains("File too large"), "{err}");
    // the summary covers the whole run, and the log is there
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(s["sim_time_s"].as_f64(), Some(120.0));
    assert!(dir.path().join("ev.log").exists());
    // nothing claims the recording was written
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("recording written"), "{stdout}");
    assert!(!stdout.contains("MCAP replay written"), "{stdout}");
}

#[test]
fn an_unwritable_summary_is_named_and_the_recording_is_still_complete() {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(
        &[
            "run",
            "maze_run",
            "--duration",
            "5",
            "--rrd",
            "ok.rrd",
            "--summary",
            "missing/s.json",
            "--log",
            "ev.log",
            "--quiet",
        ],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("missing/s.json: cannot write the summary"),
        "{err}"
    );
    assert!(dir.path().join("ev.log").exists());
    if let Some(venv) = test_tool(TestTool::Rerun) {
        let verify = Command::new(venv.join("bin/rerun"))
            .args(["rrd", "verify", "ok.rrd"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            verify.status.success(),
            "{}",
            String::from_utf8_lossy(&verify.stderr)
        );
    }
}

/// Starts a long `sim run maze_run` writing both recordings, kills it with SIGKILL once both
/// files have a few chunks, and returns when it is gone.
fn killed_run(dir: &Path) {
    use std::os::unix::process::ExitStatusExt;
    let mut child = Command::new(env!("CARGO_BIN_EXE_sim"))
        .args(["run", "maze_run", "--duration", "100000", "--quiet"])
        .args(["--rrd", "cut.rrd", "--mcap", "cut.mcap", "--threads", "2"])
        .current_dir(dir)
        .spawn()
        .unwrap();
    let size = |name: &str| std::fs::metadata(dir.join(name)).map_or(0, |m| m.len());
    let started = Instant::now();
    // MCAP chunks end every 10 s of simulated time and .rrd chunks at 1 MiB: 4 MB is well
    // past the first few of each. The .rrd is written by background threads, which on a busy
    // machine lag behind the MCAP file: both are waited for.
    while size("cut.mcap") < 4_000_000 || size("cut.rrd") < 4_000_000 {
        assert!(started.elapsed() < Duration::from_secs(120), "no MCAP data");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(9));
}

#[test]
fn sigkill_leaves_recordings_whose_complete_part_is_read() {
    let dir = tempfile::tempdir().unwrap();
    killed_run(dir.path());
    let mcap = dir.path().join("cut.mcap");
    // ours: the strict read names the damage and the way out; the recovering read keeps the
    // complete chunks
    let e = McapRecording::open(&mcap).unwrap_err().to_string();
    assert!(e.contains("sim replay --recover"), "{e}");
    let rec = McapRecording::open_recovering(&mcap).unwrap();
    let scans = rec.decode_topic::<LaserScan>("/scout/scan").unwrap();
    let last = scans.last().unwrap().0 as f64 * 1e-9;
    assert!(last >= 10.0, "scans up to {last} s");
    // `sim replay --recover` takes it
    let replay = sim(
        &["replay", "cut.mcap", "--recover", "--no-rrd", "--quiet"],
        dir.path(),
    );
    assert!(
        replay.status.success(),
        "{}",
        String::from_utf8_lossy(&replay.stderr)
    );
    // Foxglove's reader, reading the file as a stream, gives the same messages before it
    // stops at the chunk that was being written
    if let Some(venv) = test_tool(TestTool::McapReaders) {
        let script = "import sys\nfrom mcap.reader import NonSeekingReader\n\
                      n = 0\n\
                      try:\n    \
                      for _ in NonSeekingReader(open(sys.argv[1], 'rb')).iter_messages(log_time_order=False):\n        \
                      n += 1\n\
                      except Exception as e:\n    \
                      print(type(e).__name__, file=sys.stderr)\n\
                      print(n)\n";
        let out = Command::new(venv.join("bin/python"))
            .args(["-c", script])
            .arg(&mcap)
            .output()
            .unwrap();
        assert!(out.status.success());
        let n: usize = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
        assert_eq!(n, rec.messages.len());
    }
    // Rerun's: `rrd verify` wants the footer a killed run never wrote; `rrd merge` rewrites
    // the complete part with one, which then verifies and reads
    if let Some(venv) = test_tool(TestTool::Rerun) {
        let rerun = |args: &[&str]| {
            Command::new(venv.join("bin/rerun"))
                .args(args)
                .current_dir(dir.path())
                .output()
                .unwrap()
        };
        let verify = rerun(&["rrd", "verify", "cut.rrd"]);
        assert!(!verify.status.success());
        assert!(String::from_utf8_lossy(&verify.stderr).contains("footer"));
        let merge = rerun(&["rrd", "merge", "cut.rrd", "-o", "fixed.rrd"]);
        assert!(merge.status.success());
        let verify = rerun(&["rrd", "verify", "fixed.rrd"]);
        assert!(
            verify.status.success(),
            "{}",
            String::from_utf8_lossy(&verify.stderr)
        );
        let check = Command::new(venv.join("bin/python"))
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/check_rrd.py"))
            .arg(dir.path().join("fixed.rrd"))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&check.stdout);
        assert!(check.status.success(), "{text}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let paths: Vec<&str> = v["entity_paths"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|p| p.as_str())
            .collect();
        assert!(paths.contains(&"/robots/scout/truth"), "{paths:?}");
    }
}
