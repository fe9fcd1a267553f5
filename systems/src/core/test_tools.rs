//! The outside tools some tests check our files with: Rerun 0.36.3's CLI and Python SDK and
//! Foxglove's Python MCAP readers (in the virtual environment `$SIM_RERUN_VENV`), and evo
//! 1.38.1 (in `$SIM_EVO_VENV`). `tests/run.sh` (the README's test command, which CI runs)
//! installs them from PyPI into virtual environments under `$SIM_CACHE` (default
//! `~/.cache/sim`), sets both variables and `SIM_REQUIRE_TOOLS=1`.
//!
//! A test that needs one asks [`test_tool`] for it. Without the tool, plain `cargo test` skips
//! that test (or the part of it that needs the tool) and says so on standard error; with
//! `SIM_REQUIRE_TOOLS=1` the test fails instead, naming the tool, so CI runs every such check.

use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;

/// An outside tool a test needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestTool {
    /// Rerun 0.36.3: `bin/rerun` (`rerun rrd verify`, `rerun rrd stats`) and the Python SDK
    /// (`bin/python`, tests/check_rrd.py), in `$SIM_RERUN_VENV`.
    Rerun,
    /// Foxglove's Python MCAP readers, mcap 1.6.0 and mcap-ros2-support 0.6.0 (`bin/python`,
    /// tests/check_mcap.py), installed beside Rerun's SDK in `$SIM_RERUN_VENV`.
    McapReaders,
    /// evo 1.38.1 (`bin/python`, tests/check_evo.py, which runs `evo_ape` and `evo_rpe`), in
    /// `$SIM_EVO_VENV`.
    Evo,
}

impl TestTool {
    /// What the messages call it.
    pub fn name(self) -> &'static str {
        match self {
            TestTool::Rerun => "Rerun 0.36.3 (rerun CLI and Python SDK)",
            TestTool::McapReaders => "Foxglove's Python MCAP readers (mcap, mcap-ros2-support)",
            TestTool::Evo => "evo 1.38.1",
        }
    }

    /// The environment variable naming its virtual environment.
    pub fn variable(self) -> &'static str {
        match self {
            TestTool::Rerun | TestTool::McapReaders => "SIM_RERUN_VENV",
            TestTool::Evo => "SIM_EVO_VENV",
        }
    }

    /// The program of the virtual environment its presence is judged by.
    fn program(self) -> &'static str {
        match self {
            TestTool::Rerun => "bin/rerun",
            TestTool::McapReaders | TestTool::Evo => "bin/python",
        }
    }
}

/// Whether tests must have their tools: `SIM_REQUIRE_TOOLS=1` (set by tests/run.sh).
pub fn tools_required() -> bool {
    std::env::var_os("SIM_REQUIRE_TOOLS").is_some_and(|v| v == "1")
}

/// The virtual environment holding `tool` (run its `bin/python`, `bin/rerun`), or `None` when
/// it is missing: then the calling test skips what needs it, after this printed
/// `skipped: <test> needs <tool> (…)` to standard error, where `cargo test` shows it even
/// though the test passes. With `SIM_REQUIRE_TOOLS=1` a missing tool panics instead, saying
/// how to get it. A test that needs nothing else begins with
/// `let Some(venv) = test_tool(TestTool::Evo) else { return };`.
#[track_caller]
pub fn test_tool(tool: TestTool) -> Option<PathBuf> {
    let missing = match find(tool, std::env::var_os(tool.variable())) {
        Ok(venv) => return Some(venv),
        Err(why) => why,
    };
    let thread = std::thread::current();
    // the test harness names each test's thread after the test
    let test = thread
        .name()
        .filter(|n| *n != "main")
        .unwrap_or("this test");
    if tools_required() {
        panic!(
            "{test} needs {} and SIM_REQUIRE_TOOLS=1, but {missing}: run the tests with \
             tests/run.sh, which installs it from PyPI into a virtual environment under \
             $SIM_CACHE (default ~/.cache/sim) and sets ${}",
            tool.name(),
            tool.variable()
        );
    }
    // straight to the stream, past the test harness's capture of a passing test's output
    let _ = writeln!(
        std::io::stderr(),
        "skipped: {test} needs {} (run tests/run.sh, or set SIM_REQUIRE_TOOLS=1 to require it)",
        tool.name()
    );
    None
}

/// The tool's virtual environment given the value of its variable, or why it is not there.
fn find(tool: TestTool, value: Option<OsString>) -> Result<PathBuf, String> {
    let var = tool.variable();
    let venv = match value {
        Some(v) if !v.is_empty() => PathBuf::from(v),
        _ => return Err(format!("${var} is not set")),
    };
    let program = venv.join(tool.program());
    if program.is_file() {
        Ok(venv)
    } else {
        Err(format!(
            "${var} is {} and has no {}",
            venv.display(),
            tool.program()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tool_is_found_by_its_program_in_the_variables_folder() {
        let dir = tempfile::tempdir().unwrap();
        let venv = || Some(dir.path().as_os_str().to_owned());
        let e = find(TestTool::Evo, None).unwrap_err();
        assert_eq!(e, "$SIM_EVO_VENV is not set");
        let e = find(TestTool::Rerun, Some(OsString::new())).unwrap_err();
        assert_eq!(e, "$SIM_RERUN_VENV is not set");
        let e = find(TestTool::McapReaders, venv()).unwrap_err();
        assert!(e.starts_with("$SIM_RERUN_VENV is ") && e.ends_with(" has no bin/python"));
        std::fs::create_dir(dir.path().join("bin")).unwrap();
        std::fs::write(dir.path().join("bin/python"), "").unwrap();
        assert_eq!(find(TestTool::Evo, venv()).unwrap(), dir.path());
        assert_eq!(find(TestTool::McapReaders, venv()).unwrap(), dir.path());
        // Rerun's own CLI is its program
        let e = find(TestTool::Rerun, venv()).unwrap_err();
        assert!(e.ends_with(" has no bin/rerun"), "{e}");
    }
}
