//! The park runs end to end: the thesis car drives the 190 m route that avoids a U-turn to its
//! goal by road localization and camera road following, and the recording holds the roads, GPS
//! fixes, road beliefs, the planned route and camera images.

use crate::common::*;
use sim::{RunOptions, load_scenario, run_scenario};

#[test]
fn the_short_park_route_reaches_its_goal_without_a_u_turn_and_is_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("park.rrd");
    let s = load_scenario(&bundled("park_route_short")).unwrap();
    let out = run_scenario(
        &s,
        &RunOptions {
            rrd: Some(path.clone()),
            threads: 1,
            progress: false,
            trajectory_period: None,
        },
    )
    .unwrap();
    let r = &out.summary.robots[0];
    let road = r
        .road
        .as_ref()
        .expect("a robot with a route has a road summary");
    assert!(road.reached, "{road:#?}");
    assert!(
        r.route_completed,
        "the road route's arrival completes the route"
    );
    // the shortest path needs a U-turn (67.9 m); the planner went round (190.2 m)
    let planned = road.planned_length_m.unwrap();
    assert!(planned > 150.0, "planned {planned:.1} m");
    assert!(r.distance_m > 150.0, "drove {:.1} m", r.distance_m);
    assert_eq!(r.collisions, 0);
    assert!(road.off_road_time_s < 10.0, "{road:#?}");
    for (name, l) in &road.localizers {
        let mean = l.mean_error_m.unwrap();
        assert!(mean < 3.0, "{name}: mean error {mean:.2} m");
    }
    assert!(
        out.summary.sim_time_s < s.duration,
        "the run ended at arrival"
    );

    let Some(v) = check_rrd(&path) else {
        return;
    };
    let paths = entity_paths(&v);
    for want in [
        "/world/roads",
        "/robots/car/gps",
        "/robots/car/estimate/road_grid",
        "/robots/car/estimate/road_mcl",
        "/robots/car/particles/road_grid",
        "/robots/car/particles/road_mcl",
        "/robots/car/path",
        "/robots/car/camera",
        "/robots/car/truth",
    ] {
        assert!(
            paths.iter().any(|p| p == want),
            "missing {want} in {paths:?}"
        );
    }
}

#[test]
fn the_same_seed_drives_the_same_park_run() {
    let mut s = load_scenario(&bundled("park_route_short")).unwrap();
    s.duration = 40.0;
    let opts = RunOptions {
        rrd: None,
        threads: 2,
        progress: false,
        trajectory_period: Some(1.0),
    };
    let a = run_scenario(&s, &opts).unwrap();
    let b = run_scenario(&s, &RunOptions { threads: 1, ..opts }).unwrap();
    assert_eq!(a.trajectory, b.trajectory);
    assert_eq!(
        a.summary.deterministic_part(),
        b.summary.deterministic_part()
    );
    assert!(a.summary.robots[0].distance_m > 10.0);
}

/// Issue item: the short route (the one that needs a U-turn by the shortest path) reaches its
/// goal over 20 seeds at a rate of at least 90 %, navigating by either road localizer
/// (`sim experiment park --routes park_route_short --runs 20`; about 45 s on 2 cores).
#[test]
fn the_short_route_reaches_its_goal_in_nine_of_ten_seeds_by_either_localizer() {
    use sim::experiment::park::{ParkOptions, run_park_experiment};
    let (rows, runs) = run_park_experiment(&ParkOptions {
        routes: vec!["park_route_short".into()],
        runs: 20,
        threads: 0,
        progress: false,
    })
    .unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(runs.len(), 40);
    for r in &rows {
        assert_eq!(r.runs, 20);
        assert!(
            r.reached_percent >= 90.0,
            "{} by {}: {} % reached",
            r.route,
            r.navigate_by,
            r.reached_percent
        );
    }
}
