//! Loop-closure kernels (Cartographer's global SLAM [Hess 2016]; [SLAM thesis §3.3.2]).
//!
//! * `bnb/window_3m_30deg` — one branch-and-bound loop-closure query (Hess et al. 2016 §V):
//!   a 1081-beam SICK LMS100 scan against a 30 × 30 m submap at 5 cm (a crop of the hospital
//!   map, blurred by σ = 0.1 m), search window ±3 m × ±3 m × ±π/6, depth 7, min score 0.6, the
//!   true pose 2.5 m and 0.3 rad from the guess;
//! * `bnb/window_0.5m_3deg` and `exhaustive/window_0.5m_3deg` — the same query over a window
//!   small enough to score every candidate (Hess Algorithm 1), for the speed-up;
//! * `precompute/depth_7` — building the precomputed grids of the submap (once per submap),
//!   and `depth_7_plain`, the sliding-window version it replaced;
//! * `pose_graph/manhattan_1000` and `pose_graph/manhattan_3500` — sparse pose adjustment
//!   (Konolige et al. 2010) of Manhattan-world graphs (1000 nodes / ~1500 edges, and the size of
//!   Olson's M3500: 3500 / ~5450), from dead reckoning to convergence.
//!
//! `cargo bench -p systems --bench loop_closure`

use criterion::{Criterion, criterion_group, criterion_main};
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::{Duration, Instant};
use systems::core::{Pose2, stream_rng};
use systems::mapping::pose_graph::{OptimizeParams, optimize, synthetic};
use systems::matching::{
    BnbWindow, PrecomputedGrids, likelihood_grid, match_bnb, match_exhaustive, scan_to_points,
};
use systems::raycast::RayMap;
use systems::world::{OccupancyGrid, load_map};

/// A `w` × `h` m crop of `grid` with its lower-left corner at (x0, y0).
fn crop(grid: &OccupancyGrid, x0: f64, y0: f64, w: f64, h: f64) -> OccupancyGrid {
    let r = grid.resolution;
    let (c0, r0) = ((x0 / r).round() as usize, (y0 / r).round() as usize);
    let (cw, ch) = ((w / r).round() as usize, (h / r).round() as usize);
    let mut out = OccupancyGrid::new(cw, ch, r, [c0 as f64 * r, r0 as f64 * r], grid.get(0, 0));
    for row in 0..ch {
        for col in 0..cw {
            out.set(col, row, grid.get(c0 + col, r0 + row));
        }
    }
    out
}

fn bench_bnb(c: &mut Criterion) {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let map = load_map(&path).expect("the hospital map loads");
    let rays = RayMap::from_grid(&map);
    let submap = likelihood_grid(&crop(&map, 17.0, 1.0, 30.0, 30.0), 0.1);
    let truth = Pose2::new(32.0, 18.7, 1.2);
    let (angle_min, inc) = (-135f32.to_radians(), 0.25f32.to_radians());
    let mut ranges = vec![0f32; 1081];
    rays.cast_scan(
        [truth.x as f32, truth.y as f32],
        truth.theta as f32 + angle_min,
        inc,
        20.0,
        &mut ranges,
    );
    let points = scan_to_points(angle_min, inc, &ranges, 0.5, 20.0);
    let guess = Pose2::new(truth.x - 2.0, truth.y + 1.5, truth.theta - 0.3);
    let grids = PrecomputedGrids::new(&submap, 7);
    let wide = BnbWindow {
        x: 3.0,
        y: 3.0,
        theta: PI / 6.0,
    };
    let found = match_bnb(&grids, &points, guess, &wide, 0.6).expect("the submap match");
    eprintln!(
        "bnb: {} points, found {:?} (score {:.3}), truth {truth:?}",
        points.len(),
        found.pose,
        found.score
    );
    // once: the exhaustive search over the whole window (too slow to sample), same answer
    let t = Instant::now();
    let brute = match_exhaustive(&grids, &points, guess, &wide, 0.6);
    eprintln!(
        "exhaustive over the same window: {:.2} s, same result: {}",
        t.elapsed().as_secs_f64(),
        brute == Some(found)
    );

    let mut g = c.benchmark_group("bnb");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(4))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("window_3m_30deg", |b| {
        b.iter(|| match_bnb(&grids, black_box(&points), guess, &wide, 0.6))
    });
    let near = Pose2::new(truth.x - 0.3, truth.y + 0.2, truth.theta - 0.03);
    let small = BnbWindow {
        x: 0.5,
        y: 0.5,
        theta: 3f64.to_radians(),
    };
    g.bench_function("window_0.5m_3deg", |b| {
        b.iter(|| match_bnb(&grids, black_box(&points), near, &small, 0.6))
    });
    g.finish();

    let mut g = c.benchmark_group("exhaustive");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(8))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("window_0.5m_3deg", |b| {
        b.iter(|| match_exhaustive(&grids, black_box(&points), near, &small, 0.6))
    });
    g.finish();

    let mut g = c.benchmark_group("precompute");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("depth_7", |b| {
        b.iter(|| PrecomputedGrids::new(black_box(&submap), 7))
    });
    g.bench_function("depth_7_plain", |b| {
        b.iter(|| PrecomputedGrids::new_plain(black_box(&submap), 7))
    });
    g.finish();
}

fn bench_pose_graph(c: &mut Criterion) {
    let params = OptimizeParams::default();
    let mut g = c.benchmark_group("pose_graph");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(4))
        .warm_up_time(Duration::from_secs(1));
    for n in [1000, 3500] {
        let mut rng = stream_rng(1, "bench", "manhattan");
        let world = synthetic::manhattan(n, &synthetic::Noise::default(), &mut rng);
        let mut once = world.graph.clone();
        let report = optimize(&mut once, &params);
        eprintln!(
            "pose graph: {} nodes, {} edges, {report:?}",
            world.graph.nodes.len(),
            world.graph.edges.len()
        );
        g.bench_function(format!("manhattan_{n}"), |b| {
            b.iter(|| {
                let mut graph = world.graph.clone();
                optimize(black_box(&mut graph), &params)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_bnb, bench_pose_graph);
criterion_main!(benches);
