//! User controllers and estimators: a controller drives its robot exactly as the same held
//! command would, a failing one ends the run with an error naming the robot and the tick, and
//! bad registrations are typed errors.

use crate::run::{Command, SimError, Simulation, SimulationBuilder, Twist};
use systems::mapping::{ScanToMapConfig, ScanToMapSlam};

/// A walled 6 m room, one robot with a laser and encoders standing still.
const ROOM: &str = r#"
name = "room"
seed = 3
duration = 3.0
walls = [
  { from = [0.0, 0.0], to = [6.0, 0.0], thickness = 0.2 },
  { from = [0.0, 6.0], to = [6.0, 6.0], thickness = 0.2 },
  { from = [0.0, 0.0], to = [0.0, 6.0], thickness = 0.2 },
  { from = [6.0, 0.0], to = [6.0, 6.0], thickness = 0.2 },
]
[[robots]]
name = "r1"
start = [2.0, 3.0, 0.0]
behaviour = { type = "wander", speed = 0.4 }
[robots.sensors.laser]
preset = "hokuyo_urg04lx"
[robots.sensors.encoder]
"#;

fn room() -> SimulationBuilder {
    Simulation::from_toml(ROOM, "room")
}

#[test]
fn a_controller_drives_its_robot_as_the_same_held_command_would() {
    let mut by_controller = room()
        .controller("r1", |_: &super::Observation| Twist { v: 0.3, w: 0.2 })
        .build()
        .unwrap();
    let mut by_command = room().build().unwrap();
    by_command
        .command("r1", Command::Drive { v: 0.3, w: 0.2 })
        .unwrap();
    by_controller.run_for(2.0).unwrap();
    by_command.run_for(2.0).unwrap();
    let (a, b) = (
        by_controller.robot("r1").unwrap(),
        by_command.robot("r1").unwrap(),
    );
    assert_eq!(a.pose(), b.pose());
    assert_eq!(a.odometry(), b.odometry());
    // it moved: forward and turning left
    assert!(a.pose().x > 2.3 && a.pose().y > 3.0, "{:?}", a.pose());
}

#[test]
fn a_controller_sees_its_robot_and_the_clock() {
    let mut seen = Vec::new();
    let (tx, rx) = std::sync::mpsc::channel();
    let mut s = room()
        .controller("r1", move |o: &super::Observation| {
            tx.send((
                o.tick,
                o.time,
                o.robot.name().to_string(),
                o.robot.scan().is_some(),
            ))
            .unwrap();
            Twist::default()
        })
        .build()
        .unwrap();
    s.run_for(0.5).unwrap();
    seen.extend(rx.try_iter());
    assert_eq!(seen.len() as u64, s.ticks());
    assert_eq!(seen[0].0, 0);
    assert_eq!(seen[0].2, "r1");
    assert!((seen[3].1 - 3.0 * s.scenario().dt).abs() < 1e-12);
    // the laser's first scan is read by a later tick's controller
    assert!(seen.iter().any(|s| s.3));
    // standing still: the wander behaviour no longer drives
    assert_eq!(s.robot("r1").unwrap().pose().x, 2.0);
}

#[test]
fn a_panicking_controller_ends_the_run_naming_the_robot_and_the_tick() {
    let s = room()
        .controller("r1", |o: &super::Observation| {
            if o.tick == 7 {
                panic!("lost my way");
            }
            Twist { v: 0.2, w: 0.0 }
        })
        .build()
        .unwrap();
    let err = s.run().err().expect("the run fails");
    let e = err.downcast_ref::<SimError>().expect("a SimError");
    match e {
        SimError::ControllerFailed {
            robot, tick, what, ..
        } => {
            assert_eq!(robot, "r1");
            assert_eq!(*tick, 7);
            assert!(what.contains("lost my way"), "{what}");
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("robot `r1`") && err.to_string().contains("tick 7"));
}

#[test]
fn a_non_finite_command_is_an_error_and_the_simulation_stops_stepping() {
    let mut s = room()
        .controller("r1", |o: &super::Observation| Twist {
            v: if o.tick < 3 { 0.1 } else { f64::NAN },
            w: 0.0,
        })
        .build()
        .unwrap();
    let e = s.run_for(1.0).unwrap_err();
    assert!(
        matches!(&e, SimError::ControllerFailed { tick: 3, what, .. } if what.contains("not finite")),
        "{e}"
    );
    let ticks = s.ticks();
    assert_eq!(s.step().unwrap_err(), e);
    assert_eq!(s.ticks(), ticks, "no tick after the failure");
    // the run can still be finished, covering the ticks run
    let done = s.finish().unwrap();
    assert!((done.summary.sim_time_s - 4.0 * 0.05).abs() < 1e-9 || done.summary.sim_time_s > 0.0);
}

#[test]
fn bad_registrations_are_typed_errors() {
    let e = room()
        .controller("r9", |_: &super::Observation| Twist::default())
        .build()
        .err()
        .unwrap();
    assert!(
        matches!(e.downcast_ref::<SimError>(), Some(SimError::UnknownRobot { name, .. }) if name == "r9"),
        "{e}"
    );
    let e = room()
        .controller("r1", |_: &super::Observation| Twist::default())
        .controller("r1", |_: &super::Observation| Twist::default())
        .build()
        .err()
        .unwrap();
    assert!(e.to_string().contains("one controller per robot"), "{e}");
    let slam = || ScanToMapSlam::new(ScanToMapConfig::default());
    let e = room()
        .slam("r1", "a", slam())
        .slam("r1", "a", slam())
        .build()
        .err()
        .unwrap();
    assert!(e.to_string().contains("`a`"), "{e}");
    let no_laser = ROOM.replace("[robots.sensors.laser]\npreset = \"hokuyo_urg04lx\"\n", "");
    let e = Simulation::from_toml(&no_laser, "room")
        .slam("r1", "a", slam())
        .build()
        .err()
        .unwrap();
    assert!(
        matches!(e.downcast_ref::<SimError>(), Some(SimError::NoSuchSensor { robot, .. }) if robot == "r1"),
        "{e}"
    );
}

#[test]
fn a_users_slam_system_is_evaluated_and_summarised_under_its_name() {
    // its map frame is the world frame: it starts at the robot's start pose
    let config = ScanToMapConfig {
        init_pose: systems::core::Pose2::new(2.0, 3.0, 0.0),
        ..ScanToMapConfig::default()
    };
    let mut s = room()
        .slam("r1", "my_slam", ScanToMapSlam::new(config))
        .build()
        .unwrap();
    s.run_for(2.0).unwrap();
    let view = s
        .robot("r1")
        .unwrap()
        .localizer("my_slam")
        .expect("its view");
    assert_eq!(view.kind, "scan_to_map");
    let e = view.estimate.expect("an estimate after 2 s of scans");
    let truth = s.robot("r1").unwrap().pose();
    assert!(truth.x != 2.0, "the robot wandered");
    assert!(
        (e.pose.x - truth.x).abs() < 0.2 && (e.pose.y - truth.y).abs() < 0.2,
        "{e:?} {truth:?}"
    );
    assert!(view.map().is_some() && !view.trajectory().is_empty());
    let done = s.finish().unwrap();
    let json = serde_json::to_string(&done.summary).unwrap();
    assert!(json.contains("\"my_slam\""), "{json}");
}
