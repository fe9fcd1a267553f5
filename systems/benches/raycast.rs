//! Ray-casting kernels on the hospital map (and tiled 4 × 4): random single rays and whole scans
//! from random free poses, 20 m rays (and Stage's 180-beam 8 m ranger), against the plain DDA
//! baseline; scans also ray by ray (`raymap_rays`: the distance-field walk the sweep replaces).
//! Throughput is rays/s.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use std::hint::black_box;
use systems::core::stream_rng;
use systems::raycast::{RayMap, cast_dda};
use systems::world::{OccupancyGrid, load_map};

struct Setup {
    name: &'static str,
    grid: OccupancyGrid,
    occ: Vec<bool>,
    map: RayMap,
    poses: Vec<([f32; 2], f32)>,
}

fn setup(name: &'static str, grid: OccupancyGrid) -> Setup {
    let occ = grid.obstacles();
    let map = RayMap::new(
        grid.width,
        grid.height,
        grid.resolution as f32,
        [grid.origin[0] as f32, grid.origin[1] as f32],
        &occ,
    );
    let mut rng = stream_rng(1, "bench", name);
    let b = grid.bounds();
    let mut poses = Vec::new();
    while poses.len() < 4096 {
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        if let Some((c, r)) = grid.cell_of(x, y)
            && grid.get(c, r) == systems::world::Cell::Free
        {
            let a = rng.random_range(-std::f32::consts::PI..std::f32::consts::PI);
            poses.push(([x as f32, y as f32], a));
        }
    }
    Setup {
        name,
        grid,
        occ,
        map,
        poses,
    }
}

fn bench(c: &mut Criterion) {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let hospital = load_map(&path).expect("the hospital map loads");
    let setups = [
        setup("hospital", hospital.clone()),
        setup("hospital_4x4", hospital.tiled(4, 4)),
    ];
    let mut g = c.benchmark_group("single_rays_20m");
    g.throughput(Throughput::Elements(4096));
    for s in &setups {
        g.bench_function(BenchmarkId::new("raymap", s.name), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for &(p, a) in &s.poses {
                    acc += s.map.cast(p, a, 20.0).min(20.0);
                }
                black_box(acc)
            })
        });
        let mut out = vec![0f32; s.poses.len()];
        g.bench_function(BenchmarkId::new("raymap_batch", s.name), |b| {
            b.iter(|| {
                s.map.cast_many(&s.poses, 20.0, &mut out);
                black_box(out.iter().map(|r| r.min(20.0)).sum::<f32>())
            })
        });
        let gr = &s.grid;
        g.bench_function(BenchmarkId::new("dda", s.name), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for &(p, a) in &s.poses {
                    acc += cast_dda(
                        gr.width,
                        gr.height,
                        gr.resolution as f32,
                        [gr.origin[0] as f32, gr.origin[1] as f32],
                        &s.occ,
                        p,
                        a,
                        20.0,
                    )
                    .min(20.0);
                }
                black_box(acc)
            })
        });
    }
    g.finish();

    for (beams, fov, range) in [
        (1081usize, 270f32, 20f32),
        (180, 180.0, 8.0),
        (180, 180.0, 20.0),
    ] {
        let mut g = c.benchmark_group(format!("scans_{beams}_beams_{range}m"));
        let n_scans = 256;
        g.throughput(Throughput::Elements((n_scans * beams) as u64));
        let inc = fov.to_radians() / (beams - 1) as f32;
        for s in &setups {
            let mut out = vec![0f32; beams];
            g.bench_function(BenchmarkId::new("raymap", s.name), |b| {
                b.iter(|| {
                    for &(p, a) in &s.poses[..n_scans] {
                        s.map
                            .cast_scan(p, a - fov.to_radians() / 2.0, inc, range, &mut out);
                    }
                    black_box(out[beams / 2])
                })
            });
            g.bench_function(BenchmarkId::new("raymap_rays", s.name), |b| {
                b.iter(|| {
                    for &(p, a) in &s.poses[..n_scans] {
                        s.map
                            .cast_scan_rays(p, a - fov.to_radians() / 2.0, inc, range, &mut out);
                    }
                    black_box(out[beams / 2])
                })
            });
            let gr = &s.grid;
            g.bench_function(BenchmarkId::new("dda", s.name), |b| {
                b.iter(|| {
                    for &(p, a) in &s.poses[..n_scans] {
                        let a0 = a - fov.to_radians() / 2.0;
                        for (k, o) in out.iter_mut().enumerate() {
                            *o = cast_dda(
                                gr.width,
                                gr.height,
                                gr.resolution as f32,
                                [gr.origin[0] as f32, gr.origin[1] as f32],
                                &s.occ,
                                p,
                                a0 + k as f32 * inc,
                                range,
                            );
                        }
                    }
                    black_box(out[beams / 2])
                })
            });
        }
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
