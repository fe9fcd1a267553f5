//! Scenarios built in code: [`Scenario::builder`] and [`RobotConfig::builder`].
//!
//! The builders fill in the file model ([`ScenarioFile`], [`RobotFile`] and each feature's file
//! tables) and [`ScenarioBuilder::build`] runs the resolver a TOML file goes through. So a value
//! the builder is not given takes the file's default, and a bad value gets the file's error,
//! naming the key (`robots[0].sensors.laser.max_range`); only the line is missing. The
//! example is on [`Scenario::builder`].

use super::check::PointOrPlace;
use super::error::{ErrorContext, KeyPath, ScenarioError};
use super::events::{EventFile, EventType};
use super::file::{
    BehaviourFile, BehaviourType, BoxFile, DiscFile, FootprintFile, KinematicsFile, KinematicsType,
    MapFile, RecordFile, RobotFile, ScenarioFile, SensorsFile, WallFile,
};
use super::localizers::{LocalizerFile, LocalizerType};
use super::model::{RobotConfig, Scenario, SensorName};
use super::navigation::{NavigationFile, TaskFile, TaskType};
use super::outdoor::{RoadsFile, ZoneFile};
use super::outdoor_robot::{CameraFile, CompassFile, GpsFile, RouteFile};
use super::people::PersonFile;
use super::places::{DoorFile, PlaceFile};
use super::sensors::{EncoderFile, LaserFile};
use super::slam::{SlamFile, SlamList, SlamType};
use super::sonar::SonarFile;
use std::path::{Path, PathBuf};
use systems::core::Pose2;

#[cfg(test)]
mod tests;

/// What errors of a built scenario name instead of a file.
pub const CODE_LABEL: &str = "<code>";

/// A value given to a builder that could not become part of the file model (a type name that
/// is no type): its key and message, reported by `build` as the file's parse error would be.
type Deferred = Option<(KeyPath, String)>;

/// A name read as the file reads it (`"mcl"` → [`LocalizerType::Mcl`]), with serde's message
/// when it is none of the names.
fn parse_name<T: serde::de::DeserializeOwned>(name: &str) -> Result<T, String> {
    use serde::de::IntoDeserializer;
    let d: serde::de::value::StringDeserializer<serde::de::value::Error> =
        name.to_string().into_deserializer();
    T::deserialize(d).map_err(|e| e.to_string())
}

impl From<[f64; 2]> for PointOrPlace {
    fn from(p: [f64; 2]) -> Self {
        PointOrPlace::Coords(p.to_vec())
    }
}

impl From<[f64; 3]> for PointOrPlace {
    fn from(p: [f64; 3]) -> Self {
        PointOrPlace::Coords(p.to_vec())
    }
}

impl From<Pose2> for PointOrPlace {
    fn from(p: Pose2) -> Self {
        PointOrPlace::Coords(vec![p.x, p.y, p.theta])
    }
}

impl From<&str> for PointOrPlace {
    fn from(name: &str) -> Self {
        PointOrPlace::Place(name.to_string())
    }
}

impl From<String> for PointOrPlace {
    fn from(name: String) -> Self {
        PointOrPlace::Place(name)
    }
}

