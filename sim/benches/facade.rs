//! What the library face ([`sim::Simulation`]) costs: one tick of a one-robot world through the
//! facade against the same world's schedule run directly, and reading every robot's pose and
//! latest scan through the views between two ticks of a 1000-robot swarm against the tick itself.
//! Swarm worlds are those of `sim bench swarm` (the hospital map tiled 4 × 4, 180-beam lasers).

use criterion::{Criterion, criterion_group, criterion_main};
use sim::bench::swarm::{swarm_scenario, swarm_world};
use sim::{Command, Simulation};
use std::hint::black_box;
use systems::core::SimClock;

/// One robot held still (a wandering robot's tick costs more or less with where it is, by far
/// more than the facade's share), its laser scanning at 10 Hz. Both cases step the same world,
/// so they differ only in the facade's own work (a world built a second time runs a few percent
/// faster or slower than the first, from where its memory lies).
fn one_robot(c: &mut Criterion) {
    let grid = swarm_world().unwrap();
    let sc = swarm_scenario(&grid, 1, 180, 1e6).unwrap();
    let mut s = Simulation::from_scenario(sc).threads(1).build().unwrap();
    s.command("r0000", Command::Drive { v: 0.0, w: 0.0 })
        .unwrap();
    s.step().unwrap();
    let mut g = c.benchmark_group("one_robot_tick");
    g.bench_function("facade", |b| b.iter(|| s.step().unwrap()));
    g.bench_function("schedule", |b| {
        b.iter(|| {
            let (world, schedule) = s.world_and_schedule();
            schedule.run(world);
            world.resource_mut::<SimClock>().advance();
        })
    });
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
    g.bench_function("tick", |b| b.iter(|| s.step().unwrap()));
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
