//! `use sim::prelude::*;`: the library face ([`crate::Simulation`] with its views, commands and
//! errors), the scenario type, and the `systems` prelude.

pub use crate::run::{
    Command, Controller, Estimate, Finished, LocalizerView, NavigationView, Observation, RobotView,
    ScanView, SimError, Simulation, SimulationBuilder, Target, Twist,
};
pub use crate::scenario::{RobotBuilder, RobotConfig, Scenario, ScenarioBuilder};
pub use systems::body::Collisions;
pub use systems::prelude::*;
