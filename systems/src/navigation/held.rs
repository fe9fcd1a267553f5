//! A velocity command held on a robot by a script or a program ([`HeldCommand`]): while it is
//! held it replaces what the robot's behaviour or navigator commands; once released they drive
//! again. Their own state goes on meanwhile (a waypoint follower resumes towards the waypoint it
//! was heading for).

use crate::body::DriveCommand;
use bevy_ecs::prelude::*;

/// The command held on a robot (None: none, its behaviour or navigator drives).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct HeldCommand(pub Option<DriveCommand>);

/// Control set, after every driver: a held command replaces the tick's command.
pub fn apply_held_commands(mut robots: Query<(&HeldCommand, &mut DriveCommand)>) {
    for (held, mut command) in &mut robots {
        if let Some(c) = held.0 {
            *command = c;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_command_replaces_the_drivers_and_release_hands_back() {
        let mut world = World::new();
        let driven = DriveCommand::new(0.5, 0.1);
        let held = DriveCommand::new(-0.2, 1.0);
        let a = world.spawn((HeldCommand(Some(held)), driven)).id();
        let b = world.spawn((HeldCommand(None), driven)).id();
        let mut schedule = Schedule::default();
        schedule.add_systems(apply_held_commands);
        schedule.run(&mut world);
        assert_eq!(*world.get::<DriveCommand>(a).unwrap(), held);
        assert_eq!(*world.get::<DriveCommand>(b).unwrap(), driven);
    }
}
