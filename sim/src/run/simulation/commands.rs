//! Commands between ticks: each becomes a scenario event due now, checked against the
//! scenario first (robots, places, doors, the map), so it takes effect at the next tick in the
//! Script set exactly as the same event in the file would.

use super::Simulation;
use crate::build::script::EventQueue;
use crate::run::command::{Command, SimError, Target, go_task, names};
use crate::scenario::{Event, EventAction};
use bevy_ecs::prelude::*;
use systems::navigation::Navigator;

impl Simulation {
    /// Tells robot `robot` what to do; it takes effect at the next tick, as the same event in
    /// the scenario file would.
    pub fn command(&mut self, robot: &str, command: Command) -> Result<(), SimError> {
        let index = self.robot_index(robot)?;
        let config = &self.scenario.robots[index];
        let command = match command {
            Command::GoTo(Target::Place(name)) => {
                let Some(pose) = self.scenario.places.get(&name) else {
                    return Err(SimError::UnknownPlace {
                        known: names(self.scenario.places.keys().map(String::as_str)),
                        name,
                    });
                };
                Command::Tasks(vec![go_task(name, *pose)])
            }
            c => c,
        };
        match &command {
            Command::GoTo(_) | Command::Tasks(_)
                if self
                    .sim
                    .world
                    .get::<Navigator>(self.sim.robots[index])
                    .is_none() =>
            {
                return Err(SimError::NotNavigating {
                    robot: robot.to_string(),
                });
            }
            Command::Waypoints { .. } if config.navigation.is_some() => {
                return Err(SimError::NotOnWaypoints {
                    robot: robot.to_string(),
                });
            }
            Command::SensorFault { sensor, .. } => {
                let has = match sensor {
                    crate::scenario::SensorName::Laser => config.laser.is_some(),
                    crate::scenario::SensorName::Encoder => config.encoder.is_some(),
                    crate::scenario::SensorName::Sonar => config.sonar.is_some(),
                };
                if !has {
                    return Err(SimError::NoSuchSensor {
                        robot: robot.to_string(),
                        sensor: format!("{sensor:?}").to_lowercase(),
                    });
                }
            }
            _ => {}
        }
        let action = command.action(robot, &config.kinematics)?;
        match &action {
            EventAction::Teleport(p) => {
                let what = format!("teleport pose of `{robot}`");
                self.check_inside(&what, p.x, p.y)?;
                let radius = config.footprint.bounding_radius();
                if !self.scenario.grid.disc_is_clear(p.x, p.y, radius) {
                    return Err(SimError::InsideObstacle {
                        what,
                        x: p.x,
                        y: p.y,
                    });
                }
            }
            EventAction::Waypoints { points, .. } => {
                for (i, p) in points.iter().enumerate() {
                    self.check_inside(&format!("waypoint {i} of `{robot}`"), p[0], p[1])?;
                }
            }
            EventAction::Tasks(tasks) => {
                let radius = config.footprint.bounding_radius();
                for t in tasks {
                    for g in t.goals() {
                        let what = format!("goal `{}` of task `{}` of `{robot}`", g.name, t.name);
                        self.check_inside(&what, g.pose.x, g.pose.y)?;
                        if !self.scenario.grid.disc_is_clear(g.pose.x, g.pose.y, radius) {
                            return Err(SimError::InsideObstacle {
                                what,
                                x: g.pose.x,
                                y: g.pose.y,
                            });
                        }
                    }
                }
            }
            _ => {}
        }
        let entity = self.sim.robots[index];
        self.push(Some(robot.to_string()), Some(entity), action);
        Ok(())
    }

    /// Opens or closes the door called `door` at the next tick, as the same event in the
    /// scenario file would.
    pub fn set_door(&mut self, door: &str, open: bool) -> Result<(), SimError> {
        let doors = &self.scenario.doors;
        let index =
            doors
                .iter()
                .position(|d| d.name == door)
                .ok_or_else(|| SimError::UnknownDoor {
                    name: door.to_string(),
                    known: names(doors.iter().map(|d| d.name.as_str())),
                })?;
        self.push(None, None, EventAction::Door { index, open });
        Ok(())
    }

    fn push(&mut self, robot: Option<String>, entity: Option<Entity>, action: EventAction) {
        let event = Event {
            at: self.time(),
            robot,
            action,
        };
        self.sim
            .world
            .resource_mut::<EventQueue>()
            .push_now(event, entity);
    }

    fn check_inside(&self, what: &str, x: f64, y: f64) -> Result<(), SimError> {
        let [x0, y0, x1, y1] = self.scenario.grid.bounds();
        if (x0..=x1).contains(&x) && (y0..=y1).contains(&y) {
            return Ok(());
        }
        Err(SimError::OutsideMap {
            what: what.to_string(),
            x,
            y,
            bounds: format!("x {x0} to {x1}, y {y0} to {y1}"),
        })
    }
}
