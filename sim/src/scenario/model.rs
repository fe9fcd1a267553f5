//! The validated scenario: every value checked and every default filled in, as world building
//! and the run read it.

use super::localizers::LocalizerConfig;
use super::navigation::NavConfig;
use super::people::PersonConfig;
use super::sonar::SonarConfig;
use serde::Deserialize;
use std::collections::BTreeMap;
use systems::body::{Footprint, Kinematics};
use systems::core::Pose2;
use systems::navigation::BehaviourKind;
use systems::sensors::{EncoderSpec, LaserSpec};
use systems::world::OccupancyGrid;

/// The most ticks one run may have (`duration / dt`): about 58 days simulated at dt = 0.05 s.
/// Longer runs would never end in practice; they are refused before their first tick.
pub const MAX_TICKS: f64 = 1e8;

/// Why a run of `duration` s at `dt` s per tick is too long, if it is.
pub fn too_many_ticks(duration: f64, dt: f64) -> Option<String> {
    let ticks = duration / dt;
    let fits = ticks <= MAX_TICKS; // false for NaN too
    (!fits).then(|| {
        format!(
            "{duration:?} s at dt = {dt:?} s is {ticks:.3e} ticks; a run has at most {MAX_TICKS:.0e} \
             (shorten the duration or lengthen dt)"
        )
    })
}

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
    pub roads: Option<super::outdoor::RoadsConfig>,
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
    /// The localizer the recording's map view shows for the robots that have it (None: each
    /// robot's first).
    pub map_localizer: Option<String>,
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
            map_localizer: None,
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
    /// Index of the localizer the behaviour drives by (None: wheel odometry).
    pub behaviour_localizer: Option<usize>,
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
    pub route: Option<super::outdoor_robot::RouteConfig>,
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
    /// A velocity command (m/s, rad/s; or a car's speed and steering angle) held on the robot:
    /// it replaces what its behaviour or navigator commands until released.
    Drive(systems::body::DriveCommand),
    /// The held command is dropped: the behaviour or navigator drives again.
    ReleaseDrive,
    /// Tasks appended to a navigating robot's queue.
    Tasks(Vec<systems::navigation::Task>),
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum SensorName {
    Laser,
    Encoder,
    Sonar,
}
