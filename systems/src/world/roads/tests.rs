use super::raw::parse_width;
use super::*;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    crate::core::source::source_path("tests/fixtures/roads").join(name)
}

fn options() -> RoadOptions {
    RoadOptions {
        reference: Some(GeoPoint::new(50.0, 14.0)),
        ..RoadOptions::default()
    }
}

/// The fixtures' network in local metres: a 40 m × 30 m loop (with a shape point at
/// (20, −2)) and a 30 m tail east of its south-east corner.
fn check_small(g: &RoadGraph, source_of_corner: Option<&str>) {
    assert_eq!(g.nodes.len(), 6, "nodes: {:?}", g.nodes);
    assert_eq!(g.edges.len(), 6);
    assert_eq!(g.roads.len(), 2);
    let expected = 20f64.hypot(2.0) * 2.0 + 30.0 + 40.0 + 30.0 + 30.0;
    assert!(
        (g.total_length() - expected).abs() < 1e-3,
        "{}",
        g.total_length()
    );
    let at = |x: f64, y: f64| {
        g.nodes
            .iter()
            .position(|n| (n.pos[0] - x).abs() < 1e-3 && (n.pos[1] - y).abs() < 1e-3)
            .unwrap_or_else(|| panic!("no node at ({x}, {y})"))
    };
    let corner = at(40.0, 0.0);
    assert_eq!(g.degree(corner), 3);
    assert_eq!(g.degree(at(70.0, 0.0)), 1);
    assert_eq!(g.degree(at(20.0, -2.0)), 2);
    if let Some(s) = source_of_corner {
        assert_eq!(g.node_by_source(s), Some(corner));
    }
    // the tail runs due east from the corner
    let tail = g.edge_between(corner, at(70.0, 0.0)).unwrap();
    assert!((g.azimuth_from(tail, corner).to_degrees() - 90.0).abs() < 1e-6);
    assert!((g.azimuth_from(tail, at(70.0, 0.0)).to_degrees() - 270.0).abs() < 1e-6);
    // north side of the loop: (40, 30) → (0, 30) is due west
    let north = g.edge_between(at(40.0, 30.0), at(0.0, 30.0)).unwrap();
    assert!((g.azimuth_from(north, at(40.0, 30.0)).to_degrees() - 270.0).abs() < 1e-6);
}

#[test]
fn osm_roads_become_a_graph_with_surfaces_and_widths() {
    let g = load_roads(&fixture("small.osm"), &options()).unwrap();
    check_small(&g, Some("2"));
    let main = g.roads.iter().find(|r| r.name == "Main loop").unwrap();
    assert_eq!(
        (main.kind.as_str(), main.surface, main.width),
        ("service", Surface::Asphalt, 4.0)
    );
    let tail = g.roads.iter().find(|r| r.kind == "footway").unwrap();
    assert_eq!(
        (tail.surface, tail.width),
        (Surface::Gravel, default_width("footway"))
    );
    assert_eq!(tail.name, "way 11");
    // the surface: on the 4 m loop 1.9 m off its centre line, off it at 2.1 m; the 2 m tail
    let on = |x, y| g.surface_at([x, y]).map(|(_, s)| s);
    assert_eq!(on(10.0, 30.0 + 1.9), Some(Surface::Asphalt));
    assert_eq!(on(10.0, 30.0 + 2.1), None);
    assert_eq!(on(55.0, 0.9), Some(Surface::Gravel));
    assert_eq!(on(55.0, 1.1), None);
    assert_eq!(on(20.0, 15.0), None); // inside the loop: grass
    // the building and the proposed highway are not roads
    assert!(g.nodes.iter().all(|n| n.pos[1] < 45.0));
}

