//! Reactive avoidance (`navigation::avoid`), what every wandering robot of `sim bench swarm` runs
//! each tick: reducing a scan to sector points (Stage's 180-beam ranger over 180° and a SICK
//! LMS100's 1081 beams over 270°), and choosing a heading when the way
//! ahead is blocked (a robot 1 m from the end of a 2 m wide dead end, so most candidate headings
//! are tested before the way back is found). The ranges carry noise and a few lost beams.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::RngExt;
use std::f64::consts::PI;
use std::hint::black_box;
use systems::core::{Pose2, stream_rng};
use systems::navigation::avoid::SectorRanges;
use systems::raycast::RayMap;
use systems::sensors::LaserScan;
use systems::world::{Cell, load_map};

/// Range along angle `a` from the origin in a dead end: walls at x = 1 ahead and y = ±1 beside.
fn dead_end_range(a: f64) -> f32 {
    let (s, c) = a.sin_cos();
    let mut r = f64::INFINITY;
    if c > 1e-9 {
        r = r.min(1.0 / c);
    }
    if s.abs() > 1e-9 {
        r = r.min(1.0 / s.abs());
    }
    if r > 8.0 { f32::INFINITY } else { r as f32 }
}

/// `n` beams over `fov` radians, centred ahead.
fn noisy_scan(n: usize, fov: f64) -> LaserScan {
    let inc = fov / (n - 1) as f64;
    LaserScan {
        stamp: 0.0,
        angle_min: (-fov / 2.0) as f32,
        angle_increment: inc as f32,
        range_min: 0.1,
        range_max: 8.0,
        // range noise of about a centimetre and a few beams lost (no return), as a real scan
        ranges: (0..n)
            .map(|k| {
                let h = (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
                let jitter = (h % 2001) as f32 * 1e-5 - 0.01;
                if h.is_multiple_of(13) {
                    f32::INFINITY
                } else {
                    dead_end_range(-fov / 2.0 + k as f64 * inc) + jitter
                }
            })
            .collect(),
    }
}

/// 180-beam, 8 m scans (Stage's ranger) cast from `n` random free poses on the hospital map,
/// with a centimetre of noise and beams beyond 8 m lost: in a run no two scans alike, so a
/// branch on the readings is as (un)predictable as in a swarm.
fn hospital_scans(n: usize) -> Vec<LaserScan> {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let grid = load_map(&path).expect("the hospital map loads");
    let map = RayMap::from_grid(&grid);
    let mut rng = stream_rng(1, "bench", "avoid");
    let b = grid.bounds();
    let inc = PI / 179.0;
    let mut scans = Vec::with_capacity(n);
    while scans.len() < n {
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        let Some((c, r)) = grid.cell_of(x, y) else {
            continue;
        };
        if grid.get(c, r) != Cell::Free {
            continue;
        }
        let a: f32 = rng.random_range(-std::f32::consts::PI..std::f32::consts::PI);
        let mut ranges = vec![0f32; 180];
        let a0 = a - std::f32::consts::FRAC_PI_2;
        map.cast_scan([x as f32, y as f32], a0, inc as f32, 8.0, &mut ranges);
        for r in &mut ranges {
            let noise: f32 = rng.random_range(-0.01..0.01);
            *r = if *r >= 8.0 { f32::INFINITY } else { *r + noise };
        }
        scans.push(LaserScan {
            stamp: 0.0,
            angle_min: -std::f32::consts::FRAC_PI_2,
            angle_increment: inc as f32,
            range_min: 0.1,
            range_max: 8.0,
            ranges,
        });
    }
    scans
}

fn bench_avoid(c: &mut Criterion) {
    let scan = noisy_scan(180, PI);
    let mut g = c.benchmark_group("avoid_180_beams");
    g.bench_function("from_scan", |b| {
        b.iter(|| SectorRanges::from_scan(black_box(&scan), &Pose2::IDENTITY))
    });
    // what a behaviour does with each new scan: the previous reduction's storage is reused
    let mut reused = SectorRanges::from_scan(&scan, &Pose2::IDENTITY);
    g.bench_function("update", |b| {
        b.iter(|| reused.update(black_box(&scan), &Pose2::IDENTITY))
    });
    // the same on a different scan each time (1024 scans from the hospital, in turn)
    let scans = hospital_scans(1024);
    let mut k = 0;
    g.bench_function("update_hospital_scans", |b| {
        b.iter(|| {
            k = (k + 1) % scans.len();
            reused.update(black_box(&scans[k]), &Pose2::IDENTITY)
        })
    });
    let sectors = SectorRanges::from_scan(&scan, &Pose2::IDENTITY);
    g.bench_function("choose_heading_dead_end", |b| {
        b.iter(|| sectors.choose_heading(black_box(0.0), 0.3, 1.8, PI * 0.8))
    });
    g.finish();
    let sick = noisy_scan(1081, 1.5 * PI);
    let mut g = c.benchmark_group("avoid_1081_beams");
    let mut reused = SectorRanges::from_scan(&sick, &Pose2::IDENTITY);
    g.bench_function("update", |b| {
        b.iter(|| reused.update(black_box(&sick), &Pose2::IDENTITY))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = bench_avoid
}
criterion_main!(benches);
