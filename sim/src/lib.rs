//! The simulator: scenario files, building their ECS worlds, stepping them, recording and
//! exporting runs, batches, benches and the `sim` command line.
//!
//! As a library its face is [`Simulation`]: load a scenario (a bundled name, a file or TOML
//! text), step it, read every robot's state between ticks and command robots; `sim run` drives
//! the same type.
//!
//! ```
//! use sim::{Command, Simulation};
//!
//! let mut s = Simulation::load("hospital_patrol").duration(1.0).threads(1).build()?;
//! s.run_for(0.5)?;
//! let r1 = s.robot("r1")?;
//! assert!(r1.scan().is_some() && r1.odometry().is_some());
//! let home = r1.pose();
//! s.command("r2", Command::Teleport(home))?; // r2 is kidnapped at the next tick
//! let done = s.run()?;
//! assert_eq!(done.summary.robots.len(), 4);
//! # anyhow::Ok(())
//! ```
//!
//! `use sim::prelude::*;` brings these names and the `systems` prelude. Next: the guide
//! (sim/docs/scripting.md), [`run::RobotView`] for what can be read,
//! [`Command`] for what can be told, and the `systems` crate for the components and systems
//! themselves.

pub mod batch;
pub mod bench;
pub mod build;
pub mod cache;
pub mod cli;
pub mod experiment;
pub mod formats;
pub mod log_slam;
pub mod options;
pub mod prelude;
pub mod record;
pub mod replay;
pub mod report;
pub mod run;
pub mod scenario;
pub mod stats;

pub use run::exports::RunExports;
pub use run::{
    Command, Controller, Finished, Observation, RunOptions, RunOutput, SimError, Simulation,
    SimulationBuilder, run_scenario, run_scenario_exporting,
};
pub use scenario::{RobotConfig, Scenario, load_scenario, parse_scenario};
