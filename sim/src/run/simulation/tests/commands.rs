//! Scripted commands (drive, teleport, faults, doors, goals, steering) equal the same events in
//! the scenario file bit for bit, and bad ones are typed errors.

use super::*;

#[test]
fn scripted_commands_equal_the_same_events_in_the_scenario_file() {
    let base = patrol_text();
    let sc = from_text(&base, "patrol").scenario().unwrap();
    let home = sc.robots[1].start;
    let events = format!(
        r#"
[[events]]
at = 2.0
type = "sensor_fault"
robot = "r1"
sensor = "laser"
active = true

[[events]]
at = 3.0
type = "teleport"
robot = "r2"
pose = [{:?}, {:?}, {:?}]

[[events]]
at = 4.0
type = "sensor_fault"
robot = "r1"
sensor = "laser"
active = false

[[events]]
at = 5.0
type = "waypoints"
robot = "r4"
points = [[3.8, 16.0], [30.1, 24.75]]

[[events]]
at = 1.0
type = "drive"
robot = "r3"
v = 0.3
w = -0.4

[[events]]
at = 3.5
type = "release"
robot = "r3"
"#,
        home.x, home.y, home.theta
    );
    let file = from_text(&(base.clone() + &events), "patrol-events")
        .duration(7.0)
        .threads(2)
        .build()
        .unwrap();
    let mut scripted = from_text(&base, "patrol")
        .duration(7.0)
        .threads(2)
        .build()
        .unwrap();
    scripted.run_for(1.0).unwrap();
    let drive = Command::Drive { v: 0.3, w: -0.4 };
    scripted.command("r3", drive).unwrap();
    scripted.run_for(1.0).unwrap();
    let fault = |active| Command::SensorFault {
        sensor: SensorName::Laser,
        active,
    };
    scripted.command("r1", fault(true)).unwrap();
    scripted.run_for(1.0).unwrap();
    scripted.command("r2", Command::Teleport(home)).unwrap();
    // the held command replaced r3's behaviour: it turns right at 0.3 m/s
    let twist = scripted.robot("r3").unwrap().twist();
    assert!(
        (twist.v - 0.3).abs() < 0.05 && (twist.w + 0.4).abs() < 0.1,
        "{twist:?}"
    );
    scripted.run_for(0.5).unwrap();
    scripted.command("r3", Command::Release).unwrap();
    scripted.run_for(0.5).unwrap();
    scripted.command("r1", fault(false)).unwrap();
    scripted.run_for(1.0).unwrap();
    let route = Command::Waypoints {
        points: vec![[3.8, 16.0], [30.1, 24.75]],
        looping: false,
    };
    scripted.command("r4", route).unwrap();

    let mut file = file;
    while !file.is_over() {
        file.step().unwrap();
    }
    while !scripted.is_over() {
        scripted.step().unwrap();
    }
    assert_eq!(scripted.ticks(), 140);
    assert_eq!(fingerprint(&mut file), fingerprint(&mut scripted));
    let (a, b) = (file.finish().unwrap(), scripted.finish().unwrap());
    assert_eq!(summary_json(&a), summary_json(&b));
    // the commands did something: the teleport and the faults are in the log
    let log: Vec<&str> = b.log.iter().map(|(_, _, t)| t.as_str()).collect();
    assert!(log.iter().any(|t| t.starts_with("teleported")), "{log:?}");
    assert!(
        log.contains(&"laser fault on") && log.contains(&"laser fault off"),
        "{log:?}"
    );
    assert!(log.contains(&"drive command released"), "{log:?}");
}

#[test]
fn a_door_closes_at_the_next_tick() {
    let mut s = Simulation::load("hospital_delivery")
        .duration(1.0)
        .threads(1)
        .build()
        .unwrap();
    let door = s.doors()[0].clone();
    assert!(door.open);
    s.set_door(&door.name, false).unwrap();
    assert!(s.doors()[0].open, "not before the next tick");
    s.step().unwrap();
    assert!(!s.doors()[0].open);
    // a robot with navigation tasks takes goals, not waypoints
    let route = Command::Waypoints {
        points: vec![[3.8, 16.0]],
        looping: false,
    };
    let r1 = s.robots()[0].name().to_string();
    assert_eq!(
        s.command(&r1, route),
        Err(SimError::NotOnWaypoints { robot: r1.clone() })
    );
    assert!(s.robot(&r1).unwrap().navigation().is_some());
}

