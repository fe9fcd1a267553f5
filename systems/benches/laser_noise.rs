//! Laser noise (`sensors::laser::apply_noise`), what every scan of `sim bench swarm` pays after
//! ray casting: one normal deviate per beam (`core::normal`, the ziggurat in f32), against
//! `rand_distr`'s f64 ziggurat drawing the same count, for a 180-beam and a 1081-beam scan.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::hint::black_box;
use systems::core::normal::fill_standard_normal;
use systems::core::stream_rng;
use systems::sensors::laser::{LaserSpec, apply_noise};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("laser_noise");
    for beams in [180usize, 1081] {
        g.throughput(Throughput::Elements(beams as u64));
        let mut spec = LaserSpec::sick_lms100();
        spec.max_range = 20.0;
        let exact: Vec<f32> = (0..beams).map(|k| 1.0 + (k % 17) as f32).collect();
        let mut ranges = exact.clone();
        let mut rng = stream_rng(1, "bench", "noise");
        g.bench_function(BenchmarkId::new("apply_noise", beams), |b| {
            b.iter(|| {
                ranges.copy_from_slice(&exact);
                apply_noise(&spec, &mut rng, &mut ranges);
                black_box(ranges[beams / 2])
            })
        });
        let mut out = vec![0f32; beams];
        g.bench_function(BenchmarkId::new("deviates_f32_ziggurat", beams), |b| {
            b.iter(|| {
                fill_standard_normal(&mut rng, &mut out);
                black_box(out[beams / 2])
            })
        });
        g.bench_function(BenchmarkId::new("deviates_rand_distr_f64", beams), |b| {
            b.iter(|| {
                for o in out.iter_mut() {
                    let x: f64 = rng.sample(StandardNormal);
                    *o = x as f32;
                }
                black_box(out[beams / 2])
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
