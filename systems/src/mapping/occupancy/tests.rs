use super::*;
use crate::mapping::inverse_model::log_odds;
use crate::raycast::RayMap;
use crate::world::Cell;
use crate::world::map_file::{load_map, save_map};
use std::f32::consts::PI;

fn scan(angle_min: f32, inc: f32, range_max: f32, ranges: Vec<f32>) -> LaserScan {
    LaserScan {
        stamp: 0.0,
        angle_min,
        angle_increment: inc,
        range_min: 0.1,
        range_max,
        ranges,
    }
}

/// 6 × 4 m room, walls one 10 cm cell thick, a 0.4 m pillar; origin (−1, −1).
fn room() -> OccupancyGrid {
    let mut g = OccupancyGrid::new(60, 40, 0.1, [-1.0, -1.0], Cell::Free);
    for c in 0..60 {
        g.set(c, 0, Cell::Occupied);
        g.set(c, 39, Cell::Occupied);
    }
    for r in 0..40 {
        g.set(0, r, Cell::Occupied);
        g.set(59, r, Cell::Occupied);
    }
    for (c, r) in (40..44).flat_map(|c| (10..14).map(move |r| (c, r))) {
        g.set(c, r, Cell::Occupied);
    }
    g
}

/// A 360-beam scan of `grid` from `pose`.
fn cast(grid: &OccupancyGrid, pose: &Pose2) -> LaserScan {
    let inc = 2.0 * PI / 360.0;
    let mut ranges = vec![0.0; 360];
    RayMap::from_grid(grid).cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 - PI,
        inc,
        10.0,
        &mut ranges,
    );
    scan(-PI, inc, 10.0, ranges)
}

fn l(map: &LogOddsMap, x: f64, y: f64) -> f32 {
    let (c, r) = map.cell_of(x, y).expect("inside the map");
    map.log_odds()[r * map.width() + c]
}

#[test]
fn log_odds_and_probability_are_inverse() {
    for p in [0.1192f32, 0.4, 0.5, 0.7, 0.971] {
        assert!((probability(log_odds(p)) - p).abs() < 1e-6);
    }
    assert_eq!(log_odds(0.5), 0.0);
}

#[test]
fn no_return_beams_clear_free_space_but_never_mark_a_wall() {
    let params = OccupancyParams {
        max_range: 12.0,
        clear_range: 5.0,
        ..Default::default()
    };
    let mut map = LogOddsMap::new(0.1, params);
    let inc = 2.0 * PI / 720.0;
    // +Inf (no return), a return beyond range_max, and one beyond params.max_range
    let mut ranges = vec![f32::INFINITY; 720];
    ranges[100] = 25.0;
    ranges[200] = 15.0;
    let sensor = Pose2::new(3.0, -2.0, 0.3);
    for _ in 0..5 {
        let s = map.insert_scan(&sensor, &scan(-PI, inc, 20.0, ranges.clone()));
        assert_eq!((s.hits, s.clears, s.ignored), (0, 720, 0));
    }
    assert!(
        map.log_odds().iter().all(|&v| v <= 0.0),
        "a cell was marked"
    );
    // cleared out to clear_range in every direction, nothing beyond
    for k in [0, 100, 200, 450] {
        let a = sensor.theta - std::f64::consts::PI + k as f64 * inc as f64;
        let at = |d: f64| map.probability_at(sensor.x + d * a.cos(), sensor.y + d * a.sin());
        assert!(at(1.0) < 0.2 && at(4.8) < 0.2, "beam {k}");
        assert_eq!(at(5.3), 0.5, "beam {k}");
    }
    // clearing disabled: no-return beams change nothing
    let params = OccupancyParams {
        max_range: 12.0,
        clear_range: 0.0,
        ..Default::default()
    };
    let mut map = LogOddsMap::new(0.1, params);
    map.insert_scan(&sensor, &scan(-PI, inc, 20.0, ranges));
    assert!(map.log_odds().iter().all(|&v| v == 0.0));
}

#[test]
fn invalid_readings_change_nothing() {
    let mut map = LogOddsMap::with_bounds(50, 50, 0.1, [0.0, 0.0], OccupancyParams::default());
    let ranges = vec![f32::NAN, f32::NEG_INFINITY, 0.05];
    let s = map.insert_scan(&Pose2::new(2.5, 2.5, 0.0), &scan(0.0, 0.1, 10.0, ranges));
    assert_eq!((s.hits, s.clears, s.ignored), (0, 0, 3));
    assert!(map.log_odds().iter().all(|&v| v == 0.0));
    // nor does a pose that is not finite
    let s = map.insert_scan(
        &Pose2::new(f64::NAN, 2.5, 0.0),
        &scan(0.0, 0.1, 10.0, vec![1.0]),
    );
    assert_eq!(s, InsertStats::default());
    assert!(map.log_odds().iter().all(|&v| v == 0.0));
}

