//! Occupancy mapping on the hospital map (64 × 32 m, 5 cm cells): SICK LMS100 scans (270°,
//! 0.25°, 1081 beams, 0.5–20 m, 12 mm noise) ray-cast from random free poses.
//!
//! * `insert/lms100_1081_beams` — one scan inserted at its known pose into a map already grown
//!   to the hospital's size (the per-scan hot kernel: beam walks, hit/miss updates);
//! * `export/to_occupancy` — the whole log-odds map to a thresholded occupancy grid;
//! * `quality/map_quality` — precision and recall of the mapped hospital against the true map
//!   (1280 × 640 cells).
//!
//! Short on purpose: `cargo bench -p systems --bench mapping`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;
use systems::core::{Pose2, stream_rng};
use systems::mapping::{LogOddsMap, OccupancyParams, map_quality};
use systems::raycast::RayMap;
use systems::sensors::{LaserScan, LaserSpec};
use systems::world::{Cell, load_map};

fn bench(c: &mut Criterion) {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let truth = load_map(&path).expect("the hospital map loads");
    let rays = RayMap::from_grid(&truth);
    let spec = LaserSpec::sick_lms100();
    let mut rng = stream_rng(3, "bench", "mapping");
    let b = truth.bounds();
    let mut scans: Vec<(Pose2, LaserScan)> = Vec::new();
    while scans.len() < 256 {
        let (x, y) = (rng.random_range(b[0]..b[2]), rng.random_range(b[1]..b[3]));
        let free = truth
            .cell_of(x, y)
            .is_some_and(|(c, r)| truth.get(c, r) == Cell::Free);
        if !free || !truth.disc_is_clear(x, y, 0.3) {
            continue;
        }
        let pose = Pose2::new(x, y, rng.random_range(-PI..PI));
        let mut ranges = vec![0f32; spec.beams()];
        rays.cast_scan(
            [x as f32, y as f32],
            (pose.theta + spec.angle_min()) as f32,
            spec.increment as f32,
            spec.max_range as f32,
            &mut ranges,
        );
        for r in ranges.iter_mut().filter(|r| r.is_finite()) {
            let n: f64 = rng.sample(StandardNormal);
            *r += (spec.noise_std * n) as f32;
        }
        let scan = LaserScan {
            stamp: 0.0,
            angle_min: spec.angle_min() as f32,
            angle_increment: spec.increment as f32,
            range_min: spec.min_range as f32,
            range_max: spec.max_range as f32,
            ranges,
        };
        scans.push((pose, scan));
    }
    let mut map = LogOddsMap::new(0.05, OccupancyParams::default());
    for (pose, scan) in &scans {
        map.insert_scan(pose, scan);
    }

    let mut g = c.benchmark_group("insert");
    g.sample_size(50)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    g.throughput(Throughput::Elements(spec.beams() as u64));
    let mut k = 0;
    g.bench_function("lms100_1081_beams", |bch| {
        bch.iter(|| {
            let (pose, scan) = &scans[k % scans.len()];
            k += 1;
            map.insert_scan(pose, black_box(scan))
        })
    });
    g.finish();

    let est = map.to_occupancy();
    let mut g = c.benchmark_group("export");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("to_occupancy", |bch| {
        bch.iter(|| black_box(&map).to_occupancy())
    });
    g.finish();

    let mut g = c.benchmark_group("quality");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("map_quality", |bch| {
        bch.iter(|| map_quality(black_box(&est), &truth, &Pose2::IDENTITY))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
