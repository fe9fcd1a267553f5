//! The scenario file as written (TOML, deserialized with serde; unknown keys are errors).
//! Validation and defaults live in `resolve`.

use serde::Deserialize;

#[derive(Deserialize, Debug, Default)]
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
    pub people: Vec<super::people::PersonFile>,
    /// An outdoor road network (`[roads]`).
    pub roads: Option<super::outdoor::RoadsFile>,
    /// Areas that degrade GPS and compass (`[[zones]]`).
    #[serde(default)]
    pub zones: Vec<super::outdoor::ZoneFile>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct MapFile {
    /// ROS map_server YAML, relative to the scenario file.
    pub file: Option<String>,
    /// Named places (TOML), relative to the scenario file.
    pub places: Option<String>,
    /// Cell size of a world made of vector shapes only (m).
    pub resolution: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct WallFile {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BoxFile {
    pub center: [f64; 2],
    pub size: [f64; 2],
    pub yaw: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DiscFile {
    pub center: [f64; 2],
    pub radius: f64,
}

#[derive(Deserialize, Debug, Default)]
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
}

#[derive(Deserialize, Debug)]
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
    pub localization: Vec<super::localizers::LocalizerFile>,
    /// SLAM systems: one `slam = { type = … }` table or `[[robots.slam]]` tables.
    pub slam: Option<super::slam::SlamList>,
    /// Planner, follower and stop-and-wait settings of a robot with tasks.
    pub navigation: Option<NavigationFile>,
    /// The robot's task queue (`[[robots.tasks]]`).
    #[serde(default)]
    pub tasks: Vec<TaskFile>,
    /// Drive to a node of the road network (`[robots.route]`).
    pub route: Option<super::outdoor_robot::RouteFile>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct NavigationFile {
    /// Name of the localizer to navigate by (default: wheel odometry).
    pub localizer: Option<String>,
    pub speed: Option<f64>,
    pub max_accel: Option<f64>,
    pub max_yaw_rate: Option<f64>,
    pub tolerance: Option<f64>,
    pub lookahead: Option<f64>,
    /// Added to the robot radius for the costmap's impassable band (m).
    pub safety_margin: Option<f64>,
    pub inflation_radius: Option<f64>,
    pub cost_weight: Option<f64>,
    pub stop_distance: Option<f64>,
    pub wait_time: Option<f64>,
    pub priority: Option<u32>,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum TaskType {
    Delivery,
    Go,
    Wait,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct TaskFile {
    #[serde(rename = "type")]
    pub kind: TaskType,
    pub name: Option<String>,
    pub from: Option<PointOrPlace>,
    pub to: Option<PointOrPlace>,
    /// Loading time at `from` (s).
    pub load: Option<f64>,
    /// Unloading time at `to` (s).
    pub unload: Option<f64>,
    /// Waiting time of a `wait` task (s).
    pub time: Option<f64>,
}

/// A point given as coordinates or as the name of a place.
#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
pub enum PointOrPlace {
    Coords(Vec<f64>),
    Place(String),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct FootprintFile {
    /// Radius of a round robot (m).
    pub circle: Option<f64>,
    /// [length, width] of a rectangular robot (m).
    pub rectangle: Option<[f64; 2]>,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum KinematicsType {
    DiffDrive,
    Ackermann,
}

#[derive(Deserialize, Debug)]
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

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum BehaviourType {
    Idle,
    Waypoints,
    Wander,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BehaviourFile {
    #[serde(rename = "type")]
    pub kind: BehaviourType,
    pub points: Option<Vec<PointOrPlace>>,
    #[serde(rename = "loop")]
    pub looping: Option<bool>,
    pub speed: Option<f64>,
    pub tolerance: Option<f64>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct SensorsFile {
    pub laser: Option<LaserFile>,
    pub encoder: Option<EncoderFile>,
    pub sonar: Option<super::sonar::SonarFile>,
    pub gps: Option<super::outdoor_robot::GpsFile>,
    pub compass: Option<super::outdoor_robot::CompassFile>,
    pub camera: Option<super::outdoor_robot::CameraFile>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct LaserFile {
    pub preset: Option<String>,
    pub fov_deg: Option<f64>,
    pub increment_deg: Option<f64>,
    pub min_range: Option<f64>,
    pub max_range: Option<f64>,
    pub rate: Option<f64>,
    pub noise_std: Option<f64>,
    pub dropout: Option<f64>,
    /// [x, y, yaw] in the robot frame.
    pub mount: Option<[f64; 3]>,
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct EncoderFile {
    pub ticks_per_rev: Option<u32>,
    pub left_radius_error: Option<f64>,
    pub right_radius_error: Option<f64>,
    pub wheel_base_error: Option<f64>,
    pub slip_std: Option<f64>,
    pub rate: Option<f64>,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum EventType {
    Waypoints,
    #[serde(alias = "kidnap")]
    Teleport,
    SensorFault,
    Door,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum SensorName {
    Laser,
    Encoder,
    Sonar,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct EventFile {
    /// Simulated time (s).
    pub at: f64,
    #[serde(rename = "type")]
    pub kind: EventType,
    /// The robot (every event but `door`).
    pub robot: Option<String>,
    // waypoints
    pub points: Option<Vec<PointOrPlace>>,
    #[serde(rename = "loop")]
    pub looping: Option<bool>,
    // teleport
    pub pose: Option<PointOrPlace>,
    // sensor_fault
    pub sensor: Option<SensorName>,
    /// true: the fault starts (sensor silent); false: it ends.
    pub active: Option<bool>,
    // door
    pub door: Option<String>,
    pub open: Option<bool>,
}

/// Named places next to a map: `[places.<name>] pose = [x, y, yaw]`.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct PlacesFile {
    #[serde(default)]
    pub places: std::collections::BTreeMap<String, PlaceFile>,
    /// Doors: `[doors.<name>] from = [x, y], to = [x, y], thickness = 0.15`.
    #[serde(default)]
    pub doors: std::collections::BTreeMap<String, DoorFile>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DoorFile {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct PlaceFile {
    pub pose: [f64; 3],
    pub kind: Option<String>,
    pub description: Option<String>,
}
