//! A scenario built in code equals the same scenario written in TOML (the resolved value, the
//! defaults of a bare robot, the errors with their keys, and a run's summary).

use super::*;
use crate::run::{Finished, Simulation};
use crate::scenario::{
    EncoderFile, KinematicsFile, LaserFile, LocalizerFile, LocalizerType, NavigationFile,
    RobotConfig, RouteFile, SensorName, SlamFile, SlamType, TaskFile, assets_dir, parse_scenario,
};

/// Parses scenario text as a file in the bundled scenarios' folder would be.
fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    parse_scenario(text, "t.toml", &assets_dir().join("scenarios"), "t")
}

/// The resolved scenario as text, its source (the file's name, or `<code>`) aside.
fn fingerprint(mut s: Scenario) -> String {
    s.source = String::new();
    format!("{s:?}")
}

const SHAPES_TOML: &str = r#"
name = "shapes"
description = "two robots in a room"
seed = 3
dt = 0.05
duration = 2.0
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0] },
  { from = [10.0, 0.0], to = [10.0, 8.0] },
  { from = [10.0, 8.0], to = [0.0, 8.0] },
  { from = [0.0, 8.0], to = [0.0, 0.0] },
  { from = [5.0, 0.0], to = [5.0, 4.0], thickness = 0.2 },
]
boxes = [{ center = [7.0, 6.0], size = [1.0, 0.5], yaw = 0.3 }]
discs = [{ center = [2.0, 6.0], radius = 0.3 }]

[places.dock]
pose = [2.0, 2.0, 0.0]

[record]
rate = 5.0

[[robots]]
name = "r1"
start = "dock"
footprint = { circle = 0.3 }
behaviour = { type = "wander", speed = 0.5 }
[robots.sensors.laser]
preset = "sick_lms100"
max_range = 8.0
[robots.sensors.encoder]
slip_std = 0.01
[[robots.localization]]
type = "mcl"
max_particles = 300
init = "pose"

[[robots]]
name = "r2"
start = [8.0, 2.0, 1.57]
footprint = { rectangle = [0.5, 0.4] }
kinematics = { type = "diff_drive", wheel_base = 0.4 }
behaviour = { type = "waypoints", points = [[8.0, 5.0], "dock"], loop = true, tolerance = 0.3 }
[robots.sensors.laser]
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
name = "amcl"
max_particles = 200
"#;

fn shapes_built() -> ScenarioBuilder {
    Scenario::builder("shapes")
        .description("two robots in a room")
        .seed(3)
        .dt(0.05)
        .duration(2.0)
        .room([0.0, 0.0], [10.0, 8.0])
        .wall_table(WallFile {
            from: [5.0, 0.0],
            to: [5.0, 4.0],
            thickness: Some(0.2),
        })
        .box_table(BoxFile {
            center: [7.0, 6.0],
            size: [1.0, 0.5],
            yaw: Some(0.3),
        })
        .disc([2.0, 6.0], 0.3)
        .place("dock", [2.0, 2.0, 0.0])
        .record(RecordFile {
            rate: Some(5.0),
            ..Default::default()
        })
        .robot(
            RobotConfig::builder("r1", "dock")
                .circle(0.3)
                .wander()
                .speed(0.5)
                .laser(LaserFile {
                    max_range: Some(8.0),
                    ..LaserFile::preset("sick_lms100")
                })
                .encoder(EncoderFile {
                    slip_std: Some(0.01),
                    ..Default::default()
                })
                .localizer(LocalizerFile {
                    max_particles: Some(300),
                    init: Some(super::super::localizers::InitType::Pose),
                    ..LocalizerFile::of_type(LocalizerType::Mcl)
                }),
        )
        .robot(
            RobotConfig::builder("r2", [8.0, 2.0, 1.57])
                .rectangle(0.5, 0.4)
                .kinematics(KinematicsFile {
                    wheel_base: Some(0.4),
                    ..KinematicsFile::diff_drive()
                })
                .waypoints([PointOrPlace::from([8.0, 5.0]), "dock".into()], true)
                .tolerance(0.3)
                .laser(LaserFile::default())
                .encoder(EncoderFile::default())
                .localizer(LocalizerFile {
                    name: Some("amcl".into()),
                    max_particles: Some(200),
                    ..LocalizerFile::of_type(LocalizerType::Mcl)
                }),
        )
}

const HOSPITAL_TOML: &str = r#"
name = "ward_run"
duration = 30.0
end_when_done = true

[map]
file = "../maps/hospital/hospital.yaml"
places = "../maps/hospital/places.toml"

[places.lobby]
pose = [32.0, 16.0, 0.0]

[doors.side]
from = [41.9, 11.6]
to = [44.6, 11.6]
thickness = 0.2

