use super::*;
use crate::navigation::costmap::{CostmapParams, LETHAL};
use crate::navigation::shortcut::segment_clear;
use crate::world::{Cell, OccupancyGrid, load_map};

/// A 6 m × 4 m room of 0.1 m cells with walls all round.
fn room() -> OccupancyGrid {
    let mut g = OccupancyGrid::new(60, 40, 0.1, [0.0, 0.0], Cell::Free);
    for c in 0..60 {
        g.set(c, 0, Cell::Occupied);
        g.set(c, 39, Cell::Occupied);
    }
    for r in 0..40 {
        g.set(0, r, Cell::Occupied);
        g.set(59, r, Cell::Occupied);
    }
    g
}

/// The room with a wall at x = 3.0..3.1 m from the floor up to y = `top` (cells).
fn room_with_wall(top: usize) -> Costmap {
    let mut g = room();
    for r in 0..top {
        g.set(30, r, Cell::Occupied);
    }
    Costmap::from_grid(&g, &CostmapParams::default())
}

/// Every grid cell and every segment of the shortened path is on passable cells.
fn assert_collision_free(map: &Costmap, path: &Path) {
    for &(c, r) in &path.cells {
        assert!(map.cost(c, r) < INSCRIBED, "cell ({c},{r})");
    }
    for w in path.waypoints.windows(2) {
        assert!(segment_clear(map, w[0], w[1], INSCRIBED - 1), "{w:?}");
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

#[test]
fn straight_line_in_an_empty_room() {
    let map = Costmap::from_grid(&room(), &CostmapParams::default());
    let mut p = Planner::new(PlannerParams::default());
    let (a, b) = ([1.0, 1.0], [5.0, 3.0]);
    let path = p.plan(&map, a, b).unwrap();
    assert!((path.length - dist(a, b)).abs() <= 0.1, "{}", path.length);
    assert_eq!(path.waypoints, vec![a, b]);
    assert_collision_free(&map, &path);
    // the grid path is at least as long as the octile distance
    assert!(path.cost >= (4.0 - 2.0 + 2.0 * 2f64.sqrt()) * 0.999 - 0.2);
}

#[test]
fn path_goes_around_a_wall() {
    let map = room_with_wall(30);
    let mut p = Planner::new(PlannerParams::default());
    let (a, b) = ([1.5, 1.0], [4.5, 1.0]);
    let path = p.plan(&map, a, b).unwrap();
    // through the 0.9 m gap between the wall's end (y = 3.0) and the top wall (y = 3.9)
    assert!(path.cells.iter().any(|&(c, r)| c == 30 && r >= 30));
    assert!(path.length >= 2.0 * 1.5f64.hypot(2.3), "{}", path.length);
    assert!(path.waypoints.len() >= 3);
    assert_eq!(path.waypoints[0], a);
    assert_eq!(*path.waypoints.last().unwrap(), b);
    assert_collision_free(&map, &path);
}

#[test]
fn unreachable_goal_is_an_error() {
    let map = room_with_wall(40);
    let mut p = Planner::new(PlannerParams::default());
    let e = p.plan(&map, [1.5, 1.0], [4.5, 1.0]).unwrap_err();
    assert!(matches!(e, PlanError::Unreachable { expanded, .. } if expanded > 100));
    assert!(e.to_string().contains("unreachable"), "{e}");
    // and the planner still works afterwards
    assert!(p.plan(&map, [1.5, 1.0], [1.5, 3.0]).is_ok());
}

#[test]
fn blocked_or_outside_ends_are_named() {
    let map = room_with_wall(30);
    let mut p = Planner::new(PlannerParams::default());
    let free = [1.5, 1.0];
    assert_eq!(
        p.plan(&map, [3.05, 1.0], free),
        Err(PlanError::StartBlocked {
            x: 3.05,
            y: 1.0,
            cost: LETHAL
        })
    );
    assert_eq!(
        p.plan(&map, [2.85, 1.0], free),
        Err(PlanError::StartBlocked {
            x: 2.85,
            y: 1.0,
            cost: INSCRIBED
        })
    );
    let e = p.plan(&map, free, [3.05, 2.0]).unwrap_err();
    assert!(matches!(e, PlanError::GoalBlocked { cost: LETHAL, .. }));
    assert!(
        e.to_string()
            .starts_with("goal (3.050, 2.000) m is in an obstacle"),
        "{e}"
    );
    assert!(matches!(
        p.plan(&map, [-1.0, 1.0], free),
        Err(PlanError::StartOutside { .. })
    ));
    assert!(matches!(
        p.plan(&map, free, [1.0, 4.0]),
        Err(PlanError::GoalOutside { .. })
    ));
    assert!(matches!(
        p.plan(&map, [f64::NAN, 1.0], free),
        Err(PlanError::StartOutside { .. })
    ));
    assert!(matches!(
        p.plan(&map, free, [1.0, f64::INFINITY]),
        Err(PlanError::GoalOutside { .. })
    ));
}

#[test]
fn same_cell_and_repeated_queries() {
    let map = room_with_wall(30);
    let mut p = Planner::new(PlannerParams::default());
    let path = p.plan(&map, [1.52, 1.01], [1.55, 1.07]).unwrap();
    assert_eq!(path.waypoints, vec![[1.52, 1.01], [1.55, 1.07]]);
    assert_eq!(path.cells.len(), 1);

    let (a, b) = ([1.5, 1.0], [4.5, 1.0]);
    let first = p.plan(&map, a, b).unwrap();
    let other = p.plan(&map, [5.5, 3.2], [0.6, 0.6]).unwrap();
    assert_ne!(first, other);
    let again = p.plan(&map, a, b).unwrap();
    let fresh = Planner::new(PlannerParams::default())
        .plan(&map, a, b)
        .unwrap();
    assert_eq!(first, again);
    assert_eq!(first, fresh);
}

/// Costs of the least-cost path by plain Dijkstra over the same moves (O(n²), small maps).
fn dijkstra(map: &Costmap, step: &[f32; 256], s: usize, t: usize) -> Option<f64> {
    let (w, h) = (map.width as i64, map.height as i64);
    let n = map.costs.len();
    let mut g = vec![f64::INFINITY; n];
    let mut done = vec![false; n];
    g[s] = 0.0;
    let pass = |c: i64, r: i64| {
        c >= 0 && r >= 0 && c < w && r < h && map.costs[(r * w + c) as usize] < INSCRIBED
    };
    loop {
        let i = (0..n)
            .filter(|&i| !done[i] && g[i].is_finite())
            .min_by(|&a, &b| g[a].total_cmp(&g[b]))?;
        if i == t {
            return Some(g[t]);
        }
        done[i] = true;
        let (c, r) = (i as i64 % w, i as i64 / w);
        for (dc, dr) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ] {
            let (nc, nr) = (c + dc, r + dr);
            if !pass(nc, nr) || (dc != 0 && dr != 0 && !(pass(c + dc, r) && pass(c, r + dr))) {
                continue;
            }
            let j = (nr * w + nc) as usize;
            let len = if dc != 0 && dr != 0 { 2f64.sqrt() } else { 1.0 };
            let cand = g[i] + len * step[map.costs[j] as usize] as f64;
            if cand < g[j] {
                g[j] = cand;
            }
        }
    }
}

#[test]
fn costs_are_optimal_on_cluttered_maps() {
    let mut state = 12345u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as usize
    };
    for _ in 0..4 {
        let mut g = OccupancyGrid::new(40, 30, 0.1, [0.0, 0.0], Cell::Free);
        for _ in 0..25 {
            let (c, r) = (next() % 40, next() % 30);
            g.set(c, r, Cell::Occupied);
        }
        let params = CostmapParams {
            robot_radius: 0.1,
            inflation_radius: 0.5,
            ..Default::default()
        };
        let map = Costmap::from_grid(&g, &params);
        let mut p = Planner::new(PlannerParams::default());
        let mut pairs = 0;
        while pairs < 5 {
            let (s, t) = (next() % map.costs.len(), next() % map.costs.len());
            if map.costs[s] >= INSCRIBED || map.costs[t] >= INSCRIBED {
                continue;
            }
            pairs += 1;
            let a = map.cell_center(s % 40, s / 40);
            let b = map.cell_center(t % 40, t / 40);
            let want = dijkstra(&map, &p.step, s, t);
            match p.plan(&map, a, b) {
                Ok(path) => {
                    let want = want.expect("A* found a path Dijkstra did not") * 0.1;
                    assert!(
                        (path.cost - want).abs() <= 1e-4 * want.max(1.0),
                        "{} vs {want}",
                        path.cost
                    );
                    assert_collision_free(&map, &path);
                }
                Err(e) => {
                    assert!(matches!(e, PlanError::Unreachable { .. }));
                    assert_eq!(want, None);
                }
            }
        }
    }
}

