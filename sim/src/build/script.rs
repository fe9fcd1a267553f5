//! Script set: timed scenario events fire at the first tick starting at or after their time:
//! new waypoints, teleporting (kidnapping) a robot, sensor faults on and off, held velocity
//! commands and their release, new navigation tasks, doors opening and closing. A door edits the static world (ray map, colliders, navigation costmaps follow its
//! version) and the map the localizers believe in: the building tells its robots.

use crate::scenario::{Event, EventAction, RobotConfig, SensorName};
use bevy_ecs::prelude::*;
use systems::body::{Physics, PhysicsBody, TruePose};
use systems::core::{SimClock, SimPlugin, SimSet};
use systems::localization::LocalizationMap;
use systems::navigation::{Behaviour, HeldCommand, Navigator};
use systems::raycast::{Doors, StaticWorld};
use systems::sensors::{Encoder, Laser, Sonars};

#[derive(Resource)]
pub struct EventQueue {
    /// Each event with its robot's entity (None for world events).
    events: Vec<(Event, Option<Entity>)>,
    next: usize,
    /// Events fired so far (time, robot, description), for logs and summaries.
    pub fired: Vec<(f64, String, String)>,
}

impl EventQueue {
    pub fn new(events: Vec<Event>, robots: &[RobotConfig], entities: &[Entity]) -> Self {
        let events = events
            .into_iter()
            .filter_map(|e| match &e.robot {
                None => Some((e, None)),
                Some(name) => {
                    let i = robots.iter().position(|r| &r.name == name)?;
                    Some((e, Some(entities[i])))
                }
            })
            .collect();
        EventQueue {
            events,
            next: 0,
            fired: Vec::new(),
        }
    }

    /// Adds an event due at `now` (of the robot `entity`, or of the world): it fires at the
    /// next tick, after the scenario's own events due then.
    pub fn push_now(&mut self, event: Event, entity: Option<Entity>) {
        let due = self.events[self.next..]
            .iter()
            .take_while(|(e, _)| e.at <= event.at + 1e-9)
            .count();
        self.events.insert(self.next + due, (event, entity));
    }
}

/// The scenario's script: [`fire_events`] in the Script set (the world holds the [`EventQueue`]).
pub struct ScriptPlugin;

impl SimPlugin for ScriptPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(fire_events.in_set(SimSet::Script));
    }
}

#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub fn fire_events(
    clock: Res<SimClock>,
    mut queue: ResMut<EventQueue>,
    mut physics: ResMut<Physics>,
    mut world: ResMut<StaticWorld>,
    mut doors: ResMut<Doors>,
    mut belief_map: Option<ResMut<LocalizationMap>>,
    mut robots: Query<(
        Option<&mut Behaviour>,
        &PhysicsBody,
        &mut TruePose,
        Option<&mut Laser>,
        Option<&mut Encoder>,
        Option<&mut Sonars>,
        Option<&mut HeldCommand>,
        Option<&mut Navigator>,
    )>,
) {
    let now = clock.start();
    while queue.next < queue.events.len() && queue.events[queue.next].0.at <= now + 1e-9 {
        let (event, entity) = queue.events[queue.next].clone();
        queue.next += 1;
        if let EventAction::Door { index, open } = event.action {
            let edits = doors.set(index, open, &mut world);
            if let Some(m) = belief_map.as_mut() {
                m.set_cells(&edits);
            }
            let name = doors.doors.get(index).map_or("?", |d| d.name.as_str());
            let what = format!("door {name} {}", if open { "opened" } else { "closed" });
            queue.fired.push((now, String::new(), what));
            continue;
        }
        let Some(Ok((behaviour, body, mut truth, laser, encoder, sonars, held, navigator))) =
            entity.map(|e| robots.get_mut(e))
        else {
            continue;
        };
        let what = match &event.action {
            EventAction::Waypoints { points, looping } => {
                let Some(mut behaviour) = behaviour else {
                    continue; // a robot with tasks ignores routes (resolve rejects this)
                };
                behaviour.set_waypoints(points.clone(), *looping);
                format!("new route of {} waypoints", points.len())
            }
            EventAction::Teleport(pose) => {
                physics.teleport(*body, pose);
                *truth = TruePose::at(*pose);
                format!(
                    "teleported to ({:.2}, {:.2}, {:.2})",
                    pose.x, pose.y, pose.theta
                )
            }
            EventAction::SensorFault { sensor, active } => {
                match sensor {
                    SensorName::Laser => {
                        if let Some(mut l) = laser {
                            l.enabled = !active;
                        }
                    }
                    SensorName::Encoder => {
                        if let Some(mut e) = encoder {
                            e.enabled = !active;
                        }
                    }
                    SensorName::Sonar => {
                        if let Some(mut s) = sonars {
                            s.enabled = !active;
                        }
                    }
                }
                format!(
                    "{} fault {}",
                    format!("{sensor:?}").to_lowercase(),
                    if *active { "on" } else { "off" }
                )
            }
            EventAction::Drive(cmd) => {
                let Some(mut held) = held else { continue };
                held.0 = Some(*cmd);
                match cmd.steer {
                    Some(steer) => format!(
                        "drive command held: speed {:.2} m/s, steer {steer:.3} rad",
                        cmd.v
                    ),
                    None => format!(
                        "drive command held: v {:.2} m/s, w {:.2} rad/s",
                        cmd.v, cmd.w
                    ),
                }
            }
            EventAction::ReleaseDrive => {
                let Some(mut held) = held else { continue };
                held.0 = None;
                "drive command released".to_string()
            }
            EventAction::Tasks(tasks) => {
                let Some(mut navigator) = navigator else {
                    continue; // resolve and the facade reject this
                };
                navigator.tasks.extend(tasks.iter().cloned());
                let names: Vec<&str> = tasks.iter().map(|t| t.name.as_str()).collect();
                format!("new tasks: {}", names.join(", "))
            }
            EventAction::Door { .. } => continue, // handled above
        };
        queue
            .fired
            .push((now, event.robot.clone().unwrap_or_default(), what));
    }
}