[[robots]]
name = "courier"
start = "charger_1"
footprint = { circle = 0.3 }
navigation = { localizer = "mcl", speed = 0.8 }
[robots.sensors.laser]
mount = [0.15, 0.0, 0.0]
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
init = "pose"
max_particles = 500
[[robots.tasks]]
type = "delivery"
name = "drugs"
from = "pharmacy"
to = "ward_2"
load = 5.0
[[robots.tasks]]
type = "go"
to = "lobby"

[[people]]
name = "visitor"
route = ["corridor_main_w", "corridor_main_c"]
loop = true
speed = 1.0

[[events]]
at = 10.0
type = "door"
door = "fire_door_w"
open = false

[[events]]
at = 5.0
type = "sensor_fault"
robot = "courier"
sensor = "laser"
active = true
"#;

fn hospital_built() -> ScenarioBuilder {
    Scenario::builder("ward_run")
        .duration(30.0)
        .end_when_done(true)
        .relative_to(assets_dir().join("scenarios"))
        .map_file("../maps/hospital/hospital.yaml")
        .places_file("../maps/hospital/places.toml")
        .place("lobby", [32.0, 16.0, 0.0])
        .door_table(
            "side",
            DoorFile {
                from: [41.9, 11.6],
                to: [44.6, 11.6],
                thickness: Some(0.2),
            },
        )
        .robot(
            RobotConfig::builder("courier", "charger_1")
                .circle(0.3)
                .navigation(NavigationFile {
                    localizer: Some("mcl".into()),
                    speed: Some(0.8),
                    ..Default::default()
                })
                .laser(LaserFile {
                    mount: Some([0.15, 0.0, 0.0]),
                    ..Default::default()
                })
                .encoder(EncoderFile::default())
                .localizer(LocalizerFile {
                    init: Some(super::super::localizers::InitType::Pose),
                    max_particles: Some(500),
                    ..LocalizerFile::of_type(LocalizerType::Mcl)
                })
                .task(TaskFile {
                    load: Some(5.0),
                    ..TaskFile::delivery("pharmacy", "ward_2").named("drugs")
                })
                .task(TaskFile::go("lobby")),
        )
        .person(PersonFile {
            looping: Some(true),
            speed: Some(1.0),
            ..PersonFile::new("visitor", ["corridor_main_w", "corridor_main_c"])
        })
        .event(EventFile::door(10.0, "fire_door_w", false))
        .event(EventFile::sensor_fault(
            5.0,
            "courier",
            SensorName::Laser,
            true,
        ))
}

#[test]
fn a_shapes_world_built_in_code_equals_its_toml() {
    let built = shapes_built().build().unwrap();
    let file = parse(SHAPES_TOML).unwrap();
    assert_eq!(built.source, CODE_LABEL);
    assert_eq!(built.robots.len(), 2);
    assert_eq!(fingerprint(built), fingerprint(file));
}

#[test]
fn a_map_world_with_tasks_people_and_events_built_in_code_equals_its_toml() {
    let built = hospital_built().build().unwrap();
    let file = parse(HOSPITAL_TOML).unwrap();
    // the scenario's own place and door join the places file's
    assert!(built.places.contains_key("lobby") && built.places.contains_key("pharmacy"));
    assert!(
        built
            .doors
            .iter()
            .any(|d| d.name == "side" && d.thickness == 0.2)
    );
    assert_eq!(built.people.len(), 1);
    assert_eq!(built.events.len(), 2);
    assert!(built.robots[0].navigation.is_some());
    assert_eq!(fingerprint(built), fingerprint(file));
}

#[test]
fn a_robot_with_only_a_name_and_a_start_takes_the_files_defaults() {
    let room = "duration = 1.0\nwalls = [{ from = [0.0, 0.0], to = [6.0, 6.0] }]\n";
    let file = parse(&format!(
        "{room}[[robots]]\nname = \"bare\"\nstart = [1.0, 4.0, 0.5]\n"
    ))
    .unwrap();
    let built = Scenario::builder("t")
        .duration(1.0)
        .wall([0.0, 0.0], [6.0, 6.0])
        .robot(RobotConfig::builder("bare", [1.0, 4.0, 0.5]))
        .build()
        .unwrap();
    assert_eq!(
        format!("{:?}", built.robots[0]),
        format!("{:?}", file.robots[0])
    );
    // and the scenario's own defaults (seed, dt, record rates) are the file's too
    assert_eq!(fingerprint(built), fingerprint(file));
}

