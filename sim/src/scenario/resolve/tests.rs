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

/// The world's grid sized from the shapes' bounds, without allocating, has the cells of the
/// grid that `grid_for_shapes` used to allocate only to measure them (the plain version).
#[test]
fn the_grid_sized_without_allocating_is_the_one_measured_before() {
    use super::grid_for_world;
    use systems::world::shapes::{Shape, grid_for_shapes};
    let plain = |shapes: &[Shape], roads: Option<([f64; 4], f64)>, res: f64| {
        let from_shapes = grid_for_shapes(shapes, res, 2.0).map(|g| g.bounds());
        let from_roads = roads.map(|(b, m)| [b[0] - m, b[1] - m, b[2] + m, b[3] + m]);
        let b = match (from_shapes, from_roads) {
            (Some(a), Some(b)) => [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[2].max(b[2]),
                a[3].max(b[3]),
            ],
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => return None,
        };
        let w = ((b[2] - b[0]) / res).ceil().max(1.0) as usize;
        let h = ((b[3] - b[1]) / res).ceil().max(1.0) as usize;
        Some((w, h, [b[0], b[1]]))
    };
    let shapes = [
        Shape::Box {
            center: [26.0, 59.5],
            size: [40.0, 15.0],
            yaw: 0.3,
        },
        Shape::Disc {
            center: [-60.0, 80.0],
            radius: 0.5,
        },
        Shape::Disc {
            center: [118.03, 88.1],
            radius: 0.4,
        },
        Shape::Box {
            center: [0.013, -7.77],
            size: [0.1, 3.3],
            yaw: 1.0,
        },
    ];
    let roads = [None, Some(([-151.3, -130.7, 160.2, 120.9], 10.0))];
    for n in 0..=shapes.len() {
        for &r in &roads {
            for res in [0.05, 0.1, 0.2, 0.3, 0.07] {
                let got = grid_for_world(&shapes[..n], r, res)
                    .unwrap()
                    .map(|g| (g.width, g.height, g.origin));
                assert_eq!(got, plain(&shapes[..n], r, res), "{n} shapes, {r:?}, {res}");
            }
        }
    }
}

/// Zero-length time steps are refused: `dt` 0, negative, NaN, infinite (and over 1 s), in a
/// file and from the builder alike, with an error naming the key and the value.
#[test]
fn a_zero_negative_or_nan_time_step_is_refused() {
    use crate::scenario::Scenario;
    parse(&format!("dt = 0.05\n{TEST_ROOM}")).unwrap();
    for dt in ["0.0", "-0.05", "nan", "inf", "-inf", "1.5"] {
        let e = parse(&format!("dt = {dt}\n{TEST_ROOM}")).unwrap_err();
        assert!(e.contains("t.toml:1") && e.contains("`dt`"), "{dt}: {e}");
        assert!(e.contains("(0, 1]"), "{dt}: {e}");
    }
    for dt in [0.0, -0.05, f64::NAN, f64::INFINITY] {
        let built = Scenario::builder("steps")
            .dt(dt)
            .duration(1.0)
            .room([0.0, 0.0], [10.0, 8.0])
            .build();
        let e = built.map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("`dt`") && e.contains("(0, 1]"), "{dt}: {e}");
    }
}
