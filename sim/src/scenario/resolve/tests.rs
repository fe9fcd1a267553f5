//! The world's size is checked before its grid is allocated.

use crate::scenario::load::parse_scenario;
use crate::scenario::{TEST_ROOM, assets_dir};

fn parse(text: &str) -> Result<(), String> {
    let base = assets_dir().join("scenarios");
    parse_scenario(text, "t.toml", &base, "t")
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// A box far away (found by fuzzing: the grid was allocated before its size was checked).
#[test]
fn a_world_too_large_for_memory_is_refused_before_it_is_allocated() {
    parse(TEST_ROOM).unwrap();
    let far = format!("{TEST_ROOM}boxes = [{{ center = [3.0e6, 2.0e6], size = [1.0, 1.0] }}]\n");
    let e = parse(&far).unwrap_err();
    assert!(
        e.contains("t.toml:") && e.contains("`map`") && e.contains("at most 400 million"),
        "{e}"
    );
    let huge = format!("{TEST_ROOM}discs = [{{ center = [5.0, 5.0], radius = 1.0e300 }}]\n");
    let e = parse(&huge).unwrap_err();
    assert!(e.contains("at most 400 million"), "{e}");
}

/// The park's roads with their reference point moved 20° of longitude east (found by fuzzing:
/// the roads then lie 1 400 km from the origin, and the grid over them took 9.5 GB).
#[test]
fn roads_far_from_their_reference_point_are_refused_before_allocating() {
    let text =
        std::fs::read_to_string(assets_dir().join("scenarios/park_route_short.toml")).unwrap();
    assert!(text.contains("reference = [50.0645, 14.418]"));
    parse(&text).unwrap();
    let moved = text.replace(
        "reference = [50.0645, 14.418]",
        "reference = [50.0645, 34.418]",
    );
    let e = parse(&moved).unwrap_err();
    assert!(
        e.contains("`map`") && e.contains("at most 400 million"),
        "{e}"
    );
}