impl Scenario {
    /// A scenario built in code, named `name` (letters, digits, `_`, `-`: it names output
    /// files). Everything not given takes the scenario file's default; `duration` is required
    /// as in a file.
    ///
    /// ```
    /// use sim::scenario::{LaserFile, LocalizerFile, LocalizerType, RobotConfig, Scenario};
    ///
    /// let scenario = Scenario::builder("two_rooms")
    ///     .seed(7)
    ///     .duration(1.0)
    ///     .room([0.0, 0.0], [10.0, 8.0])
    ///     .wall([5.0, 0.0], [5.0, 5.0])
    ///     .place("dock", [2.0, 2.0, 0.0])
    ///     .robot(
    ///         RobotConfig::builder("r1", "dock")
    ///             .laser(LaserFile::preset("sick_lms100"))
    ///             .encoder(Default::default())
    ///             .localizer(LocalizerFile {
    ///                 max_particles: Some(500),
    ///                 ..LocalizerFile::of_type(LocalizerType::Mcl)
    ///             })
    ///             .waypoints([[8.0, 2.0], [8.0, 6.0]], true),
    ///     )
    ///     .build()?;
    /// assert_eq!(scenario.robots[0].localizers[0].name, "mcl");
    /// let done = sim::Simulation::from_scenario(scenario).threads(1).build()?.run()?;
    /// assert_eq!(done.summary.robots.len(), 1);
    /// # anyhow::Ok(())
    /// ```
    pub fn builder(name: impl Into<String>) -> ScenarioBuilder {
        ScenarioBuilder {
            file: ScenarioFile {
                name: Some(name.into()),
                ..Default::default()
            },
            base_dir: PathBuf::new(),
            label: CODE_LABEL.to_string(),
            deferred: None,
        }
    }
}

/// Builds a [`Scenario`] in code (see the [module](self) docs); made by [`Scenario::builder`].
#[derive(Clone, Debug)]
pub struct ScenarioBuilder {
    file: ScenarioFile,
    base_dir: PathBuf,
    label: String,
    deferred: Deferred,
}

impl ScenarioBuilder {
    /// One line about the scenario (the file's `description`).
    pub fn description(mut self, text: impl Into<String>) -> Self {
        self.file.description = Some(text.into());
        self
    }

    /// The random seed (`seed`).
    pub fn seed(mut self, seed: u64) -> Self {
        self.file.seed = Some(seed);
        self
    }

    /// The time step in seconds (`dt`).
    pub fn dt(mut self, dt: f64) -> Self {
        self.file.dt = Some(dt);
        self
    }

    /// Simulated seconds (`duration`, required).
    pub fn duration(mut self, seconds: f64) -> Self {
        self.file.duration = Some(seconds);
        self
    }

    /// End the run once every robot with tasks has done them (`end_when_done`).
    pub fn end_when_done(mut self, yes: bool) -> Self {
        self.file.end_when_done = Some(yes);
        self
    }

    /// Relative paths (map, places and road files) resolve against `dir` instead of the
    /// current folder.
    pub fn relative_to(mut self, dir: impl Into<PathBuf>) -> Self {
        self.base_dir = dir.into();
        self
    }

    /// What errors name as the scenario's source (default [`CODE_LABEL`]).
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    fn map(&mut self) -> &mut MapFile {
        self.file.map.get_or_insert_with(Default::default)
    }

    /// A ROS map_server YAML file (`map.file`).
    pub fn map_file(mut self, path: impl AsRef<Path>) -> Self {
        self.map().file = Some(path.as_ref().to_string_lossy().into_owned());
        self
    }

    /// A places file of named poses and doors (`map.places`).
    pub fn places_file(mut self, path: impl AsRef<Path>) -> Self {
        self.map().places = Some(path.as_ref().to_string_lossy().into_owned());
        self
    }

    /// The cell size (m) of a world made of shapes (`map.resolution`).
    pub fn resolution(mut self, metres: f64) -> Self {
        self.map().resolution = Some(metres);
        self
    }

    /// A wall of the default thickness (`[[walls]]`).
    pub fn wall(self, from: [f64; 2], to: [f64; 2]) -> Self {
        self.wall_table(WallFile {
            from,
            to,
            thickness: None,
        })
    }

    /// A wall given as its table (to set its `thickness`).
    pub fn wall_table(mut self, wall: WallFile) -> Self {
        self.file.walls.push(wall);
        self
    }

    /// Four walls (of the default thickness) around the rectangle from `min` to `max`.
    pub fn room(self, min: [f64; 2], max: [f64; 2]) -> Self {
        let [x0, y0] = min;
        let [x1, y1] = max;
        self.wall([x0, y0], [x1, y0])
            .wall([x1, y0], [x1, y1])
            .wall([x1, y1], [x0, y1])
            .wall([x0, y1], [x0, y0])
    }

