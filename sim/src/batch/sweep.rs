//! [`Sweep`]: a batch from code. The runs, parallelism, determinism, rows and statistics are
//! `sim batch`'s own ([`super::Batch::execute`]); only the files are left to the program.
//!
//! ```no_run
//! use sim::batch::Sweep;
//!
//! let results = Sweep::new("maze_run", 0..8)
//!     .duration(30.0)
//!     .sweep("robots[name=scout].behaviour.speed", &["0.4", "0.6"])
//!     .run()?;
//! print!("{}", results.table); // what `sim batch` prints
//! # anyhow::Ok(())
//! ```

use super::{BatchArgs, BatchResults, prepare};
use std::ops::Range;

/// Many seeded runs of one scenario, with parameter sets: `sim batch` without its files.
#[derive(Clone, Debug)]
pub struct Sweep {
    args: BatchArgs,
}

impl Sweep {
    /// Runs of `scenario` (a bundled scenario's name or a file) for each seed of `seeds`, one
    /// run per core at a time, each with one kernel thread (as `sim batch`'s defaults).
    pub fn new(scenario: &str, seeds: Range<u64>) -> Self {
        Sweep {
            args: BatchArgs {
                scenario: scenario.to_string(),
                seeds: format!("{}..{}", seeds.start, seeds.end),
                duration: None,
                sets: Vec::new(),
                sweeps: Vec::new(),
                zips: Vec::new(),
                jobs: 0,
                threads: 1,
                out: None,
                shard: None,
                rrd: false,
                resume: false,
                report: false,
                quiet: true,
            },
        }
    }

    /// Simulated seconds per run (`--duration`).
    pub fn duration(mut self, seconds: f64) -> Self {
        self.args.duration = Some(seconds);
        self
    }

    /// Overrides a scenario key in every run (`--set KEY=VALUE`).
    pub fn set(mut self, key: &str, value: &str) -> Self {
        self.args.sets.push(format!("{key}={value}"));
        self
    }

    /// Runs each value of a key (`--sweep KEY=V1,V2,...`); sweeps form the Cartesian product.
    pub fn sweep(mut self, key: &str, values: &[&str]) -> Self {
        self.args.sweeps.push(format!("{key}={}", values.join(",")));
        self
    }

    /// Keys whose values advance together (`--zip KEY=V1,V2,...`), one more axis of the product.
    pub fn zip(mut self, key: &str, values: &[&str]) -> Self {
        self.args.zips.push(format!("{key}={}", values.join(",")));
        self
    }

    /// Runs at the same time (`--jobs`; 0: one per core).
    pub fn jobs(mut self, jobs: usize) -> Self {
        self.args.jobs = jobs;
        self
    }

    /// Kernel threads of each run (`--threads`; 0: one per core).
    pub fn threads(mut self, threads: usize) -> Self {
        self.args.threads = threads;
        self
    }

    /// The same batch as `sim batch` arguments.
    pub fn args(&self) -> &BatchArgs {
        &self.args
    }

    /// Runs every job: the rows, statistics and table of `sim batch` with the same arguments.
    /// A run that fails is counted in `failed` and its row says why; the others go on.
    pub fn run(&self) -> anyhow::Result<BatchResults> {
        let batch = prepare(&self.args)?;
        batch.execute(self.args.jobs, self.args.threads, None, false)
    }
}
