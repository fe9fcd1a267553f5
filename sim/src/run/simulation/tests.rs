//! The facade: scripted commands equal the same events in the scenario file bit for bit, a run
//! through the builder equals `sim run`'s, and every bad request is a typed error naming what
//! it concerns.

use super::*;
use crate::run::{Command, RunOptions, Target, run_scenario};
use crate::scenario::{SensorName, assets_dir, find_scenario};
use systems::core::Pose2;
use systems::core::pool::KernelPool;

/// hospital_patrol's file without its own events (they start at 40 s anyway).
fn patrol_text() -> String {
    let text = std::fs::read_to_string(find_scenario("hospital_patrol").unwrap()).unwrap();
    let cut = text.find("# --- events").expect("the events section");
    text[..cut].to_string()
}

/// Scenario TOML whose relative paths are those of the bundled scenarios.
fn from_text(text: &str, label: &str) -> SimulationBuilder {
    Simulation::from_toml(text, label).relative_to(assets_dir().join("scenarios"))
}

/// What a run leaves that must not depend on how its events were given: the summary (wall
/// time aside), every robot's true pose, odometry and localizer estimates, the event log.
fn fingerprint(s: &mut Simulation) -> String {
    let mut out = String::new();
    for r in s.robots() {
        let locs: Vec<_> = r.localizers().iter().map(|l| l.estimate).collect();
        out += &format!(
            "{} {:?} {:?} {:?}\n",
            r.name(),
            r.pose(),
            r.odometry(),
            locs
        );
    }
    out
}

fn summary_json(done: &Finished) -> String {
    let mut v = serde_json::to_value(&done.summary).unwrap();
    v.as_object_mut().unwrap().remove("wall_time_s");
    v.as_object_mut().unwrap().remove("real_time_factor");
    format!("{v}\n{:?}", done.log)
}

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
fn a_run_through_the_builder_equals_sim_run() {
    let built = Simulation::load("hospital_patrol")
        .seed(5)
        .duration(3.0)
        .threads(2)
        .build()
        .unwrap()
        .run()
        .unwrap();
    let mut sc = crate::scenario::scenario_arg(Some("hospital_patrol")).unwrap();
    sc.seed = 5;
    sc.duration = 3.0;
    let opts = RunOptions {
        threads: 2,
        ..RunOptions::default()
    };
    let direct = run_scenario(&sc, &opts).unwrap();
    assert_eq!(built.summary.sim_time_s, 3.0);
    let mut a = serde_json::to_value(&built.summary).unwrap();
    let mut b = serde_json::to_value(&direct.summary).unwrap();
    for v in [&mut a, &mut b] {
        v.as_object_mut().unwrap().remove("wall_time_s");
        v.as_object_mut().unwrap().remove("real_time_factor");
    }
    assert_eq!(a, b);
}

#[test]
fn stepping_reports_time_and_reads_the_robots() {
    let mut s = Simulation::load("hospital_patrol")
        .duration(2.0)
        .threads(1)
        .build()
        .unwrap();
    assert_eq!((s.ticks(), s.time(), s.end_tick()), (0, 0.0, 40));
    let start = s.robot("r1").unwrap().pose();
    s.run_for(1.0).unwrap();
    assert_eq!(s.ticks(), 20);
    assert!((s.time() - 1.0).abs() < 1e-9);
    let r1 = s.robot("r1").unwrap();
    assert!(r1.twist().v > 0.1, "{:?}", r1.twist());
    let moved = (r1.pose().x - start.x).hypot(r1.pose().y - start.y);
    assert!(moved > 0.05, "r1 moved {moved} m");
    // odometry follows the truth closely after a second
    let odo = r1.odometry().unwrap();
    assert!((odo.x - r1.pose().x).hypot(odo.y - r1.pose().y) < 0.05);
    // the latest scan, its world points inside the map
    let scan = r1.scan().expect("a scan within a second");
    assert_eq!(scan.angles().count(), scan.ranges().len());
    let points = scan.world_points();
    assert!(points.len() > scan.ranges().len() / 2, "{}", points.len());
    let [x0, y0, x1, y1] = s.scenario().grid.bounds();
    assert!(
        points
            .iter()
            .all(|p| p[0] >= x0 - 0.1 && p[0] <= x1 + 0.1 && p[1] >= y0 - 0.1 && p[1] <= y1 + 0.1)
    );
    let locs = r1.localizers();
    assert_eq!((locs[0].name, locs[0].kind), ("mcl", "mcl"));
    assert_eq!(s.robots().len(), 4);
    // run_until stops as soon as its condition holds
    let held = s.run_until(|s| s.time() >= 1.5 - 1e-9, 10.0).unwrap();
    assert!(held && s.ticks() == 30, "{}", s.ticks());
    let done = s.run().unwrap();
    assert_eq!(done.summary.sim_time_s, 2.0);
}

