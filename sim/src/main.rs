//! `sim`: the command line of the simulator.

use clap::{Parser, Subcommand};
use sim::bench::{SwarmOptions, run_swarm_bench};
use sim::bench_loc::{LocBenchOptions, run_markov_grid_bench, run_mcl_bench};
use sim::bench_match::{DeMatchBenchOptions, run_de_match_bench};
use sim::bench_record::{RecordBenchOptions, run_record_bench};
use sim::bench_slam::{SlamBenchOptions, run_slam_bench};
use sim::experiment::de_match::{DeMatchOptions, run_de_match_experiment};
use sim::experiment::slam_compare::{
    METHODS as SLAM_METHODS, SCENARIOS as SLAM_SCENARIOS, SlamExperimentOptions,
    run_slam_experiment, table as slam_table,
};
use sim::interrupt::Interrupted;
use sim::match_cmd::{CrossoverArg, FitnessArg, MatchOptions, parse_strategy, run_match};
use sim::run_cmd::{RunArgs, check_duration, parse_threads, run_command, scenario_arg};
use sim::runner::ScanCapture;
use sim::scenario::{bundled_scenarios, load_scenario};
use sim::slam_cmd::{SlamArgs, run_slam_command};
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
    Run(RunArgs),
    /// Run a scenario for many seeds and parameter sets in parallel; one row per run
    /// (runs.csv, runs.jsonl) and statistics per set (aggregate.csv, printed). Exit code 2 if
    /// any run failed.
    Batch(sim::batch::BatchArgs),
    /// Merge the output folders of the shards of one batch (`sim batch --shard k/n`) into one.
    BatchMerge(sim::batch::merge::MergeArgs),
    /// Re-run localization, SLAM and evaluation on the sensor data of an MCAP file (one written
    /// by `sim run --mcap`, or LaserScan + Odometry of another ROS 2 system with --scenario).
    Replay(sim::replay::ReplayArgs),
    /// Run a SLAM system on a recorded CARMEN log (e.g. one written by `sim run --carmen-out`).
    Slam(SlamArgs),
    /// List the bundled scenarios.
    Scenarios,
    /// Capture laser scans with their true sensor poses into a SCANS file (CSV, see README).
    /// Localizers are not run: they never influence motion or sensing.
    Scans {
        /// A scenario file or the name of a bundled scenario (default: hospital_patrol).
        scenario: Option<String>,
        /// The SCANS file to write.
        #[arg(long)]
        out: PathBuf,
        /// Keep one scan per robot every this many simulated seconds.
        #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
        period: f64,
        /// Override the scenario's duration (simulated seconds).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
        /// Only this robot's scans (repeatable; default: every robot with a laser).
        #[arg(long = "robot")]
        robots: Vec<String>,
        /// Override the scenario's seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads for parallel kernels (0 = one per core; at most 1024). Results do not
        /// depend on it.
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
        /// No progress bar and no report, only errors.
        #[arg(long)]
        quiet: bool,
    },
    /// Align two scans of a SCANS file (the thesis's program: -file, -reference, -current,
    /// -gen, -pop, -F, -C) and compare with the true transform.
    Match {
        /// The SCANS file.
        scans: PathBuf,
        /// Index of the reference scan (the `index` column).
        #[arg(long)]
        reference: u64,
        /// Index of the current (test) scan.
        #[arg(long)]
        current: u64,
        /// Matcher: the thesis's DE with a fitness, or the improved matcher.
        #[arg(long, value_enum, default_value_t = FitnessArg::Improved)]
        fitness: FitnessArg,
        /// DE mutation strategy (default rand1): rand1, rand2, best1, best2, current-to-best1,
        /// current-to-best2, rand-to-best1, rand-to-best2, either-or.
        #[arg(long, value_parser = parse_strategy)]
        strategy: Option<systems::matching::Strategy>,
        /// DE crossover (default binomial).
        #[arg(long, value_enum)]
        crossover: Option<CrossoverArg>,
        /// DE population size (default 100, the thesis program's).
        #[arg(long, allow_negative_numbers = true, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(..=sim::match_cmd::MAX_POPULATION as u64))]
        pop: Option<usize>,
        /// DE generations (default 10000, the thesis program's).
        #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(..=sim::match_cmd::MAX_GENERATIONS as u64))]
        gens: Option<usize>,
        /// DE mutation constant F (default 0.9).
        #[arg(short = 'F', allow_negative_numbers = true)]
        f: Option<f64>,
        /// DE crossover rate CR (default 0.9).
        #[arg(short = 'C', allow_negative_numbers = true)]
        cr: Option<f64>,
        /// Stop the DE after this many generations without improvement (default: never).
        #[arg(long)]
        stall: Option<usize>,
        /// Wall-time limit of the DE in seconds (the thesis's -time; breaks determinism).
        #[arg(long, allow_negative_numbers = true)]
        time: Option<f64>,
        /// Search window: |x|, |y| <= this (m).
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
        max_xy: f64,
        /// Search window: |θ| <= this (degrees).
        #[arg(long, default_value_t = 180.0, allow_negative_numbers = true)]
        max_theta: f64,
        /// Seed of the matcher's random stream.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// One JSON object instead of the text report.
        #[arg(long)]
        json: bool,
    },
    /// Experiments reproducing the seed documents.
    Experiment {
        #[command(subcommand)]
        which: ExperimentCommand,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Run time with no recording, with the .rrd, with the MCAP replay and with both (median
    /// of --reps runs each), and the overhead of each against no recording.
    Record {
        /// One JSON object per scenario and mode, one per line.
        #[arg(long)]
        json: bool,
        /// Scenarios: bundled names or paths.
        #[arg(long = "scenario", value_delimiter = ',', num_args = 1.., default_values_t = sim::bench_record::SCENARIOS.map(String::from))]
        scenarios: Vec<String>,
        /// Runs per mode (the median is reported).
        #[arg(long, default_value_t = 3)]
        reps: usize,
        /// Simulated seconds per run (default: 10 s of hospital_patrol, a scenario's own
        /// duration otherwise).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
        /// Kernel threads (0 = one per core; at most 1024).
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
    },
    /// Wall time of a batch with --jobs 1 --threads 1 and with --jobs 2, and the speed-up.
    Batch(sim::bench_batch::BenchBatchArgs),
    /// Real-time factor and rays/s for swarms of wandering robots with lasers at 10 Hz.
    Swarm {
        /// One JSON object per population and laser, one per line.
        #[arg(long)]
        json: bool,
        /// Populations to run.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [1usize, 10, 100, 1000])]
        robots: Vec<usize>,
        /// Beams per scan.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [180usize, 1081])]
        beams: Vec<usize>,
        /// Simulated seconds per configuration.
        #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
        duration: f64,
        /// Worker threads (0 = one per core; at most 1024).
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
    },
    /// Real-time factor and time per scan of each SLAM mode on the hospital loop run.
    Slam {
        /// One JSON object per mode, one per line.
        #[arg(long)]
        json: bool,
        /// SLAM modes to time.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = sim::bench_slam::MODES.map(String::from))]
        modes: Vec<String>,
        /// Kernel threads the SLAM runs on (0 = one per core; at most 1024; the targets are for
        /// one core).
        #[arg(long, default_value_t = 1, value_parser = parse_threads)]
        threads: usize,
        /// Simulate only this many seconds of the scenario (quick checks; at most its 600 s).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
    },
    /// DE scan-matching time per alignment of 1081-beam hospital scans (one core).
    DeMatch {
        /// One JSON object per method, one per line.
        #[arg(long)]
        json: bool,
        /// Number of hospital scan pairs timed.
        #[arg(long, default_value_t = 100)]
        pairs: usize,
    },
    /// MCL update time (likelihood field, KLD off) on the hospital map, one core.
    Mcl {
        /// One JSON object per particle count, one per line.
        #[arg(long)]
        json: bool,
        /// Timed updates per configuration (the median is reported; 1 for a quick check).
        #[arg(long, default_value_t = 50)]
        reps: usize,
        /// Particle counts.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [1000usize, 5000, 20000])]
        particles: Vec<usize>,
        /// Beams used per scan.
        #[arg(long, default_value_t = 60)]
        beams: usize,
    },
    /// Markov grid update time (0.25 m × 10°) on the hospital map, global and selective, one
    /// core.
    MarkovGrid {
        /// One JSON object per mode, one per line.
        #[arg(long)]
        json: bool,
        /// Timed updates per mode (the median is reported; 1 for a quick check).
        #[arg(long, default_value_t = 10)]
        reps: usize,
        /// Beams used per scan.
        #[arg(long, default_value_t = 60)]
        beams: usize,
    },
}

#[derive(Subcommand)]
enum ExperimentCommand {
    /// The park runs of 004_95e533f2514531b8.txt: each route N times (seeds 0..N), navigating by
    /// road-grid localization and by road MCL; reached-goal rate, wrong turns, recoveries,
    /// time and localization error of both localizers. A route with several robots judges each
    /// of them: `robot runs` = runs × robots with a route, and reached %, wrong turns and
    /// recoveries count robot runs.
    Park {
        /// Runs per route and localizer (at most 100000).
        #[arg(long, default_value_t = 20)]
        runs: u64,
        /// One JSON object per row, one per line (and one per run with --per-run).
        #[arg(long)]
        json: bool,
        /// With --json: also print every run.
        #[arg(long, requires = "json")]
        per_run: bool,
        /// Routes (bundled scenario names or paths; each once).
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = sim::experiment::park::ROUTES.map(String::from))]
        routes: Vec<String>,
        /// Worker threads (0 = one per core; at most 1024). Results do not depend on it.
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
    },
    /// The scan-matching protocol of 000_9f0113837c153763.txt on maze and hospital scans:
    /// success λ, σx, σy, σθ and time per alignment for every DE strategy, the Euclidean
    /// reference and the improved matcher.
    DeMatch {
        /// One JSON object per row, one per line.
        #[arg(long)]
        json: bool,
        /// The thesis's full protocol: 80 reference scans × steps 5, 10, 20, 30 × 50 repeats,
        /// up to 5000 generations (hours).
        #[arg(long)]
        full: bool,
        /// Worker threads for the pairs (0 = one per core; at most 1024). Results do not
        /// depend on it.
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
        /// Seed of the pair selection and of the matchers.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Pairs of the default protocol (a small number for quick checks).
        #[arg(long, hide = true, conflicts_with = "full")]
        pairs: Option<usize>,
        /// Pairs on which the brute-force Euclidean reference runs.
        #[arg(long, default_value_t = 50)]
        brute_pairs: usize,
        /// Write the captured scans of both scenarios to this folder (maze_run.csv,
        /// hospital_patrol.csv), for `sim match`.
        #[arg(long)]
        save_scans: Option<PathBuf>,
        /// Only the methods whose name contains this text (e.g. `improved`, `rand/1`).
        #[arg(long)]
        only: Option<String>,
        /// Print every wrong alignment (scan indices, truth, answer) to stderr.
        #[arg(long)]
        list_wrong: bool,
    },
    /// The maze run of 000_9f0113837c153763.txt and the hospital loop: ATE, RPE and map quality
    /// of wheel odometry, DE scan-to-scan odometry, scan-to-map, RBPF and graph SLAM on
    /// identical data.
    MazeSlam {
        /// One JSON object per scenario and method, one per line.
        #[arg(long)]
        json: bool,
        /// Scenarios: bundled names or paths.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = SLAM_SCENARIOS.map(String::from))]
        scenarios: Vec<String>,
        /// Methods to run.
        #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = SLAM_METHODS.map(String::from))]
        methods: Vec<String>,
        /// Kernel threads (0 = one per core; at most 1024). Results do not depend on it.
        #[arg(long, default_value_t = 0, value_parser = parse_threads)]
        threads: usize,
    },
}

