use sim::build::{SimWorld, build_world};
use sim::scenario::{Scenario, assets_dir, parse_scenario};
use std::path::{Path, PathBuf};

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

pub fn world(text: &str) -> SimWorld {
    build_world(&scenario(text), 1).expect("world builds")
}

pub fn bundled(name: &str) -> PathBuf {
    assets_dir().join("scenarios").join(format!("{name}.toml"))
}

/// The Rerun 0.36.3 tools: `$SIM_RERUN_VENV` (set by tests/run.sh).
pub fn rerun_venv() -> PathBuf {
    match std::env::var_os("SIM_RERUN_VENV") {
        Some(v) => PathBuf::from(v),
        None => panic!(
            "SIM_RERUN_VENV is not set: run the tests with tests/run.sh, which installs \
             rerun-sdk 0.36.3 in a virtual environment"
        ),
    }
}

pub fn repo_file(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
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
