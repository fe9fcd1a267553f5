//! `sim bench batch`: the wall time of one batch run serially (`--jobs 1 --threads 1`) and on
//! two workers (`--jobs 2 --threads 1`), and the speed-up. Both give the same summaries; the bench checks that too. Nothing is written.

use crate::batch::runner::MAX_RUNS;
use crate::batch::{self, BatchArgs};
use crate::stats::median;
use serde::Serialize;
use std::time::Instant;

#[derive(clap::Args, Clone, Debug)]
pub struct BenchBatchArgs {
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// A scenario file or the name of a bundled scenario.
    #[arg(long, default_value = "hospital_patrol")]
    pub scenario: String,
    /// Runs per batch (seeds 0..N; at most 1000000, as in `sim batch`).
    #[arg(long, default_value_t = 4,
          value_parser = clap::value_parser!(u64).range(1..=MAX_RUNS as u64))]
    pub seeds: u64,
    /// Simulated seconds per run (in place of the scenario's own duration).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub duration: f64,
    /// Time each configuration this many times (alternating); medians are reported.
    #[arg(long, default_value_t = 1,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    pub reps: usize,
}

/// The figures (the JSON object of `--json`).
#[derive(Clone, Debug, Serialize)]
pub struct BatchBenchRow {
    pub scenario: String,
    pub runs: usize,
    pub duration_s: f64,
    pub reps: usize,
    /// Median wall time of the batch with --jobs 1 --threads 1 (s), and every repetition.
    pub serial_s: f64,
    pub serial_all_s: Vec<f64>,
    /// The same with --jobs 2 --threads 1.
    pub parallel_s: f64,
    pub parallel_all_s: Vec<f64>,
    pub speedup: f64,
    pub target: f64,
    /// Both configurations gave identical summaries (but wall-clock fields).
    pub identical: bool,
}

pub fn run_batch_bench(o: &BenchBatchArgs) -> anyhow::Result<BatchBenchRow> {
    crate::options::check_duration(o.duration)?;
    let args = BatchArgs {
        scenario: o.scenario.clone(),
        seeds: format!("0..{}", o.seeds),
        duration: Some(o.duration),
        sets: Vec::new(),
        sweeps: Vec::new(),
        zips: Vec::new(),
        jobs: 1,
        threads: 1,
        out: None,
        shard: None,
        rrd: false,
        resume: false,
        report: false,
        quiet: true,
    };
    let b = batch::prepare(&args)?;
    let mut serial = Vec::new();
    let mut parallel = Vec::new();
    let mut identical = true;
    for rep in 0..o.reps {
        let mut results = Vec::new();
        for (jobs, times) in [(1, &mut serial), (2, &mut parallel)] {
            if !o.json {
                eprintln!(
                    "rep {}/{}: {} runs of {} s with --jobs {jobs} --threads 1…",
                    rep + 1,
                    o.reps,
                    b.jobs.len(),
                    o.duration
                );
            }
            let t = Instant::now();
            let done = batch::run_batch(&b, jobs, 1, None, false, (None, &Default::default()))?;
            times.push(t.elapsed().as_secs_f64());
            let mut summaries = Vec::new();
            for f in done {
                match f.result {
                    Ok(s) => summaries.push(s.deterministic_part()),
                    Err(e) => {
                        anyhow::bail!("run {} (seed {}) failed: {e}", f.job.index, f.job.seed)
                    }
                }
            }
            results.push(summaries);
        }
        identical &= results[0] == results[1];
    }
    let (s, p) = (median(&mut serial.clone()), median(&mut parallel.clone()));
    let row = BatchBenchRow {
        scenario: b.name.clone(),
        runs: b.jobs.len(),
        duration_s: o.duration,
        reps: o.reps,
        serial_s: s,
        serial_all_s: serial,
        parallel_s: p,
        parallel_all_s: parallel,
        speedup: s / p.max(1e-9),
        target: 1.8,
        identical,
    };
    if o.json {
        println!("{}", crate::bench::machine::json_line(&row)?);
    } else {
        println!(
            "{} runs of {} ({} s simulated each), median of {}:\n\
             --jobs 1 --threads 1  {:>8.2} s\n\
             --jobs 2 --threads 1  {:>8.2} s\n\
             speed-up              {:>8.2}× (target ≥ {}×); identical summaries: {}",
            row.runs,
            row.scenario,
            row.duration_s,
            row.reps,
            row.serial_s,
            row.parallel_s,
            row.speedup,
            row.target,
            row.identical
        );
    }
    Ok(row)
}