fn main() -> ExitCode {
    restore_sigpipe();
    let cli = Cli::parse();
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<Interrupted>() => {
            eprintln!("{e}");
            ExitCode::from(sim::interrupt::EXIT_CODE)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.is::<sim::batch::RunsFailed>() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// Ends quietly when whoever reads standard output goes away (`sim bench swarm --json | head -2`),
/// as Unix tools do: Rust ignores SIGPIPE, so the next write to the closed pipe panicked.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: the default disposition of a signal, set before any other thread exists
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn dispatch(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Run(args) => {
            sim::interrupt::install_handler()?;
            run_command(&args)
        }
        Command::Batch(args) => sim::batch::batch_command(&args)?.into_result().map(|_| ()),
        Command::BatchMerge(args) => sim::batch::merge::merge_command(&args)?
            .into_result()
            .map(|_| ()),
        Command::Replay(args) => {
            sim::interrupt::install_handler()?;
            sim::replay::replay_command(&args)
        }
        Command::Slam(args) => run_slam_command(&args).map(|_| ()),
        Command::Scenarios => {
            for (name, path) in bundled_scenarios()? {
                let desc = load_scenario(&path)
                    .map(|s| s.description)
                    .unwrap_or_else(|e| format!("(invalid: {e})"));
                println!("{name:<20} {desc}");
            }
            Ok(())
        }
        Command::Scans {
            scenario,
            out,
            period,
            duration,
            robots,
            seed,
            threads,
            quiet,
        } => {
            let mut sc = scenario_arg(scenario.as_deref())?;
            if let Some(s) = seed {
                sc.seed = s;
            }
            if let Some(d) = duration {
                sc.duration = check_duration(d)?;
            }
            if !(period.is_finite() && period > 0.0) {
                anyhow::bail!("--period: expected a positive number of seconds, got {period}");
            }
            let capture = ScanCapture {
                period_s: period,
                robots: (!robots.is_empty()).then_some(robots),
            };
            if !quiet {
                eprintln!(
                    "capturing scans of {} ({} robots, {:.1} s simulated, seed {}, one scan per \
                     robot every {period} s)",
                    sc.name,
                    sc.robots.len(),
                    sc.duration,
                    sc.seed
                );
            }
            let scans = sim::scans::capture_scans(&sc, &capture, threads, !quiet)?;
            if scans.is_empty() {
                anyhow::bail!(
                    "{}: no laser scans captured (does any selected robot carry a laser?)",
                    sc.source
                );
            }
            sim::scans::write_scans(&out, &scans)?;
            if !quiet {
                println!("{} scans written to {}", scans.len(), out.display());
            }
            Ok(())
        }
        Command::Match {
            scans,
            reference,
            current,
            fitness,
            strategy,
            crossover,
            pop,
            gens,
            f,
            cr,
            stall,
            time,
            max_xy,
            max_theta,
            seed,
            json,
        } => run_match(&MatchOptions {
            scans,
            reference,
            current,
            fitness,
            strategy,
            crossover,
            population: pop,
            generations: gens,
            f,
            cr,
            stall,
            time_limit: time,
            max_xy,
            max_theta_deg: max_theta,
            seed,
            json,
        }),
        Command::Experiment { which } => match which {
            ExperimentCommand::Park {
                runs,
                json,
                per_run,
                routes,
                threads,
            } => {
                let (rows, all) = sim::experiment::park::run_park_experiment(
                    &sim::experiment::park::ParkOptions {
                        routes,
                        runs,
                        threads,
                        progress: !json,
                    },
                )?;
                if json {
                    for r in &rows {
                        println!("{}", serde_json::to_string(r)?);
                    }
                    if per_run {
                        for r in &all {
                            println!("{}", serde_json::to_string(r)?);
                        }
                    }
                } else {
                    print!("{}", sim::experiment::park::table(&rows));
                }
                Ok(())
            }
            ExperimentCommand::DeMatch {
                json,
                full,
                threads,
                seed,
                pairs,
                brute_pairs,
                save_scans,
                only,
                list_wrong,
            } => run_de_match_experiment(&DeMatchOptions {
                json,
                full,
                threads,
                seed,
                pairs,
                brute_pairs,
                save_scans,
                only,
                list_wrong,
            }),
            ExperimentCommand::MazeSlam {
                json,
                scenarios,
                methods,
                threads,
            } => {
                let rows = run_slam_experiment(&SlamExperimentOptions {
                    scenarios,
                    methods,
                    threads,
                    progress: !json,
                })?;
                if json {
                    for r in &rows {
                        println!("{}", serde_json::to_string(r)?);
                    }
                } else {
                    print!("{}", slam_table(&rows));
                }
                Ok(())
            }
        },
        Command::Bench { which } => match which {
            BenchCommand::Record {
                json,
                scenarios,
                reps,
                duration,
                threads,
            } => run_record_bench(&RecordBenchOptions {
                json,
                scenarios,
                reps,
                duration,
                threads,
            })
            .map(|_| ()),
            BenchCommand::Batch(args) => sim::bench_batch::run_batch_bench(&args).map(|_| ()),
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
            BenchCommand::Mcl {
                json,
                reps,
                particles,
                beams,
            } => run_mcl_bench(&LocBenchOptions {
                json,
                reps,
                particles,
                beams,
            }),
            BenchCommand::MarkovGrid { json, reps, beams } => {
                run_markov_grid_bench(&LocBenchOptions {
                    json,
                    reps,
                    particles: Vec::new(),
                    beams,
                })
            }
            BenchCommand::Slam {
                json,
                modes,
                threads,
                duration,
            } => run_slam_bench(&SlamBenchOptions {
                json,
                modes,
                threads,
                duration,
            })
            .map(|_| ()),
            BenchCommand::DeMatch { json, pairs } => {
                run_de_match_bench(&DeMatchBenchOptions { json, pairs })
            }
        },
    }
}
