//! Commands a program gives a [`super::Simulation`] between ticks, and the errors of the
//! facade. A command becomes a scenario event due now: it takes effect at the next tick, in the
//! Script set, exactly as the same event written in the scenario file would.

use crate::scenario::{EventAction, SensorName};
use systems::body::{DriveCommand, Kinematics};
use systems::core::Pose2;
use systems::navigation::{Goal, Task, TaskKind};

/// What a robot is told to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// A new route for a robot driven by a behaviour (followed once, or round and round).
    Waypoints {
        /// The route's points (m), in order.
        points: Vec<[f64; 2]>,
        /// Back to the first point after the last, for ever.
        looping: bool,
    },
    /// Moves the robot to `pose` without telling its estimators (a kidnapping).
    Teleport(Pose2),
    /// A sensor stops (`active`) or resumes producing readings.
    SensorFault {
        /// Which of the robot's sensors.
        sensor: SensorName,
        /// True: the fault starts (the sensor is silent); false: it ends.
        active: bool,
    },
    /// A velocity command (forward m/s, yaw rate rad/s; an Ackermann robot steers to that yaw
    /// rate) held until replaced or released; the robot's limits still apply.
    Drive {
        /// Forward speed (m/s).
        v: f64,
        /// Yaw rate (rad/s).
        w: f64,
    },
    /// A car's (Ackermann robot's) command in its own terms: forward speed (m/s) and steering
    /// angle (rad, within the car's `max_steer`), held like [`Command::Drive`]. The wheels turn to
    /// the angle at the car's steering rate, also at a standstill.
    Steer {
        /// Forward speed (m/s).
        speed: f64,
        /// Steering angle (rad), positive to the left.
        steer: f64,
    },
    /// Drops the held velocity command: the behaviour or navigator drives again.
    Release,
    /// Sends a navigating robot (one with tasks) to a place or a point: a `go` task appended
    /// to its queue, planned and driven once the tasks before it are done.
    GoTo(Target),
    /// Appends tasks (deliveries, trips, waits) to a navigating robot's queue.
    Tasks(Vec<Task>),
}

/// Where a robot is sent.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// A named place of the scenario's map.
    Place(String),
    /// A point of the map (m).
    Point([f64; 2]),
}

/// Why the facade refused a request. `known` fields list the names that would have been
/// accepted, comma-separated (`none` when there are none).
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum SimError {
    /// A robot name that is not the scenario's.
    #[error("no robot named `{name}` (robots: {known})")]
    UnknownRobot {
        /// The name asked for.
        name: String,
        /// The scenario's robots.
        known: String,
    },
    /// A localizer or SLAM name that the robot does not have.
    #[error("robot `{robot}` has no localizer or SLAM system named `{name}` (it has: {known})")]
    UnknownLocalizer {
        /// The robot.
        robot: String,
        /// The name asked for.
        name: String,
        /// The robot's localizers and SLAM systems.
        known: String,
    },
    /// A door name that the map's places file does not define.
    #[error("no door named `{name}` (doors: {known})")]
    UnknownDoor {
        /// The name asked for.
        name: String,
        /// The map's doors.
        known: String,
    },
    /// A sensor fault for a sensor the robot does not carry.
    #[error("robot `{robot}` has no {sensor}")]
    NoSuchSensor {
        /// The robot.
        robot: String,
        /// The sensor (laser, encoder, sonar).
        sensor: String,
    },
    /// A car's command ([`Command::Steer`]) for a differential drive.
    #[error("robot `{robot}` has a differential drive; {what} drives a car (Ackermann)")]
    NotACar {
        /// The robot.
        robot: String,
        /// The command.
        what: &'static str,
    },
    /// Waypoints for a robot that follows navigation tasks.
    #[error("robot `{robot}` follows navigation tasks, not waypoints")]
    NotOnWaypoints {
        /// The robot.
        robot: String,
    },
    /// A goal or tasks for a robot without a task queue.
    #[error("robot `{robot}` has no task queue (a robot with `[[robots.tasks]]` takes tasks)")]
    NotNavigating {
        /// The robot.
        robot: String,
    },
    /// A place name that the map's places file does not define.
    #[error("no place named `{name}` (places: {known})")]
    UnknownPlace {
        /// The name asked for.
        name: String,
        /// The map's places.
        known: String,
    },
    /// A number out of its range: NaN or infinite, negative where it cannot be, an empty list.
    #[error("{what}: expected {expected}, got {got}")]
    BadValue {
        /// What the value is (names the robot).
        what: String,
        /// What was expected.
        expected: &'static str,
        /// What was given.
        got: String,
    },
    /// A pose or goal where the robot's footprint would overlap an obstacle.
    #[error("{what} ({x}, {y}) would place the robot inside an obstacle")]
    InsideObstacle {
        /// What the point is (names the robot).
        what: String,
        /// The point (m).
        x: f64,
        /// The point (m).
        y: f64,
    },
    /// A user controller panicked or returned a non-finite command; the simulation does not
    /// step any further, and can still be finished.
    #[error("the controller of robot `{robot}` {what} at tick {tick} (t = {time} s)")]
    ControllerFailed {
        /// The robot the controller drove.
        robot: String,
        /// The tick it failed at.
        tick: u64,
        /// Simulated time at the start of that tick (s).
        time: f64,
        /// What it did: the panic's message, or the command it returned.
        what: String,
    },
    /// A point outside the map's bounds.
    #[error("{what} ({x}, {y}) is outside the map ({bounds})")]
    OutsideMap {
        /// What the point is (names the robot).
        what: String,
        /// The point (m).
        x: f64,
        /// The point (m).
        y: f64,
        /// The map's bounds.
        bounds: String,
    },
}

