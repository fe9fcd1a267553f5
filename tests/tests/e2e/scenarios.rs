//! Scenario files: bundled ones load; bad input gives errors naming file, line and key.

use crate::common::*;
use sim::scenario::{bundled_scenarios, load_scenario};

#[test]
fn bundled_scenarios_load() {
    let all = bundled_scenarios().expect("the bundled scenarios are found");
    let names: Vec<&str> = all.iter().map(|(n, _)| n.as_str()).collect();
    assert!(names.contains(&"hospital_patrol"), "{names:?}");
    assert!(names.contains(&"maze_run"), "{names:?}");
    for (name, path) in &all {
        let s = load_scenario(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!s.robots.is_empty(), "{name} has robots");
    }
    let h = load_scenario(&bundled("hospital_patrol")).unwrap();
    assert!(h.robots.len() >= 4);
    assert!(h.people.len() >= 2, "people walk the patrol's corridors");
    for r in &h.robots {
        let l = r.laser.as_ref().expect("every patrol robot has a laser");
        assert_eq!(l.beams(), 1081, "SICK LMS100");
        assert!(r.encoder.is_some());
    }
}

fn with_robot(robot: &str) -> String {
    format!("{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [5.0, 5.0, 0.0]\n{robot}\n")
}

#[test]
fn unknown_top_level_key() {
    expect_error("duration = 1.0\ncolour = \"red\"\n", 2, &["colour"]);
}

