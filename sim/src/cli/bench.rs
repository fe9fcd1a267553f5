//! `sim bench …`: the benchmarks' subcommands; each takes its benchmark's own options.

use crate::bench;
use clap::Subcommand;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Run time with no recording, with the .rrd, with the MCAP replay and with both (median
    /// of --reps runs each), and the overhead of each against no recording.
    Record(bench::record::RecordBenchOptions),
    /// Wall time of a batch with --jobs 1 --threads 1 and with --jobs 2, and the speed-up.
    Batch(bench::batch::BenchBatchArgs),
    /// Real-time factor and rays/s for swarms of wandering robots with lasers at 10 Hz.
    Swarm(bench::swarm::SwarmOptions),
    /// A tick through the library facade against the bare schedule, alternating on one world:
    /// the median of the paired differences.
    Facade(bench::facade::FacadeBenchOptions),
    /// Where a tick's time goes: each system's time per tick and share, on one thread.
    Profile(bench::profile::ProfileOptions),
    /// Time before the first tick, phase by phase, and the first tick against the next ones.
    Startup(bench::startup::StartupOptions),
    /// Real-time factor and time per scan of each SLAM mode on the hospital loop run.
    Slam(bench::slam::SlamBenchOptions),
    /// DE scan-matching time per alignment of 1081-beam hospital scans (one core).
    DeMatch(bench::matching::DeMatchBenchOptions),
    /// MCL update time (likelihood field, KLD off) on the hospital map, one core.
    Mcl(bench::localization::LocBenchOptions),
    /// Markov grid update time (0.25 m × 10°) on the hospital map, global and selective, one
    /// core.
    MarkovGrid(bench::localization::GridBenchOptions),
}

/// `sim bench …`.
pub fn bench_command(which: BenchCommand) -> anyhow::Result<()> {
    match which {
        BenchCommand::Record(o) => bench::record::run_record_bench(&o).map(drop),
        BenchCommand::Batch(a) => bench::batch::run_batch_bench(&a).map(drop),
        BenchCommand::Swarm(o) => bench::swarm::run_swarm_bench(&o),
        BenchCommand::Facade(o) => bench::facade::run_facade_bench(&o),
        BenchCommand::Profile(o) => bench::profile::run_profile(&o),
        BenchCommand::Startup(o) => bench::startup::run_startup_bench(&o),
        BenchCommand::Slam(o) => bench::slam::run_slam_bench(&o).map(drop),
        BenchCommand::DeMatch(o) => bench::matching::run_de_match_bench(&o),
        BenchCommand::Mcl(o) => bench::localization::run_mcl_bench(&o),
        BenchCommand::MarkovGrid(o) => bench::localization::run_markov_grid_bench(&o),
    }
}
