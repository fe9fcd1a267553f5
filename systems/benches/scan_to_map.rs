//! Hector-style scan-to-map matching (`systems::matching::match_scan`) on the hospital map (5 cm
//! cells, 1280 × 640), 3-level pyramid for a map_server map:
//!
//! * `match/1081_beams` — one match of a SICK LMS100 scan (270°, 0.25°, 20 m, 12 mm range noise)
//!   from 0.2 m and 0.1 rad off the truth, cycling over 16 free poses;
//! * `match/270_beams` — the same with every fourth point (`max_points` 271);
//! * `pyramid/rebuild` — recomputing all three levels from the grid;
//! * `pyramid/update_2m_window` — recomputing what a 2 m × 2 m edit (40 × 40 cells) touches;
//! * `pyramid/update_scan_cells` — `update_cells` with the cells under one scan's 1081 end
//!   points (what a SLAM front end's hit updates touch).
//!
//! The target: scan-to-map SLAM at ≥ 50× real time with a 10 Hz laser on one core, a
//! match plus map update well under 2 ms. `cargo bench -p systems --bench scan_to_map`.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;
use systems::core::{Pose2, SimRng, stream_rng, wrap_angle};
use systems::matching::{
    GaussNewtonParams, MapPyramid, ProbGrid, PyramidOptions, match_scan, scan_to_points,
};
use systems::raycast::RayMap;
use systems::world::{Cell, OccupancyGrid, load_map};

struct Case {
    truth: Pose2,
    initial: Pose2,
    points: Vec<[f32; 2]>,
}

fn scan(map: &RayMap, pose: Pose2, rng: &mut SimRng) -> Vec<[f32; 2]> {
    let (start, inc) = (-135f32.to_radians(), 0.25f32.to_radians());
    let mut ranges = vec![0f32; 1081];
    map.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + start,
        inc,
        20.0,
        &mut ranges,
    );
    for r in ranges.iter_mut().filter(|r| r.is_finite()) {
        let n: f64 = rng.sample(StandardNormal);
        *r += (0.012 * n) as f32;
    }
    scan_to_points(start, inc, &ranges, 0.5, 20.0)
}

fn cases(grid: &OccupancyGrid, map: &RayMap) -> Vec<Case> {
    let mut rng = stream_rng(1, "bench", "scan-to-map");
    let b = grid.bounds();
    let mut out = Vec::new();
    while out.len() < 16 {
        let (x, y) = (rng.random_range(b[0]..b[2]), rng.random_range(b[1]..b[3]));
        let free = grid
            .cell_of(x, y)
            .is_some_and(|(c, r)| grid.get(c, r) == Cell::Free)
            && grid.disc_is_clear(x, y, 0.5);
        if !free {
            continue;
        }
        let truth = Pose2::new(x, y, rng.random_range(-PI..PI));
        let a: f64 = rng.random_range(-PI..PI);
        let turn = if out.len() % 2 == 0 { 0.1 } else { -0.1 };
        let initial = Pose2::new(x + 0.2 * a.cos(), y + 0.2 * a.sin(), truth.theta + turn);
        let points = scan(map, truth, &mut rng);
        out.push(Case {
            truth,
            initial,
            points,
        });
    }
    out
}

fn bench(c: &mut Criterion) {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let grid = load_map(&path).expect("the hospital map loads");
    let map = RayMap::from_grid(&grid);
    let prob = ProbGrid::from_occupancy(&grid);
    let mut pyramid = MapPyramid::with_options(&prob, 3, PyramidOptions::static_map());
    let cases = cases(&grid, &map);
    let full = GaussNewtonParams::default();
    let sub = GaussNewtonParams {
        max_points: 271,
        ..full
    };
    // the bench times right answers, not early exits
    for (params, tol) in [(&full, 0.02), (&sub, 0.03)] {
        for case in &cases {
            let r = match_scan(&pyramid, &case.points, case.initial, None, params);
            assert!(
                r.pose.distance(&case.truth) < tol
                    && wrap_angle(r.pose.theta - case.truth.theta).abs() < 0.01,
                "truth {:?}: found {r:?}",
                case.truth
            );
        }
    }

    let mut g = c.benchmark_group("match");
    g.sample_size(50)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (name, params) in [("1081_beams", &full), ("270_beams", &sub)] {
        let mut k = 0;
        g.bench_function(name, |b| {
            b.iter(|| {
                let case = &cases[k % cases.len()];
                k += 1;
                match_scan(
                    black_box(&pyramid),
                    black_box(&case.points),
                    case.initial,
                    None,
                    params,
                )
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("pyramid");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("rebuild", |b| b.iter(|| pyramid.rebuild(black_box(&prob))));
    let mut k = 0usize;
    g.bench_function("update_2m_window", |b| {
        b.iter(|| {
            // windows spread over the map, 40 × 40 cells each
            k = (k + 1) % 64;
            let (c0, r0) = ((k % 8) * 150, (k / 8) * 70);
            pyramid.update_region(black_box(&prob), c0, r0, c0 + 40, r0 + 40)
        })
    });
    let mut k = 0usize;
    let scan_cells: Vec<Vec<(usize, usize)>> = cases
        .iter()
        .map(|case| {
            case.points
                .iter()
                .filter_map(|p| {
                    let w = case.truth.transform_point([p[0] as f64, p[1] as f64]);
                    prob.cell_of(w[0], w[1])
                })
                .collect()
        })
        .collect();
    g.bench_function("update_scan_cells", |b| {
        b.iter(|| {
            k = (k + 1) % scan_cells.len();
            pyramid.update_cells(black_box(&prob), &scan_cells[k])
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
