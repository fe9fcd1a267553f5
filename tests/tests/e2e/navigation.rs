//! Task-driven navigation: deliveries on the hospital floor, unreachable goals,
//! robots meeting head-on in a one-lane corridor, and the scenario errors of tasks and doors.

use crate::common::*;
use sim::{RunOptions, run_scenario};

fn run(text: &str) -> sim::RunOutput {
    run_scenario(&scenario(text), &RunOptions::default()).expect("runs")
}

fn nav(out: &sim::RunOutput, robot: usize) -> &sim::run::summary::NavigationSummary {
    out.summary.robots[robot]
        .navigation
        .as_ref()
        .expect("a robot with tasks has navigation metrics")
}

/// The bundled hospital_delivery scenario, run whole (it ends once every task is done, ≈ 8
/// simulated minutes): every delivery completes, nobody touches a wall, and the fire door
/// closing at 50 s makes r1 re-plan.
#[test]
fn hospital_delivery_completes_every_delivery_without_wall_collisions() {
    let path = bundled("hospital_delivery");
    let sc = sim::scenario::load_scenario(&path).expect("loads");
    let out = run_scenario(&sc, &RunOptions::default()).expect("runs");
    assert_eq!(out.summary.robots.len(), 4);
    for (i, r) in out.summary.robots.iter().enumerate() {
        let n = nav(&out, i);
        assert!(n.all_tasks_done, "{}: {n:?}", r.name);
        assert_eq!(n.tasks_failed, 0, "{}: {:?}", r.name, n.failures);
        assert_eq!(n.deliveries_completed, 2, "{}", r.name);
        assert_eq!(n.wall_collisions, 0, "{}", r.name);
        assert!(
            n.path_ratio.is_some_and(|q| q > 0.9 && q < 2.0),
            "{}: {n:?}",
            r.name
        );
    }
    assert!(
        out.log
            .iter()
            .any(|(t, who, what)| *t >= 50.0 && who == "r1" && what.contains("re-planning")),
        "the closed fire door forces a re-plan"
    );
    assert!(
        out.summary.sim_time_s < sc.duration,
        "ends when all tasks are done"
    );
}

/// hospital_delivery with seed 1, whose people once held two robots for the rest of the run:
/// the doctor, stepping aside in the north corridor, stood between r4 and r2 (and in r4's way)
/// until people held up for 10 s began turning back. Every task now completes.
#[test]
fn hospital_delivery_seed_1_does_not_jam_between_robots_and_a_person() {
    let mut sc = sim::scenario::load_scenario(&bundled("hospital_delivery")).expect("loads");
    sc.seed = 1;
    let out = run_scenario(&sc, &RunOptions::default()).expect("runs");
    for (i, r) in out.summary.robots.iter().enumerate() {
        let n = nav(&out, i);
        assert!(n.all_tasks_done, "{}: {n:?}", r.name);
        assert_eq!(n.tasks_failed, 0, "{}: {:?}", r.name, n.failures);
    }
    assert!(
        out.summary.sim_time_s < sc.duration,
        "ends when all tasks are done"
    );
}

/// A closed box inside a room: the goal is free but unreachable.
const ROOM_WITH_VAULT: &str = r#"
duration = 30.0
end_when_done = true
[map]
resolution = 0.05
[[walls]]
from = [0.0, 0.0]
to = [8.0, 0.0]
[[walls]]
from = [8.0, 0.0]
to = [8.0, 6.0]
[[walls]]
from = [8.0, 6.0]
to = [0.0, 6.0]
[[walls]]
from = [0.0, 6.0]
to = [0.0, 0.0]
# the vault: a closed 2 × 2 m square
[[walls]]
from = [5.0, 2.0]
to = [7.0, 2.0]
[[walls]]
from = [7.0, 2.0]
to = [7.0, 4.0]
[[walls]]
from = [7.0, 4.0]
to = [5.0, 4.0]
[[walls]]
from = [5.0, 4.0]
to = [5.0, 2.0]
[[robots]]
name = "r"
start = [1.5, 3.0, 0.0]
footprint = { circle = 0.3 }
[robots.sensors.laser]
preset = "hokuyo_urg04lx"
[robots.sensors.encoder]
[[robots.tasks]]
type = "go"
name = "into_the_vault"
to = [6.0, 3.0]
[[robots.tasks]]
type = "go"
name = "corner"
to = [2.0, 5.0]
"#;

