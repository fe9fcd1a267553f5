//! A car-like (Ackermann) robot driving its tasks through the whole stack:
//! planner, pure pursuit limited to the car's turning circle, physics. It never turns on the
//! spot, never steers tighter than its turning radius and reaches both goals, the second of
//! which lies behind it.

use crate::common::*;
use systems::body::{TruePose, TrueTwist};
use systems::eval::RobotMetrics;
use systems::navigation::Navigator;

const WHEELBASE: f64 = 0.5;
const MAX_STEER: f64 = 0.5;

/// A 24 × 14 m yard with a 6 × 6 m block in the middle; the car starts in the south-west corner
/// heading east, drives to the north-east corner and then back west along the north side.
fn yard() -> String {
    format!(
        r#"
duration = 150.0
end_when_done = true
[map]
resolution = 0.1
[[walls]]
from = [0.0, 0.0]
to = [24.0, 0.0]
[[walls]]
from = [0.0, 14.0]
to = [24.0, 14.0]
[[walls]]
from = [0.0, 0.0]
to = [0.0, 14.0]
[[walls]]
from = [24.0, 0.0]
to = [24.0, 14.0]
[[boxes]]
center = [9.0, 7.0]
size = [6.0, 6.0]

[[robots]]
name = "car"
start = [2.5, 2.0, 0.0]
footprint = {{ circle = 0.4 }}
[robots.kinematics]
type = "ackermann"
wheelbase = {WHEELBASE}
max_steer = {MAX_STEER}
[robots.sensors.laser]
preset = "sick_lms100"
mount = [0.2, 0.0, 0.0]
[robots.sensors.encoder]
[[robots.tasks]]
type = "go"
name = "north_east"
to = [21.0, 12.0]
[[robots.tasks]]
type = "go"
name = "north_west"
to = [3.0, 12.0]
"#
    )
}

#[test]
fn an_ackermann_robot_drives_its_tasks_without_turning_on_the_spot() {
    let mut sim = world(&yard());
    let car = sim.robots[0];
    let kmax = MAX_STEER.tan() / WHEELBASE;
    let (mut spins, mut too_tight, mut max_v) = (0, 0, 0.0_f64);
    while sim.time() < 150.0 {
        sim.step();
        let t = *sim.world.get::<TrueTwist>(car).unwrap();
        max_v = max_v.max(t.v.abs());
        if t.v.abs() < 0.02 && t.w.abs() > 0.05 {
            spins += 1;
        }
        if t.v.abs() >= 0.02 && (t.w / t.v).abs() > kmax * 1.1 {
            too_tight += 1;
        }
        if sim.world.get::<Navigator>(car).unwrap().finished() {
            break;
        }
    }
    let nav = sim.world.get::<Navigator>(car).unwrap();
    let m = &nav.metrics;
    assert!(nav.finished(), "done within 150 s: {m:?}");
    assert_eq!((m.tasks_completed, m.tasks_failed), (2, 0), "{m:?}");
    assert!(max_v > 0.3, "it drove: {max_v}");
    assert_eq!(spins, 0, "ticks turning on the spot");
    assert_eq!(too_tight, 0, "ticks tighter than the turning radius");
    let counts = sim.world.get::<RobotMetrics>(car).unwrap();
    assert_eq!(counts.collisions.total(), 0, "{counts:?}");
    let p = sim.world.get::<TruePose>(car).unwrap().pose;
    assert!(
        (p.x - 3.0).hypot(p.y - 12.0) < 0.5,
        "at the last goal: {p:?}"
    );
}
