//! Outdoor scenario keys: `[roads]`, `[[zones]]`, the `thesis_car` preset, GPS, compass and
//! camera tables and `[robots.route]`; bad input names the file, line and key.

use crate::common::*;
use systems::body::{Footprint, Kinematics};

/// A park world with one robot whose route table is `route` (TOML lines).
fn park(robot: &str) -> String {
    format!(
        "duration = 1.0\n[roads]\nfile = \"../roads/park/park.osm\"\n\
         [[robots]]\nname = \"car\"\n{robot}\n"
    )
}

fn line_of(text: &str, prefix: &str) -> usize {
    text.lines().position(|l| l.starts_with(prefix)).unwrap() + 1
}

/// The error is at the first line starting with `prefix`.
fn expect_at(text: &str, prefix: &str, fragments: &[&str]) {
    expect_error(text, line_of(text, prefix), fragments);
}

#[test]
fn the_thesis_car_preset_gives_the_thesis_robot() {
    let s = scenario(&park(
        "preset = \"thesis_car\"\n[robots.route]\nstart = \"37\"\ntoward = \"19\"\ngoal = \"10\"",
    ));
    let r = &s.robots[0];
    assert_eq!(
        r.footprint,
        Footprint::Rectangle {
            length: 0.52,
            width: 0.40
        }
    );
    assert!(matches!(r.kinematics, Kinematics::Ackermann(_)));
    let enc = r.encoder.as_ref().unwrap();
    assert!(enc.left_radius_error > 0.0 && enc.left_radius_error <= 0.011);
    assert_eq!(
        r.sonar.as_ref().unwrap().mounts.len(),
        4,
        "front, ±45°, rear"
    );
    assert!(r.gps.is_some() && r.compass.is_some() && r.camera.is_some());
    // the robot starts on node 37 facing node 19 (azimuth 344.1°: north-north-west)
    let g = &s.roads.as_ref().unwrap().graph;
    let n37 = g.nodes[g.node_by_source("37").unwrap()].pos;
    assert!((r.start.x - n37[0]).hypot(r.start.y - n37[1]) < 1e-9);
    let azimuth = (90.0 - r.start.theta.to_degrees()).rem_euclid(360.0);
    assert!((azimuth - 344.1).abs() < 0.2, "{azimuth}");
    assert!(s.grid.resolution > 0.1, "outdoors the grid is coarse");
}

#[test]
fn sensor_tables_override_the_preset() {
    let s = scenario(&park(
        "preset = \"thesis_car\"\n[robots.sensors.gps]\nrate = 2.0\nstart = \"cold\"\n\
         [robots.sensors.compass]\nnoise_std_deg = 0.2\n[robots.sensors.camera]\nwidth = 160\n\
         [robots.route]\nstart = \"13\"\ngoal = \"36\"",
    ));
    let r = &s.robots[0];
    let gps = r.gps.as_ref().unwrap();
    assert_eq!(gps.rate, 2.0);
    assert_eq!(gps.first_fix, 35.0, "cold start");
    assert_eq!(r.compass.as_ref().unwrap().noise_std_deg, 0.2);
    assert_eq!(r.camera.as_ref().unwrap().width, 160);
}

#[test]
fn zones_are_read_and_checked() {
    let ok = format!(
        "{}[[zones]]\nname = \"grove\"\nkind = \"trees\"\npolygon = [[0.0, 0.0], [10.0, 0.0], [5.0, 8.0]]\n\
         [[zones]]\nname = \"spot\"\nkind = \"em\"\ncircle = {{ center = [46.0, 6.0], radius = 12.0 }}\n",
        park("start = [0.0, 4.0, 0.0]")
    );
    let s = scenario(&ok);
    assert_eq!(s.zones.len(), 2);
    let bad_kind = ok.replace("kind = \"trees\"", "kind = \"fog\"");
    expect_at(
        &bad_kind,
        "kind = \"fog\"",
        &["fog", "open, trees, buildings or em"],
    );
    let two_vertices = ok.replace(", [5.0, 8.0]]", "]");
    expect_at(&two_vertices, "polygon", &["at least 3 vertices"]);
    let bad_radius = ok.replace("radius = 12.0", "radius = -1.0");
    expect_at(&bad_radius, "circle", &["radius"]);
}

