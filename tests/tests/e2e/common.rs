use sim::build::{SimWorld, build_world};
use sim::scenario::{Scenario, assets_dir, parse_scenario};
use std::path::{Path, PathBuf};
pub use systems::core::test_tools::{TestTool, test_tool};

/// Parses a scenario given as TOML text (relative paths against the assets folder).
pub fn scenario(text: &str) -> Scenario {
    match parse_scenario(text, "test.toml", &assets_dir().join("scenarios"), "test") {
        Ok(s) => s,
        Err(e) => panic!("scenario should parse: {e}"),
    }
}

/// The error message of a scenario that must not parse.
pub fn scenario_error(text: &str) -> String {
    match parse_scenario(text, "test.toml", &assets_dir().join("scenarios"), "test") {
        Ok(_) => panic!("scenario should have been rejected:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The scenario is rejected with an error at `line` of test.toml containing every fragment.
pub fn expect_error(text: &str, line: usize, fragments: &[&str]) {
    let e = scenario_error(text);
    assert!(
        e.starts_with(&format!("test.toml:{line}:")),
        "expected line {line} in: {e}"
    );
    for f in fragments {
        assert!(e.contains(f), "expected `{f}` in: {e}");
    }
}

pub fn world(text: &str) -> SimWorld {
    build_world(&scenario(text), 1).expect("world builds")
}

pub fn bundled(name: &str) -> PathBuf {
    assets_dir().join("scenarios").join(format!("{name}.toml"))
}

pub fn repo_file(rel: &str) -> PathBuf {
    systems::core::source::source_root().join("tests").join(rel)
}

/// A 10 × 10 m room (inner faces at x, y = 0.1 and 9.9) built from vector walls.
pub const SQUARE_ROOM: &str = r#"
duration = 1.0
dt = 0.05
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0], thickness = 0.2 },
  { from = [0.0, 10.0], to = [10.0, 10.0], thickness = 0.2 },
  { from = [0.0, 0.0], to = [0.0, 10.0], thickness = 0.2 },
  { from = [10.0, 0.0], to = [10.0, 10.0], thickness = 0.2 },
]
"#;

/// `sim run ARGS` as the binary runs it: Err (a non-zero exit) carries the message it prints.
pub fn sim_run(args: &[&str]) -> Result<(), String> {
    use sim::cli::run::{RunArgs, run_command};
    use sim::options::parse_args;
    let a: RunArgs = parse_args(args).map_err(|e| e.to_string())?;
    run_command(&a).map_err(|e| format!("{e:#}"))
}

/// `sim slam ARGS` as the binary runs it, with its report.
pub fn sim_slam(args: &[&str]) -> Result<sim::log_slam::report::SlamReport, String> {
    use sim::log_slam::{SlamArgs, run_slam_command};
    use sim::options::parse_args;
    let a: SlamArgs = parse_args(args).map_err(|e| e.to_string())?;
    run_slam_command(&a).map_err(|e| format!("{e:#}"))
}

/// Checks an .rrd with the Rerun 0.36.3 tools: `rerun rrd verify`, then the SDK's reader
/// through check_rrd.py, whose JSON (entity paths, timelines, scalar statistics) it returns;
/// `None` when the tools are missing (see [`test_tool`]: the test skips its check).
#[track_caller]
pub fn check_rrd(path: &Path) -> Option<serde_json::Value> {
    test_tool(TestTool::Rerun).map(|rerun| check_rrd_with(&rerun, path))
}

/// [`check_rrd`] with the Rerun tools of the virtual environment `rerun`.
pub fn check_rrd_with(rerun: &Path, path: &Path) -> serde_json::Value {
    use std::process::Command;
    let verify = Command::new(rerun.join("bin/rerun"))
        .args(["rrd", "verify"])
        .arg(path)
        .output()
        .unwrap();
    assert!(
        verify.status.success(),
        "rerun rrd verify failed:\n{}\n{}",
        String::from_utf8_lossy(&verify.stdout),
        String::from_utf8_lossy(&verify.stderr)
    );
    let out = Command::new(rerun.join("bin/python"))
        .arg(repo_file("check_rrd.py"))
        .arg(path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&text).unwrap()
}

/// The entity paths of [`check_rrd`]'s answer.
pub fn entity_paths(v: &serde_json::Value) -> Vec<String> {
    v["entity_paths"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p.as_str().map(str::to_string))
        .collect()
}
