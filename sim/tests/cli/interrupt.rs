//! Ctrl-C (SIGINT) and SIGTERM during `sim run --mcap`: the run stops at the end of a tick,
//! finishes its files and exits with 130; the MCAP replay is complete (our strict reader and
//! Foxglove's Python reader open it) and holds the readings up to the interruption.

use sim::record::mcap::McapRecording;
use sim::record::mcap::messages::LaserScan;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use systems::core::test_tools::{TestTool, test_tool};

/// Starts `sim run maze_run` for a long time (it runs at some 200× real time; the heavy
/// hospital_patrol would make the time reached depend on the machine's load), signals it once
/// it has simulated for a while, and returns (exit code, stderr).
fn interrupted_run(signal: &str, dir: &Path) -> (Option<i32>, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_sim"))
        .args([
            "run",
            "maze_run",
            "--mcap",
            "run.mcap",
            "--duration",
            "100000",
            "--no-rrd",
            "--quiet",
            "--summary",
            "summary.json",
            "--threads",
            "2",
        ])
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .expect("sim starts");
    // the file appears when the world is built and the first tick is about to run
    let started = Instant::now();
    while !dir.join("run.mcap").exists() && started.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_secs(2));
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(kill.success());
    let out = child.wait_with_output().expect("sim ends");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn check_interrupted(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (code, stderr) = interrupted_run(signal, dir.path());
    assert_eq!(code, Some(130), "{stderr}");
    assert!(stderr.contains("interrupted at t = "), "{stderr}");
    let path = dir.path().join("run.mcap");
    let rec = McapRecording::open(&path).unwrap_or_else(|e| panic!("{e}"));
    let scans = rec.decode_topic::<LaserScan>("/scout/scan").unwrap();
    assert!(!scans.is_empty());
    let last = scans.last().unwrap().0 as f64 * 1e-9;
    assert!(last > 1.0, "scans up to {last} s");
    // the summary covers the ticks run, up to the last scan
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    let sim_time = s["sim_time_s"].as_f64().unwrap();
    assert!(
        sim_time < 100000.0 && (sim_time - last).abs() < 0.1,
        "{sim_time} vs {last}"
    );
    assert!(
        stderr.contains(&format!("interrupted at t = {sim_time:.2} s")),
        "{stderr}"
    );
    // Foxglove's reader opens it too (summary section and all)
    if let Some(venv) = test_tool(TestTool::McapReaders) {
        let script = "import sys\nfrom mcap.reader import make_reader\n\
                      r = make_reader(open(sys.argv[1], 'rb'))\n\
                      s = r.get_summary()\n\
                      n = sum(1 for _ in r.iter_messages())\n\
                      assert s is not None and s.statistics.message_count == n, n\n\
                      print(n)\n";
        let out = Command::new(venv.join("bin/python"))
            .args(["-c", script])
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let n: usize = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
        assert_eq!(n, rec.messages.len());
    }
}

#[test]
fn sigint_finishes_the_mcap_and_exits_130() {
    check_interrupted("-INT");
}

#[test]
fn sigterm_finishes_the_mcap_and_exits_130() {
    check_interrupted("-TERM");
}
