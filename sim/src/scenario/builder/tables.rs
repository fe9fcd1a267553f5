//! Constructors of the file's tables (a laser preset, a task, an event) for the builders.

use crate::scenario::check::PointOrPlace;
use crate::scenario::events::{EventFile, EventType};
use crate::scenario::file::{KinematicsFile, KinematicsType};
use crate::scenario::localizers::{LocalizerFile, LocalizerType};
use crate::scenario::model::SensorName;
use crate::scenario::navigation::{TaskFile, TaskType};
use crate::scenario::people::PersonFile;
use crate::scenario::sensors::LaserFile;
use crate::scenario::slam::{SlamFile, SlamType};
use crate::scenario::sonar::SonarFile;

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
