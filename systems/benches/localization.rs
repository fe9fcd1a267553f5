//! Localizer updates on the hospital map, on one core (a 1-thread rayon pool), with the scans and
//! odometry of a drive along the hospital's corridors ([`fixtures::recorded_drive`]):
//!
//! - `mcl_update/<n>`: a full MCL update (motion sampling, likelihood-field weighing of 60
//!   beams, resampling when due, clustering) with n = 1 000, 5 000, 20 000 particles, KLD off;
//! - `mcl_weigh/<n>`: the likelihood-field kernel alone on the same particle sets;
//! - `mcl_field_kernel_5000/{best,scalar}`: its scoring loop, vectorised against scalar;
//! - `markov_grid_update/selective`: a Markov grid update (0.25 m × 10°) once converged;
//!   `markov_grid_update/global`: with every cell scored (selective update off);
//! - `de_filter_update`: a DE filter update (population 2 000, global start);
//! - `cluster/{dense,plain}/<n>`: the dominant-cluster estimate of n particles spread over the
//!   whole floor (a global filter's first estimates), dense histogram against hash map.
//!
//! The filter is rebuilt when the drive runs out, so every update follows a real motion.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use systems::core::stream_rng;
use systems::localization::de_filter::{DeFilter, DeFilterConfig};
use systems::localization::fixtures::{
    CORRIDOR, DriveStep, bench_markov_grid, bench_mcl, hospital, recorded_drive,
};
use systems::localization::markov_grid::layout::Layout;
use systems::localization::markov_grid::{belief_ops, prediction};
use systems::localization::mcl::field_kernel::{self, GridPose};
use systems::localization::mcl::{BeamSubset, sensor_model};
use systems::localization::{LocalizationMap, MarkovGrid};

const BEAMS: usize = 60;

fn one_core<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(f)
}

fn subsets(steps: &[DriveStep]) -> Vec<BeamSubset> {
    steps
        .iter()
        .map(|s| BeamSubset::from_scan(&s.scan, &systems::core::Pose2::IDENTITY, BEAMS))
        .collect()
}

fn mcl(c: &mut Criterion, map: &LocalizationMap, steps: &[DriveStep], beams: &[BeamSubset]) {
    let mut g = c.benchmark_group("mcl_update");
    for n in [1_000usize, 5_000, 20_000] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            one_core(|| {
                let mut f = bench_mcl(map, n, BEAMS, &steps[0].truth);
                let mut k = 0;
                b.iter(|| {
                    if k == steps.len() {
                        f = bench_mcl(map, n, BEAMS, &steps[0].truth);
                        k = 0;
                    }
                    black_box(f.update(map, &beams[k], &steps[k].odom));
                    k += 1;
                })
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("mcl_weigh");
    for n in [1_000usize, 5_000, 20_000] {
        let f = bench_mcl(map, n, BEAMS, &steps[0].truth);
        let table = sensor_model::likelihood_table(&map.field, &f.config.laser, 20.0);
        let points = beams[0].returns();
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            one_core(|| {
                let mut w = f.w.clone();
                b.iter(|| {
                    sensor_model::weigh_likelihood_field(
                        &map.field, &table, &points, &f.xs, &f.ys, &f.ths, &mut w,
                    );
                    w.iter_mut().for_each(|v| *v = 1.0);
                    black_box(&w);
                })
            })
        });
    }
    g.finish();
    // the scoring kernel alone, vectorised (AVX2 where the CPU has it) against one particle at a
    // time: identical sums, the speed-up of the vector path
    let mut g = c.benchmark_group("mcl_field_kernel_5000");
    let f = bench_mcl(map, 5_000, BEAMS, &steps[0].truth);
    let table = sensor_model::likelihood_table(&map.field, &f.config.laser, 20.0);
    let far = table[255];
    let points = beams[0].returns();
    let poses: Vec<GridPose> = (0..f.xs.len())
        .map(|i| GridPose::new(&map.field, f.xs[i], f.ys[i], f.ths[i]))
        .collect();
    let mut out = vec![0.0f32; poses.len()];
    g.bench_function("best", |b| {
        b.iter(|| {
            field_kernel::score_all(&map.field, &table, far, &points, &poses, &mut out);
            black_box(&out);
        })
    });
    g.bench_function("scalar", |b| {
        b.iter(|| {
            field_kernel::score_all_scalar(&map.field, &table, far, &points, &poses, &mut out);
            black_box(&out);
        })
    });
    g.finish();
}

