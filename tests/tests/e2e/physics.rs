//! Kinematics through the whole physics step, collisions counted as contact starts, no tunnelling.

use crate::common::*;
use bevy_ecs_helpers::*;
use systems::body::kinematics::integrate_arc;
use systems::body::{DriveCommand, DriveState, Kinematics, TruePose};
use systems::core::Pose2;
use systems::eval::RobotMetrics;
use systems::navigation::Behaviour;

mod bevy_ecs_helpers {
    use sim::build::SimWorld;
    use systems::body::DriveCommand;

    /// Drives robot `i` with a fixed command for `ticks` ticks (its behaviour removed).
    pub fn drive(sim: &mut SimWorld, i: usize, cmd: DriveCommand, ticks: usize) {
        let e = sim.robots[i];
        for _ in 0..ticks {
            if let Some(mut c) = sim.world.get_mut::<DriveCommand>(e) {
                *c = cmd;
            }
            sim.step();
        }
    }
}

fn free_space(robot: &str) -> String {
    format!(
        "duration = 100.0\ndt = 0.02\nwalls = [{{ from = [-50.0, -50.0], to = [-49.0, -50.0] }}, {{ from = [50.0, 50.0], to = [49.0, 50.0] }}]\n{robot}"
    )
}

#[test]
fn physics_follows_closed_form_arcs() {
    let mut sim = world(&free_space(
        "[[robots]]\nname = \"r\"\nstart = [0.0, 0.0, 0.3]\nkinematics = { type = \"diff_drive\", wheel_base = 0.5, wheel_radius = 0.1, max_wheel_speed = 50.0, max_wheel_accel = 1e6 }\n",
    ));
    let e = sim.robots[0];
    sim.world.entity_mut(e).remove::<Behaviour>();
    let cmd = DriveCommand::new(1.0, 0.5);
    let Kinematics::DiffDrive(d) = sim.world.get::<Kinematics>(e).unwrap().clone() else {
        unreachable!()
    };
    let (l, r) = d.wheel_targets(&cmd);
    *sim.world.get_mut::<DriveState>(e).unwrap() = DriveState {
        left: l,
        right: r,
        ..Default::default()
    };
    // a full circle of radius 2 m takes 4π s = 628.3 ticks; check after a quarter and a full turn
    let dt = 0.02;
    for &ticks in &[157usize, 471] {
        drive(&mut sim, 0, cmd, ticks);
    }
    let t = 628.0 * dt;
    let expected = integrate_arc(&Pose2::new(0.0, 0.0, 0.3), 1.0, 0.5, t);
    let got = sim.world.get::<TruePose>(e).unwrap().pose;
    let err = got.distance(&expected);
    assert!(
        err < 2e-3,
        "pose {got:?} vs closed form {expected:?}: {err} m"
    );
    assert!(systems::core::wrap_angle(got.theta - expected.theta).abs() < 1e-3);
    // and it stayed on the circle of radius 2 around its centre
    let centre = Pose2::new(0.0, 0.0, 0.3).transform_point([0.0, 2.0]);
    let radius = (got.x - centre[0]).hypot(got.y - centre[1]);
    assert!((radius - 2.0).abs() < 2e-3, "radius {radius}");
}

#[test]
fn ackermann_drives_an_arc_of_its_steering_angle() {
    let mut sim = world(&free_space(
        "[[robots]]\nname = \"car\"\nstart = [0.0, 0.0, 0.0]\nkinematics = { type = \"ackermann\", wheelbase = 0.35, max_steer = 0.5, max_steer_rate = 100.0, max_speed = 2.0, max_accel = 1e6 }\n",
    ));
    let e = sim.robots[0];
    sim.world.entity_mut(e).remove::<Behaviour>();
    // steering saturates at 0.5 rad: radius L / tan(0.5)
    drive(&mut sim, 0, DriveCommand::new(1.0, 10.0), 1);
    let p0 = sim.world.get::<TruePose>(e).unwrap().pose;
    drive(&mut sim, 0, DriveCommand::new(1.0, 10.0), 100);
    let p1 = sim.world.get::<TruePose>(e).unwrap().pose;
    let w = 1.0 * 0.5f64.tan() / 0.35;
    let expected = integrate_arc(&p0, 1.0, w, 100.0 * 0.02);
    assert!(p1.distance(&expected) < 2e-3, "{p1:?} vs {expected:?}");
    // it cannot turn on the spot
    drive(&mut sim, 0, DriveCommand::new(0.0, 1.0), 200);
    let p2 = sim.world.get::<TruePose>(e).unwrap().pose;
    drive(&mut sim, 0, DriveCommand::new(0.0, 1.0), 50);
    let p3 = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!(p2.distance(&p3) < 1e-6 && (p2.theta - p3.theta).abs() < 1e-6);
}