/// A one-robot room: the TOML of the robot's extra `lines`, and the builder of `robot`.
fn bad(lines: &str, robot: RobotBuilder) -> (ScenarioError, ScenarioError) {
    let room = "duration = 1.0\nwalls = [{ from = [0.0, 0.0], to = [6.0, 6.0] }]\n\
                [places.home]\npose = [1.0, 4.0, 0.0]\n";
    let text = format!("{room}[[robots]]\nname = \"r\"\nstart = [1.0, 4.0, 0.0]\n{lines}");
    let file = parse(&text).expect_err("the file should be rejected");
    let built = Scenario::builder("t")
        .duration(1.0)
        .wall([0.0, 0.0], [6.0, 6.0])
        .place("home", [1.0, 4.0, 0.0])
        .robot(robot)
        .build()
        .expect_err("the built scenario should be rejected");
    (built, file)
}

/// The builder's error is the file's, key and message, without a line.
fn same_error(built: &ScenarioError, file: &ScenarioError, key: &str) {
    assert_eq!(built.key.as_deref(), Some(key), "{built}");
    assert_eq!(file.key.as_deref(), Some(key), "{file}");
    assert_eq!(built.message, file.message);
    assert_eq!((built.file.as_str(), built.line), (CODE_LABEL, None));
    assert_eq!(
        built.to_string(),
        format!("<code>: `{key}`: {}", file.message)
    );
}

fn robot() -> RobotBuilder {
    RobotConfig::builder("r", [1.0, 4.0, 0.0])
}

#[test]
fn a_negative_laser_range_is_the_files_error() {
    let (built, file) = bad(
        "[robots.sensors.laser]\nmax_range = -1.0\n",
        robot().laser(LaserFile {
            max_range: Some(-1.0),
            ..Default::default()
        }),
    );
    same_error(&built, &file, "robots[0].sensors.laser.max_range");
    assert!(built.message.contains("got -1"), "{built}");
}

#[test]
fn an_unknown_preset_is_the_files_error() {
    let (built, file) = bad("preset = \"tank\"\n", robot().preset("tank"));
    same_error(&built, &file, "robots[0].preset");
    assert!(
        built.message.contains("unknown robot preset `tank`"),
        "{built}"
    );
    let (built, file) = bad(
        "[robots.sensors.laser]\npreset = \"lidar9000\"\n",
        robot().laser(LaserFile::preset("lidar9000")),
    );
    same_error(&built, &file, "robots[0].sensors.laser.preset");
}

#[test]
fn an_unknown_place_in_a_waypoint_is_the_files_error() {
    let (built, file) = bad(
        "[robots.sensors.encoder]\n[robots.behaviour]\ntype = \"waypoints\"\n\
         points = [\"home\", \"nowhere\"]\n",
        robot()
            .encoder(EncoderFile::default())
            .waypoints(["home", "nowhere"], false),
    );
    same_error(&built, &file, "robots[0].behaviour.points[1]");
    assert!(built.message.contains("unknown place `nowhere`"), "{built}");
}

#[test]
fn an_unknown_localizer_type_is_the_files_error() {
    let (built, file) = bad(
        "[robots.sensors.laser]\n[robots.sensors.encoder]\n\
         [[robots.localization]]\ntype = \"mcl\"\n[[robots.localization]]\ntype = \"kalman\"\n",
        robot()
            .laser(LaserFile::default())
            .encoder(EncoderFile::default())
            .localizer_type("mcl")
            .localizer_type("kalman"),
    );
    same_error(&built, &file, "robots[0].localization[1].type");
    assert!(
        built.message.contains("unknown variant `kalman`"),
        "{built}"
    );
}

#[test]
fn a_behaviour_driving_by_an_unknown_localizer_is_the_files_error() {
    let (built, file) = bad(
        "[robots.sensors.laser]\n[robots.sensors.encoder]\n[robots.behaviour]\n\
         type = \"waypoints\"\npoints = [\"home\"]\nlocalizer = \"amcl\"\n\
         [[robots.localization]]\ntype = \"mcl\"\n",
        robot()
            .laser(LaserFile::default())
            .encoder(EncoderFile::default())
            .waypoints(["home"], false)
            .behaviour_localizer("amcl")
            .localizer_type("mcl"),
    );
    same_error(&built, &file, "robots[0].behaviour.localizer");
    assert!(
        built
            .message
            .contains("no localizer named `amcl`; the robot has: mcl"),
        "{built}"
    );
    // an idle robot has nothing to drive by it
    let (built, file) = bad(
        "[robots.sensors.laser]\n[robots.sensors.encoder]\n[robots.behaviour]\n\
         type = \"idle\"\nlocalizer = \"mcl\"\n[[robots.localization]]\ntype = \"mcl\"\n",
        robot()
            .laser(LaserFile::default())
            .encoder(EncoderFile::default())
            .idle()
            .behaviour_localizer("mcl")
            .localizer_type("mcl"),
    );
    same_error(&built, &file, "robots[0].behaviour.localizer");
    assert!(
        built.message.contains("`idle` robot does not move"),
        "{built}"
    );
}

