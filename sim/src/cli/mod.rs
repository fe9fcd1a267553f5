//! The `sim` command line: the commands ([`Command`]), one module per command that is more than
//! a call, and [`dispatch`]. Each command's options are a clap `Args` struct owned by the module
//! that does the work, so a new option is written once.

pub mod bench;
pub mod experiment;
pub mod run;
pub mod scans;
pub mod schedule;

use crate::scenario::{bundled_scenarios, load_scenario};
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "sim",
    version,
    about = "Headless deterministic multi-robot simulator"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Build every map-derived structure instead of reading it from the on-disk cache (also
    /// `SIM_NO_CACHE=1`); nothing is written to the cache either.
    #[arg(long, global = true)]
    pub no_cache: bool,
}

#[derive(Subcommand)]
pub enum Command {
    /// Run a scenario (a file, or the name of a bundled scenario; default: hospital_patrol).
    Run(run::RunArgs),
    /// Run a scenario for many seeds and parameter sets in parallel; one row per run
    /// (runs.csv, runs.jsonl) and statistics per set (aggregate.csv, printed). Exit code 2 if
    /// any run failed.
    Batch(crate::batch::BatchArgs),
    /// Merge the output folders of the shards of one batch (`sim batch --shard k/n`) into one.
    BatchMerge(crate::batch::merge::MergeArgs),
    /// Re-run localization, SLAM and evaluation on the sensor data of an MCAP file (one written
    /// by `sim run --mcap`, or LaserScan + Odometry of another ROS 2 system with --scenario).
    Replay(crate::replay::ReplayArgs),
    /// Run a SLAM system on a recorded CARMEN log (e.g. one written by `sim run --carmen-out`).
    Slam(crate::log_slam::SlamArgs),
    /// Draw the HTML report again from what `sim run --report` (report.json), `--summary` or
    /// `sim batch` (runs.jsonl) wrote.
    Report(crate::report::ReportArgs),
    /// List the bundled scenarios.
    Scenarios,
    /// Print the tick order of a scenario's run (or, with --replay, of its replay): the systems
    /// of each set in the order they run, with every output a run can have.
    Schedule(schedule::ScheduleArgs),
    /// Capture laser scans with their true sensor poses into a SCANS file (CSV, see the
    /// recordings documentation). Localizers are not run: they never influence motion or
    /// sensing.
    Scans(scans::ScansArgs),
    /// Align two scans of a SCANS file (the thesis's program: -file, -reference, -current,
    /// -gen, -pop, -F, -C) and compare with the true transform.
    Match(crate::experiment::match_pair::MatchOptions),
    /// Experiments reproducing the theses' protocols.
    Experiment {
        #[command(subcommand)]
        which: experiment::ExperimentCommand,
    },
    /// The on-disk cache of map-derived structures (distance fields, costmaps, road raster):
    /// where it is and what it holds, or clear it.
    Cache {
        #[command(subcommand)]
        which: crate::cache::CacheCommand,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: bench::BenchCommand,
    },
}

/// Runs one command. Errors are for `main` to print; [`crate::batch::RunsFailed`] and
/// [`crate::run::interrupt::Interrupted`] among them choose the exit code.
pub fn dispatch(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Run(a) => {
            crate::run::interrupt::install_handler()?;
            run::run_command(&a)
        }
        Command::Batch(a) => crate::batch::batch_command(&a)?.into_result().map(drop),
        Command::BatchMerge(a) => crate::batch::merge::merge_command(&a)?
            .into_result()
            .map(drop),
        Command::Replay(a) => {
            crate::run::interrupt::install_handler()?;
            crate::replay::replay_command(&a)
        }
        Command::Slam(a) => crate::log_slam::run_slam_command(&a).map(drop),
        Command::Report(a) => crate::report::report_command(&a),
        Command::Scenarios => {
            for (name, path) in bundled_scenarios()? {
                let desc = load_scenario(&path)
                    .map(|s| s.description)
                    .unwrap_or_else(|e| format!("(invalid: {e})"));
                println!("{name:<20} {desc}");
            }
            Ok(())
        }
        Command::Schedule(a) => schedule::schedule_command(&a),
        Command::Scans(a) => scans::scans_command(a),
        Command::Match(o) => crate::experiment::match_pair::run_match(&o),
        Command::Experiment { which } => experiment::experiment_command(which),
        Command::Cache { which } => crate::cache::cache_command(&which),
        Command::Bench { which } => bench::bench_command(which),
    }
}
