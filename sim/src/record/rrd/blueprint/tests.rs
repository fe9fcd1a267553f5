use super::*;

fn paths(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// Two indoor robots with two localizers each, people, a costmap and events.
fn indoor() -> Vec<String> {
    paths(&[
        "robots/r1/truth",
        "robots/r1/truth/path",
        "robots/r1/body",
        "robots/r1/odometry",
        "robots/r1/odometry/path",
        "robots/r1/odometry/drift",
        "robots/r1/estimate/mcl",
        "robots/r1/estimate/mcl/path",
        "robots/r1/particles/mcl",
        "robots/r1/estimate/de_filter",
        "robots/r1/particles/de_filter",
        "robots/r1/error/mcl",
        "robots/r1/error/de_filter",
        "robots/r1/heading_error/mcl",
        "robots/r1/goal_distance",
        "robots/r2/truth",
        "robots/r2/estimate/de_odometry",
        "robots/r2/estimate/de_filter",
        "robots/r2/error/de_filter",
        "people/nurse",
        "events",
        "world/map",
        "world/costmap",
    ])
}

fn view<'a>(root: &'a Node, name: &str) -> &'a ViewSpec {
    root.views()
        .into_iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no view {name}"))
}

#[test]
fn the_map_shows_one_localizer_per_robot_and_hides_the_rest() {
    let p = indoor();
    let root = default_layout(&Inputs {
        paths: &p,
        bounds: Some([0.0, 0.0, 40.0, 20.0]),
        ..Default::default()
    });
    let map = view(&root, "Map");
    assert_eq!(map.class, ViewClass::Spatial3D);
    // r1 shows its first localizer (mcl), r2 its first (de_odometry)
    assert_eq!(
        map.hidden,
        paths(&[
            "robots/r1/estimate/de_filter",
            "robots/r1/particles/de_filter",
            "robots/r1/odometry",
            "robots/r2/estimate/de_filter",
            "world/costmap",
        ])
    );
    assert_eq!(
        map.whole_history,
        paths(&[
            "robots/r1/truth/path",
            "robots/r1/odometry/path",
            "robots/r1/estimate/mcl/path",
        ])
    );
    // straight above the middle, high enough for the 40 m side
    let [eye, target] = map.eye.unwrap();
    assert_eq!(target, [20.0, 10.0, 0.0]);
    assert_eq!(&eye[..2], &[20.0, 10.0]);
    assert!(eye[2] >= 40.0, "{eye:?}");
}

#[test]
fn a_scenario_chooses_the_localizer_the_map_shows() {
    let p = indoor();
    let root = default_layout(&Inputs {
        paths: &p,
        map_localizer: Some("de_filter"),
        ..Default::default()
    });
    let map = view(&root, "Map");
    assert!(map.hidden.contains(&"robots/r1/estimate/mcl".to_string()));
    assert!(map.hidden.contains(&"robots/r1/particles/mcl".to_string()));
    assert!(!map.hidden.iter().any(|h| h.contains("de_filter")));
    assert!(
        map.hidden
            .contains(&"robots/r2/estimate/de_odometry".to_string())
    );
}

#[test]
fn each_metric_family_has_its_plot_with_every_robot_that_has_it() {
    let p = indoor();
    let root = default_layout(&Inputs {
        paths: &p,
        position_axis: 1.5,
        heading_axis: 0.3,
        drift_axis: 2.0,
        ..Default::default()
    });
    let pos = view(&root, "Position error (m)");
    assert_eq!(pos.class, ViewClass::TimeSeries);
    assert_eq!(
        pos.contents,
        paths(&["/robots/r1/error/**", "/robots/r2/error/**"])
    );
    assert_eq!(pos.y_range, Some([0.0, 1.5]));
    let heading = view(&root, "Heading error (rad)");
    assert_eq!(heading.contents, paths(&["/robots/r1/heading_error/**"]));
    assert_eq!(heading.y_range, Some([0.0, 0.3]));
    let drift = view(&root, "Odometry drift (m)");
    assert_eq!(drift.contents, paths(&["/robots/r1/odometry/drift"]));
    let goal = view(&root, "Distance to goal (m)");
    assert_eq!(goal.contents, paths(&["/robots/r1/goal_distance"]));
    assert_eq!(view(&root, "Events").class, ViewClass::TextLog);
    // no camera, so no image view
    assert!(!root.views().iter().any(|v| v.class == ViewClass::Spatial2D));
}

#[test]
fn cameras_get_image_views_and_stay_off_the_map() {
    let mut p = indoor();
    p.push("robots/r1/camera".into());
    p.push("robots/r2/camera".into());
    let root = default_layout(&Inputs {
        paths: &p,
        ..Default::default()
    });
    let images: Vec<_> = root
        .views()
        .into_iter()
        .filter(|v| v.class == ViewClass::Spatial2D)
        .map(|v| v.origin.clone())
        .collect();
    assert_eq!(images, paths(&["/robots/r1/camera", "/robots/r2/camera"]));
    let map = view(&root, "Map");
    assert!(map.contents.contains(&"- /robots/r2/camera".to_string()));
}

#[test]
fn a_run_without_localizers_has_a_map_and_events_only() {
    let p = paths(&["robots/r1/truth", "robots/r1/body", "events", "world/map"]);
    let root = default_layout(&Inputs {
        paths: &p,
        ..Default::default()
    });
    let names: Vec<_> = root.views().iter().map(|v| v.name.clone()).collect();
    assert_eq!(names, paths(&["Map", "Events"]));
}