#[test]
fn a_place_given_twice_is_an_error() {
    let e = hospital_built()
        .place("pharmacy", [3.0, 13.0, 0.0])
        .build()
        .unwrap_err();
    assert_eq!(e.key.as_deref(), Some("places.pharmacy"), "{e}");
    assert!(e.message.contains("also in the places file"), "{e}");
}

/// A run's summary and event log, wall-clock times aside.
fn summary_json(done: &Finished) -> String {
    let v = serde_json::to_value(done.summary.deterministic_part()).unwrap();
    format!("{v}\n{:?}", done.log)
}

#[test]
fn a_built_scenario_runs_as_its_toml() {
    let built = shapes_built().seed(11).build().unwrap();
    let a = Simulation::from_scenario(built)
        .duration(2.0)
        .build()
        .unwrap()
        .run()
        .unwrap();
    let b = Simulation::from_toml(SHAPES_TOML, CODE_LABEL)
        .seed(11)
        .duration(2.0)
        .build()
        .unwrap()
        .run()
        .unwrap();
    assert_eq!(a.summary.sim_time_s, 2.0);
    assert_eq!(summary_json(&a), summary_json(&b));
}

#[test]
fn an_outdoor_world_with_a_route_robot_built_in_code_equals_its_toml() {
    let text = r#"
name = "park"
duration = 10.0
[roads]
file = "../roads/park/park.osm"
reference = [50.0645, 14.418]
[[zones]]
name = "transformer"
kind = "em"
circle = { center = [46.0, 6.0], radius = 12.0 }
[[robots]]
name = "car"
preset = "thesis_car"
[robots.route]
start = "37"
toward = "19"
goal = "10"
speed = 1.0
"#;
    let built = Scenario::builder("park")
        .duration(10.0)
        .relative_to(assets_dir().join("scenarios"))
        .roads(RoadsFile {
            file: "../roads/park/park.osm".into(),
            reference: Some([50.0645, 14.418]),
            ..Default::default()
        })
        .zone(ZoneFile {
            name: "transformer".into(),
            kind: "em".into(),
            circle: Some(super::super::outdoor::CircleFile {
                center: [46.0, 6.0],
                radius: 12.0,
            }),
            ..Default::default()
        })
        .robot(
            RobotConfig::builder_on_route(
                "car",
                RouteFile {
                    start: "37".into(),
                    toward: Some("19".into()),
                    goal: "10".into(),
                    speed: Some(1.0),
                    ..Default::default()
                },
            )
            .preset("thesis_car"),
        )
        .build()
        .unwrap();
    assert!(built.roads.is_some() && built.robots[0].route.is_some());
    assert_eq!(fingerprint(built), fingerprint(parse(text).unwrap()));
}

#[test]
fn slam_systems_built_in_code_equal_their_toml() {
    let room = "duration = 1.0\nwalls = [{ from = [0.0, 0.0], to = [6.0, 6.0] }]\n\
                [[robots]]\nname = \"r\"\nstart = [1.0, 4.0, 0.0]\n\
                sensors = { laser = {}, encoder = {} }\n";
    let robot = || {
        RobotConfig::builder("r", [1.0, 4.0, 0.0])
            .laser(LaserFile::default())
            .encoder(EncoderFile::default())
    };
    let build = |r: RobotBuilder| {
        Scenario::builder("t")
            .duration(1.0)
            .wall([0.0, 0.0], [6.0, 6.0])
            .robot(r)
            .build()
    };
    // one system is the `slam = { … }` table
    let one = build(robot().slam(SlamFile {
        resolution: Some(0.1),
        ..SlamFile::of_type(SlamType::Graph)
    }))
    .unwrap();
    let file = parse(&format!(
        "{room}slam = {{ type = \"graph\", resolution = 0.1 }}\n"
    ))
    .unwrap();
    assert_eq!(fingerprint(one), fingerprint(file));
    // several are `[[robots.slam]]` tables, and their errors name the index
    let two = build(
        robot()
            .slam(SlamFile::of_type(SlamType::ScanToMap))
            .slam(SlamFile {
                resolution: Some(0.0),
                ..SlamFile::of_type(SlamType::Rbpf)
            }),
    )
    .unwrap_err();
    let file = parse(&format!(
        "{room}[[robots.slam]]\ntype = \"scan_to_map\"\n[[robots.slam]]\ntype = \"rbpf\"\nresolution = 0.0\n"
    ))
    .unwrap_err();
    same_error(&two, &file, "robots[0].slam[1].resolution");
}