#[test]
fn overrides_change_the_file_and_bad_ones_name_the_key() {
    let b = Simulation::load("hospital_patrol").set("robots[name=r1].behaviour.speed", "0.5");
    assert_eq!(b.scenario().unwrap().robots[0].speed, 0.5);
    let e = Simulation::load("hospital_patrol")
        .set("robots[name=r1].behaviour.speed", "-3")
        .scenario()
        .unwrap_err()
        .to_string();
    assert!(e.contains("robots[name=r1].behaviour.speed"), "{e}");
    let e = Simulation::load("no_such_scenario")
        .scenario()
        .unwrap_err()
        .to_string();
    assert!(e.contains("no_such_scenario"), "{e}");
    let e = Simulation::load("hospital_patrol")
        .duration(f64::NAN)
        .scenario()
        .unwrap_err()
        .to_string();
    assert!(e.contains("duration"), "{e}");
    let sc = Simulation::load("hospital_patrol").scenario().unwrap();
    let e = Simulation::from_scenario(sc)
        .set("seed", "3")
        .scenario()
        .unwrap_err()
        .to_string();
    assert!(e.contains("built in code"), "{e}");
}

#[test]
fn bad_requests_are_typed_errors_naming_what_they_concern() {
    let mut s = Simulation::load("hospital_patrol")
        .duration(1.0)
        .threads(1)
        .build()
        .unwrap();
    let e = s.robot("r9").err().unwrap();
    assert_eq!(
        e,
        SimError::UnknownRobot {
            name: "r9".into(),
            known: "r1, r2, r3, r4".into()
        }
    );
    let r1 = s.robot("r1").unwrap();
    let e = r1.localizer("amcl").err().unwrap();
    assert!(
        matches!(&e, SimError::UnknownLocalizer { robot, name, .. } if robot == "r1" && name == "amcl"),
        "{e}"
    );
    let known: Vec<String> = r1.localizers().iter().map(|l| l.name.to_string()).collect();
    assert!(e.to_string().contains(&known.join(", ")), "{e}");
    assert!(r1.localizer(&known[0]).is_ok());
    let nan = Command::Teleport(Pose2::new(f64::NAN, 1.0, 0.0));
    assert!(matches!(
        s.command("r1", nan),
        Err(SimError::BadValue { .. })
    ));
    // a point of the map inside a wall
    let grid = &s.scenario().grid;
    let [x0, y0, x1, y1] = grid.bounds();
    let wall = (0..100)
        .flat_map(|i| (0..100).map(move |j| (i, j)))
        .map(|(i, j)| {
            (
                x0 + (x1 - x0) * (i as f64 + 0.5) / 100.0,
                y0 + (y1 - y0) * (j as f64 + 0.5) / 100.0,
            )
        })
        .find(|&(x, y)| !grid.disc_is_clear(x, y, 0.05))
        .unwrap();
    let wall = Command::Teleport(Pose2::new(wall.0, wall.1, 0.0));
    assert!(matches!(
        s.command("r1", wall),
        Err(SimError::InsideObstacle { .. })
    ));
    let still = Command::Drive {
        v: 0.2,
        w: f64::NAN,
    };
    assert!(matches!(
        s.command("r1", still),
        Err(SimError::BadValue { .. })
    ));
    let far = Command::Waypoints {
        points: vec![[3.8, 16.0], [1e4, 0.0]],
        looping: false,
    };
    let e = s.command("r1", far).unwrap_err();
    assert!(e.to_string().contains("waypoint 1 of `r1`"), "{e}");
    assert!(matches!(
        s.set_door("nowhere", true),
        Err(SimError::UnknownDoor { .. })
    ));
    let sonar = Command::SensorFault {
        sensor: SensorName::Sonar,
        active: true,
    };
    assert!(matches!(
        s.command("r1", sonar),
        Err(SimError::NoSuchSensor { .. })
    ));
    assert!(matches!(s.run_for(-1.0), Err(SimError::BadValue { .. })));
    assert!(matches!(
        s.run_for(f64::INFINITY),
        Err(SimError::BadValue { .. })
    ));
    // nothing was queued by the refused commands: the run is that of the file
    assert_eq!(s.ticks(), 0);
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

/// One navigating robot in the hospital, on a trip to the west corridor.
const COURIER: &str = r#"
name = "courier"
seed = 5
duration = 20.0
[map]
file = "../maps/hospital/hospital.yaml"
places = "../maps/hospital/places.toml"
[[robots]]
name = "r1"
start = "charger_1"
footprint = { circle = 0.3 }
navigation = { speed = 0.8 }
[robots.sensors.laser]
preset = "sick_lms100"
[robots.sensors.encoder]
[[robots.tasks]]
type = "go"
to = "corridor_main_w"
"#;

fn navigation_fingerprint(s: &mut Simulation) -> String {
    let r = s.robot("r1").unwrap();
    let n = r.navigation().unwrap();
    let nav = format!("{} {} {}", n.tasks(), n.tasks_done(), n.status());
    format!("{}{nav}", fingerprint(s))
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
fn a_reset_equals_a_fresh_simulation_with_that_seed() {
    // a navigating robot (costmaps reused) and localizers (distance field reused)
    let text = COURIER.replace(
        "[[robots.tasks]]",
        "[[robots.localization]]\nname = \"mcl\"\ntype = \"mcl\"\ninit = \"pose\"\n[[robots.tasks]]",
    );
    let mut s = from_text(&text, "courier").build().unwrap();
    s.run_for(2.0).unwrap();
    s.reset(9).unwrap();
    assert_eq!((s.ticks(), s.time(), s.scenario().seed), (0, 0.0, 9));
    let mut fresh = from_text(&text, "courier").seed(9).build().unwrap();
    for _ in 0..2 {
        s.run_for(1.5).unwrap();
        fresh.run_for(1.5).unwrap();
        assert_eq!(
            navigation_fingerprint(&mut s),
            navigation_fingerprint(&mut fresh)
        );
    }
    let (a, b) = (s.finish().unwrap(), fresh.finish().unwrap());
    assert_eq!(summary_json(&a), summary_json(&b));
}

/// Worlds on a shared pool, or running their kernels inline on a pool stepping them side by
/// side, give the run of a simulation with a pool of its own; a reset keeps the pool.
#[test]
fn a_given_kernel_pool_gives_the_same_run() {
    let text = COURIER.replace(
        "[[robots.tasks]]",
        "[[robots.localization]]\nname = \"mcl\"\ntype = \"mcl\"\ninit = \"pose\"\n[[robots.tasks]]",
    );
    let mut own = from_text(&text, "courier").threads(1).build().unwrap();
    own.run_for(3.0).unwrap();
    let want = summary_json(&own.finish().unwrap());
    let shared = KernelPool::new(2).unwrap();
    let mut worlds: Vec<Simulation> = [shared.clone(), shared, KernelPool::inline()]
        .into_iter()
        .map(|pool| {
            from_text(&text, "courier")
                .kernel_pool(pool)
                .build()
                .unwrap()
        })
        .collect();
    let outer = KernelPool::new(2).unwrap();
    outer.install(|| {
        use rayon::prelude::*;
        worlds.par_iter_mut().for_each(|w| {
            w.run_for(1.0).unwrap();
            let seed = w.scenario().seed;
            w.reset(seed).unwrap();
            w.run_for(3.0).unwrap();
        })
    });
    for w in worlds {
        assert_eq!(summary_json(&w.finish().unwrap()), want);
    }
}

#[test]
fn a_simulation_writing_files_refuses_to_reset() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = from_text(COURIER, "courier")
        .rrd(dir.path().join("a.rrd"))
        .build()
        .unwrap();
    let e = s.reset(2).unwrap_err().to_string();
    assert!(e.contains("writes recordings"), "{e}");
}

/// Every robot's true pose, each tick, as a program's own Evaluate system saw it.
#[derive(Resource, Default)]
struct Watched(Vec<(u64, Entity, Pose2)>);

fn watch(
    clock: Res<systems::core::SimClock>,
    robots: Query<(Entity, &systems::body::TruePose), With<systems::core::RobotId>>,
    mut seen: ResMut<Watched>,
) {
    for (e, p) in &robots {
        seen.0.push((clock.tick, e, p.pose));
    }
}

/// A program's own Control system, ordered after held commands: r1 stands still.
fn hold_r1(mut robots: Query<(&systems::core::RobotId, &mut systems::body::DriveCommand)>) {
    for (name, mut cmd) in &mut robots {
        if name.0 == "r1" {
            *cmd = systems::body::DriveCommand::default();
        }
    }
}

#[test]
fn a_programs_own_systems_run_in_their_sets() {
    use systems::core::SimSet;
    let mut s = Simulation::load("hospital_patrol")
        .duration(2.0)
        .threads(2)
        .build()
        .unwrap();
    let start = s.robot("r1").unwrap().pose();
    let (world, schedule) = s.world_and_schedule();
    world.init_resource::<Watched>();
    schedule.add_systems((
        watch.in_set(SimSet::Evaluate),
        hold_r1
            .in_set(SimSet::Control)
            .after(systems::navigation::held::apply_held_commands),
    ));
    s.run_for(1.0).unwrap();
    let seen = &s.world().resource::<Watched>().0;
    // four robots, twenty ticks, in tick order
    assert_eq!(seen.len(), 4 * 20);
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0));
    let r2 = s.robot("r2").unwrap();
    let last = seen
        .iter()
        .rev()
        .find(|(_, e, _)| *e == r2.entity())
        .unwrap();
    assert_eq!(last.2, r2.pose(), "Evaluate sees the tick's final poses");
    let r1 = s.robot("r1").unwrap().pose();
    assert!(
        r1.distance(&start) < 1e-6,
        "r1 held still: {r1:?} from {start:?}"
    );
    assert!(r2.distance() > 0.1, "r2 drove on");
}
