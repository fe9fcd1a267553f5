//! Script set: timed scenario events fire at the first tick starting at or after their time:
//! new waypoints, teleporting (kidnapping) a robot, sensor faults on and off.

use crate::scenario::{Event, EventAction, RobotConfig, SensorName};
use bevy_ecs::prelude::*;
use systems::body::{Physics, PhysicsBody, TruePose};
use systems::core::SimClock;
use systems::navigation::Behaviour;
use systems::sensors::{Encoder, Laser, Sonars};

#[derive(Resource)]
pub struct EventQueue {
    events: Vec<(Event, Entity)>,
    next: usize,
    /// Events fired so far (time, robot, description), for logs and summaries.
    pub fired: Vec<(f64, String, String)>,
}

impl EventQueue {
    pub fn new(events: Vec<Event>, robots: &[RobotConfig], entities: &[Entity]) -> Self {
        let events = events
            .into_iter()
            .filter_map(|e| {
                let i = robots.iter().position(|r| r.name == e.robot)?;
                Some((e, entities[i]))
            })
            .collect();
        EventQueue {
            events,
            next: 0,
            fired: Vec::new(),
        }
    }
}

#[allow(clippy::type_complexity)]
pub fn fire_events(
    clock: Res<SimClock>,
    mut queue: ResMut<EventQueue>,
    mut physics: ResMut<Physics>,
    mut robots: Query<(
        &mut Behaviour,
        &PhysicsBody,
        &mut TruePose,
        Option<&mut Laser>,
        Option<&mut Encoder>,
        Option<&mut Sonars>,
    )>,
) {
    let now = clock.start();
    while queue.next < queue.events.len() && queue.events[queue.next].0.at <= now + 1e-9 {
        let (event, entity) = queue.events[queue.next].clone();
        queue.next += 1;
        let Ok((mut behaviour, body, mut truth, laser, encoder, sonars)) = robots.get_mut(entity)
        else {
            continue;
        };
        let what = match &event.action {
            EventAction::Waypoints { points, looping } => {
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
        };
        queue.fired.push((now, event.robot.clone(), what));
    }
}
