//! What the library face ([`sim::Simulation`]) costs: one tick of a one-robot world through the
//! facade against the same world's schedule run directly, and reading every robot's pose and
//! latest scan through the views between two ticks of a 1000-robot swarm against the tick itself.
//! Swarm worlds are those of `sim bench swarm` (the hospital map tiled 4 × 4, 180-beam lasers).

use criterion::{Criterion, criterion_group, criterion_main};
use sim::Simulation;
use sim::bench::swarm::{swarm_scenario, swarm_world};
use sim::build::build_world;
use std::hint::black_box;

fn one_robot(c: &mut Criterion) {
    let grid = swarm_world().unwrap();
    let sc = swarm_scenario(&grid, 1, 180, 1e6).unwrap();
    let mut g = c.benchmark_group("one_robot_tick");
    let mut direct = build_world(&sc, 1).unwrap();
    g.bench_function("schedule", |b| b.iter(|| direct.step()));
    let mut facade = Simulation::from_scenario(sc).threads(1).build().unwrap();
    g.bench_function("facade", |b| b.iter(|| facade.step()));
    g.finish();
}

fn swarm_views(c: &mut Criterion) {
    let grid = swarm_world().unwrap();
    let sc = swarm_scenario(&grid, 1000, 180, 1e6).unwrap();
    let mut s = Simulation::from_scenario(sc).threads(0).build().unwrap();
    // every laser has scanned (10 Hz, dt 0.05 s)
    s.run_for(0.2).unwrap();
    let mut g = c.benchmark_group("swarm_1000");
    g.sample_size(20);
    g.bench_function("tick", |b| b.iter(|| s.step()));
    g.bench_function("read_poses_and_scans", |b| {
        b.iter(|| {
            let mut beams = 0;
            for r in s.robots() {
                black_box(r.pose());
                beams += r.scan().map_or(0, |scan| scan.ranges().len());
            }
            assert_eq!(beams, 180_000);
            black_box(beams)
        })
    });
    g.finish();
}

criterion_group!(benches, one_robot, swarm_views);
criterion_main!(benches);
