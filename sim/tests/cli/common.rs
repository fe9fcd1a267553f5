//! What the CLI tests share: running the binary, and a small scenario.

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

pub fn expect_failure(args: &[&str], cwd: &Path, fragments: &[&str]) {
    let out = sim(args, cwd);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    for f in fragments {
        assert!(err.contains(f), "expected `{f}` in: {err}");
    }
}

pub const ROOM: &str = r#"
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