#[test]
fn a_goal_sent_by_the_program_equals_a_tasks_event_in_the_file() {
    let events = r#"
[[events]]
at = 1.0
type = "tasks"
robot = "r1"
tasks = [{ type = "go", name = "go_corridor_main_c", to = "corridor_main_c" }]
"#;
    let mut file = from_text(&format!("{COURIER}{events}"), "file")
        .build()
        .unwrap();
    let mut scripted = from_text(COURIER, "scripted").build().unwrap();
    scripted.run_for(1.0).unwrap();
    file.run_for(1.0).unwrap();
    scripted
        .command("r1", Command::GoTo(Target::Place("corridor_main_c".into())))
        .unwrap();
    for _ in 0..3 {
        file.run_for(1.0).unwrap();
        scripted.run_for(1.0).unwrap();
        assert_eq!(
            navigation_fingerprint(&mut file),
            navigation_fingerprint(&mut scripted)
        );
    }
    assert_eq!(
        scripted.robot("r1").unwrap().navigation().unwrap().tasks(),
        2
    );
    let (a, b) = (file.finish().unwrap(), scripted.finish().unwrap());
    assert_eq!(summary_json(&a), summary_json(&b));
    assert!(
        b.log
            .iter()
            .any(|(_, _, what)| what == "new tasks: go_corridor_main_c"),
        "{:?}",
        b.log
    );
}

/// A car in an empty 20 × 20 m yard, wandering, with wheel encoders.
const CAR_YARD: &str = r#"
duration = 8.0
[map]
resolution = 0.1
[[walls]]
from = [0.0, 0.0]
to = [20.0, 0.0]
[[walls]]
from = [0.0, 20.0]
to = [20.0, 20.0]
[[walls]]
from = [0.0, 0.0]
to = [0.0, 20.0]
[[walls]]
from = [20.0, 0.0]
to = [20.0, 20.0]

[[robots]]
name = "car"
start = [10.0, 10.0, 0.0]
footprint = { circle = 0.3 }
kinematics = { type = "ackermann", max_steer = 0.45 }
behaviour = { type = "wander" }
[robots.sensors.encoder]
"#;

#[test]
fn a_speed_steer_command_equals_the_drive_event_in_the_file() {
    let events = r#"
[[events]]
at = 1.0
type = "drive"
robot = "car"
speed = 0.0
steer = -0.4

[[events]]
at = 2.0
type = "drive"
robot = "car"
speed = 0.8
steer = -0.4

[[events]]
at = 5.0
type = "release"
robot = "car"
"#;
    let mut file = from_text(&format!("{CAR_YARD}{events}"), "file")
        .build()
        .unwrap();
    let mut scripted = from_text(CAR_YARD, "scripted").build().unwrap();
    scripted.run_for(1.0).unwrap();
    let steer = |speed| Command::Steer { speed, steer: -0.4 };
    scripted.command("car", steer(0.0)).unwrap();
    scripted.run_for(1.0).unwrap();
    // standing, the wheels turn and the car stays where it is
    let car = scripted.robot("car").unwrap();
    assert!(car.twist().v.abs() < 1e-9, "{:?}", car.twist());
    scripted.command("car", steer(0.8)).unwrap();
    scripted.run_for(3.0).unwrap();
    // rolling on the circle of that angle: ω = v tan(δ) / L (wheelbase 0.35 m), as the
    // physics step (in f32) moves it
    let twist = scripted.robot("car").unwrap().twist();
    let w = 0.8 * (-0.4f64).tan() / 0.35;
    assert!(
        (twist.v - 0.8).abs() < 1e-3 && (twist.w - w).abs() < 1e-3,
        "{twist:?} against ω {w}"
    );
    scripted.command("car", Command::Release).unwrap();
    file.run_for(5.0).unwrap();
    assert_eq!(fingerprint(&mut file), fingerprint(&mut scripted));
    let (a, b) = (file.run().unwrap(), scripted.run().unwrap());
    assert_eq!(summary_json(&a), summary_json(&b));
    assert!(
        b.log
            .iter()
            .any(|(_, _, what)| what == "drive command held: speed 0.80 m/s, steer -0.400 rad"),
        "{:?}",
        b.log
    );
}

#[test]
fn a_speed_steer_command_is_for_cars_within_their_steering_limit() {
    let mut car = from_text(CAR_YARD, "car").build().unwrap();
    let e = car
        .command(
            "car",
            Command::Steer {
                speed: 0.5,
                steer: 0.5,
            },
        )
        .unwrap_err();
    assert!(
        matches!(&e, SimError::BadValue { what, .. } if what == "steering angle of `car`"),
        "{e}"
    );
    assert!(e.to_string().contains("max_steer 0.45"), "{e}");
    let nan = Command::Steer {
        speed: f64::NAN,
        steer: 0.1,
    };
    assert!(matches!(
        car.command("car", nan),
        Err(SimError::BadValue { .. })
    ));
    let mut p = from_text(&patrol_text(), "patrol").build().unwrap();
    let e = p
        .command(
            "r1",
            Command::Steer {
                speed: 0.5,
                steer: 0.1,
            },
        )
        .unwrap_err();
    assert!(
        matches!(&e, SimError::NotACar { robot, .. } if robot == "r1"),
        "{e}"
    );
}

