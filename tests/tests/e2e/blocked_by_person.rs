//! A robot whose way a person blocks: it stops short of the person, waits, and then
//! passes, either because the person walks off or, when the person stays, by planning around.
//! Run tick by tick on ground truth, so the tests see where both bodies were at every step.

use crate::common::*;
use systems::body::TruePose;
use systems::eval::RobotMetrics;
use systems::navigation::{Navigator, Phase};

/// A corridor 2.4 m wide (y 0–2.4) and 14 m long, with a 2 × 2.6 m side room north of it at
/// x 6–8 (doorway x 6.5–7.5). A person stands in the middle of the corridor at x 7 until
/// `leaves_at` s, then walks into the room; robot `r` drives from x 1 to x 13 along the middle,
/// waiting `wait` s at an obstacle before planning around it. `sensors` are the robot's
/// range-sensor tables.
fn corridor(leaves_at: f64, wait: f64, sensors: &str) -> String {
    format!(
        r#"
duration = 80.0
end_when_done = true
[map]
resolution = 0.05
[[walls]]
from = [-0.05, 0.0]
to = [14.05, 0.0]
[[walls]]
from = [-0.05, 2.4]
to = [6.5, 2.4]
[[walls]]
from = [7.5, 2.4]
to = [14.05, 2.4]
[[walls]]
from = [0.0, -0.05]
to = [0.0, 2.45]
[[walls]]
from = [14.0, -0.05]
to = [14.0, 2.45]
[[walls]]
from = [6.0, 2.4]
to = [6.0, 5.0]
[[walls]]
from = [8.0, 2.4]
to = [8.0, 5.0]
[[walls]]
from = [5.95, 5.0]
to = [8.05, 5.0]

[[robots]]
name = "r"
start = [1.0, 1.2, 0.0]
footprint = {{ circle = 0.3 }}
{sensors}
[robots.sensors.encoder]
[robots.navigation]
wait_time = {wait}
[[robots.tasks]]
type = "go"
name = "east_end"
to = [13.0, 1.2]

[[people]]
name = "blocker"
route = [[7.0, 1.2], [7.0, 4.0]]
start_at = {leaves_at}
loop = false
speed = 1.0
"#
    )
}

const LASER: &str = "[robots.sensors.laser]\npreset = \"sick_lms100\"\nmount = [0.15, 0.0, 0.0]";
/// The default SRF02-like ring (front, ±45°, rear) and no laser.
const SONAR_ONLY: &str = "[robots.sensors.sonar]";

/// What happened, tick by tick.
struct Trace {
    /// Closest approach of the robot's and the person's centres (m).
    closest: f64,
    /// Largest x the robot reached while the person still stood in the corridor (y < 2.4).
    furthest_while_blocked: f64,
    /// First time the robot was past the person (x > 7.6), s.
    passed_at: Option<f64>,
}

fn run(text: &str) -> (sim::build::SimWorld, Trace) {
    let mut sim = world(text);
    let (r, person) = (sim.robots[0], sim.people[0]);
    let mut trace = Trace {
        closest: f64::INFINITY,
        furthest_while_blocked: f64::NEG_INFINITY,
        passed_at: None,
    };
    while sim.time() < 80.0 {
        sim.step();
        let p = sim.world.get::<TruePose>(r).unwrap().pose;
        let q = sim.world.get::<TruePose>(person).unwrap().pose;
        trace.closest = trace.closest.min((p.x - q.x).hypot(p.y - q.y));
        if q.y < 2.4 && (q.x - 7.0).abs() < 0.3 {
            trace.furthest_while_blocked = trace.furthest_while_blocked.max(p.x);
        }
        if p.x > 7.6 && trace.passed_at.is_none() {
            trace.passed_at = Some(sim.time());
        }
        if sim.world.get::<Navigator>(r).unwrap().finished() {
            break;
        }
    }
    (sim, trace)
}

/// Touching distance of the robot (0.3 m) and the person (0.25 m).
const TOUCH: f64 = 0.55;

