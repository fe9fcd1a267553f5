//! The simulator application: scenario files, world building, the run loop, recording, benches
//! and the `sim` command line.

pub mod batch;
pub mod bench;
pub mod bench_batch;
pub mod bench_loc;
pub mod bench_match;
pub mod bench_record;
pub mod bench_slam;
pub mod build;
pub mod build_outdoor;
pub mod carmen;
pub mod carmen_out;
pub mod experiment;
pub mod interrupt;
pub mod machine;
pub mod map_out;
pub mod match_cmd;
pub mod mcap_out;
pub mod record;
pub mod replay;
pub mod run_cmd;
pub mod run_exports;
pub mod runner;
pub mod scans;
pub mod scenario;
pub mod script;
pub mod slam_cmd;
pub mod stats;
pub mod summary;
pub mod summary_road;

pub use run_exports::RunExports;
pub use runner::{RunOptions, RunOutput, run_scenario, run_scenario_exporting};
pub use scenario::{Scenario, load_scenario, parse_scenario};