#[test]
fn bad_goals_are_typed_errors() {
    let mut s = from_text(COURIER, "courier").build().unwrap();
    let go = |t: Target| Command::GoTo(t);
    assert!(matches!(
        s.command("r1", go(Target::Place("moon".into()))),
        Err(SimError::UnknownPlace { name, known }) if name == "moon" && known.contains("charger_1")
    ));
    assert!(matches!(
        s.command("r1", go(Target::Point([1e6, 0.0]))),
        Err(SimError::OutsideMap { .. })
    ));
    assert!(matches!(
        s.command("r1", go(Target::Point([f64::NAN, 0.0]))),
        Err(SimError::BadValue { .. })
    ));
    assert!(matches!(
        s.command("r1", Command::Tasks(Vec::new())),
        Err(SimError::BadValue { .. })
    ));
    // a wall of the hospital
    let grid = &s.scenario().grid;
    let wall = (0..grid.height)
        .flat_map(|row| (0..grid.width).map(move |col| (col, row)))
        .find(|&(col, row)| grid.get(col, row) == systems::world::Cell::Occupied)
        .map(|(col, row)| grid.cell_center(col, row))
        .unwrap();
    assert!(matches!(
        s.command("r1", go(Target::Point(wall))),
        Err(SimError::InsideObstacle { .. })
    ));
    // a robot without tasks takes none
    let mut p = from_text(&patrol_text(), "patrol").build().unwrap();
    assert!(matches!(
        p.command("r1", go(Target::Point([1.0, 1.0]))),
        Err(SimError::NotNavigating { robot }) if robot == "r1"
    ));
}

#[test]
fn a_faulted_laser_leaves_the_localizers_degraded_on_the_odometry_never_nan() {
    let mut s = from_text(&patrol_text(), "patrol")
        .duration(12.0)
        .threads(1)
        .build()
        .unwrap();
    let fault = |active| Command::SensorFault {
        sensor: SensorName::Laser,
        active,
    };
    let mcl = |s: &Simulation| {
        let r1 = s.robot("r1").unwrap();
        let l = r1.localizers()[0];
        assert_eq!(l.name, "mcl");
        let e = l
            .estimate
            .expect("mcl from its start pose publishes at once");
        let truth = r1.pose();
        (
            e,
            l.degraded,
            (e.pose.x - truth.x).hypot(e.pose.y - truth.y),
        )
    };
    s.run_for(2.0).unwrap();
    let (healthy, degraded, _) = mcl(&s);
    assert!(!degraded);
    s.command("r1", fault(true)).unwrap();
    s.command("r1", Command::Drive { v: 0.3, w: 0.2 }).unwrap();
    s.run_for(3.0).unwrap();
    // every map localizer of r1 says so, and publishes each tick, finite
    let r1 = s.robot("r1").unwrap();
    for l in r1.localizers() {
        assert!(l.degraded, "{}", l.name);
        if let Some(e) = l.estimate {
            assert!(
                (e.stamp - s.time()).abs() < 0.06,
                "{} at {}",
                l.name,
                e.stamp
            );
            let values = [e.pose.x, e.pose.y, e.pose.theta];
            assert!(values.iter().all(|v| v.is_finite()), "{}", l.name);
            assert!(
                e.covariance.concat().iter().all(|v| v.is_finite()),
                "{}",
                l.name
            );
        }
    }
    // the others' lasers still work
    assert!(
        s.robot("r2")
            .unwrap()
            .localizers()
            .iter()
            .all(|l| !l.degraded)
    );
    // mcl followed the robot on the odometry, and its covariance grew with the path
    let (carried, _, error) = mcl(&s);
    assert!(error < 0.15, "carried {error} m off");
    let spread = |e: &crate::run::view::Estimate| e.covariance[0][0] + e.covariance[1][1];
    assert!(
        spread(&carried) > spread(&healthy) + 2.0 * (0.05f64 * 0.8).powi(2),
        "{:?} → {:?}",
        healthy.covariance,
        carried.covariance
    );
    // the laser back: the filter corrects again
    s.command("r1", fault(false)).unwrap();
    s.command("r1", Command::Release).unwrap();
    s.run_for(3.0).unwrap();
    let (back, degraded, error) = mcl(&s);
    assert!(!degraded && (back.stamp - s.time()).abs() < 1.0, "{back:?}");
    assert!(error < 0.15, "{error} m off after the fault");
}
