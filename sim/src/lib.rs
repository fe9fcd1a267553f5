//! The simulator application: scenario files, world building, the run loop, recording, benches
//! and the `sim` command line.

pub mod batch;
pub mod bench;
pub mod build;
pub mod cli;
pub mod experiment;
pub mod formats;
pub mod log_slam;
pub mod options;
pub mod record;
pub mod replay;
pub mod run;
pub mod scenario;
pub mod stats;

pub use run::exports::RunExports;
pub use run::{RunOptions, RunOutput, run_scenario, run_scenario_exporting};
pub use scenario::{Scenario, load_scenario, parse_scenario};
