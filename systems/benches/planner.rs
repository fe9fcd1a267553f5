//! Global planner on the hospital map (robot radius 0.3 m, inflation 1.0 m): A* plus
//! line-of-sight shortening for fixed far-apart start/goal pairs across the building, one
//! query per iteration with the scratch buffers reused, as a robot re-plans. The target is
//! under 20 ms per cross-building query. Also the costmap build from the static grid.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use systems::navigation::{Costmap, CostmapParams, Planner, PlannerParams};
use systems::world::{OccupancyGrid, load_map};

/// Far-apart free points (m): room to room diagonally across, corridor end to end.
const PAIRS: [(&str, [f64; 2], [f64; 2]); 4] = [
    ("sw_room_to_ne_room", [2.0, 4.5], [62.0, 28.0]),
    ("nw_room_to_se_room", [2.0, 28.0], [62.0, 4.5]),
    ("corridor_w_to_e", [3.0, 16.5], [61.0, 16.5]),
    ("w_wing_to_e_wing", [6.0, 19.0], [60.0, 12.0]),
];

fn hospital() -> OccupancyGrid {
    let yaml = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    load_map(&yaml).unwrap()
}

fn params() -> CostmapParams {
    CostmapParams {
        robot_radius: 0.3,
        inflation_radius: 1.0,
        ..Default::default()
    }
}

fn bench_queries(c: &mut Criterion) {
    let map = Costmap::from_grid(&hospital(), &params());
    let mut planner = Planner::new(PlannerParams::default());
    let mut g = c.benchmark_group("plan_hospital");
    for (name, a, b) in PAIRS {
        let path = planner.plan(&map, a, b).unwrap();
        eprintln!(
            "{name}: straight {:.1} m, path {:.1} m (cost {:.3} m), {} waypoints, {} cells expanded",
            (b[0] - a[0]).hypot(b[1] - a[1]),
            path.length,
            path.cost,
            path.waypoints.len(),
            path.expanded
        );
        g.bench_with_input(
            BenchmarkId::from_parameter(name),
            &(a, b),
            |bch, &(a, b)| {
                bch.iter(|| black_box(planner.plan(&map, black_box(a), black_box(b)).unwrap()))
            },
        );
    }
    g.finish();
}

fn bench_costmap(c: &mut Criterion) {
    let grid = hospital();
    c.bench_function("costmap_hospital", |b| {
        b.iter(|| black_box(Costmap::from_grid(black_box(&grid), &params())))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench_queries, bench_costmap
}
criterion_main!(benches);