/// A Markov grid after `warm` updates of the drive, and the index of the next step.
fn warmed_grid(
    map: &LocalizationMap,
    steps: &[DriveStep],
    beams: &[BeamSubset],
    threshold: f64,
    warm: usize,
) -> (MarkovGrid, usize) {
    let mut g = bench_markov_grid(map, threshold);
    for k in 0..warm {
        g.update(map, &beams[k].returns(), beams[k].range_max, &steps[k].odom);
    }
    (g, warm)
}

fn markov_grid(
    c: &mut Criterion,
    map: &LocalizationMap,
    steps: &[DriveStep],
    beams: &[BeamSubset],
) {
    let mut g = c.benchmark_group("markov_grid_update");
    g.sample_size(10);
    for (name, threshold, warm) in [("selective", 1e-6, 20), ("global", 0.0, 0)] {
        g.bench_function(name, |b| {
            one_core(|| {
                let (mut f, mut k) = warmed_grid(map, steps, beams, threshold, warm);
                b.iter(|| {
                    if k == steps.len() {
                        (f, k) = warmed_grid(map, steps, beams, threshold, warm);
                    }
                    let pts = beams[k].returns();
                    black_box(f.update(map, &pts, beams[k].range_max, &steps[k].odom));
                    k += 1;
                })
            })
        });
    }
    g.finish();
}

fn de_filter(c: &mut Criterion, map: &LocalizationMap, steps: &[DriveStep], beams: &[BeamSubset]) {
    let config = DeFilterConfig {
        update_min_d: 0.0,
        update_min_a: 0.0,
        ..DeFilterConfig::default()
    };
    let new = || DeFilter::new(config.clone(), map, stream_rng(0, "bench", "de"));
    let mut g = c.benchmark_group("de_filter_update");
    g.sample_size(20);
    g.bench_function("2000", |b| {
        one_core(|| {
            let mut f = new();
            let mut k = 0;
            b.iter(|| {
                if k == steps.len() {
                    f = new();
                    k = 0;
                }
                black_box(f.update(map, &beams[k], &steps[k].odom));
                k += 1;
            })
        })
    });
    g.finish();
}

fn cluster(c: &mut Criterion, map: &LocalizationMap) {
    use rand::RngExt;
    use systems::localization::mcl::{BinSize, cluster};
    let mut g = c.benchmark_group("cluster");
    for n in [5_000usize, 100_000] {
        let mut rng = stream_rng(1, "bench", "cluster");
        let (mut xs, mut ys, mut ths) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..n {
            let (x, y, th) = map.random_free_pose(&mut || rng.random::<f64>());
            xs.push(x);
            ys.push(y);
            ths.push(th);
        }
        let w = vec![1.0 / n as f64; n];
        let bins = BinSize::default();
        g.bench_with_input(BenchmarkId::new("dense", n), &n, |b, _| {
            b.iter(|| black_box(cluster::dominant_cluster(&xs, &ys, &ths, &w, &bins)))
        });
        g.bench_with_input(BenchmarkId::new("plain", n), &n, |b, _| {
            b.iter(|| black_box(cluster::dominant_cluster_plain(&xs, &ys, &ths, &w, &bins)))
        });
    }
    g.finish();
}

