//! [`RobotBuilder`]: one robot of a scenario built in code.

use super::deferred::{Deferred, parse_name};
use crate::scenario::check::PointOrPlace;
use crate::scenario::error::KeyPath;
use crate::scenario::file::{
    BehaviourFile, BehaviourType, FootprintFile, KinematicsFile, RobotFile, SensorsFile,
};
use crate::scenario::localizers::{LocalizerFile, LocalizerType};
use crate::scenario::model::RobotConfig;
use crate::scenario::navigation::{NavigationFile, TaskFile};
use crate::scenario::outdoor_robot::{CameraFile, CompassFile, GpsFile, RouteFile};
use crate::scenario::sensors::{EncoderFile, LaserFile};
use crate::scenario::slam::SlamFile;
use crate::scenario::sonar::SonarFile;

impl RobotConfig {
    /// A robot built in code, named `name`, starting at `start`: a pose `[x, y, yaw]` (or
    /// `[x, y]`, or a [`Pose2`](systems::core::Pose2)) or the name of a place. Everything not given takes the
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
/// given to [`ScenarioBuilder::robot`](super::ScenarioBuilder::robot).
#[derive(Clone, Debug)]
pub struct RobotBuilder {
    pub(super) file: RobotFile,
    pub(super) slam: Vec<SlamFile>,
    pub(super) deferred: Deferred,
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

    /// Drive the behaviour by this localizer (its name) instead of the wheel odometry.
    pub fn behaviour_localizer(mut self, name: impl Into<String>) -> Self {
        self.behaviour_mut().localizer = Some(name.into());
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