#[test]
fn gpx_tracks_sharing_points_make_the_same_graph() {
    let g = load_roads(&fixture("small.gpx"), &options()).unwrap();
    check_small(&g, None);
    let tail = g.roads.iter().find(|r| r.name == "Tail").unwrap();
    assert_eq!(
        (tail.kind.as_str(), tail.surface, tail.width),
        ("gpx", Surface::Gravel, 3.0)
    );
    // the one-point track is no road
    assert!(g.roads.iter().all(|r| r.name != "Lonely point"));
    let osm = load_roads(&fixture("small.osm"), &options()).unwrap();
    assert!((g.total_length() - osm.total_length()).abs() < 1e-6);
}

#[test]
fn the_default_reference_is_the_centre_of_the_roads() {
    let g = load_roads(&fixture("small.osm"), &RoadOptions::default()).unwrap();
    let b = g.bounds();
    // roads span x 0..70 and y −2..30 around their centre
    assert!(
        (b[0] + 35.0).abs() < 0.01 && (b[2] - 35.0).abs() < 0.01,
        "{b:?}"
    );
    assert!(
        (b[1] + 16.0).abs() < 0.01 && (b[3] - 16.0).abs() < 0.01,
        "{b:?}"
    );
    // and local metres map back to the file's coordinates
    let n = &g.nodes[g.node_by_source("5").unwrap()];
    let back = g.projection.to_geo(n.pos);
    let o = load_roads(&fixture("small.osm"), &options()).unwrap();
    let direct = o
        .projection
        .to_geo(o.nodes[o.node_by_source("5").unwrap()].pos);
    assert!(haversine(back, direct) < 1e-3);
}

#[test]
fn queries_on_edges() {
    let g = load_roads(&fixture("small.osm"), &options()).unwrap();
    let near = g.nearest_edge([55.0, 3.0]).unwrap();
    let e = &g.edges[near.edge];
    assert_eq!(g.roads[e.road].kind, "footway");
    assert!((near.distance - 3.0).abs() < 1e-3);
    let p = g.point_on(near.edge, near.along);
    assert!((p[0] - 55.0).abs() < 1e-3 && p[1].abs() < 1e-3);
    let within: Vec<_> = g.edges_within([40.0, 15.0], 10.0);
    assert_eq!(within.len(), 1, "{within:?}"); // the east side only
    assert!(within[0].distance.abs() < 1e-3);
    // + the north side, the south-east piece and the tail, all 15 m away
    assert_eq!(g.edges_within([40.0, 15.0], 16.0).len(), 4);
}

/// The error of loading a fixture, as text.
fn error_of(name: &str) -> String {
    let e = load_roads(&fixture(name), &options()).expect_err(name);
    let s = e.to_string();
    assert!(s.contains(name), "{s}");
    s
}

#[test]
fn malformed_files_give_clear_errors() {
    // XML errors say where, once; a file that ends too soon, at its end
    let s = error_of("not_xml.osm");
    assert!(s.contains("not well-formed XML"), "{s}");
    assert!(s.contains("not_xml.osm:") && !s.contains(" at "), "{s}");
    let s = error_of("truncated.gpx");
    assert!(s.contains("truncated.gpx:5:22: not well-formed XML"), "{s}");
    let s = error_of("bad_lat.osm");
    assert!(s.contains(":4:") && s.contains("`lat` = \"north\""), "{s}");
    let s = error_of("missing_node.osm");
    assert!(
        s.contains(":6:") && s.contains("way 5 refers to node 99"),
        "{s}"
    );
    let s = error_of("bad_width.osm");
    assert!(s.contains(":9:") && s.contains("width = \"wide\""), "{s}");
    let s = error_of("no_roads.osm");
    assert!(s.contains("no roads"), "{s}");
    let s = error_of("empty.gpx");
    assert!(s.contains("no roads"), "{s}");
    let s = error_of("bad_lon.gpx");
    assert!(s.contains(":5:") && s.contains("`lon` = \"194.5\""), "{s}");
    let s = error_of("wrong_root.xml");
    assert!(s.contains("root element <kml>"), "{s}");
    let e = load_roads(&fixture("does_not_exist.osm"), &options()).unwrap_err();
    assert!(matches!(e, RoadError::Read { .. }), "{e}");
}