#[test]
fn route_errors_name_the_key() {
    let no_roads = "duration = 1.0\nwalls = [{ from = [0.0, 0.0], to = [10.0, 0.0] }]\n\
                    [[robots]]\nname = \"car\"\npreset = \"thesis_car\"\n[robots.route]\nstart = \"1\"\ngoal = \"2\"\n";
    expect_at(no_roads, "[robots.route]", &["road network"]);
    let t = park("preset = \"thesis_car\"\n[robots.route]\nstart = \"999\"\ngoal = \"10\"");
    expect_at(&t, "start = \"999\"", &["no node `999`"]);
    let t = park("preset = \"thesis_car\"\n[robots.route]\nstart = \"37\"\ngoal = \"10\"");
    expect_at(&t, "[robots.route]", &["toward", "19", "25"]);
    let t = park(
        "preset = \"thesis_car\"\n[robots.route]\nstart = \"37\"\ntoward = \"10\"\ngoal = \"10\"",
    );
    expect_at(&t, "toward", &["not a neighbour"]);
    let t = park(
        "preset = \"thesis_car\"\n[robots.route]\nstart = \"13\"\ngoal = \"36\"\nnavigate_by = \"amcl\"",
    );
    expect_at(&t, "navigate_by", &["road_grid", "road_mcl"]);
    let t = park("[robots.sensors.encoder]\n[robots.route]\nstart = \"13\"\ngoal = \"36\"");
    expect_at(
        &t,
        "[robots.route]",
        &["gps", "compass", "camera", "thesis_car"],
    );
    let t = park(
        "preset = \"thesis_car\"\nstart = [0.0, 4.0, 0.0]\n[robots.route]\nstart = \"13\"\ngoal = \"36\"",
    );
    expect_at(&t, "start = [", &["remove `start`"]);
    let t = park("preset = \"rc_truck\"\nstart = [0.0, 4.0, 0.0]");
    expect_at(&t, "preset", &["rc_truck", "thesis_car"]);
}

#[test]
fn outdoor_sensor_errors_name_the_key() {
    let t =
        park("preset = \"thesis_car\"\nstart = [0.0, 4.0, 0.0]\n[robots.sensors.gps]\nrate = 20.0");
    expect_at(&t, "rate = 20.0", &["rate", "[1, 10]"]);
    let t = park(
        "preset = \"thesis_car\"\nstart = [0.0, 4.0, 0.0]\n[robots.sensors.gps]\nstart = \"warm\"",
    );
    expect_at(&t, "start = \"warm\"", &["hot", "cold"]);
    let t = park(
        "preset = \"thesis_car\"\nstart = [0.0, 4.0, 0.0]\n[robots.sensors.camera]\npitch_deg = 95.0",
    );
    expect_at(&t, "pitch_deg", &["pitch_deg"]);
}

#[test]
fn a_malformed_road_file_names_its_own_line() {
    let t = "duration = 1.0\n[roads]\nfile = \"../../tests/fixtures/roads/not_xml.osm\"\n";
    let fixture = repo_file("fixtures/roads/not_xml.osm");
    if !fixture.exists() {
        panic!("fixture missing: {}", fixture.display());
    }
    let e = scenario_error(t);
    assert!(e.starts_with("test.toml:3:"), "{e}");
    assert!(e.contains("not_xml.osm"), "{e}");
    let t = "duration = 1.0\n[roads]\nfile = \"nowhere.osm\"\n";
    let e = scenario_error(t);
    assert!(
        e.contains("nowhere.osm") && e.contains("cannot read"),
        "{e}"
    );
    let t =
        "duration = 1.0\n[roads]\nfile = \"../roads/park/park.osm\"\nreference = [95.0, 14.0]\n";
    let e = scenario_error(t);
    assert!(
        e.starts_with("test.toml:4:") && e.contains("latitude"),
        "{e}"
    );
}
