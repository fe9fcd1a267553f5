//! `sim`: the command line of the simulator.

use clap::{Parser, Subcommand};
use sim::bench::{SwarmOptions, run_swarm_bench};
use sim::scenario::{DEFAULT_SCENARIO, bundled_scenarios, find_scenario, load_scenario};
use sim::{RunOptions, run_scenario};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "sim",
    version,
    about = "Headless deterministic multi-robot simulator"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario (a file, or the name of a bundled scenario; default: hospital_patrol).
    Run {
        scenario: Option<String>,
        /// Override the scenario's seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Override the scenario's duration (simulated seconds).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
        /// Where to write the Rerun recording (default: <scenario>-seed<N>.rrd here).
        #[arg(long, conflicts_with = "no_rrd")]
        rrd: Option<PathBuf>,
        /// Do not write a recording.
        #[arg(long)]
        no_rrd: bool,
        /// Write the summary as JSON to this file.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Worker threads for parallel kernels (0 = one per core). Results do not depend on it.
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// No progress bar and no table, only errors.
        #[arg(long)]
        quiet: bool,
        /// Write ground truth and every localizer's estimates here in TUM format (for evo).
        #[arg(long)]
        trajectories: Option<PathBuf>,
    },
    /// List the bundled scenarios.
    Scenarios,
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Real-time factor and rays/s for swarms of wandering robots with lasers at 10 Hz.
    Swarm {
        /// One JSON object per population and laser, one per line.
        #[arg(long)]
        json: bool,
        /// Populations to run.
        #[arg(long, value_delimiter = ',', default_values_t = [1usize, 10, 100, 1000])]
        robots: Vec<usize>,
        /// Beams per scan.
        #[arg(long, value_delimiter = ',', default_values_t = [180usize, 1081])]
        beams: Vec<usize>,
        /// Simulated seconds per configuration.
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
        /// Worker threads (0 = one per core).
        #[arg(long, default_value_t = 0)]
        threads: usize,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn dispatch(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Run {
            scenario,
            seed,
            duration,
            rrd,
            no_rrd,
            summary,
            threads,
            quiet,
            trajectories,
        } => {
            let arg = scenario.unwrap_or_else(|| DEFAULT_SCENARIO.to_string());
            let path = find_scenario(&arg).ok_or_else(|| {
                let names: Vec<String> = bundled_scenarios().into_iter().map(|(n, _)| n).collect();
                anyhow::anyhow!(
                    "{arg}: no such file and no bundled scenario of that name (bundled: {})",
                    names.join(", ")
                )
            })?;
            let mut sc = load_scenario(&path)?;
            if let Some(s) = seed {
                sc.seed = s;
            }
            if let Some(d) = duration {
                if !(d.is_finite() && d > 0.0) {
                    anyhow::bail!("--duration: expected a positive number of seconds, got {d}");
                }
                sc.duration = d;
            }
            let rrd_path =
                if no_rrd {
                    None
                } else {
                    Some(rrd.unwrap_or_else(|| {
                        PathBuf::from(format!("{}-seed{}.rrd", sc.name, sc.seed))
                    }))
                };
            if !quiet {
                eprintln!(
                    "running {} ({} robots, {:.1} s simulated, seed {})",
                    sc.name,
                    sc.robots.len(),
                    sc.duration,
                    sc.seed
                );
            }
            let out = run_scenario(
                &sc,
                &RunOptions {
                    rrd: rrd_path.clone(),
                    threads,
                    progress: !quiet,
                    trajectory_period: None,
                },
            )?;
            if !quiet {
                print!("{}", out.summary.table());
                if let Some(p) = &rrd_path {
                    println!(
                        "recording written to {} (open it with: rerun {})",
                        p.display(),
                        p.display()
                    );
                }
            }
            if let Some(dir) = &trajectories {
                let files = sim::record::write_trajectories(dir, &out.localization)?;
                if !quiet {
                    println!(
                        "{} trajectory files written to {}",
                        files.len(),
                        dir.display()
                    );
                }
            }
            if let Some(p) = summary {
                let json = serde_json::to_string_pretty(&out.summary)?;
                std::fs::write(&p, json + "\n").map_err(|e| {
                    anyhow::anyhow!("{}: cannot write the summary: {e}", p.display())
                })?;
            }
            Ok(())
        }
        Command::Scenarios => {
            for (name, path) in bundled_scenarios() {
                let desc = load_scenario(&path)
                    .map(|s| s.description)
                    .unwrap_or_else(|e| format!("(invalid: {e})"));
                println!("{name:<20} {desc}");
            }
            Ok(())
        }
        Command::Bench { which } => match which {
            BenchCommand::Swarm {
                json,
                robots,
                beams,
                duration,
                threads,
            } => run_swarm_bench(&SwarmOptions {
                json,
                robots,
                beams,
                duration,
                threads,
            }),
        },
    }
}
