//! A robot spawned from [`RobotBundle`] into a world made here, with no scenario: the drivers
//! and the physics move it.

use super::*;
use crate::body::kinematics::DiffDrive;
use crate::body::{Physics, PhysicsPlugin};
use crate::core::{KernelPool, SimClock, SimPlugin, SimSet, new_schedule, stream_rng};
use crate::navigation::BehaviourKind;
use crate::navigation::held::apply_held_commands;
use crate::raycast::StaticWorld;
use crate::world::{Cell, OccupancyGrid};

#[test]
fn a_robot_from_the_bundle_drives_where_it_is_told() {
    let dt = 0.05;
    let mut world = World::new();
    world.insert_resource(SimClock::new(dt));
    world.insert_resource(KernelPool::new(1).unwrap());
    let mut ground = StaticWorld::new(OccupancyGrid::new(100, 100, 0.1, [0.0, 0.0], Cell::Free));
    let mut physics = Physics::new(&mut ground, dt);
    let start = Pose2::new(2.0, 5.0, 0.0);
    let footprint = Footprint::Circle { radius: 0.2 };
    let body = physics.add_robot(0, &start, &footprint);
    world.insert_resource(ground);
    world.insert_resource(physics);
    let drive = Kinematics::DiffDrive(DiffDrive {
        wheel_base: 0.4,
        wheel_radius: 0.1,
        max_wheel_speed: 10.0,
        max_wheel_accel: 20.0,
    });
    let idle = Behaviour::new(
        BehaviourKind::Idle,
        0.5,
        0.2,
        stream_rng(1, "r1", "behaviour"),
    );
    let robot = world
        .spawn(RobotBundle::new(
            "r1", 0, start, footprint, drive, body, idle,
        ))
        .id();
    world.get_mut::<HeldCommand>(robot).unwrap().0 = Some(DriveCommand::new(0.5, 0.0));
    let mut schedule = new_schedule();
    schedule.add_systems(apply_held_commands.in_set(SimSet::Control));
    PhysicsPlugin.build(&mut world, &mut schedule);
    for _ in 0..40 {
        schedule.run(&mut world);
        world.resource_mut::<SimClock>().advance();
    }
    // 2 s at up to 0.5 m/s, after accelerating: well over a metre east, still on its line
    let pose = world.get::<TruePose>(robot).unwrap().pose;
    assert!(pose.x > 2.8 && pose.x < 3.05, "{pose:?}");
    assert!((pose.y - 5.0).abs() < 1e-3, "{pose:?}");
    assert!(world.get::<TrueTwist>(robot).unwrap().v > 0.4);
}