/// A robot driving into a wall and pushing against it for seconds counts ONE collision.
#[test]
fn pushing_into_a_wall_counts_one_contact_start() {
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r\"\nstart = [5.0, 5.0, 0.0]\nbehaviour = {{ type = \"waypoints\", points = [[12.0, 5.0]], speed = 1.0 }}\n[robots.sensors.encoder]\n"
    )
    .replace("duration = 1.0", "duration = 10.0");
    let mut sim = world(&text);
    for _ in 0..200 {
        sim.step();
    }
    let e = sim.robots[0];
    let m = sim.world.get::<RobotMetrics>(e).unwrap().clone();
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    assert_eq!(m.collisions.wall, 1, "{m:?}");
    assert_eq!(m.collisions.robot, 0);
    // it stopped at the wall (inner face x = 9.9, radius 0.25)
    assert!(p.x < 9.9 - 0.25 + 0.02 && p.x > 9.5, "{p:?}");
}

#[test]
fn robots_meeting_head_on_collide_once() {
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"a\"\nstart = [2.0, 5.0, 0.0]\nbehaviour = {{ type = \"waypoints\", points = [[8.0, 5.0]], speed = 0.8 }}\n[robots.sensors.encoder]\n[[robots]]\nname = \"b\"\nstart = [8.0, 5.0, 3.14159265]\nbehaviour = {{ type = \"waypoints\", points = [[2.0, 5.0]], speed = 0.8 }}\n[robots.sensors.encoder]\n"
    )
    .replace("duration = 1.0", "duration = 10.0");
    let mut sim = world(&text);
    for _ in 0..160 {
        sim.step();
    }
    for &e in &sim.robots {
        let m = sim.world.get::<RobotMetrics>(e).unwrap().clone();
        assert_eq!(m.collisions.robot, 1, "{m:?}");
        assert_eq!(m.collisions.wall, 0, "{m:?}");
    }
}

#[test]
fn no_tunnelling_through_a_thin_wall_at_top_speed() {
    // 10 cm wall; the robot does 4 m/s with dt = 0.1 s: 40 cm per step, four wall thicknesses
    let text = "duration = 5.0\ndt = 0.1\nwalls = [{ from = [5.0, -3.0], to = [5.0, 3.0], thickness = 0.1 }, { from = [-1.0, -3.0], to = [-1.0, 3.0], thickness = 0.1 }, { from = [10.0, -3.0], to = [10.0, 3.0], thickness = 0.1 }]\n[[robots]]\nname = \"fast\"\nstart = [0.0, 0.0, 0.0]\nfootprint = { circle = 0.2 }\nkinematics = { type = \"diff_drive\", wheel_radius = 0.1, max_wheel_speed = 40.0, max_wheel_accel = 1e4 }\nbehaviour = { type = \"waypoints\", points = [[9.0, 0.0]], speed = 4.0 }\n[robots.sensors.encoder]\n";
    let mut sim = world(text);
    for _ in 0..50 {
        sim.step();
    }
    let e = sim.robots[0];
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!(p.x < 4.95 - 0.2 + 0.02, "tunnelled: {p:?}");
    assert!(p.x > 4.0, "{p:?}");
    let m = sim.world.get::<RobotMetrics>(e).unwrap();
    assert_eq!(m.collisions.wall, 1);
}

#[test]
fn a_door_edit_changes_physics_and_lasers() {
    use systems::raycast::StaticWorld;
    use systems::world::Cell;
    // a wall across the room at x = 5 with a 1.2 m door gap around y = 5
    let text = format!(
        "{}\n[[robots]]\nname = \"r\"\nstart = [2.0, 5.0, 0.0]\nbehaviour = {{ type = \"waypoints\", points = [[8.0, 5.0]], speed = 1.0 }}\n[robots.sensors.encoder]\n[robots.sensors.laser]\nnoise_std = 0.0\nmin_range = 0.05\n",
        SQUARE_ROOM.replace(
            "walls = [",
            "walls = [\n  { from = [5.0, 0.0], to = [5.0, 4.4], thickness = 0.1 },\n  { from = [5.0, 5.6], to = [5.0, 10.0], thickness = 0.1 },"
        )
    )
    .replace("duration = 1.0", "duration = 20.0");
    let mut sim = world(&text);
    // close the door before anything moves
    sim.world
        .resource_mut::<StaticWorld>()
        .set_region(4.95, 4.4, 5.05, 5.6, Cell::Occupied);
    for _ in 0..200 {
        sim.step();
    }
    let e = sim.robots[0];
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!(p.x < 5.0, "the closed door stops it: {p:?}");
    // open it again: the robot gets through
    sim.world
        .resource_mut::<StaticWorld>()
        .set_region(4.95, 4.4, 5.05, 5.6, Cell::Free);
    for _ in 0..300 {
        sim.step();
    }
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    assert!(p.x > 7.0, "through the open door: {p:?}");
}
