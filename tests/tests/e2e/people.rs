//! Walking people: they walk their routes at their speed through the physics step, stop rather
//! than walk into a robot standing in their way (and resume when it leaves), pass each other
//! keeping right, and a robot driving into one counts a person collision.

use crate::common::*;
use sim::build::SimWorld;
use sim::{RunOptions, run_scenario};
use systems::body::people::ARRIVE_TOL;
use systems::body::{Person, TruePose, Walker};
use systems::eval::RobotMetrics;

fn pos(sim: &SimWorld, e: bevy_ecs::entity::Entity) -> [f64; 2] {
    let p = sim.world.get::<TruePose>(e).unwrap().pose;
    [p.x, p.y]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[test]
fn a_person_walks_its_route_at_its_speed() {
    let text = format!(
        "{SQUARE_ROOM}\n[[people]]\nname = \"alice\"\nroute = [[2.0, 2.0], [8.0, 2.0], [8.0, 8.0]]\nspeed = 1.0\nloop = false\nstart_at = 1.0\n"
    );
    let mut sim = world(&text);
    let e = sim.people[0];
    let route = sim.world.get::<Person>(e).unwrap().route.clone();
    // (time, position) of each point reached
    let mut reached = Vec::new();
    for _ in 0..400 {
        sim.step();
        let n = sim.world.get::<Walker>(e).unwrap().reached as usize;
        if n > reached.len() {
            reached.push((sim.time(), pos(&sim, e)));
        }
    }
    assert_eq!(reached.len(), 2, "{reached:?}");
    // 6 m legs at 1.0 m/s (±5 % per leg), starting at t = 1 s
    let (t1, p1) = reached[0];
    let (t2, p2) = reached[1];
    assert!(dist(p1, route[1]) <= ARRIVE_TOL + 0.01, "{p1:?}");
    assert!(dist(p2, route[2]) <= ARRIVE_TOL + 0.01, "{p2:?}");
    assert!((5.5..=7.6).contains(&t1), "first point at {t1} s");
    assert!(
        (5.5..=6.6).contains(&(t2 - t1)),
        "second leg took {} s",
        t2 - t1
    );
    // a route that does not loop ends there
    let end = pos(&sim, e);
    assert!(dist(end, route[2]) <= ARRIVE_TOL + 0.01, "{end:?}");
    assert!(sim.world.get::<Walker>(e).unwrap().finished);
}

/// A 0.9 m wide corridor along y = 5 (no room to step aside) with an idle robot in it at x = 6;
/// the robot is teleported away at t = 10 s.
fn corridor_with_robot(person_extra: &str) -> String {
    format!(
        "{}\n[[robots]]\nname = \"r\"\nstart = [6.0, 5.0, 0.0]\n[[events]]\nat = 10.0\ntype = \"teleport\"\nrobot = \"r\"\npose = [2.0, 8.0, 0.0]\n[[people]]\nname = \"bob\"\nroute = [[1.0, 5.0], [9.0, 5.0]]\nloop = false\n{person_extra}",
        SQUARE_ROOM
            .replace("duration = 1.0", "duration = 20.0")
            .replace(
                "walls = [",
                "walls = [\n  { from = [0.0, 4.5], to = [10.0, 4.5], thickness = 0.1 },\n  { from = [0.0, 5.5], to = [10.0, 5.5], thickness = 0.1 },"
            )
    )
}

#[test]
fn a_person_stops_before_a_robot_in_its_way_and_resumes() {
    let mut sim = world(&corridor_with_robot(""));
    let (person, robot) = (sim.people[0], sim.robots[0]);
    let mut min_gap = f64::INFINITY;
    for _ in 0..190 {
        sim.step();
        let gap = dist(pos(&sim, person), pos(&sim, robot)) - 0.25 - 0.25;
        min_gap = min_gap.min(gap);
    }
    // standing still, a polite distance before the robot (it stops at a 0.6 m gap)
    let before = pos(&sim, person);
    for _ in 0..10 {
        sim.step();
    }
    let at_10s = pos(&sim, person);
    assert!(dist(before, at_10s) < 1e-3, "{before:?} → {at_10s:?}");
    assert!(min_gap > 0.5, "came within {min_gap} m of the robot");
    assert!((4.6..=5.0).contains(&at_10s[0]), "{at_10s:?}");
    let m = sim.world.get::<RobotMetrics>(robot).unwrap();
    assert_eq!(m.collisions.person, 0, "{m:?}");
    // the robot leaves at t = 10 s: the person walks on to its last point (4 m at ~1.2 m/s)
    for _ in 0..120 {
        sim.step();
    }
    let end = pos(&sim, person);
    assert!(dist(end, [9.0, 5.0]) <= ARRIVE_TOL + 0.01, "{end:?}");
}

#[test]
fn people_meeting_head_on_keep_right_and_pass() {
    let text = format!(
        "{SQUARE_ROOM}\n[[people]]\nname = \"a\"\nroute = [[1.0, 5.0], [9.0, 5.0]]\nloop = false\n[[people]]\nname = \"b\"\nroute = [[9.0, 5.0], [1.0, 5.0]]\nloop = false\n"
    );
    let mut sim = world(&text);
    let (a, b) = (sim.people[0], sim.people[1]);
    let mut min_d = f64::INFINITY;
    for _ in 0..300 {
        sim.step();
        min_d = min_d.min(dist(pos(&sim, a), pos(&sim, b)));
    }
    assert!(min_d > 0.5 + 0.1, "they came within {min_d} m (centres)");
    assert!(dist(pos(&sim, a), [9.0, 5.0]) <= ARRIVE_TOL + 0.01);
    assert!(dist(pos(&sim, b), [1.0, 5.0]) <= ARRIVE_TOL + 0.01);
}

/// A blind robot (no laser) driving through a standing person: one person collision, counted in
/// the total and shown in the summary; neither walls nor robots.
#[test]
fn a_robot_driving_into_a_person_counts_a_person_collision() {
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r\"\nstart = [2.0, 5.0, 0.0]\nbehaviour = {{ type = \"waypoints\", points = [[7.0, 5.0]], speed = 0.8 }}\n[robots.sensors.encoder]\n[[people]]\nname = \"carol\"\nroute = [[4.5, 5.0], [4.5, 8.0]]\nstart_at = 100.0\n"
    )
    .replace("duration = 1.0", "duration = 10.0");
    let out = run_scenario(
        &scenario(&text),
        &RunOptions {
            threads: 1,
            ..Default::default()
        },
    )
    .unwrap();
    let r = &out.summary.robots[0];
    assert_eq!(r.person_collisions, 1, "{r:?}");
    assert_eq!((r.wall_collisions, r.robot_collisions), (0, 0), "{r:?}");
    assert_eq!(r.collisions, 1, "{r:?}");
    let table = out.summary.table();
    assert!(table.contains("people"), "{table}");
    let json = serde_json::to_value(&out.summary).unwrap();
    assert_eq!(json["robots"][0]["person_collisions"], 1);
}
