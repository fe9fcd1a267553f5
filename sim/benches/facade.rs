//! What the library face ([`sim::Simulation`]) costs: one tick of a one-robot world through the
//! facade against the same world's schedule run directly, and reading every robot's pose and
//! latest scan through the views between two ticks of a 1000-robot swarm against the tick itself.
//! Swarm worlds are those of `sim bench swarm` (the hospital map tiled 4 × 4, 180-beam lasers).

use criterion::{Criterion, criterion_group, criterion_main};
use sim::bench::swarm::{swarm_scenario, swarm_world};
use sim::build::build_world;
use sim::{Command, Simulation};
use std::hint::black_box;
use systems::body::DriveCommand;
use systems::navigation::HeldCommand;

/// One robot held still (a wandering robot's tick costs more or less with where it is, by far
/// more than the facade's share), its laser scanning at 10 Hz.
fn one_robot(c: &mut Criterion) {
    let grid = swarm_world().unwrap();
    let sc = swarm_scenario(&grid, 1, 180, 1e6).unwrap();
    let still = Some(DriveCommand::default());
    let mut g = c.benchmark_group("one_robot_tick");
    // each world alone, built just before it is measured
    {
        let mut facade = Simulation::from_scenario(sc.clone())
            .threads(1)
            .build()
            .unwrap();
        let (v, w) = (0.0, 0.0);
        facade.command("r0000", Command::Drive { v, w }).unwrap();
        facade.step().unwrap();
        g.bench_function("facade", |b| b.iter(|| facade.step().unwrap()));
    }
    let mut direct = build_world(&sc, 1).unwrap();
    let robot = direct.robots[0];
    direct.world.get_mut::<HeldCommand>(robot).unwrap().0 = still;
    direct.step();
    g.bench_function("schedule", |b| b.iter(|| direct.step()));
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