#[test]
fn a_cell_is_updated_at_most_once_per_scan_and_hits_win() {
    let p = OccupancyParams::default();
    let (hit, miss) = (log_odds(p.p_hit), log_odds(p.p_miss));
    let mut map = LogOddsMap::with_bounds(100, 100, 0.1, [0.0, 0.0], p);
    let sensor = Pose2::new(5.05, 5.05, 0.0);
    // 1081 beams all cross the sensor's cell; beams 0 and 1 end in the same cell (2.0 m ahead);
    // beam 2 passes through that cell on its way to 3 m
    let inc = 0.25f32.to_radians();
    let mut ranges = vec![2.0f32; 1081];
    ranges[2] = 3.0;
    let scan = scan(0.0, inc / 16.0, 10.0, ranges);
    for n in 1..=3 {
        let s = map.insert_scan(&sensor, &scan);
        assert_eq!(s.hits, 1081);
        let nf = n as f32;
        assert!((l(&map, 5.05, 5.05) - nf * miss).abs() < 1e-5, "scan {n}");
        // the end cell of beams 0 and 1: one hit per scan, not cleared by beam 2
        assert!((l(&map, 7.08, 5.06) - (nf * hit).min(log_odds(0.971))).abs() < 1e-5);
    }
    // clamped at p_max after many scans, at p_min on the free side
    for _ in 0..20 {
        map.insert_scan(&sensor, &scan);
    }
    assert!((probability(l(&map, 7.08, 5.06)) - 0.971).abs() < 1e-4);
    assert!((probability(l(&map, 6.0, 5.06)) - 0.1192).abs() < 1e-4);
}

#[test]
fn fixed_bounds_clip_beams_and_drop_returns_outside() {
    let mut map = LogOddsMap::with_bounds(20, 20, 0.1, [0.0, 0.0], OccupancyParams::default());
    // from outside the grid, through it, ending beyond it: cells inside are cleared only
    let s = map.insert_scan(
        &Pose2::new(-1.0, 1.05, 0.0),
        &scan(0.0, 0.1, 10.0, vec![4.0]),
    );
    assert_eq!(s.hits, 0);
    assert_eq!((map.width(), map.height()), (20, 20));
    let row: Vec<f32> = (0..20).map(|c| map.log_odds()[10 * 20 + c]).collect();
    assert!(row.iter().all(|&v| v < 0.0), "{row:?}");
    assert_eq!(map.log_odds().iter().filter(|&&v| v != 0.0).count(), 20);
}

#[test]
fn growth_keeps_earlier_cells_at_their_world_positions() {
    let truth = room();
    let mut map = LogOddsMap::new(0.05, OccupancyParams::default());
    map.insert_scan(
        &Pose2::new(1.0, 1.0, 0.4),
        &cast(&truth, &Pose2::new(1.0, 1.0, 0.4)),
    );
    let before = map.clone();
    assert_eq!(before.width() % BLOCK, 0);
    // origin on the lattice of the world origin, by whole blocks
    for o in before.origin() {
        let blocks = o / (BLOCK as f64 * 0.05);
        assert!((blocks - blocks.round()).abs() < 1e-9, "{o}");
    }
    // a scan far away (its returns out of reach of the first one's cells) grows the map
    let far = Pose2::new(-40.02, 30.02, 0.0);
    let s = map.insert_scan(&far, &scan(0.0, 0.5, 10.0, vec![3.0; 12]));
    assert_eq!(s.hits, 12);
    assert!(map.width() > before.width() && map.height() > before.height());
    assert_eq!((map.width() % BLOCK, map.height() % BLOCK), (0, 0));
    let mut marked = 0;
    for r in 0..before.height() {
        for c in 0..before.width() {
            let x = before.origin()[0] + (c as f64 + 0.5) * 0.05;
            let y = before.origin()[1] + (r as f64 + 0.5) * 0.05;
            let v = before.log_odds()[r * before.width() + c];
            assert_eq!(l(&map, x, y), v, "({c}, {r})");
            marked += (v > 0.0) as usize;
        }
    }
    assert!(marked > 100, "{marked}");
    // the far scan's hits are where it saw them
    assert!(map.probability_at(-37.02, 30.02) > 0.65);
}