impl Command {
    /// The scenario event action of the command, after checking its numbers (`robot` names it
    /// in errors).
    pub(super) fn action(
        self,
        robot: &str,
        kinematics: &Kinematics,
    ) -> Result<EventAction, SimError> {
        let finite = |what: String, v: &[f64]| {
            if v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(SimError::BadValue {
                    what,
                    expected: "finite numbers",
                    got: format!("{v:?}"),
                })
            }
        };
        match self {
            Command::Waypoints { points, looping } => {
                if points.is_empty() {
                    return Err(SimError::BadValue {
                        what: format!("waypoints of `{robot}`"),
                        expected: "at least one point",
                        got: "none".into(),
                    });
                }
                for (i, p) in points.iter().enumerate() {
                    finite(format!("waypoint {i} of `{robot}`"), p)?;
                }
                Ok(EventAction::Waypoints { points, looping })
            }
            Command::Teleport(p) => {
                finite(format!("teleport pose of `{robot}`"), &[p.x, p.y, p.theta])?;
                Ok(EventAction::Teleport(p))
            }
            Command::SensorFault { sensor, active } => {
                Ok(EventAction::SensorFault { sensor, active })
            }
            Command::Drive { v, w } => {
                finite(format!("drive command of `{robot}`"), &[v, w])?;
                Ok(EventAction::Drive(DriveCommand::new(v, w)))
            }
            Command::Steer { speed, steer } => {
                let Kinematics::Ackermann(car) = kinematics else {
                    return Err(SimError::NotACar {
                        robot: robot.to_string(),
                        what: "a speed/steer command",
                    });
                };
                finite(format!("speed/steer command of `{robot}`"), &[speed, steer])?;
                if steer.abs() > car.max_steer {
                    return Err(SimError::BadValue {
                        what: format!("steering angle of `{robot}`"),
                        expected: "an angle within the car's max_steer",
                        got: format!("{steer} rad (max_steer {} rad)", car.max_steer),
                    });
                }
                Ok(EventAction::Drive(car.command(speed, steer)))
            }
            Command::Release => Ok(EventAction::ReleaseDrive),
            Command::GoTo(Target::Point(p)) => {
                finite(format!("goal of `{robot}`"), &p)?;
                let name = format!("({:.2}, {:.2})", p[0], p[1]);
                let pose = Pose2::new(p[0], p[1], 0.0);
                Ok(EventAction::Tasks(vec![go_task(name, pose)]))
            }
            Command::GoTo(Target::Place(name)) => Err(SimError::UnknownPlace {
                name,
                known: String::new(), // the facade resolves places before this
            }),
            Command::Tasks(tasks) => {
                if tasks.is_empty() {
                    return Err(SimError::BadValue {
                        what: format!("tasks of `{robot}`"),
                        expected: "at least one task",
                        got: "none".into(),
                    });
                }
                for t in &tasks {
                    let what = format!("task `{}` of `{robot}`", t.name);
                    match &t.kind {
                        TaskKind::Delivery {
                            from,
                            to,
                            load,
                            unload,
                        } => {
                            finite(what.clone(), &[from.pose.x, from.pose.y, to.pose.x])?;
                            finite(what.clone(), &[to.pose.y, *load, *unload])?;
                            non_negative(&what, &[*load, *unload])?;
                        }
                        TaskKind::Go { to } => finite(what, &[to.pose.x, to.pose.y])?,
                        TaskKind::Wait { time } => {
                            finite(what.clone(), &[*time])?;
                            non_negative(&what, &[*time])?;
                        }
                    }
                }
                Ok(EventAction::Tasks(tasks))
            }
        }
    }
}

/// A `go` task to `pose`, named after the goal.
pub(super) fn go_task(name: String, pose: Pose2) -> Task {
    Task {
        name: format!("go_{name}"),
        kind: TaskKind::Go {
            to: Goal { name, pose },
        },
    }
}

fn non_negative(what: &str, v: &[f64]) -> Result<(), SimError> {
    if v.iter().all(|x| *x >= 0.0) {
        return Ok(());
    }
    Err(SimError::BadValue {
        what: what.to_string(),
        expected: "times of 0 s or more",
        got: format!("{v:?}"),
    })
}

/// `a, b, c`, or `none`: the known names an error lists.
pub(super) fn names<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let v: Vec<&str> = names.collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}