#[test]
fn unknown_nested_key() {
    let text = with_robot("[robots.sensors.laser]\npreset = \"sick_lms100\"\nfrequency = 10.0\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("frequency"))
        .unwrap()
        + 1;
    expect_error(&text, line, &["frequency"]);
}

#[test]
fn out_of_range_values_name_the_key() {
    let text = with_robot("[robots.sensors.laser]\ndropout = 1.5\n");
    let line = text.lines().position(|l| l.starts_with("dropout")).unwrap() + 1;
    expect_error(
        &text,
        line,
        &["robots[0].sensors.laser.dropout", "[0, 1]", "1.5"],
    );

    let text = format!("{SQUARE_ROOM}\n").replace("dt = 0.05", "dt = -0.1");
    let line = text.lines().position(|l| l.starts_with("dt")).unwrap() + 1;
    expect_error(&text, line, &["`dt`", "-0.1"]);

    let text = with_robot("kinematics = { type = \"diff_drive\", wheel_radius = 0.0 }\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("kinematics"))
        .unwrap()
        + 1;
    expect_error(&text, line, &["wheel_radius", "greater than 0"]);
}

#[test]
fn type_errors_and_bad_enums() {
    let text = with_robot("[robots.sensors.laser]\nrate = \"fast\"\n");
    let line = text.lines().position(|l| l.starts_with("rate")).unwrap() + 1;
    expect_error(&text, line, &[]);
    let text = with_robot("kinematics = { type = \"tank\" }\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("kinematics"))
        .unwrap()
        + 1;
    expect_error(&text, line, &["tank"]);
}

#[test]
fn semantic_errors() {
    let e = scenario_error(&with_robot(
        "[robots.sensors.laser]\npreset = \"velodyne\"\n",
    ));
    assert!(e.contains("velodyne") && e.contains("sick_lms100"), "{e}");
    let e = scenario_error(&with_robot(
        "kinematics = { type = \"diff_drive\", max_steer = 0.3 }\n",
    ));
    assert!(
        e.contains("max_steer") && e.contains("does not apply"),
        "{e}"
    );
    let e = scenario_error(&with_robot("[robots.sensors.laser]\nmin_range = 30.0\n"));
    assert!(
        e.contains("min_range") && e.contains("below max_range"),
        "{e}"
    );
    // start inside a wall
    let text = format!("{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [0.05, 5.0, 0.0]\n");
    let line = text.lines().position(|l| l.starts_with("start")).unwrap() + 1;
    expect_error(&text, line, &["overlap an obstacle"]);
    // outside the map
    let e = scenario_error(&format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [50.0, 5.0, 0.0]\n"
    ));
    assert!(e.contains("outside the map"), "{e}");
    // duplicate names
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"a\"\nstart = [2.0, 2.0, 0.0]\n[[robots]]\nname = \"a\"\nstart = [5.0, 5.0, 0.0]\n"
    );
    let e = scenario_error(&text);
    assert!(e.contains("duplicate robot name"), "{e}");
    // waypoints need odometry
    let e = scenario_error(&with_robot(
        "behaviour = { type = \"waypoints\", points = [[2.0, 2.0]] }\n",
    ));
    assert!(e.contains("encoder"), "{e}");
    // unknown place
    let e = scenario_error(&with_robot(
        "behaviour = { type = \"waypoints\", points = [\"pharmacy\"] }\n[robots.sensors.encoder]\n",
    ));
    assert!(e.contains("unknown place `pharmacy`"), "{e}");
    // events
    let e = scenario_error(&format!(
        "{}\n[[events]]\nat = 0.5\ntype = \"teleport\"\nrobot = \"nobody\"\npose = [1.0, 1.0, 0.0]\n",
        with_robot("")
    ));
    assert!(e.contains("no robot named `nobody`"), "{e}");
    let e = scenario_error(&format!(
        "{}\n[[events]]\nat = 5.0\ntype = \"sensor_fault\"\nrobot = \"r1\"\nsensor = \"laser\"\n",
        with_robot("[robots.sensors.laser]\n")
    ));
    assert!(e.contains("events[0].at"), "{e}");
    let e = scenario_error(&format!(
        "{}\n[[events]]\nat = 0.5\ntype = \"sensor_fault\"\nrobot = \"r1\"\nsensor = \"encoder\"\n",
        with_robot("")
    ));
    assert!(e.contains("no encoder sensor"), "{e}");
    // held velocity commands
    let event = |body: &str| {
        format!(
            "{}\n[[events]]\nat = 0.5\nrobot = \"r1\"\n{body}",
            with_robot("")
        )
    };
    let e = scenario_error(&event("type = \"drive\"\nv = 0.3\n"));
    assert!(e.contains("a drive event needs `w`"), "{e}");
    let e = scenario_error(&event("type = \"drive\"\nv = nan\nw = 0.0\n"));
    assert!(e.contains("events[0].v") && e.contains("finite"), "{e}");
    let e = scenario_error(&event(
        "type = \"teleport\"\npose = [1.0, 1.0, 0.0]\nv = 0.3\n",
    ));
    assert!(e.contains("`v` applies to `drive` events only"), "{e}");
    // a car's speed/steer form
    let e = scenario_error(&event("type = \"drive\"\nspeed = 0.3\nsteer = 0.1\n"));
    assert!(
        e.contains("events[0].steer") && e.contains("has a differential drive"),
        "{e}"
    );
    let car_event = |body: &str| {
        format!(
            "{}\n[[events]]\nat = 0.5\nrobot = \"r1\"\n{body}",
            with_robot("kinematics = { type = \"ackermann\", max_steer = 0.4 }\n")
        )
    };
    let e = scenario_error(&car_event("type = \"drive\"\nspeed = 0.3\nsteer = 0.5\n"));
    assert!(
        e.contains("events[0].steer") && e.contains("[-0.4, 0.4]"),
        "{e}"
    );
    let e = scenario_error(&car_event("type = \"drive\"\nspeed = 0.3\n"));
    assert!(e.contains("needs both `speed` (m/s) and `steer`"), "{e}");
    let e = scenario_error(&car_event(
        "type = \"drive\"\nspeed = 0.3\nsteer = 0.1\nw = 0.2\n",
    ));
    assert!(
        e.contains("events[0].w") && e.contains("two forms of a drive event"),
        "{e}"
    );
    let e = scenario_error(&car_event("type = \"release\"\nsteer = 0.1\n"));
    assert!(e.contains("`steer` applies to `drive` events only"), "{e}");
    let e = scenario_error(&car_event(
        "type = \"teleport\"\npose = [1.0, 1.0, 0.0]\nspeed = 0.3\n",
    ));
    assert!(e.contains("`speed` applies to `drive` events only"), "{e}");
    let e = scenario_error(&event("type = \"release\"\npose = [1.0, 1.0, 0.0]\n"));
    assert!(
        e.contains("`pose` does not apply to a `release` event"),
        "{e}"
    );
    // new tasks
    let e = scenario_error(&event(
        "type = \"tasks\"\ntasks = [{ type = \"go\", to = [2.0, 2.0] }]\n",
    ));
    assert!(
        e.contains("events[0].robot") && e.contains("no task queue"),
        "{e}"
    );
    let navigating = |body: &str| {
        format!(
            "{}\n[[events]]\nat = 0.5\nrobot = \"r1\"\n{body}",
            with_robot(
                "[robots.sensors.laser]\n[robots.sensors.encoder]\n\
                 [[robots.tasks]]\ntype = \"wait\"\ntime = 1.0\n"
            )
        )
    };
    let e = scenario_error(&navigating("type = \"tasks\"\n"));
    assert!(e.contains("a tasks event needs `tasks`"), "{e}");
    let e = scenario_error(&navigating(
        "type = \"tasks\"\ntasks = [{ type = \"go\", to = [0.05, 5.0] }]\n",
    ));
    assert!(
        e.contains("events[0].tasks[0].to") && e.contains("too close to an obstacle"),
        "{e}"
    );
    let e = scenario_error(&navigating(
        "type = \"tasks\"\ntasks = [{ type = \"go\", to = [2.0, 2.0] }]\nv = 1.0\n",
    ));
    assert!(e.contains("`v` applies to `drive` events only"), "{e}");
    let e = scenario_error(&navigating(
        "type = \"teleport\"\npose = [2.0, 2.0, 0.0]\ntasks = []\n",
    ));
    assert!(e.contains("`tasks` applies to `tasks` events only"), "{e}");
    // no world
    let e = scenario_error("duration = 3.0\n");
    assert!(e.contains("world is empty"), "{e}");
    let e = scenario_error("walls = [{ from = [0.0, 0.0], to = [1.0, 0.0] }]\n");
    assert!(e.contains("duration"), "{e}");
}

#[test]
fn missing_map_file_is_reported_with_its_key() {
    let text = "duration = 1.0\n[map]\nfile = \"../maps/nowhere/none.yaml\"\n";
    let e = scenario_error(text);
    assert!(e.starts_with("test.toml:3:"), "{e}");
    assert!(e.contains("map.file") && e.contains("none.yaml"), "{e}");
}

#[test]
fn places_resolve_from_the_map_places_file() {
    let s = load_scenario(&bundled("hospital_patrol")).unwrap();
    assert!(s.places.contains_key("pharmacy"), "{:?}", s.places.keys());
}

/// The bundled patrol really patrols: every robot keeps reaching its waypoints (a renamed place
/// or a stuck behaviour shows up here) with few collisions.
#[test]
fn hospital_patrol_robots_make_progress() {
    use sim::{RunOptions, run_scenario};
    for seed in [0, 1] {
        let mut s = load_scenario(&bundled("hospital_patrol")).unwrap();
        s.seed = seed;
        // localizers only write estimates, which nothing that moves the robots reads
        for r in &mut s.robots {
            r.localizers.clear();
        }
        let out = run_scenario(
            &s,
            &RunOptions {
                threads: 2,
                ..Default::default()
            },
        )
        .unwrap();
        for r in &out.summary.robots {
            assert!(r.waypoints_reached >= 5, "seed {seed}: {r:?}");
            assert!(r.collisions <= 3, "seed {seed}: {r:?}");
            assert!(r.distance_m > 40.0, "seed {seed}: {r:?}");
        }
    }
}

/// `[record] map_localizer` must name a localizer some robot has; the error lists them.
#[test]
fn a_map_localizer_no_robot_has_is_an_error() {
    let line_of = |text: &str| {
        text.lines()
            .position(|l| l.starts_with("map_localizer"))
            .unwrap()
            + 1
    };
    let text = format!("{}\n[record]\nmap_localizer = \"amcl\"\n", with_robot(""));
    expect_error(
        &text,
        line_of(&text),
        &["record.map_localizer", "'amcl'", "localizers: none"],
    );
    // a name some robot has is fine, and the error lists the robots' localizers
    let robot = "[robots.sensors.laser]\npreset = \"sick_lms100\"\n[robots.sensors.encoder]\n\
                 [[robots.localization]]\ntype = \"mcl\"\ninit = \"pose\"\n";
    let ok = format!("{}\n[record]\nmap_localizer = \"mcl\"\n", with_robot(robot));
    let s = scenario(&ok);
    assert_eq!(s.record.map_localizer.as_deref(), Some("mcl"));
    let bad = ok.replace("map_localizer = \"mcl\"", "map_localizer = \"amcl\"");
    expect_error(&bad, line_of(&bad), &["'amcl'", "localizers: mcl"]);
}
