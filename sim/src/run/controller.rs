//! User controllers: a program's own driving code for a robot, in place of its behaviour or
//! navigator. Each tick, in the Control set after the built-in drivers and before held commands
//! (which still override it, as they do a behaviour), the controller sees the robot through the
//! same [`RobotView`] a program reads between ticks and returns a velocity command.
//!
//! A controller that panics or returns a NaN or infinite command stops its robot; the
//! simulation then refuses to step ([`SimError::ControllerFailed`], naming the robot and the
//! tick) and the run can still be finished, so its recordings are complete up to that tick.

use super::command::SimError;
use super::view::{RobotView, Twist};
use bevy_ecs::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};
use systems::body::DriveCommand;
use systems::core::SimClock;

/// What a controller sees at a tick.
pub struct Observation<'w> {
    /// Simulated time at the start of the tick (s).
    pub time: f64,
    /// The tick's length (s).
    pub dt: f64,
    /// The tick's number (0 for the first).
    pub tick: u64,
    /// The robot: its sensors' latest readings, odometry, localizers' estimates, and (for
    /// evaluation, not for fair control) its true pose.
    pub robot: RobotView<'w>,
}

/// A robot's driver written by the user: one velocity command (forward m/s, yaw rate rad/s;
/// an Ackermann robot steers to that yaw rate) per tick. The robot's kinematic limits apply
/// to it as to every command. A closure `FnMut(&Observation) -> Twist` is a controller.
pub trait Controller: Send + Sync + 'static {
    /// The command for this tick, from what the robot senses (`observation`).
    fn control(&mut self, observation: &Observation) -> Twist;
}

impl<F> Controller for F
where
    F: FnMut(&Observation) -> Twist + Send + Sync + 'static,
{
    fn control(&mut self, observation: &Observation) -> Twist {
        self(observation)
    }
}

/// One robot's controller.
pub(crate) struct Controlled {
    pub entity: Entity,
    pub index: usize,
    pub name: String,
    pub controller: Box<dyn Controller>,
}

/// Every user controller of the run, in the scenario's robot order, and the first failure.
#[derive(Resource, Default)]
pub(crate) struct UserControllers {
    pub items: Vec<Controlled>,
    pub failure: Option<SimError>,
}

/// Control set: every user controller commands its robot (an exclusive system, since a
/// controller may read any part of its robot).
pub(crate) fn run_user_controllers(world: &mut World) {
    let Some(mut ctrls) = world.remove_resource::<UserControllers>() else {
        return;
    };
    let clock = world.resource::<SimClock>();
    let (time, dt, tick) = (clock.start(), clock.dt, clock.tick);
    let mut commands = Vec::with_capacity(ctrls.items.len());
    if ctrls.failure.is_none() {
        for c in &mut ctrls.items {
            let observation = Observation {
                time,
                dt,
                tick,
                robot: RobotView {
                    world,
                    entity: c.entity,
                    name: &c.name,
                    index: c.index,
                },
            };
            let out = catch_unwind(AssertUnwindSafe(|| c.controller.control(&observation)));
            let failed = match out {
                Ok(t) if t.v.is_finite() && t.w.is_finite() => {
                    commands.push((c.entity, DriveCommand::new(t.v, t.w)));
                    continue;
                }
                Ok(t) => format!(
                    "returned a command that is not finite (v {}, w {})",
                    t.v, t.w
                ),
                Err(panic) => format!("panicked: {}", panic_text(panic.as_ref())),
            };
            ctrls.failure = Some(SimError::ControllerFailed {
                robot: c.name.clone(),
                tick,
                time,
                what: failed,
            });
            break;
        }
    }
    if ctrls.failure.is_some() {
        // every controlled robot stops
        commands = ctrls
            .items
            .iter()
            .map(|c| (c.entity, DriveCommand::default()))
            .collect();
    }
    for (e, cmd) in commands {
        if let Some(mut d) = world.get_mut::<DriveCommand>(e) {
            *d = cmd;
        }
    }
    world.insert_resource(ctrls);
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".to_string()
    }
}

#[cfg(test)]
mod tests;
