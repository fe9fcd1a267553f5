//! The scenario file as written (TOML, deserialized with serde; unknown keys are errors).
//! Validation and defaults live in `resolve`; each feature's own tables live in its module.

use super::check::PointOrPlace;
use super::events::EventFile;
use super::localizers::LocalizerFile;
use super::navigation::{NavigationFile, TaskFile};
use super::outdoor::{RoadsFile, ZoneFile};
use super::outdoor_robot::{CameraFile, CompassFile, GpsFile, RouteFile};
use super::people::PersonFile;
use super::places::{DoorFile, PlaceFile};
use super::sensors::{EncoderFile, LaserFile};
use super::slam::SlamList;
use super::sonar::SonarFile;
use serde::Deserialize;
use std::collections::BTreeMap;

/// A scenario file as written: every key optional here, checked and defaulted by the resolver
/// (`resolve`); the scenario builder fills one in code.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    pub name: Option<String>,
    pub description: Option<String>,
    pub seed: Option<u64>,
    pub dt: Option<f64>,
    pub duration: Option<f64>,
    /// End the run once every robot with tasks is done (default false: run `duration`).
    pub end_when_done: Option<bool>,
    pub map: Option<MapFile>,
    /// Named places of the scenario itself (`[places.<name>]`, as in a places file), beside
    /// those of `map.places`.
    #[serde(default)]
    pub places: BTreeMap<String, PlaceFile>,
    /// Doors of the scenario itself (`[doors.<name>]`, as in a places file).
    #[serde(default)]
    pub doors: BTreeMap<String, DoorFile>,
    #[serde(default)]
    pub walls: Vec<WallFile>,
    #[serde(default)]
    pub boxes: Vec<BoxFile>,
    #[serde(default)]
    pub discs: Vec<DiscFile>,
    pub record: Option<RecordFile>,
    #[serde(default)]
    pub robots: Vec<RobotFile>,
    #[serde(default)]
    pub events: Vec<EventFile>,
    /// Walking people (`[[people]]` tables).
    #[serde(default)]
    pub people: Vec<PersonFile>,
    /// An outdoor road network (`[roads]`).
    pub roads: Option<RoadsFile>,
    /// Areas that degrade GPS and compass (`[[zones]]`).
    #[serde(default)]
    pub zones: Vec<ZoneFile>,
}

/// `[map]`: the map file, the places file, or the cell size of a world of shapes.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct MapFile {
    /// ROS map_server YAML, relative to the scenario file.
    pub file: Option<String>,
    /// Named places (TOML), relative to the scenario file.
    pub places: Option<String>,
    /// Cell size of a world made of vector shapes only (m).
    pub resolution: Option<f64>,
}

/// One of `walls`: a segment (thickness default 0.1 m).
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct WallFile {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: Option<f64>,
}

/// One of `boxes`: a rectangle of `size` [length, width] turned by `yaw`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct BoxFile {
    pub center: [f64; 2],
    pub size: [f64; 2],
    pub yaw: Option<f64>,
}

/// One of `discs`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct DiscFile {
    pub center: [f64; 2],
    pub radius: f64,
}

/// `[record]`: the recording's rates; those not given keep `RecordConfig::default()`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct RecordFile {
    /// Robot poses per second of simulated time.
    pub rate: Option<f64>,
    /// Laser scans per second.
    pub scan_rate: Option<f64>,
    /// Driven paths per second.
    pub path_rate: Option<f64>,
    /// Localizer particle sets (MCL particles, DE populations, Markov grid cells) per second.
    pub particle_rate: Option<f64>,
    /// At most this many points per logged particle set.
    pub particle_points: Option<usize>,
    /// SLAM maps, trajectories and pose graphs per second (0: only at the end).
    pub slam_rate: Option<f64>,
    /// Camera images per second.
    pub camera_rate: Option<f64>,
    /// The localizer the recording's map view shows (of the robots that have one by this name).
    pub map_localizer: Option<String>,
}

/// One `[[robots]]` table.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct RobotFile {
    pub name: String,
    /// A robot preset filling in footprint, kinematics and sensors (`thesis_car`).
    pub preset: Option<String>,
    /// [x, y, yaw] (m, m, rad) or a place name; a robot with a `route` starts on its road.
    pub start: Option<PointOrPlace>,
    pub footprint: Option<FootprintFile>,
    pub kinematics: Option<KinematicsFile>,
    pub behaviour: Option<BehaviourFile>,
    pub sensors: Option<SensorsFile>,
    /// Localizers (`[[robots.localization]]` tables or an inline array).
    #[serde(default)]
    pub localization: Vec<LocalizerFile>,
    /// SLAM systems: one `slam = { type = … }` table or `[[robots.slam]]` tables.
    pub slam: Option<SlamList>,
    /// Planner, follower and stop-and-wait settings of a robot with tasks.
    pub navigation: Option<NavigationFile>,
    /// The robot's task queue (`[[robots.tasks]]`).
    #[serde(default)]
    pub tasks: Vec<TaskFile>,
    /// Drive to a node of the road network (`[robots.route]`).
    pub route: Option<RouteFile>,
}

/// A robot's `footprint`: exactly one of `circle` and `rectangle` (default: a 0.25 m circle).
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct FootprintFile {
    /// Radius of a round robot (m).
    pub circle: Option<f64>,
    /// [length, width] of a rectangular robot (m).
    pub rectangle: Option<[f64; 2]>,
}

/// A drive's `type`. Required in a file; the `Default` (diff_drive) only lets a table be
/// written with `..Default::default()`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum KinematicsType {
    #[default]
    DiffDrive,
    Ackermann,
}

/// A robot's `kinematics`: the drive's type and the parameters of that type (the others are
/// errors); those not given take their defaults.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct KinematicsFile {
    #[serde(rename = "type")]
    pub kind: KinematicsType,
    // differential drive
    pub wheel_base: Option<f64>,
    pub wheel_radius: Option<f64>,
    pub max_wheel_speed: Option<f64>,
    pub max_wheel_accel: Option<f64>,
    // Ackermann
    pub wheelbase: Option<f64>,
    pub max_steer: Option<f64>,
    pub max_steer_rate: Option<f64>,
    pub max_speed: Option<f64>,
    pub max_accel: Option<f64>,
}

/// A behaviour's `type`. Required in a file; the `Default` is idle.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum BehaviourType {
    #[default]
    Idle,
    Waypoints,
    Wander,
}

/// A robot's `behaviour`: idle, wander, or waypoints (`points`, `loop`), with its `speed`
/// and waypoint `tolerance`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct BehaviourFile {
    #[serde(rename = "type")]
    pub kind: BehaviourType,
    pub points: Option<Vec<PointOrPlace>>,
    #[serde(rename = "loop")]
    pub looping: Option<bool>,
    pub speed: Option<f64>,
    pub tolerance: Option<f64>,
    /// Navigate by this localizer instead of the wheel odometry.
    pub localizer: Option<String>,
}

/// `[robots.sensors]`: each sensor the robot has, each over its preset.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct SensorsFile {
    pub laser: Option<LaserFile>,
    pub encoder: Option<EncoderFile>,
    pub sonar: Option<SonarFile>,
    pub gps: Option<GpsFile>,
    pub compass: Option<CompassFile>,
    pub camera: Option<CameraFile>,
}
