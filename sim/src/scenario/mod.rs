//! Scenario files (TOML): seed, dt, duration, the world (ROS map and/or vector shapes, named
//! places), robots (kinematics, footprint, start pose, sensors from presets with overrides, a
//! driving behaviour), recording rates and timed events. Unknown keys and out-of-range values are
//! errors naming the file, line and key. The format is documented in `sim/docs/scenario-format.md`.

pub mod check;
pub mod error;
pub mod events;
pub mod file;
pub mod load;
pub mod localizers;
pub mod model;
pub mod navigation;
pub mod outdoor;
pub mod outdoor_robot;
pub mod overrides;
pub mod people;
pub mod places;
pub mod resolve;
pub mod sensors;
pub mod slam;
pub mod slam_file;
pub mod sonar;
pub mod source;

pub use error::ScenarioError;
pub use load::{
    DEFAULT_SCENARIO, assets_dir, bundled_scenarios, find_scenario, load_scenario, parse_scenario,
    scenario_arg, scenario_path,
};
pub use localizers::{LocalizerConfig, LocalizerKind};
pub use model::{DoorConfig, Event, EventAction, RecordConfig, RobotConfig, Scenario, SensorName};
pub use navigation::NavConfig;
pub use people::PersonConfig;
pub use sonar::SonarConfig;