#[test]
fn inline_edge_cases() {
    let p = std::path::Path::new("inline.osm");
    let parse = |t: &str| parse_roads(t, p, &options());
    // duplicate node ids
    let e = parse(r#"<osm><node id="1" lat="50" lon="14"/><node id="1" lat="50" lon="14"/></osm>"#)
        .unwrap_err();
    assert!(e.to_string().contains("node id 1 is defined twice"), "{e}");
    // a one-node road
    let e = parse(
        r#"<osm><node id="1" lat="50" lon="14"/><way id="3"><nd ref="1"/><tag k="highway" v="path"/></way></osm>"#,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("way 3 (highway=path) has 1 node(s)"),
        "{e}"
    );
    // a road whose two nodes coincide has no edge
    let e = parse(
        r#"<osm><node id="1" lat="50" lon="14"/><way id="3"><nd ref="1"/><nd ref="1"/><tag k="highway" v="path"/></way></osm>"#,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("no road has two distinct points"),
        "{e}"
    );
    // a missing attribute
    let e = parse(r#"<osm><node id="1" lon="14"/></osm>"#).unwrap_err();
    assert!(
        e.to_string().contains("<node> has no `lat` attribute"),
        "{e}"
    );
    // a reference point at the pole
    let o = RoadOptions {
        reference: Some(GeoPoint::new(90.0, 0.0)),
        ..RoadOptions::default()
    };
    let e = parse_roads(
        &std::fs::read_to_string(fixture("small.osm")).unwrap(),
        p,
        &o,
    )
    .unwrap_err();
    assert!(e.to_string().contains("reference point"), "{e}");
    // area=yes highways are squares, not roads
    let e = parse(
        r#"<osm><node id="1" lat="50" lon="14"/><node id="2" lat="50.001" lon="14"/><way id="3"><nd ref="1"/><nd ref="2"/><tag k="highway" v="pedestrian"/><tag k="area" v="yes"/></way></osm>"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("no roads"), "{e}");
}

#[test]
fn widths_and_surfaces_parse_like_osm_writes_them() {
    assert_eq!(parse_width("3.5"), Some(3.5));
    assert_eq!(parse_width(" 4 m"), Some(4.0));
    assert_eq!(parse_width("2.5m"), Some(2.5));
    for bad in ["", "wide", "-1", "0", "3'6\"", "NaN", "1e9"] {
        assert_eq!(parse_width(bad), None, "{bad}");
    }
    assert_eq!(Surface::from_tag("fine_gravel"), Surface::Gravel);
    assert_eq!(Surface::from_tag("Asphalt"), Surface::Asphalt);
    assert_eq!(Surface::from_tag("paving_stones"), Surface::Paving);
    assert_eq!(Surface::from_tag("woodchips"), Surface::Unknown);
}

#[test]
fn the_bundled_park_reads_the_same_from_osm_and_gpx() {
    let dir = crate::core::source::source_path("assets/roads/park");
    let osm = load_roads(&dir.join("park.osm"), &RoadOptions::default()).unwrap();
    let gpx = load_roads(&dir.join("park.gpx"), &RoadOptions::default()).unwrap();
    // assets/roads/README.md: 179 nodes, 195 edges, 2256.6 m; the building and the wood skipped
    for g in [&osm, &gpx] {
        assert_eq!((g.nodes.len(), g.edges.len()), (179, 195));
        assert!(
            (g.total_length() - 2256.6).abs() < 0.1,
            "{}",
            g.total_length()
        );
    }
    assert_eq!(osm.roads.len(), 20);
    let surfaces: std::collections::HashSet<_> = osm.roads.iter().map(|r| r.surface).collect();
    assert!(surfaces.contains(&Surface::Asphalt) && surfaces.contains(&Surface::Gravel));
    // the same reference point, so the same local coordinates
    assert!(haversine(osm.projection.reference, gpx.projection.reference) < 0.01);
}
