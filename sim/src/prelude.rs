//! `use sim::prelude::*;`: the library face ([`crate::Simulation`] with its views, commands and
//! errors), the scenario type, and the `systems` prelude.

pub use crate::run::{
    Command, Estimate, Finished, LocalizerView, NavigationView, RobotView, ScanView, SimError,
    Simulation, SimulationBuilder, Twist,
};
pub use crate::scenario::{RobotBuilder, RobotConfig, Scenario, ScenarioBuilder};
pub use systems::prelude::*;
