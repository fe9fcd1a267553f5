//! A run through the builder equals `sim run`'s; stepping reads the robots; overrides change the
//! file; every bad request is a typed error naming what it concerns.

use super::*;

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
    let a = serde_json::to_value(built.summary.deterministic_part()).unwrap();
    let b = serde_json::to_value(direct.summary.deterministic_part()).unwrap();
    assert_eq!(a, b);
    // each localizer's cost per update is timed: 4 robots × 5 localizers, every 50 Hz scan
    // consumed; the timings differ between the two runs, their deterministic parts do not
    let timed = &built.summary.timing.localizers;
    assert_eq!(timed.len(), 20);
    assert_eq!(
        (timed[0].robot.as_str(), timed[0].localizer.as_str()),
        ("r1", "mcl")
    );
    for t in timed {
        assert!((145..=155).contains(&t.updates), "{t:?}");
        assert!(t.total_s > 0.0 && t.mean_update_us > 0.0, "{t:?}");
        assert!(t.max_update_us >= t.mean_update_us, "{t:?}");
    }
    assert_ne!(timed, &direct.summary.timing.localizers);
    assert_eq!(
        built.summary.deterministic_part(),
        direct.summary.deterministic_part()
    );
    assert!(
        built
            .summary
            .deterministic_part()
            .timing
            .localizers
            .is_empty()
    );
    let json = serde_json::to_value(&built.summary).unwrap();
    assert!(json["timing"]["localizers"][19]["mean_update_us"].is_f64());
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
fn a_look_ahead_longer_than_the_map_still_drives() {
    // the clearance check samples the arc to the look-ahead point every half cell: sized from
    // the look-ahead alone, 1e9 m asked for a terabyte; the arc ends on the path, in the map
    let text = COURIER.replace(
        "navigation = { speed = 0.8 }",
        "navigation = { speed = 0.8, lookahead = 1e9 }",
    );
    let mut s = from_text(&text, "far").build().unwrap();
    let start = s.robot("r1").unwrap().pose();
    s.run_for(10.0).unwrap();
    let end = s.robot("r1").unwrap().pose();
    assert!(end.distance(&start) > 1.0, "{start:?} -> {end:?}");
}

/// Built without the `rrd` feature (as the fuzz crate builds it), a run asked for a .rrd is
/// refused before its first tick, naming the file and the feature; without one it runs.
#[cfg(not(feature = "rrd"))]
#[test]
fn a_build_without_the_recording_refuses_a_rrd_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("patrol.rrd");
    let e = Simulation::load("maze_run")
        .duration(0.5)
        .threads(1)
        .rrd(&path)
        .build()
        .err()
        .expect("a .rrd refused");
    let text = format!("{e:#}");
    assert!(
        text.contains("patrol.rrd") && text.contains("`rrd`"),
        "{text}"
    );
    assert!(!path.exists());
    let run = Simulation::load("maze_run")
        .duration(0.5)
        .threads(1)
        .build()
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(run.summary.sim_time_s, 0.5);
}