#[test]
fn cross_building_path_on_the_hospital_map() {
    let yaml = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let grid = load_map(&yaml).unwrap();
    let map = Costmap::from_grid(&grid, &CostmapParams::default());
    let mut p = Planner::new(PlannerParams::default());
    for (a, b) in [([2.0, 4.5], [62.0, 28.0]), ([3.0, 16.5], [61.0, 16.5])] {
        let path = p.plan(&map, a, b).unwrap();
        let straight = dist(a, b);
        assert!(path.length >= straight, "{} < {straight}", path.length);
        assert!(
            path.length <= 1.5 * straight,
            "{} vs {straight}",
            path.length
        );
        // shortening never lengthens the grid path
        let grid_len: f64 = path
            .cells
            .windows(2)
            .map(|w| {
                if w[0].0 != w[1].0 && w[0].1 != w[1].1 {
                    2f64.sqrt()
                } else {
                    1.0
                }
            })
            .sum::<f64>()
            * map.resolution;
        assert!(
            path.length <= grid_len + map.resolution,
            "{} vs {grid_len}",
            path.length
        );
        assert_collision_free(&map, &path);
        eprintln!(
            "{a:?} -> {b:?}: straight {straight:.2} m, path {:.2} m, grid {grid_len:.2} m, {} waypoints, {} expanded",
            path.length,
            path.waypoints.len(),
            path.expanded
        );
    }
}