/// The Markov grid's passes over a belief of the hospital's size (1.18 million cells), each
/// against its plain version.
fn belief_passes(c: &mut Criterion) {
    let n = 256 * 128 * 36;
    let v: Vec<f32> = (0..n)
        .map(|i| {
            if i % 5 == 0 {
                0.0
            } else {
                1e-7 * ((i % 97) as f32 + 1.0)
            }
        })
        .collect();
    let mut out = v.clone();
    let mut g = c.benchmark_group("markov_grid_pass");
    g.bench_function("sum", |b| b.iter(|| black_box(belief_ops::sum(&v))));
    g.bench_function("sum_plain", |b| {
        b.iter(|| black_box(belief_ops::sum_plain(&v)))
    });
    g.bench_function("peak", |b| b.iter(|| black_box(belief_ops::peak(&v))));
    g.bench_function("peak_plain", |b| {
        b.iter(|| black_box(belief_ops::peak_plain(&v)))
    });
    g.bench_function("tally", |b| {
        b.iter(|| {
            let mut t = belief_ops::Tally::default();
            t.add(&v);
            black_box((t.sum(), t.peak()))
        })
    });
    g.bench_function("scale", |b| {
        b.iter(|| {
            let mut t = belief_ops::Tally::default();
            belief_ops::scale(&mut out, 1.0, &mut t);
            black_box(t.sum())
        })
    });
    g.bench_function("weigh_and_mix", |b| {
        b.iter(|| {
            let mut t = belief_ops::Tally::default();
            belief_ops::weigh_and_mix(&mut out, &v, 5e-6, 1.0, [1.0, 1.0, 0.0], &mut t);
            black_box(t.sum())
        })
    });
    g.bench_function("scale_and_mix", |b| {
        b.iter(|| {
            let mut t = belief_ops::Tally::default();
            belief_ops::scale_and_mix(&mut out, 1.0, 1.0, 0.0, &mut t);
            black_box(t.peak())
        })
    });
    g.bench_function("find", |b| {
        let top = belief_ops::peak(&v);
        b.iter(|| black_box(belief_ops::find(&v, top)))
    });
    g.bench_function("argmax", |b| b.iter(|| black_box(belief_ops::argmax(&v))));
    g.bench_function("runs_at_or_above", |b| {
        b.iter(|| {
            let mut n = 0;
            for row in v.chunks(256) {
                belief_ops::runs_at_or_above(row, 9e-6, |_, l| n += l);
            }
            black_box(n)
        })
    });
    g.finish();
}

/// The Markov grid's motion blurs over the hospital's belief (0.25 m × 10°), with the 3-tap
/// kernel of a quarter cell² (most blurs) and a 7-tap one.
fn blurs(c: &mut Criterion, map: &LocalizationMap) {
    let l = Layout::new(&map.grid, 0.25, 36);
    let src: Vec<f32> = (0..l.len())
        .map(|c| if l.free[c % l.layer()] { 1e-6 } else { 0.0 })
        .collect();
    let mut out = src.clone();
    let mut g = c.benchmark_group("markov_grid_blur");
    for variance in [0.25, 1.0] {
        let k = prediction::kernel_of_variance(variance);
        g.bench_with_input(BenchmarkId::new("xy", k.len()), &k, |b, k| {
            b.iter(|| {
                out.copy_from_slice(&src);
                prediction::blur_xy(&l, k, &mut out);
                black_box(out[0])
            })
        });
        g.bench_with_input(BenchmarkId::new("theta", k.len()), &k, |b, k| {
            b.iter(|| {
                prediction::blur_theta(&l, k, &src, &mut out);
                black_box(out[0])
            })
        });
    }
    g.finish();
}

fn localization(c: &mut Criterion) {
    belief_passes(c);
    let map = hospital();
    blurs(c, &map);
    let steps = recorded_drive(&map, &CORRIDOR, 0.0, 1);
    let beams = subsets(&steps);
    mcl(c, &map, &steps, &beams);
    markov_grid(c, &map, &steps, &beams);
    de_filter(c, &map, &steps, &beams);
    cluster(c, &map);
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(30)
        .measurement_time(std::time::Duration::from_secs(3));
    targets = localization
}
criterion_main!(benches);