    /// A box of `size` [length, width] (m) centred at `center`, yaw 0 (`[[boxes]]`).
    pub fn box_shape(self, center: [f64; 2], size: [f64; 2]) -> Self {
        self.box_table(BoxFile {
            center,
            size,
            yaw: None,
        })
    }

    /// A box given as its table (to set its `yaw`).
    pub fn box_table(mut self, b: BoxFile) -> Self {
        self.file.boxes.push(b);
        self
    }

    /// A disc (`[[discs]]`).
    pub fn disc(mut self, center: [f64; 2], radius: f64) -> Self {
        self.file.discs.push(DiscFile { center, radius });
        self
    }

    /// A named place `[x, y, yaw]` (`[places.<name>]`), beside those of the places file.
    pub fn place(mut self, name: impl Into<String>, pose: [f64; 3]) -> Self {
        self.file.places.insert(
            name.into(),
            PlaceFile {
                pose,
                ..Default::default()
            },
        );
        self
    }

    /// A door from `from` to `to` of the default thickness (`[doors.<name>]`); it starts open.
    pub fn door(self, name: impl Into<String>, from: [f64; 2], to: [f64; 2]) -> Self {
        self.door_table(
            name,
            DoorFile {
                from,
                to,
                thickness: None,
            },
        )
    }

    /// A door given as its table (to set its `thickness`).
    pub fn door_table(mut self, name: impl Into<String>, door: DoorFile) -> Self {
        self.file.doors.insert(name.into(), door);
        self
    }

    /// The recording's rates (`[record]`); the rates not given keep their defaults.
    pub fn record(mut self, record: RecordFile) -> Self {
        self.file.record = Some(record);
        self
    }

    /// A robot (`[[robots]]`), after those added before.
    pub fn robot(mut self, robot: RobotBuilder) -> Self {
        let at = KeyPath::default()
            .key("robots")
            .index(self.file.robots.len());
        if self.deferred.is_none()
            && let Some((key, message)) = robot.deferred
        {
            let mut path = at;
            path.0.extend(key.0);
            self.deferred = Some((path, message));
        }
        let mut file = robot.file;
        file.slam = match robot.slam.len() {
            0 => None,
            1 => robot
                .slam
                .into_iter()
                .next()
                .map(|s| SlamList::One(Box::new(s))),
            _ => Some(SlamList::Many(robot.slam)),
        };
        self.file.robots.push(file);
        self
    }

    /// A walking person (`[[people]]`).
    pub fn person(mut self, person: PersonFile) -> Self {
        self.file.people.push(person);
        self
    }

    /// A timed event (`[[events]]`); see [`EventFile`]'s constructors.
    pub fn event(mut self, event: EventFile) -> Self {
        self.file.events.push(event);
        self
    }

    /// An outdoor road network (`[roads]`).
    pub fn roads(mut self, roads: RoadsFile) -> Self {
        self.file.roads = Some(roads);
        self
    }

    /// An area that degrades GPS and compass (`[[zones]]`).
    pub fn zone(mut self, zone: ZoneFile) -> Self {
        self.file.zones.push(zone);
        self
    }

    /// The file model built so far.
    pub fn file(&self) -> &ScenarioFile {
        &self.file
    }

    /// Checks everything and fills in every default, as for a scenario file; the first problem
    /// is an error naming the key.
    pub fn build(self) -> Result<Scenario, ScenarioError> {
        if let Some((key, message)) = &self.deferred {
            return Err(ErrorContext::new(self.label.clone(), "").at(key, message.clone()));
        }
        super::resolve::resolve_model(self.file, &self.label, &self.base_dir, "scenario")
    }
}

