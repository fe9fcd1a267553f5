//! Scenario files (TOML): seed, dt, duration, the world (ROS map and/or vector shapes, named
//! places), robots (kinematics, footprint, start pose, sensors from presets with overrides, a
//! driving behaviour), recording rates and timed events. Unknown keys and out-of-range values are
//! errors naming the file, line and key. The format is documented in `sim/docs/scenario-format.md`.

pub mod check;
pub mod error;
pub mod events;
pub mod file;
pub mod localizers;
pub mod navigation;
pub mod outdoor;
pub mod outdoor_robot;
pub mod people;
pub mod places;
pub mod resolve;
pub mod sensors;
pub mod slam;
pub mod slam_file;
pub mod sonar;

pub use error::ScenarioError;
pub use events::SensorName;
pub use localizers::{LocalizerConfig, LocalizerKind};
pub use navigation::NavConfig;
pub use people::PersonConfig;
pub use sonar::SonarConfig;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use systems::body::{Footprint, Kinematics};
use systems::core::Pose2;
use systems::navigation::BehaviourKind;
use systems::sensors::{EncoderSpec, LaserSpec};
use systems::world::OccupancyGrid;

/// A validated scenario with every default filled in.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    pub seed: u64,
    pub dt: f64,
    pub duration: f64,
    /// Where it came from (for messages).
    pub source: String,
    pub grid: OccupancyGrid,
    pub places: BTreeMap<String, Pose2>,
    pub record: RecordConfig,
    pub robots: Vec<RobotConfig>,
    pub events: Vec<Event>,
    /// Doors of the map (from the places file), all open at the start.
    pub doors: Vec<DoorConfig>,
    /// End the run as soon as every robot with tasks has done them all.
    pub end_when_done: bool,
    /// Walking people, in file order.
    pub people: Vec<PersonConfig>,
    /// The outdoor road network, if any.
    pub roads: Option<outdoor::RoadsConfig>,
    /// Zones that degrade GPS and compass, in file order (the last listed wins).
    pub zones: Vec<systems::world::Zone>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct DoorConfig {
    pub name: String,
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RecordConfig {
    /// Poses per second.
    pub rate: f64,
    /// Scans per second.
    pub scan_rate: f64,
    /// Driven paths per second.
    pub path_rate: f64,
    /// Localizer particle sets per second (and at most one per filter update).
    pub particle_rate: f64,
    /// At most this many points per logged particle set (subsampled).
    pub particle_points: usize,
    /// SLAM maps, trajectories and pose graphs per second (0: only at the end of the run).
    pub slam_rate: f64,
    /// Camera images per second (JPEG, with the recognized road drawn in).
    pub camera_rate: f64,
}

impl Default for RecordConfig {
    fn default() -> Self {
        RecordConfig {
            rate: 10.0,
            scan_rate: 5.0,
            path_rate: 1.0,
            particle_rate: 2.0,
            particle_points: 1000,
            slam_rate: 0.5,
            camera_rate: 1.0,
        }
    }
}

#[derive(Clone, Debug)]
pub struct RobotConfig {
    pub name: String,
    pub start: Pose2,
    pub footprint: Footprint,
    pub kinematics: Kinematics,
    pub behaviour: BehaviourKind,
    pub speed: f64,
    pub tolerance: f64,
    pub laser: Option<LaserSpec>,
    pub encoder: Option<EncoderSpec>,
    pub sonar: Option<SonarConfig>,
    pub localizers: Vec<LocalizerConfig>,
    /// Task-driven navigation (planner, follower, task queue), if the robot has tasks.
    pub navigation: Option<NavConfig>,
    pub gps: Option<systems::sensors::GpsSpec>,
    pub compass: Option<systems::sensors::CompassSpec>,
    pub camera: Option<systems::sensors::CameraSpec>,
    /// Drive to a road node, localizing on the road network.
    pub route: Option<outdoor_robot::RouteConfig>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    pub at: f64,
    /// The robot concerned (None for world events such as doors).
    pub robot: Option<String>,
    pub action: EventAction,
}

#[derive(Clone, Debug, PartialEq)]
pub enum EventAction {
    Waypoints {
        points: Vec<[f64; 2]>,
        looping: bool,
    },
    Teleport(Pose2),
    SensorFault {
        sensor: SensorName,
        active: bool,
    },
    /// Door number `index` of [`Scenario::doors`] opens or closes.
    Door {
        index: usize,
        open: bool,
    },
}

/// Loads and validates a scenario file.
pub fn load_scenario(path: &Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
        file: path.display().to_string(),
        line: None,
        column: None,
        key: None,
        message: format!("cannot read: {e}"),
    })?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scenario");
    parse_scenario(&text, &path.display().to_string(), &base, stem)
}

/// Parses and validates scenario text; relative paths resolve against `base_dir`.
pub fn parse_scenario(
    text: &str,
    file_label: &str,
    base_dir: &Path,
    default_name: &str,
) -> Result<Scenario, ScenarioError> {
    resolve::resolve(text, file_label, base_dir, default_name)
}

/// The folder of the bundled assets: `$SIM_ASSETS` or the repository's `assets/`
/// ([`systems::core::source`]).
pub fn assets_dir() -> PathBuf {
    match std::env::var_os("SIM_ASSETS") {
        Some(p) => PathBuf::from(p),
        None => systems::core::source::source_path("assets"),
    }
}

/// Bundled scenarios: (name, path), sorted; an error naming the folder when it cannot be read
/// (a `sim` binary run away from its repository, without `SIM_ASSETS`).
pub fn bundled_scenarios() -> anyhow::Result<Vec<(String, PathBuf)>> {
    let dir = assets_dir().join("scenarios");
    let entries = std::fs::read_dir(&dir).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot read the bundled scenarios ({e}); set SIM_ASSETS to the repository's \
             assets folder",
            dir.display()
        )
    })?;
    let mut out: Vec<(String, PathBuf)> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter_map(|p| Some((p.file_stem()?.to_str()?.to_string(), p.clone())))
        .collect();
    out.sort();
    Ok(out)
}

/// The scenario `sim run` uses without an argument.
pub const DEFAULT_SCENARIO: &str = "hospital_patrol";

/// Resolves a scenario argument: a path, or the name of a bundled scenario; otherwise an error
/// that lists the bundled ones.
pub fn find_scenario(arg: &str) -> anyhow::Result<PathBuf> {
    let p = PathBuf::from(arg);
    if p.exists() {
        return Ok(p);
    }
    let all = bundled_scenarios()
        .map_err(|e| anyhow::anyhow!("{arg}: no such file, and no bundled scenarios: {e}"))?;
    if let Some((_, p)) = all.iter().find(|(name, _)| name == arg) {
        return Ok(p.clone());
    }
    let names: Vec<&str> = all.iter().map(|(n, _)| n.as_str()).collect();
    anyhow::bail!(
        "{arg}: no such file and no bundled scenario of that name (bundled: {})",
        names.join(", ")
    )
}

/// A scenario file or the name of a bundled scenario (default: hospital_patrol).
pub fn scenario_arg(arg: Option<&str>) -> anyhow::Result<Scenario> {
    Ok(load_scenario(&scenario_path(arg)?)?)
}

/// The file of a scenario argument: a path, or the name of a bundled scenario (default:
/// hospital_patrol).
pub fn scenario_path(arg: Option<&str>) -> anyhow::Result<PathBuf> {
    find_scenario(arg.unwrap_or(DEFAULT_SCENARIO))
}
