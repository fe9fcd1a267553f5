//! `[[events]]`: timed scenario events (routes, kidnapping, sensor faults, doors, held drive
//! commands, new navigation tasks), checked against the robots, doors and map they concern.

use super::check::PointOrPlace;
use super::check::{Checker, R};
use super::error::KeyPath;
use super::model::{DoorConfig, Event, EventAction, RobotConfig, SensorName};
use serde::Deserialize;
use systems::body::{DriveCommand, Kinematics};
use systems::core::Pose2;
use systems::world::OccupancyGrid;

/// An event's `type`. Required in a file; the `Default` (waypoints) only lets a table be
/// written with `..Default::default()`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum EventType {
    #[default]
    Waypoints,
    #[serde(alias = "kidnap")]
    Teleport,
    SensorFault,
    Door,
    Drive,
    Release,
    Tasks,
}

/// One `[[events]]` table: the keys of its type (the others are errors).
#[derive(Deserialize, Debug, Clone, Default)]
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
    // drive: the held velocity command (m/s, rad/s), or a car's speed (m/s) and steering
    // angle (rad)
    pub v: Option<f64>,
    pub w: Option<f64>,
    pub speed: Option<f64>,
    pub steer: Option<f64>,
    /// tasks: appended to the robot's task queue (same tables as `[[robots.tasks]]`)
    pub tasks: Option<Vec<super::navigation::TaskFile>>,
}