impl RobotConfig {
    /// A robot built in code, named `name`, starting at `start`: a pose `[x, y, yaw]` (or
    /// `[x, y]`, or a [`Pose2`]) or the name of a place. Everything not given takes the
    /// scenario file's default: a 0.25 m disc with a differential drive and no sensors, idle.
    pub fn builder(name: impl Into<String>, start: impl Into<PointOrPlace>) -> RobotBuilder {
        RobotBuilder {
            file: RobotFile {
                name: name.into(),
                start: Some(start.into()),
                ..Default::default()
            },
            slam: Vec::new(),
            deferred: None,
        }
    }

    /// A robot that drives `route` on the scenario's road network, starting on its road.
    pub fn builder_on_route(name: impl Into<String>, route: RouteFile) -> RobotBuilder {
        RobotBuilder {
            file: RobotFile {
                name: name.into(),
                route: Some(route),
                ..Default::default()
            },
            slam: Vec::new(),
            deferred: None,
        }
    }
}

/// Builds one robot of a scenario (a `[[robots]]` table); made by [`RobotConfig::builder`],
/// given to [`ScenarioBuilder::robot`].
#[derive(Clone, Debug)]
pub struct RobotBuilder {
    file: RobotFile,
    slam: Vec<SlamFile>,
    deferred: Deferred,
}

impl RobotBuilder {
    /// A robot preset (`thesis_car`) filling in the footprint, kinematics and sensors not given.
    pub fn preset(mut self, name: impl Into<String>) -> Self {
        self.file.preset = Some(name.into());
        self
    }

    /// A round robot of this radius (m).
    pub fn circle(mut self, radius: f64) -> Self {
        self.file.footprint = Some(FootprintFile {
            circle: Some(radius),
            rectangle: None,
        });
        self
    }

    /// A rectangular robot, `length` along its heading (m).
    pub fn rectangle(mut self, length: f64, width: f64) -> Self {
        self.file.footprint = Some(FootprintFile {
            circle: None,
            rectangle: Some([length, width]),
        });
        self
    }

    /// The drive (`kinematics`), e.g. `KinematicsFile { wheel_base: Some(0.5),
    /// ..KinematicsFile::diff_drive() }`.
    pub fn kinematics(mut self, kinematics: KinematicsFile) -> Self {
        self.file.kinematics = Some(kinematics);
        self
    }

    /// A differential drive with the default parameters.
    pub fn diff_drive(self) -> Self {
        self.kinematics(KinematicsFile::diff_drive())
    }

    /// Ackermann steering with the default parameters.
    pub fn ackermann(self) -> Self {
        self.kinematics(KinematicsFile::ackermann())
    }

    fn behaviour_mut(&mut self) -> &mut BehaviourFile {
        self.file.behaviour.get_or_insert_with(Default::default)
    }

    /// The driving behaviour as its table.
    pub fn behaviour(mut self, behaviour: BehaviourFile) -> Self {
        self.file.behaviour = Some(behaviour);
        self
    }

    /// Stand still (the default without a behaviour).
    pub fn idle(mut self) -> Self {
        self.behaviour_mut().kind = BehaviourType::Idle;
        self
    }

    /// Drive around, turning away from obstacles.
    pub fn wander(mut self) -> Self {
        self.behaviour_mut().kind = BehaviourType::Wander;
        self
    }

    /// Drive to each point (`[x, y]` or a place name) in turn, over and over if `looping`.
    pub fn waypoints<P: Into<PointOrPlace>>(
        mut self,
        points: impl IntoIterator<Item = P>,
        looping: bool,
    ) -> Self {
        let b = self.behaviour_mut();
        b.kind = BehaviourType::Waypoints;
        b.points = Some(points.into_iter().map(Into::into).collect());
        b.looping = Some(looping);
        self
    }

    /// The behaviour's speed (m/s); without a behaviour the robot gets an idle one.
    pub fn speed(mut self, speed: f64) -> Self {
        self.behaviour_mut().speed = Some(speed);
        self
    }

    /// How close a waypoint counts as reached (m); without a behaviour the robot gets an idle
    /// one.
    pub fn tolerance(mut self, metres: f64) -> Self {
        self.behaviour_mut().tolerance = Some(metres);
        self
    }

