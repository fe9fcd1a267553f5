//! The simulator application: scenario files, world building, the run loop, recording, benches
//! and the `sim` command line.

pub mod bench;
pub mod bench_loc;
pub mod bench_match;
pub mod build;
pub mod carmen;
pub mod experiment;
pub mod match_cmd;
pub mod record;
pub mod runner;
pub mod scans;
pub mod scenario;
pub mod script;
pub mod summary;

pub use runner::{RunOptions, RunOutput, run_scenario};
pub use scenario::{Scenario, load_scenario, parse_scenario};
