//! The default recordings open on a designed layout: the blueprint inside the .rrd (read back
//! with the Rerun 0.36.3 SDK) has the map, one plot per metric family and the event log, and
//! every entity it names exists in the recording; paths go out as new segments, so a run ten
//! times longer writes a file at most eleven times larger.

use crate::common::*;
use sim::scenario::load_scenario;
use sim::{RunOptions, run_scenario};
use std::path::Path;

/// Runs bundled scenario `name` for `secs` with a recording at `path` (`map_localizer` set
/// when given).
fn record(name: &str, secs: f64, path: &Path, map_localizer: Option<&str>) {
    let mut s = load_scenario(&bundled(name)).unwrap();
    s.duration = secs;
    s.record.map_localizer = map_localizer.map(str::to_string);
    run_scenario(
        &s,
        &RunOptions {
            rrd: Some(path.to_path_buf()),
            threads: 2,
            progress: false,
            trajectory_period: None,
        },
    )
    .unwrap();
}

/// The blueprint's view named `name`.
fn view<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    v["blueprint"]["views"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == name)
        .unwrap_or_else(|| panic!("no view {name} in {}", v["blueprint"]))
}

fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

/// Every entity the blueprint queries, hides or draws whole is in the recording.
fn every_named_entity_exists(v: &serde_json::Value) {
    let paths = entity_paths(v);
    let exists = |e: &str| {
        paths
            .iter()
            .any(|p| p == e || p.starts_with(&format!("{e}/")))
    };
    for view in v["blueprint"]["views"].as_array().unwrap() {
        for q in strings(&view["queries"]) {
            if q.starts_with('-') || q == "/**" {
                continue;
            }
            let e = q.trim_end_matches("/**");
            assert!(
                exists(e),
                "{}: query {q} names nothing in {paths:?}",
                view["name"]
            );
        }
        for e in strings(&view["hidden"])
            .into_iter()
            .chain(strings(&view["whole_history"]))
        {
            assert!(exists(&e), "{}: {e} is not in the recording", view["name"]);
        }
    }
}

#[test]
fn the_default_recordings_open_on_a_layout_whose_every_entity_exists() {
    let Some(rerun) = test_tool(TestTool::Rerun) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // indoors: four robots with five localizers each, people
    let patrol = dir.path().join("patrol.rrd");
    record("hospital_patrol", 8.0, &patrol, None);
    let v = check_rrd_with(&rerun, &patrol);
    every_named_entity_exists(&v);
    assert_eq!(v["blueprint"]["auto_views"], false, "{}", v["blueprint"]);
    let map = view(&v, "Map");
    assert_eq!(map["class"], "3D");
    let s = load_scenario(&bundled("hospital_patrol")).unwrap();
    let hidden = strings(&map["hidden"]);
    for r in &s.robots {
        // the first localizer on the map, the others hidden
        for (k, l) in r.localizers.iter().enumerate() {
            let e = format!("/robots/{}/estimate/{}", r.name, l.name);
            assert_eq!(hidden.contains(&e), k > 0, "{e}: {hidden:?}");
        }
        for leaf in ["truth/path", "odometry/path"] {
            let e = format!("/robots/{}/{leaf}", r.name);
            assert!(strings(&map["whole_history"]).contains(&e), "{e}");
        }
    }
    assert!(strings(&map["properties"]).contains(&"EyeControls3D".to_string()));
    for name in [
        "Position error (m)",
        "Heading error (rad)",
        "Odometry drift (m)",
    ] {
        let plot = view(&v, name);
        assert_eq!(plot["class"], "TimeSeries", "{name}");
        assert_eq!(strings(&plot["queries"]).len(), s.robots.len(), "{name}");
        let props = strings(&plot["properties"]);
        assert!(
            props.contains(&"ScalarAxis".to_string()),
            "{name}: {props:?}"
        );
    }
    assert_eq!(view(&v, "Events")["class"], "TextLog");

    // the scenario's choice of the localizer on the map
    let chosen = dir.path().join("chosen.rrd");
    record("hospital_patrol", 3.0, &chosen, Some("de_filter"));
    let v = check_rrd_with(&rerun, &chosen);
    let hidden = strings(&view(&v, "Map")["hidden"]);
    assert!(
        !hidden.iter().any(|h| h.ends_with("/de_filter")),
        "{hidden:?}"
    );
    assert!(
        hidden.contains(&"/robots/r1/estimate/mcl".to_string()),
        "{hidden:?}"
    );

    // outdoors: the camera has its view and stays off the map
    let park = dir.path().join("park.rrd");
    record("park_route_short", 10.0, &park, None);
    let v = check_rrd_with(&rerun, &park);
    every_named_entity_exists(&v);
    let camera = v["blueprint"]["views"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["class"] == "2D")
        .expect("a camera view");
    assert!(camera["origin"].as_str().unwrap().ends_with("/camera"));
    assert!(
        strings(&view(&v, "Map")["queries"])
            .iter()
            .any(|q| q.starts_with("- ") && q.ends_with("/camera"))
    );
    // the legend names the robot: "car gps"
    let gps = v["series_names"]
        .as_object()
        .unwrap()
        .iter()
        .find(|(k, _)| k.ends_with("/error/gps"))
        .map(|(_, n)| n.clone());
    assert!(
        gps.is_some_and(|n| n[0].as_str().unwrap().ends_with(" gps")),
        "{}",
        v["series_names"]
    );
}

/// Paths are sent as new segments, not as the whole path again: the file grows linearly with
/// the run (checked on the patrol, whose estimates, particles and scans all grow with it).
#[test]
fn a_run_ten_times_longer_writes_at_most_eleven_times_the_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let short = dir.path().join("short.rrd");
    let long = dir.path().join("long.rrd");
    record("hospital_patrol", 12.0, &short, None);
    record("hospital_patrol", 120.0, &long, None);
    let size = |p: &Path| std::fs::metadata(p).unwrap().len() as f64;
    let ratio = size(&long) / size(&short);
    assert!(
        ratio <= 11.0,
        "{} B for 120 s against {} B for 12 s: {ratio:.2}×",
        size(&long),
        size(&short)
    );
}
