//! Scenario files (TOML): seed, dt, duration, the world (ROS map and/or vector shapes, named
//! places), robots (kinematics, footprint, start pose, sensors from presets with overrides, a
//! driving behaviour), recording rates and timed events. Unknown keys and out-of-range values are
//! errors naming the file, line and key. The format is documented in `sim/docs/scenario-format.md`.
//!
//! A scenario can also be built in code ([`Scenario::builder`], [`RobotConfig::builder`]): the
//! builders fill in the same file model ([`ScenarioFile`] and its tables, re-exported here) and
//! go through the same resolver, so defaults and errors are the file's.

pub mod builder;
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

pub use builder::{CODE_LABEL, RobotBuilder, ScenarioBuilder};
pub use check::{OdometrySource, PointOrPlace};

/// A 10 × 10 m room walled on four sides, 1 s long: the start of the scenario texts of unit
/// tests, which add their robots.
#[cfg(test)]
pub(crate) const TEST_ROOM: &str = r#"
duration = 1.0
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0] },
  { from = [0.0, 10.0], to = [10.0, 10.0] },
  { from = [0.0, 0.0], to = [0.0, 10.0] },
  { from = [10.0, 0.0], to = [10.0, 10.0] },
]
"#;
pub use error::ScenarioError;
pub use events::{EventFile, EventType};
pub use file::{
    BehaviourFile, BehaviourType, BoxFile, DiscFile, FootprintFile, KinematicsFile, KinematicsType,
    MapFile, RecordFile, RobotFile, ScenarioFile, SensorsFile, WallFile,
};
pub use load::{
    DEFAULT_SCENARIO, assets_dir, bundled_scenarios, find_scenario, load_scenario, parse_scenario,
    scenario_arg, scenario_path,
};
pub use localizers::{
    InitType, LaserModelType, LocalizerConfig, LocalizerFile, LocalizerKind, LocalizerType,
    MatcherType, MetricType,
};
pub use model::{DoorConfig, Event, EventAction, RecordConfig, RobotConfig, Scenario, SensorName};
pub use navigation::{NavConfig, NavigationFile, TaskFile, TaskType};
pub use outdoor::{CircleFile, RoadsFile, ZoneFile};
pub use outdoor_robot::{CameraFile, CompassFile, GpsFile, RouteFile};
pub use people::{PersonConfig, PersonFile};
pub use places::{DoorFile, PlaceFile};
pub use sensors::{EncoderFile, LaserFile};
pub use slam::{MatcherKind, SlamFile, SlamType};
pub use sonar::{SonarConfig, SonarFile};