impl EventFile {
    /// The keys of drive events, and whether each is given.
    fn drive_keys(&self) -> [(&'static str, bool); 4] {
        [
            ("v", self.v.is_some()),
            ("w", self.w.is_some()),
            ("speed", self.speed.is_some()),
            ("steer", self.steer.is_some()),
        ]
    }

    /// The keys of waypoints, teleport and sensor_fault events, and whether each is given.
    fn route_pose_and_sensor_keys(&self) -> [(&'static str, bool); 6] {
        [
            ("tasks", self.tasks.is_some()),
            ("points", self.points.is_some()),
            ("loop", self.looping.is_some()),
            ("pose", self.pose.is_some()),
            ("sensor", self.sensor.is_some()),
            ("active", self.active.is_some()),
        ]
    }
}

/// Resolves a `points` key (a list of [x, y] or place names).
type PointList<'a> = dyn Fn(&KeyPath, &Option<Vec<PointOrPlace>>) -> R<Vec<[f64; 2]>> + 'a;

/// What events may refer to.
pub(super) struct Known<'a> {
    pub robots: &'a [RobotConfig],
    pub doors: &'a [DoorConfig],
    pub grid: &'a OccupancyGrid,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn resolve_events(
    c: &Checker,
    path: &KeyPath,
    files: &[EventFile],
    duration: f64,
    known: Known,
    point: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
    inside: &dyn Fn(&KeyPath, &Pose2) -> R<()>,
    points: &PointList,
) -> R<Vec<Event>> {
    let mut events = Vec::new();
    for (i, e) in files.iter().enumerate() {
        let p = path.index(i);
        let at = c.range(&p.key("at"), e.at, Some(0.0), Some(duration), false)?;
        let (robot, action) = if e.kind == EventType::Door {
            (None, resolve_door_event(c, &p, e, known.doors)?)
        } else {
            let action = resolve_robot_event(c, &p, e, &known, point, inside, points)?;
            (e.robot.clone(), action)
        };
        events.push(Event { at, robot, action });
    }
    // stable: events at the same time fire in file order
    events.sort_by(|a, b| a.at.total_cmp(&b.at));
    Ok(events)
}

/// A `door` event: the door and whether it opens.
fn resolve_door_event(
    c: &Checker,
    p: &KeyPath,
    e: &EventFile,
    doors: &[DoorConfig],
) -> R<EventAction> {
    if e.robot.is_some() {
        return c.err(
            &p.key("robot"),
            "a door event concerns no robot: remove `robot`",
        );
    }
    for (key, present) in e
        .route_pose_and_sensor_keys()
        .into_iter()
        .chain(e.drive_keys())
    {
        if present {
            return c.err(
                &p.key(key),
                format!("`{key}` does not apply to a `door` event"),
            );
        }
    }
    let Some(door) = &e.door else {
        return c.err(
            p,
            "a door event needs `door` (a door of the map's places file)",
        );
    };
    let Some(index) = doors.iter().position(|d| &d.name == door) else {
        let known: Vec<&str> = doors.iter().map(|d| d.name.as_str()).collect();
        return c.err(
            &p.key("door"),
            if known.is_empty() {
                format!("unknown door `{door}` (the map's places file defines no doors)")
            } else {
                format!("unknown door `{door}`; known doors: {}", known.join(", "))
            },
        );
    };
    let Some(open) = e.open else {
        return c.err(p, "a door event needs `open` (true or false)");
    };
    Ok(EventAction::Door { index, open })
}

/// An event that concerns a robot: waypoints, teleport or sensor fault.
fn resolve_robot_event(
    c: &Checker,
    p: &KeyPath,
    e: &EventFile,
    known: &Known,
    point: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
    inside: &dyn Fn(&KeyPath, &Pose2) -> R<()>,
    points: &PointList,
) -> R<EventAction> {
    let Known { robots, grid, .. } = known;
    if e.kind != EventType::Tasks && e.tasks.is_some() {
        return c.err(&p.key("tasks"), "`tasks` applies to `tasks` events only");
    }
    if e.door.is_some() || e.open.is_some() {
        let key = if e.door.is_some() { "door" } else { "open" };
        return c.err(
            &p.key(key),
            format!("`{key}` applies to `door` events only"),
        );
    }
    if e.kind != EventType::Drive
        && let Some((key, _)) = e.drive_keys().into_iter().find(|(_, present)| *present)
    {
        return c.err(
            &p.key(key),
            format!("`{key}` applies to `drive` events only"),
        );
    }
    let Some(robot_name) = &e.robot else {
        return c.err(p, "missing key `robot` (the robot the event concerns)");
    };
    let Some(robot) = robots.iter().find(|r| &r.name == robot_name) else {
        return c.err(&p.key("robot"), format!("no robot named `{robot_name}`"));
    };
    let only = |key: &str, present: bool, kind: &str| -> R<()> {
        if present {
            return c.err(
                &p.key(key),
                format!("`{key}` does not apply to a `{kind}` event"),
            );
        }
        Ok(())
    };
    let action = match e.kind {
        EventType::Door => return resolve_door_event(c, p, e, known.doors),
        EventType::Waypoints => {
            if robot.navigation.is_some() {
                return c.err(
                    &p.key("robot"),
                    format!(
                        "robot `{}` is driven by its tasks; a route event cannot apply",
                        robot.name
                    ),
                );
            }
            only("pose", e.pose.is_some(), "waypoints")?;
            only("sensor", e.sensor.is_some(), "waypoints")?;
            only("active", e.active.is_some(), "waypoints")?;
            EventAction::Waypoints {
                points: points(p, &e.points)?,
                looping: e.looping.unwrap_or(false),
            }
        }
        EventType::Teleport => {
            only("points", e.points.is_some(), "teleport")?;
            only("loop", e.looping.is_some(), "teleport")?;
            only("sensor", e.sensor.is_some(), "teleport")?;
            only("active", e.active.is_some(), "teleport")?;
            let Some(pose) = &e.pose else {
                return c.err(p, "a teleport event needs `pose` ([x, y, yaw] or a place)");
            };
            let pose = point(&p.key("pose"), pose)?;
            inside(&p.key("pose"), &pose)?;
            if !grid.disc_is_clear(pose.x, pose.y, robot.footprint.bounding_radius()) {
                return c.err(
                    &p.key("pose"),
                    "the robot would be placed inside an obstacle",
                );
            }
            EventAction::Teleport(pose)
        }
        EventType::SensorFault => {
            only("points", e.points.is_some(), "sensor_fault")?;
            only("loop", e.looping.is_some(), "sensor_fault")?;
            only("pose", e.pose.is_some(), "sensor_fault")?;
            let Some(sensor) = e.sensor else {
                return c.err(
                    p,
                    "a sensor_fault event needs `sensor` (laser, encoder or sonar)",
                );
            };
            let has = match sensor {
                SensorName::Laser => robot.laser.is_some(),
                SensorName::Encoder => robot.encoder.is_some(),
                SensorName::Sonar => robot.sonar.is_some(),
            };
            if !has {
                return c.err(
                    &p.key("sensor"),
                    format!("robot `{}` has no {sensor:?} sensor", robot.name).to_lowercase(),
                );
            }
            EventAction::SensorFault {
                sensor,
                active: e.active.unwrap_or(true),
            }
        }
        EventType::Tasks => {
            if robot.navigation.is_none() {
                return c.err(
                    &p.key("robot"),
                    format!(
                        "robot `{}` has no task queue: give it `[[robots.tasks]]` (and \
                         `[robots.navigation]`) to send it tasks",
                        robot.name
                    ),
                );
            }
            let Some(tasks) = e.tasks.as_ref().filter(|t| !t.is_empty()) else {
                return c.err(
                    p,
                    "a tasks event needs `tasks` (at least one, as in `[[robots.tasks]]`)",
                );
            };
            for (key, present) in e.route_pose_and_sensor_keys().into_iter().skip(1) {
                only(key, present, "tasks")?;
            }
            let radius = robot.footprint.bounding_radius();
            let goal = |path: &KeyPath, v: &PointOrPlace| -> R<Pose2> {
                let pose = point(path, v)?;
                inside(path, &pose)?;
                super::navigation::goal_clear(c, path, grid, &pose, radius)?;
                Ok(pose)
            };
            let tp = p.key("tasks");
            let tasks = tasks
                .iter()
                .enumerate()
                .map(|(i, t)| super::navigation::resolve_task(c, &tp.index(i), t, i, &goal))
                .collect::<R<Vec<_>>>()?;
            EventAction::Tasks(tasks)
        }
        EventType::Drive | EventType::Release => {
            let kind = if e.kind == EventType::Drive {
                "drive"
            } else {
                "release"
            };
            for (key, present) in e.route_pose_and_sensor_keys() {
                only(key, present, kind)?;
            }
            if e.kind == EventType::Release {
                EventAction::ReleaseDrive
            } else if e.speed.is_some() || e.steer.is_some() {
                resolve_speed_steer(c, p, e, robot)?
            } else {
                let speed = |key: &str, v: Option<f64>| match v {
                    Some(v) => c.range(&p.key(key), v, None, None, false),
                    None => c.err(
                        p,
                        format!("a drive event needs `{key}` (`v` in m/s, `w` in rad/s)"),
                    ),
                };
                EventAction::Drive(DriveCommand::new(speed("v", e.v)?, speed("w", e.w)?))
            }
        }
    };
    Ok(action)
}

/// A drive event's speed/steer form: a car's forward speed (m/s) and steering angle (rad, within
/// its `max_steer`).
fn resolve_speed_steer(
    c: &Checker,
    p: &KeyPath,
    e: &EventFile,
    robot: &RobotConfig,
) -> R<EventAction> {
    for (key, present) in [("v", e.v.is_some()), ("w", e.w.is_some())] {
        if present {
            return c.err(
                &p.key(key),
                format!("`{key}` and `speed`/`steer` are two forms of a drive event: give one"),
            );
        }
    }
    let Kinematics::Ackermann(car) = &robot.kinematics else {
        let key = if e.steer.is_some() { "steer" } else { "speed" };
        return c.err(
            &p.key(key),
            format!(
                "`speed` and `steer` drive a car (Ackermann); robot `{}` has a differential \
                 drive: give `v` (m/s) and `w` (rad/s)",
                robot.name
            ),
        );
    };
    let (Some(speed), Some(steer)) = (e.speed, e.steer) else {
        return c.err(
            p,
            "a speed/steer drive event needs both `speed` (m/s) and `steer` (rad)",
        );
    };
    let speed = c.range(&p.key("speed"), speed, None, None, false)?;
    let max = car.max_steer;
    let steer = c.range(&p.key("steer"), steer, Some(-max), Some(max), false)?;
    Ok(EventAction::Drive(car.command(speed, steer)))
}