    fn sensors(&mut self) -> &mut SensorsFile {
        self.file.sensors.get_or_insert_with(Default::default)
    }

    /// A laser scanner: a preset with overrides, e.g. `LaserFile { max_range: Some(8.0),
    /// ..LaserFile::preset("sick_lms100") }`.
    pub fn laser(mut self, laser: LaserFile) -> Self {
        self.sensors().laser = Some(laser);
        self
    }

    /// Wheel encoders (`EncoderFile::default()`: the default encoders).
    pub fn encoder(mut self, encoder: EncoderFile) -> Self {
        self.sensors().encoder = Some(encoder);
        self
    }

    /// A sonar ring (`SonarFile::default()`: SRF02s in the `hospital` layout).
    pub fn sonar(mut self, sonar: SonarFile) -> Self {
        self.sensors().sonar = Some(sonar);
        self
    }

    /// A GPS receiver.
    pub fn gps(mut self, gps: GpsFile) -> Self {
        self.sensors().gps = Some(gps);
        self
    }

    /// A compass.
    pub fn compass(mut self, compass: CompassFile) -> Self {
        self.sensors().compass = Some(compass);
        self
    }

    /// A camera.
    pub fn camera(mut self, camera: CameraFile) -> Self {
        self.sensors().camera = Some(camera);
        self
    }

    /// A localizer (a `[[robots.localization]]` table), after those added before.
    pub fn localizer(mut self, localizer: LocalizerFile) -> Self {
        self.file.localization.push(localizer);
        self
    }

    /// A localizer of the type named as in a file (`"mcl"`, `"de_filter"`, …) with its default
    /// parameters; an unknown name is `build`'s error, as in a file.
    pub fn localizer_type(mut self, name: &str) -> Self {
        let i = self.file.localization.len();
        let kind = parse_name::<LocalizerType>(name).unwrap_or_else(|message| {
            if self.deferred.is_none() {
                let key = KeyPath::default().key("localization").index(i).key("type");
                self.deferred = Some((key, message));
            }
            LocalizerType::default()
        });
        self.localizer(LocalizerFile::of_type(kind))
    }

    /// A SLAM system. One is the file's `slam = { … }`; several are `[[robots.slam]]` tables.
    pub fn slam(mut self, slam: SlamFile) -> Self {
        self.slam.push(slam);
        self
    }

    /// The navigator's settings (`[robots.navigation]`; it needs tasks).
    pub fn navigation(mut self, navigation: NavigationFile) -> Self {
        self.file.navigation = Some(navigation);
        self
    }

    /// A task (`[[robots.tasks]]`), after those added before; see [`TaskFile`]'s constructors.
    pub fn task(mut self, task: TaskFile) -> Self {
        self.file.tasks.push(task);
        self
    }

    /// The robot's table as built so far (its SLAM systems aside).
    pub fn file(&self) -> &RobotFile {
        &self.file
    }
}

impl KinematicsFile {
    /// A differential drive; the parameters not set take their defaults.
    pub fn diff_drive() -> Self {
        KinematicsFile {
            kind: KinematicsType::DiffDrive,
            ..Default::default()
        }
    }

    /// Ackermann steering; the parameters not set take their defaults.
    pub fn ackermann() -> Self {
        KinematicsFile {
            kind: KinematicsType::Ackermann,
            ..Default::default()
        }
    }
}

impl LaserFile {
    /// A laser of this preset (`sick_lms100`, …) with none of its values overridden.
    pub fn preset(name: impl Into<String>) -> Self {
        LaserFile {
            preset: Some(name.into()),
            ..Default::default()
        }
    }
}

impl SonarFile {
    /// Sonars of this preset (`srf02`) with none of its values overridden.
    pub fn preset(name: impl Into<String>) -> Self {
        SonarFile {
            preset: Some(name.into()),
            ..Default::default()
        }
    }
}