#[test]
fn a_robot_stops_for_a_person_in_its_way_waits_and_goes_on_when_the_person_leaves() {
    // the robot reaches the person at about 10 s; the person stands until 25 s; the robot would
    // only plan around after 60 s
    let (sim, trace) = run(&corridor(25.0, 60.0, LASER));
    let r = sim.robots[0];
    let nav = sim.world.get::<Navigator>(r).unwrap();
    let m = &nav.metrics;
    assert!(nav.finished() && m.tasks_completed == 1, "{m:?}");
    assert!(m.stops >= 1, "it stopped: {m:?}");
    assert!(
        m.waiting_time_s > 10.0,
        "it waited for the person (from about 10 s to 25 s): {m:?}"
    );
    assert_eq!(m.replans, 0, "it went on along its plan: {m:?}");
    assert!(
        trace.furthest_while_blocked < 7.0 - TOUCH,
        "it stayed behind the person: x = {}",
        trace.furthest_while_blocked
    );
    assert!(
        trace.closest > TOUCH + 0.05,
        "never touched: {}",
        trace.closest
    );
    let passed = trace.passed_at.expect("it passed the person's spot");
    assert!(passed > 25.0 && passed < 35.0, "passed at {passed} s");
    let counts = sim.world.get::<RobotMetrics>(r).unwrap();
    assert_eq!(counts.collisions.total(), 0, "{counts:?}");
    let p = sim.world.get::<TruePose>(r).unwrap().pose;
    assert!((p.x - 13.0).hypot(p.y - 1.2) < 0.3, "at the goal: {p:?}");
}

#[test]
fn a_robot_blocked_by_a_person_who_stays_plans_around_after_its_wait_time() {
    // the person never leaves; the robot waits 4 s, then passes beside them with room to spare
    let (sim, trace) = run(&corridor(1000.0, 4.0, LASER));
    let r = sim.robots[0];
    let nav = sim.world.get::<Navigator>(r).unwrap();
    let m = &nav.metrics;
    assert!(nav.finished() && m.tasks_completed == 1, "{m:?}");
    assert!(
        m.stops >= 1 && m.replans >= 1,
        "stopped, then re-planned: {m:?}"
    );
    assert!(
        m.waiting_time_s >= 4.0 - 1e-6 && m.waiting_time_s < 12.0,
        "waited its wait time, not much more: {m:?}"
    );
    assert!(
        trace.closest > TOUCH + 0.15,
        "a berth of more than 15 cm while passing: {}",
        trace.closest
    );
    let passed = trace.passed_at.expect("it passed the person");
    assert!(passed < 40.0, "passed at {passed} s");
    assert_eq!(
        sim.world.get::<RobotMetrics>(r).unwrap().collisions.total(),
        0
    );
    assert_eq!(nav.phase, Phase::Idle);
    let p = sim.world.get::<TruePose>(r).unwrap().pose;
    assert!((p.x - 13.0).hypot(p.y - 1.2) < 0.3, "at the goal: {p:?}");
}

#[test]
fn a_robot_with_only_sonars_also_stops_for_the_person_and_goes_on_when_they_leave() {
    // no laser: the stop check runs on the sonar ring alone (its echoes of the corridor walls
    // are explained by the map, the person's are not)
    let (sim, trace) = run(&corridor(25.0, 60.0, SONAR_ONLY));
    let r = sim.robots[0];
    let nav = sim.world.get::<Navigator>(r).unwrap();
    let m = &nav.metrics;
    assert!(nav.finished() && m.tasks_completed == 1, "{m:?}");
    assert!(m.stops >= 1 && m.waiting_time_s > 10.0, "{m:?}");
    assert!(
        trace.closest > TOUCH + 0.05,
        "never touched: {}",
        trace.closest
    );
    let passed = trace.passed_at.expect("it passed the person's spot");
    assert!(passed > 25.0 && passed < 35.0, "passed at {passed} s");
    assert_eq!(
        sim.world.get::<RobotMetrics>(r).unwrap().collisions.total(),
        0
    );
}
