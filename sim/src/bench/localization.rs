//! `sim bench mcl` and `sim bench markov-grid`: wall time per localizer update on the hospital map,
//! on one core (a 1-thread rayon pool), with the scans (SICK LMS100-like, 1081 beams, 60 used)
//! and noisy odometry of a fixed drive along the hospital's corridors
//! ([`systems::localization::fixtures`]), so every run times the same updates.
//!
//! - mcl: a full update (motion sampling, likelihood-field weighing, resampling when due,
//!   clustering) with KLD off (the set keeps its size), no recovery injection and no
//!   challenges, started around the true pose; `ms_weigh` is the likelihood-field kernel
//!   alone, and `evals_per_s` counts particle × beam evaluations per second of a full update.
//! - markov-grid: 0.25 m × 10° over the floor; `global` scores every cell at every update (the
//!   cost before convergence), `selective` is the default selective update once converged
//!   (after 20 warm-up updates).
//!
//! Each configuration runs `warmup` untimed updates then `reps` timed ones; the reported time is
//! the median (the mean and the 90th percentile too). One JSON object per configuration and
//! line with `--json`.

use crate::scenario::assets_dir;
use serde::Serialize;
use std::time::Instant;
use systems::core::Pose2;
use systems::localization::fixtures::{
    CORRIDOR, DriveStep, SCAN_BEAMS, bench_markov_grid, bench_mcl, map_from, recorded_drive,
};
use systems::localization::mcl::{BeamSubset, sensor_model};
use systems::localization::{LocalizationMap, MarkovGridConfig};

/// Largest `--reps` (timed updates per configuration).
pub const MAX_REPS: usize = 10_000;
/// Largest `--particles` count (at 60 beams, 60 million beam evaluations an update).
pub const MAX_PARTICLES: usize = 1_000_000;
/// Largest `--beams`: every beam of the recorded scans.
pub const MAX_BEAMS: usize = SCAN_BEAMS;

/// `sim bench mcl`: MCL update time (likelihood field, KLD off) on the hospital map, one core.
#[derive(clap::Args, Clone, Debug)]
pub struct LocBenchOptions {
    /// One JSON object per particle count, one per line.
    #[arg(long)]
    pub json: bool,
    /// Timed updates per configuration (the median is reported; 1 for a quick check).
    #[arg(long, default_value_t = 50)]
    pub reps: usize,
    /// Particle counts.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [1000usize, 5000, 20000])]
    pub particles: Vec<usize>,
    /// Beams used per scan.
    #[arg(long, default_value_t = 60)]
    pub beams: usize,
}

/// `sim bench markov-grid`: Markov grid update time (0.25 m × 10°) on the hospital map, global
/// and selective, one core.
#[derive(clap::Args, Clone, Debug)]
pub struct GridBenchOptions {
    /// One JSON object per mode, one per line.
    #[arg(long)]
    pub json: bool,
    /// Timed updates per mode (the median is reported; 1 for a quick check).
    #[arg(long, default_value_t = 10)]
    pub reps: usize,
    /// Beams used per scan.
    #[arg(long, default_value_t = 60)]
    pub beams: usize,
}

#[derive(Serialize)]
struct MclRow {
    bench: &'static str,
    particles: usize,
    beams: usize,
    reps: usize,
    /// Median wall time of a full update (ms, one core).
    ms_per_update: f64,
    mean_ms: f64,
    p90_ms: f64,
    /// Median wall time of the likelihood-field kernel alone (ms).
    ms_weigh: f64,
    /// Particle × beam evaluations per second of a full update (median).
    evals_per_s: f64,
    threads: usize,
}

#[derive(Serialize)]
struct GridRow {
    bench: &'static str,
    mode: &'static str,
    particles: usize,
    cells: usize,
    resolution_m: f64,
    angular_bins: usize,
    beams: usize,
    reps: usize,
    /// Median wall time of an update (ms, one core).
    ms_per_update: f64,
    mean_ms: f64,
    p90_ms: f64,
    threads: usize,
}

struct Stats {
    median: f64,
    mean: f64,
    p90: f64,
}

fn stats(mut v: Vec<f64>) -> Stats {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    Stats {
        median,
        mean: v.iter().sum::<f64>() / n as f64,
        p90: v[((n - 1) as f64 * 0.9).round() as usize],
    }
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

struct Drive {
    map: LocalizationMap,
    steps: Vec<DriveStep>,
    beams: Vec<BeamSubset>,
}

fn hospital_drive(beams: usize) -> anyhow::Result<Drive> {
    let yaml = assets_dir().join("maps/hospital/hospital.yaml");
    let map = map_from(&yaml).map_err(|e| anyhow::anyhow!("{}: {e}", yaml.display()))?;
    let steps = recorded_drive(&map, &CORRIDOR, 0.0, 1);
    let beams = steps
        .iter()
        .map(|s| BeamSubset::from_scan(&s.scan, &Pose2::IDENTITY, beams))
        .collect();
    Ok(Drive { map, steps, beams })
}

fn one_core<R: Send>(f: impl FnOnce() -> R + Send) -> anyhow::Result<R> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()?
        .install(f))
}

/// Checks the options before anything is built or printed.
fn check(o: &LocBenchOptions) -> anyhow::Result<()> {
    if !(1..=MAX_REPS).contains(&o.reps) {
        anyhow::bail!("--reps: expected 1 to {MAX_REPS} updates, got {}", o.reps);
    }
    if !(1..=MAX_BEAMS).contains(&o.beams) {
        anyhow::bail!(
            "--beams: expected 1 to {MAX_BEAMS} (the beams of the recorded scans), got {}",
            o.beams
        );
    }
    if let Some(n) = o
        .particles
        .iter()
        .find(|n| !(1..=MAX_PARTICLES).contains(*n))
    {
        anyhow::bail!("--particles: expected 1 to {MAX_PARTICLES} particles, got {n}");
    }
    Ok(())
}