#[test]
fn an_unreachable_goal_fails_its_task_with_the_reason_and_the_robot_goes_on() {
    let out = run(ROOM_WITH_VAULT);
    let n = nav(&out, 0);
    assert_eq!(n.tasks_failed, 1, "{n:?}");
    assert_eq!(n.tasks_completed, 1, "the next task is done: {n:?}");
    assert_eq!(n.failures[0].task, "into_the_vault");
    assert!(
        n.failures[0].reason.contains("unreachable"),
        "{:?}",
        n.failures
    );
    assert!(
        n.failures[0].time_s < 1.0,
        "reported at once, not after looping"
    );
    let p = out.summary.robots[0].final_pose;
    assert!((p[0] - 2.0).hypot(p[1] - 5.0) < 0.5, "{p:?}");
}

/// A one-lane corridor (1.2 m between the walls, for 0.6 m robots) 16 m long with a passing bay
/// (2 × 1.5 m) on the north side at x 7–9. Robot `a` drives east, `b` west after waiting
/// `b_wait` seconds.
fn corridor(b_wait: f64) -> String {
    format!(
        r#"
duration = 120.0
end_when_done = true
[map]
resolution = 0.05
[[walls]]
from = [-0.05, 0.0]
to = [16.05, 0.0]
[[walls]]
from = [-0.05, 1.3]
to = [7.0, 1.3]
[[walls]]
from = [9.0, 1.3]
to = [16.05, 1.3]
[[walls]]
from = [7.0, 1.25]
to = [7.0, 2.85]
[[walls]]
from = [9.0, 1.25]
to = [9.0, 2.85]
[[walls]]
from = [6.95, 2.8]
to = [9.05, 2.8]
[[walls]]
from = [0.0, -0.05]
to = [0.0, 1.35]
[[walls]]
from = [16.0, -0.05]
to = [16.0, 1.35]

[[robots]]
name = "a"
start = [1.0, 0.65, 0.0]
footprint = {{ circle = 0.3 }}
[robots.sensors.laser]
preset = "sick_lms100"
mount = [0.15, 0.0, 0.0]
[robots.sensors.encoder]
[[robots.tasks]]
type = "go"
to = [15.0, 0.65]

[[robots]]
name = "b"
start = [15.0, 0.65, 3.14159]
footprint = {{ circle = 0.3 }}
[robots.sensors.laser]
preset = "sick_lms100"
mount = [0.15, 0.0, 0.0]
[robots.sensors.encoder]
[[robots.tasks]]
type = "wait"
time = {b_wait}
[[robots.tasks]]
type = "go"
to = [1.0, 0.65]
"#
    )
}

#[test]
fn robots_meeting_head_on_in_a_one_lane_corridor_both_arrive_using_the_passing_bay() {
    // b waits 0 s: they meet at the bay; b waits 4 s: they meet east of it, where b (the lower
    // priority) has nowhere to go, so a backs into the bay instead
    for wait in [0.0, 4.0] {
        let out = run(&corridor(wait));
        let (a, b) = (nav(&out, 0), nav(&out, 1));
        assert!(
            a.all_tasks_done && b.all_tasks_done,
            "wait {wait}: {a:?} {b:?}"
        );
        assert_eq!(a.tasks_failed + b.tasks_failed, 0, "wait {wait}");
        assert!(a.yields + b.yields >= 1, "wait {wait}: somebody gave way");
        for r in &out.summary.robots {
            assert_eq!(r.collisions, 0, "wait {wait}: {}: {:#?}", r.name, out.log);
        }
        let pa = out.summary.robots[0].final_pose;
        let pb = out.summary.robots[1].final_pose;
        assert!(
            (pa[0] - 15.0).abs() < 0.4 && (pb[0] - 1.0).abs() < 0.4,
            "{pa:?} {pb:?}"
        );
    }
}