#[test]
fn exported_map_round_trips_through_map_server_files() {
    let truth = room();
    let mut map = LogOddsMap::new(0.1, OccupancyParams::default());
    for (x, y) in [(0.5, 0.5), (2.0, 1.5), (3.5, 0.5), (4.5, 2.0)] {
        for k in 0..4 {
            let pose = Pose2::new(x, y, k as f64);
            map.insert_scan(&pose, &cast(&truth, &pose));
        }
    }
    let prob = map.to_prob_grid();
    assert_eq!(prob.origin, map.origin());
    let grid = map.to_occupancy();
    assert_eq!(grid, prob.to_occupancy());
    let occupied = grid.cells.iter().filter(|&&c| c == Cell::Occupied).count();
    let free = grid.cells.iter().filter(|&&c| c == Cell::Free).count();
    assert!(occupied > 150 && free > 1500, "{occupied} {free}");
    // every mapped wall is a wall of the room (known poses, exact ranges)
    for r in 0..grid.height {
        for c in 0..grid.width {
            if grid.get(c, r) == Cell::Occupied {
                let [x, y] = grid.cell_center(c, r);
                let near = (-1..=1).any(|dr| {
                    (-1..=1).any(|dc| {
                        let (x, y) = (x + dc as f64 * 0.1, y + dr as f64 * 0.1);
                        truth
                            .cell_of(x, y)
                            .is_some_and(|(tc, tr)| truth.is_obstacle(tc, tr))
                    })
                });
                assert!(near, "({x}, {y})");
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slam.yaml");
    save_map(&grid, &path).unwrap();
    let loaded = load_map(&path).unwrap();
    assert_eq!(loaded, grid);
}

#[test]
fn the_reported_window_holds_every_cell_a_scan_changed() {
    let g = room();
    let mut map = LogOddsMap::new(0.1, OccupancyParams::default());
    map.insert_scan(
        &Pose2::new(1.0, 1.0, 0.0),
        &cast(&g, &Pose2::new(1.0, 1.0, 0.0)),
    );
    let before = map.log_odds().to_vec();
    let (w, h) = (map.width(), map.height());
    // a second scan from elsewhere in the room, without growing the map
    let pose = Pose2::new(3.5, 0.5, 1.0);
    let stats = map.insert_scan(&pose, &cast(&g, &pose));
    assert_eq!((map.width(), map.height()), (w, h));
    let [c0, r0, c1, r1] = stats.window.expect("the scan touched the map");
    let mut changed = 0;
    for (i, (a, b)) in before.iter().zip(map.log_odds()).enumerate() {
        if a != b {
            changed += 1;
            let (c, r) = (i % w, i / w);
            assert!(
                (c0..c1).contains(&c) && (r0..r1).contains(&r),
                "cell ({c}, {r}) outside {:?}",
                [c0, r0, c1, r1]
            );
        }
    }
    assert!(changed > 100, "{changed}");
    // and it is not the whole map: the box of what the scan reached
    assert!((c1 - c0) * (r1 - r0) <= w * h);
}

/// A scan from a pose kilometres away (an odometry jump) is not allowed to grow the map over
/// the space in between: the map stays as it was, finite (it asked for an allocation as large
/// as the jump).
#[test]
fn a_scan_from_kilometres_away_does_not_grow_the_map_over_the_gap() {
    let grid = room();
    let mut map = LogOddsMap::new(0.05, OccupancyParams::default());
    let pose = Pose2::new(1.0, 1.0, 0.0);
    map.insert_scan(&pose, &cast(&grid, &pose));
    let (w, h) = (map.width(), map.height());
    for far in [Pose2::new(1e7, -1e7, 0.3), Pose2::new(1e300, 0.0, 0.0)] {
        map.insert_scan(&far, &cast(&grid, &pose));
        assert_eq!((map.width(), map.height()), (w, h));
    }
    // an empty map far out is not grown either
    let mut empty = LogOddsMap::new(0.05, OccupancyParams::default());
    empty.insert_scan(&Pose2::new(2e9, 0.0, 0.0), &cast(&grid, &pose));
    assert_eq!(empty.width() * empty.height(), 0);
    assert!(map.log_odds().iter().all(|l| l.is_finite()));
}

/// Properties: whatever the scan and the sensor pose (NaN, ±∞, far away), every cell's log
/// odds and probability stay finite and within the clamping limits.
mod props {
    use super::*;
    use crate::core::props::{config, extreme_f64, laser_fault, range_reading};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(config(48))]

        #[test]
        fn any_scan_from_any_pose_leaves_finite_cells(
            scans in proptest::collection::vec(
                (prop_oneof![
                    3 => (-1.0f64..5.0, -1.0f64..3.0, -3.2f64..3.2),
                    1 => (extreme_f64(), extreme_f64(), extreme_f64()),
                 ],
                 proptest::collection::vec(range_reading(8.0), 0..90),
                 proptest::option::of(laser_fault(8.0, 30))),
                1..6),
            range_max in prop_oneof![Just(8.0f32), Just(f32::INFINITY), Just(0.0f32), 0.1f32..50.0],
        ) {
            let grid = room();
            let mut map = LogOddsMap::new(0.1, OccupancyParams::default());
            let limits = [log_odds(map.params().p_min), log_odds(map.params().p_max)];
            for ((x, y, th), ranges, fault) in scans {
                let pose = Pose2::new(x, y, th);
                let mut s = if ranges.is_empty() { cast(&grid, &Pose2::new(1.0, 1.0, 0.0)) } else {
                    scan(-PI, 2.0 * PI / ranges.len() as f32, range_max, ranges)
                };
                if let Some(f) = fault {
                    f.apply(&mut s.ranges, 8.0, None);
                }
                map.insert_scan(&pose, &s);
                prop_assert!(map.width() * map.height() <= MAX_CELLS);
                for &l in map.log_odds() {
                    prop_assert!(l.is_finite() && l >= limits[0] - 1e-6 && l <= limits[1] + 1e-6, "{l}");
                }
                prop_assert!(map.to_prob_grid().p.iter().all(|p| p.is_finite()));
            }
        }
    }
}