impl LocalizerFile {
    /// A localizer of this type with its default parameters, named after the type.
    pub fn of_type(kind: LocalizerType) -> Self {
        LocalizerFile {
            kind,
            ..Default::default()
        }
    }
}

impl SlamFile {
    /// A SLAM system of this type with its default parameters, named after the type.
    pub fn of_type(kind: SlamType) -> Self {
        SlamFile {
            kind,
            ..Default::default()
        }
    }
}

impl TaskFile {
    /// Drive to `to` (a place or `[x, y]`).
    pub fn go(to: impl Into<PointOrPlace>) -> Self {
        TaskFile {
            kind: TaskType::Go,
            to: Some(to.into()),
            ..Default::default()
        }
    }

    /// Drive to `from`, load, drive to `to`, unload (default loading times).
    pub fn delivery(from: impl Into<PointOrPlace>, to: impl Into<PointOrPlace>) -> Self {
        TaskFile {
            kind: TaskType::Delivery,
            from: Some(from.into()),
            to: Some(to.into()),
            ..Default::default()
        }
    }

    /// Wait `seconds` where the robot is.
    pub fn wait(seconds: f64) -> Self {
        TaskFile {
            kind: TaskType::Wait,
            time: Some(seconds),
            ..Default::default()
        }
    }

    /// The task under this name (in the summary).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }
}

impl PersonFile {
    /// A person walking `route` (at least two points or place names) once, at the default
    /// speed.
    pub fn new<P: Into<PointOrPlace>>(
        name: impl Into<String>,
        route: impl IntoIterator<Item = P>,
    ) -> Self {
        PersonFile {
            name: name.into(),
            route: route.into_iter().map(Into::into).collect(),
            ..Default::default()
        }
    }
}

impl EventFile {
    fn robot_event(at: f64, kind: EventType, robot: impl Into<String>) -> Self {
        EventFile {
            at,
            kind,
            robot: Some(robot.into()),
            ..Default::default()
        }
    }

    /// At `at` s the robot's behaviour becomes driving to `points` (looping or not).
    pub fn waypoints<P: Into<PointOrPlace>>(
        at: f64,
        robot: impl Into<String>,
        points: impl IntoIterator<Item = P>,
        looping: bool,
    ) -> Self {
        EventFile {
            points: Some(points.into_iter().map(Into::into).collect()),
            looping: Some(looping),
            ..Self::robot_event(at, EventType::Waypoints, robot)
        }
    }

    /// At `at` s the robot is carried to `pose` (a kidnapping).
    pub fn teleport(at: f64, robot: impl Into<String>, pose: impl Into<PointOrPlace>) -> Self {
        EventFile {
            pose: Some(pose.into()),
            ..Self::robot_event(at, EventType::Teleport, robot)
        }
    }

    /// At `at` s the robot's `sensor` falls silent (`active`) or works again.
    pub fn sensor_fault(
        at: f64,
        robot: impl Into<String>,
        sensor: SensorName,
        active: bool,
    ) -> Self {
        EventFile {
            sensor: Some(sensor),
            active: Some(active),
            ..Self::robot_event(at, EventType::SensorFault, robot)
        }
    }

    /// At `at` s a door opens or closes.
    pub fn door(at: f64, door: impl Into<String>, open: bool) -> Self {
        EventFile {
            at,
            kind: EventType::Door,
            door: Some(door.into()),
            open: Some(open),
            ..Default::default()
        }
    }

    /// At `at` s a velocity command (m/s, rad/s) is held on the robot until a release.
    pub fn drive(at: f64, robot: impl Into<String>, v: f64, w: f64) -> Self {
        EventFile {
            v: Some(v),
            w: Some(w),
            ..Self::robot_event(at, EventType::Drive, robot)
        }
    }

    /// At `at` s the held command is dropped.
    pub fn release(at: f64, robot: impl Into<String>) -> Self {
        Self::robot_event(at, EventType::Release, robot)
    }
}
