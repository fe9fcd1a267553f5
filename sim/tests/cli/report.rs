//! `sim run --report`, `sim batch --report` and `sim report`: the files they write, and bad
//! input refused with a clear error and a non-zero exit before any run starts.

use crate::common::{ROOM, expect_failure, sim};

#[test]
fn run_report_writes_the_page_and_its_data_and_report_draws_it_again() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let out = sim(
        &["run", "tiny.toml", "--no-rrd", "--report", "rep", "--quiet"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let page = std::fs::read_to_string(dir.path().join("rep/report.html")).unwrap();
    assert!(page.contains("<svg") && page.contains("tiny, seed 3"));
    let data: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("rep/report.json")).unwrap())
            .unwrap();
    assert_eq!(data["format"], "sim-report/1");
    assert_eq!(data["summary"]["scenario"], "tiny");
    // drawn again, to another file
    let out = sim(&["report", "rep", "--out", "again.html"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("again.html")).unwrap(),
        page
    );
}

#[test]
fn a_report_over_an_existing_one_or_into_an_unwritable_folder_fails_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    std::fs::create_dir(dir.path().join("old")).unwrap();
    std::fs::write(dir.path().join("old/report.html"), "mine").unwrap();
    expect_failure(
        &[
            "run",
            "tiny.toml",
            "--rrd",
            "r.rrd",
            "--report",
            "old",
            "--quiet",
        ],
        dir.path(),
        &["old/report.html", "already there"],
    );
    // before the run: no recording was started
    assert!(!dir.path().join("r.rrd").exists());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("old/report.html")).unwrap(),
        "mine"
    );
    // a folder under a file cannot be made
    expect_failure(
        &[
            "run",
            "tiny.toml",
            "--rrd",
            "r.rrd",
            "--report",
            "tiny.toml/rep",
            "--quiet",
        ],
        dir.path(),
        &["tiny.toml/rep", "cannot create the report folder"],
    );
    assert!(!dir.path().join("r.rrd").exists());
    // a batch whose folder already has a page: refused before any run
    std::fs::create_dir(dir.path().join("b")).unwrap();
    std::fs::write(dir.path().join("b/report.html"), "mine").unwrap();
    expect_failure(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..2",
            "--out",
            "b",
            "--report",
            "--quiet",
        ],
        dir.path(),
        &["b/report.html", "already there"],
    );
    assert!(!dir.path().join("b/runs.csv").exists());
}

#[test]
fn a_batch_report_and_files_that_are_not_ours() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tiny.toml"), ROOM).unwrap();
    let out = sim(
        &[
            "batch",
            "tiny.toml",
            "--seeds",
            "0..3",
            "--duration",
            "0.5",
            "--out",
            "b",
            "--report",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let page = std::fs::read_to_string(dir.path().join("b/report.html")).unwrap();
    assert!(
        page.contains("3 runs in 1 parameter set, 0 failed"),
        "{page}"
    );
    // `sim report` does not replace a page without --force
    expect_failure(&["report", "b"], dir.path(), &["b/report.html", "--force"]);
    let out = sim(&["report", "b", "--force"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // a JSON file of someone else's
    std::fs::write(dir.path().join("other.json"), "{\"rows\": []}").unwrap();
    expect_failure(
        &["report", "other.json"],
        dir.path(),
        &["other.json", "not a file written by sim"],
    );
    expect_failure(
        &["report", "missing.json"],
        dir.path(),
        &["missing.json", "cannot read"],
    );
}