#[test]
fn navigation_errors_name_the_key() {
    let base = ROOM_WITH_VAULT;
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "[[robots.tasks]]\ntype = \"go\"\nname = \"corner\"\nto = [2.0, 5.0]\n",
            "[[robots.tasks]]\ntype = \"go\"\nname = \"corner\"\nto = \"nowhere\"\n",
            &["robots[0].tasks[1].to", "unknown place `nowhere`"],
        ),
        (
            "to = [2.0, 5.0]\n",
            "to = [2.0, 5.0]\nload = 3.0\n",
            &["tasks[1].load", "does not apply to a `go` task"],
        ),
        (
            "type = \"go\"\nname = \"corner\"\nto = [2.0, 5.0]\n",
            "type = \"delivery\"\nname = \"corner\"\nto = [2.0, 5.0]\n",
            &["robots[0].tasks[1]", "needs `from`"],
        ),
        (
            "to = [2.0, 5.0]\n",
            "to = [5.0, 2.0]\n",
            &["tasks[1].to", "too close to an obstacle"],
        ),
        (
            "to = [2.0, 5.0]\n",
            "to = [20.0, 5.0]\n",
            &["tasks[1].to", "outside the map"],
        ),
        (
            "name = \"corner\"",
            "name = \"into_the_vault\"",
            &["tasks[1].name", "duplicate task name"],
        ),
        (
            "[robots.sensors.encoder]\n",
            "[robots.sensors.encoder]\n[robots.navigation]\nlocalizer = \"amcl\"\n",
            &[
                "robots[0].navigation.localizer",
                "no localizer named `amcl`",
            ],
        ),
        (
            "[robots.sensors.encoder]\n",
            "[robots.sensors.encoder]\n[robots.navigation]\nspeed = 9.0\n",
            &["navigation.speed", "exceeds the drive's top speed"],
        ),
        (
            "[robots.sensors.encoder]\n",
            "[robots.sensors.encoder]\n[robots.navigation]\ninflation_radius = 0.2\n",
            &["navigation.inflation_radius", "at least the robot radius"],
        ),
        (
            "[robots.sensors.encoder]\n",
            "[robots.sensors.encoder]\n[robots.navigation]\nwait_time = -1.0\n",
            &["navigation.wait_time", "expected a number in [0, 600]"],
        ),
        (
            "footprint = { circle = 0.3 }\n",
            "footprint = { circle = 0.3 }\nbehaviour = { type = \"wander\" }\n",
            &["robots[0].behaviour", "driven by its navigator"],
        ),
        (
            "[robots.sensors.encoder]\n",
            "",
            &["robots[0].tasks", "sensors.encoder"],
        ),
        (
            "end_when_done = true\n",
            "end_when_done = true\n[[events]]\nat = 1.0\ntype = \"door\"\ndoor = \"front\"\nopen = false\n",
            &["events[0].door", "unknown door `front`", "defines no doors"],
        ),
        (
            "end_when_done = true\n",
            "end_when_done = true\n[[events]]\nat = 1.0\ntype = \"waypoints\"\nrobot = \"r\"\npoints = [[1.0, 1.0]]\n",
            &["events[0].robot", "driven by its tasks"],
        ),
        (
            "end_when_done = true\n",
            "end_when_done = true\n[[events]]\nat = 1.0\ntype = \"teleport\"\npose = [1.0, 1.0]\n",
            &["events[0]", "missing key `robot`"],
        ),
    ];
    for (from, to, fragments) in cases {
        assert!(base.contains(from), "fixture lacks {from:?}");
        let text = base.replacen(from, to, 1);
        let e = scenario_error(&text);
        for f in *fragments {
            assert!(e.contains(f), "{to:?}: `{e}` lacks `{f}`");
        }
    }
}

#[test]
fn door_events_need_a_known_door_and_a_state() {
    let text = format!(
        "{}\n[[events]]\nat = 1.0\ntype = \"door\"\ndoor = \"fire_door_w\"\n",
        std::fs::read_to_string(bundled("hospital_delivery"))
            .unwrap()
            .split("# --- events")
            .next()
            .unwrap()
    );
    let e = scenario_error(&text);
    assert!(e.contains("needs `open`"), "{e}");
    let e = scenario_error(&text.replace(
        "door = \"fire_door_w\"",
        "door = \"fire_door_w\"\nopen = false\nrobot = \"r1\"",
    ));
    assert!(e.contains("concerns no robot"), "{e}");
    let e = scenario_error(&text.replace(
        "door = \"fire_door_w\"",
        "door = \"fire_door_x\"\nopen = false",
    ));
    assert!(e.contains("known doors: fire_door_e, fire_door_w"), "{e}");
}