/// Untimed warm-up updates before the timed ones.
fn warmup(reps: usize) -> usize {
    reps.clamp(1, 3)
}

pub fn run_mcl_bench(o: &LocBenchOptions) -> anyhow::Result<()> {
    check(o)?;
    let d = hospital_drive(o.beams)?;
    let n_steps = d.steps.len();
    if !o.json {
        println!(
            "MCL (likelihood field, KLD off) on the hospital, {} timed updates per row, one core",
            o.reps
        );
        println!(
            "{:>10} {:>6} {:>12} {:>10} {:>10} {:>10} {:>14}",
            "particles", "beams", "median ms", "mean ms", "p90 ms", "weigh ms", "evals/s"
        );
    }
    for &n in &o.particles {
        let (update, weigh, beams_used) = one_core(|| {
            let start = d.steps[0].truth;
            let mut f = bench_mcl(&d.map, n, o.beams, &start);
            let (mut update, mut weigh) = (Vec::new(), Vec::new());
            let mut beams_used = 0;
            let warm = warmup(o.reps);
            for r in 0..warm + o.reps {
                let k = r % n_steps;
                if k == 0 && r > 0 {
                    f = bench_mcl(&d.map, n, o.beams, &start);
                }
                let b = &d.beams[k];
                // the kernel alone, on the particles as they are before the update
                let table = sensor_model::likelihood_table(
                    &d.map.field,
                    &f.config.laser,
                    b.range_max as f64,
                );
                let points = b.returns();
                let mut w = vec![1.0; f.len()];
                let t = Instant::now();
                sensor_model::weigh_likelihood_field(
                    &d.map.field,
                    &table,
                    &points,
                    &f.xs,
                    &f.ys,
                    &f.ths,
                    &mut w,
                );
                let tw = ms_since(t);
                std::hint::black_box(&w);
                let t = Instant::now();
                f.update(&d.map, b, &d.steps[k].odom);
                let tu = ms_since(t);
                if r >= warm {
                    update.push(tu);
                    weigh.push(tw);
                    beams_used = beams_used.max(b.len());
                }
            }
            (update, weigh, beams_used)
        })?;
        let (u, w) = (stats(update), stats(weigh));
        let row = MclRow {
            bench: "mcl",
            particles: n,
            beams: beams_used,
            reps: o.reps,
            ms_per_update: u.median,
            mean_ms: u.mean,
            p90_ms: u.p90,
            ms_weigh: w.median,
            evals_per_s: (n * beams_used) as f64 / (u.median * 1e-3),
            threads: 1,
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&row)?);
        } else {
            println!(
                "{:>10} {:>6} {:>12.3} {:>10.3} {:>10.3} {:>10.3} {:>14.3e}",
                row.particles,
                row.beams,
                row.ms_per_update,
                row.mean_ms,
                row.p90_ms,
                row.ms_weigh,
                row.evals_per_s
            );
        }
    }
    Ok(())
}

/// Updates to converge before the selective update is timed.
const GRID_CONVERGE_UPDATES: usize = 20;

pub fn run_markov_grid_bench(g: &GridBenchOptions) -> anyhow::Result<()> {
    let o = &LocBenchOptions {
        json: g.json,
        reps: g.reps,
        particles: Vec::new(),
        beams: g.beams,
    };
    check(o)?;
    let d = hospital_drive(o.beams)?;
    let n_steps = d.steps.len();
    if !o.json {
        println!(
            "Markov grid on the hospital, {} timed updates per row, one core",
            o.reps
        );
        println!(
            "{:>10} {:>10} {:>6} {:>12} {:>10} {:>10}",
            "mode", "cells", "beams", "median ms", "mean ms", "p90 ms"
        );
    }
    for (mode, threshold, converge) in [
        ("global", 0.0, 0),
        (
            "selective",
            MarkovGridConfig::default().selective_threshold,
            GRID_CONVERGE_UPDATES,
        ),
    ] {
        let (times, cells, beams_used, g) = one_core(|| {
            let new = || bench_markov_grid(&d.map, threshold);
            let mut g = new();
            let mut times = Vec::new();
            let mut beams_used = 0;
            let warm = converge + warmup(o.reps);
            for r in 0..warm + o.reps {
                let k = r % n_steps;
                if k == 0 && r > 0 {
                    g = new();
                }
                let b = &d.beams[k];
                let t = Instant::now();
                g.update(&d.map, &b.returns(), b.range_max, &d.steps[k].odom);
                let dt = ms_since(t);
                if r >= warm {
                    times.push(dt);
                    beams_used = beams_used.max(b.len());
                }
            }
            let cells = g.whole.free_count() * g.whole.n_theta;
            (times, cells, beams_used, g.config.clone())
        })?;
        let s = stats(times);
        let row = GridRow {
            bench: "markov-grid",
            mode,
            particles: cells,
            cells,
            resolution_m: g.resolution,
            angular_bins: g.angular_bins,
            beams: beams_used,
            reps: o.reps,
            ms_per_update: s.median,
            mean_ms: s.mean,
            p90_ms: s.p90,
            threads: 1,
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&row)?);
        } else {
            println!(
                "{:>10} {:>10} {:>6} {:>12.3} {:>10.3} {:>10.3}",
                row.mode, row.cells, row.beams, row.ms_per_update, row.mean_ms, row.p90_ms
            );
        }
    }
    Ok(())
}
