//! `sim replay` exit codes and messages for files it cannot use.

use crate::common::{expect_failure, run_ok};

#[test]
fn corrupt_truncated_and_foreign_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let recording = systems::core::source::source_path("replays/hospital_r1-seed0.mcap");
    let bytes = std::fs::read(&recording).unwrap();
    std::fs::write(cwd.join("cut.mcap"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    expect_failure(&["replay", "cut.mcap"], cwd, &["cut.mcap"]);
    std::fs::write(cwd.join("text.mcap"), "not an mcap file\n").unwrap();
    expect_failure(&["replay", "text.mcap"], cwd, &["text.mcap"]);
    expect_failure(
        &["replay", "missing.mcap"],
        cwd,
        &["missing.mcap", "cannot read"],
    );
    // our file, but topics it does not have
    let r = recording.to_str().unwrap();
    expect_failure(
        &["replay", r, "--scan-topic", "/front/scan", "--no-rrd"],
        cwd,
        &["no topic /front/scan", "/r1/scan"],
    );
    // the good file replays, with the default recording name
    let out = run_ok(&["replay", r], cwd);
    assert!(out.contains("hospital_r1-seed0-replay.rrd"), "{out}");
    assert!(cwd.join("hospital_r1-seed0-replay.rrd").exists());
}
