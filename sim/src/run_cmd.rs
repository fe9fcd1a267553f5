//! `sim run`: its arguments and what it does with them (the binary's `main.rs` only dispatches).

use crate::runner::{RunOptions, RunOutput, run_scenario_exporting};
use crate::scenario::{DEFAULT_SCENARIO, Scenario, find_scenario, load_scenario};
use crate::{RunExports, record};
use std::path::{Path, PathBuf};

#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    /// A scenario file or the name of a bundled scenario (default: hospital_patrol).
    pub scenario: Option<String>,
    /// Override the scenario's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Override the scenario's duration (simulated seconds).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    #[command(flatten)]
    pub out: OutputArgs,
    /// Write the event log here: scenario events and navigation events (task started,
    /// stops, re-plans, giving way, failures), one `time robot text` line each.
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Export the run as a CARMEN log (ODOM, TRUEPOS, ROBOTLASER1) per robot with a laser and
    /// encoders; several robots: `-<robot>` after the file's stem.
    #[arg(long)]
    pub carmen_out: Option<PathBuf>,
    /// Also write an MCAP replay of the run (ROS 2 messages: scans, odometry, ground truth,
    /// GPS, compass, camera, sonars, tf), for `sim replay` and ROS tools.
    #[arg(long)]
    pub mcap: Option<PathBuf>,
}

/// The outputs a run and a replay share.
#[derive(clap::Args, Clone, Debug)]
pub struct OutputArgs {
    /// Where to write the Rerun recording (default: <scenario>-seed<N>.rrd here for a run,
    /// <file stem>-replay.rrd for a replay).
    #[arg(long, conflicts_with = "no_rrd")]
    pub rrd: Option<PathBuf>,
    /// Do not write a recording.
    #[arg(long)]
    pub no_rrd: bool,
    /// Write the summary as JSON to this file.
    #[arg(long)]
    pub summary: Option<PathBuf>,
    /// Write ground truth and every localizer's estimates here in TUM format (for evo).
    #[arg(long)]
    pub trajectories: Option<PathBuf>,
    /// Save the maps as map_server YAML + PGM: every SLAM system's, and a known-pose map per
    /// robot with a laser and no SLAM; several: `-<robot>-<name>` after the stem.
    #[arg(long)]
    pub save_map: Option<PathBuf>,
    /// Worker threads for parallel kernels (0 = one per core; at most 1024). Results do not
    /// depend on it.
    #[arg(long, default_value_t = 0, value_parser = parse_threads)]
    pub threads: usize,
    /// No progress bar and no table, only errors.
    #[arg(long)]
    pub quiet: bool,
}

impl OutputArgs {
    /// The recording to write: `--rrd`, else `default` unless `--no-rrd`.
    pub fn rrd_path(&self, default: impl FnOnce() -> PathBuf) -> Option<PathBuf> {
        (!self.no_rrd).then(|| self.rrd.clone().unwrap_or_else(default))
    }

    /// The options of the run loop.
    pub fn run_options(&self, rrd: Option<PathBuf>) -> RunOptions {
        RunOptions {
            rrd,
            threads: self.threads,
            progress: !self.quiet,
            trajectory_period: None,
        }
    }

    /// What to print and write afterwards (`log`: the event log file, `sim run --log`).
    pub fn report<'a>(&'a self, rrd: Option<&'a Path>, log: Option<&'a Path>) -> RunReport<'a> {
        RunReport {
            quiet: self.quiet,
            rrd,
            trajectories: self.trajectories.as_deref(),
            summary: self.summary.as_deref(),
            log,
        }
    }
}

/// Parses the arguments of one `sim` subcommand as the binary does (`args` without the
/// subcommand's name), for tests and tools.
pub fn parse_args<A: clap::Args>(args: &[&str]) -> Result<A, clap::Error> {
    #[derive(clap::Parser)]
    struct Wrap<A: clap::Args> {
        #[command(flatten)]
        args: A,
    }
    <Wrap<A> as clap::Parser>::try_parse_from(std::iter::once("sim").chain(args.iter().copied()))
        .map(|w| w.args)
}

/// A scenario file or the name of a bundled scenario (default: hospital_patrol).
pub fn scenario_arg(arg: Option<&str>) -> anyhow::Result<Scenario> {
    Ok(load_scenario(&scenario_path(arg)?)?)
}

/// The file of a scenario argument: a path, or the name of a bundled scenario (default:
/// hospital_patrol).
pub fn scenario_path(arg: Option<&str>) -> anyhow::Result<PathBuf> {
    find_scenario(arg.unwrap_or(DEFAULT_SCENARIO))
}

/// `--duration`: a positive number of seconds.
pub fn check_duration(d: f64) -> anyhow::Result<f64> {
    if !(d.is_finite() && d > 0.0) {
        anyhow::bail!("--duration: expected a positive number of seconds, got {d}");
    }
    Ok(d)
}

/// The value parser of every `--threads`: 0 (one per core) or 1 to
/// [`systems::core::pool::MAX_THREADS`], checked before any thread starts.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    use systems::core::pool::MAX_THREADS;
    let bad = || format!("expected 0 (one per core) or a thread count from 1 to {MAX_THREADS}");
    let n: usize = s.trim().parse().map_err(|_| bad())?;
    if n > MAX_THREADS {
        return Err(bad());
    }
    Ok(n)
}

fn write_file(p: &Path, what: &str, text: String) -> anyhow::Result<()> {
    std::fs::write(p, text)
        .map_err(|e| anyhow::anyhow!("{}: cannot write the {what}: {e}", p.display()))
}

/// `sim run`.
pub fn run_command(a: &RunArgs) -> anyhow::Result<()> {
    let mut sc = scenario_arg(a.scenario.as_deref())?;
    if let Some(s) = a.seed {
        sc.seed = s;
    }
    if let Some(d) = a.duration {
        sc.duration = check_duration(d)?;
    }
    let rrd_path = a
        .out
        .rrd_path(|| PathBuf::from(format!("{}-seed{}.rrd", sc.name, sc.seed)));
    if !a.out.quiet {
        eprintln!(
            "running {} ({} robots, {:.1} s simulated, seed {})",
            sc.name,
            sc.robots.len(),
            sc.duration,
            sc.seed
        );
    }
    let out = run_scenario_exporting(
        &sc,
        &a.out.run_options(rrd_path.clone()),
        &RunExports {
            carmen_out: a.carmen_out.clone(),
            save_map: a.out.save_map.clone(),
            mcap: a.mcap.clone(),
        },
    )?;
    report_run(&out, &a.out.report(rrd_path.as_deref(), a.log.as_deref()))
}

/// What to print and write after a run or a replay.
pub struct RunReport<'a> {
    pub quiet: bool,
    /// The recording written.
    pub rrd: Option<&'a Path>,
    pub trajectories: Option<&'a Path>,
    pub summary: Option<&'a Path>,
    pub log: Option<&'a Path>,
}

/// Prints the summary table and what was written, writes the trajectories, the log and the
/// summary asked for; an interrupted run is then an error (exit code 130).
pub fn report_run(out: &RunOutput, r: &RunReport<'_>) -> anyhow::Result<()> {
    if !r.quiet {
        print!("{}", out.summary.table());
        if let Some(p) = r.rrd {
            println!(
                "recording written to {} (open it with: rerun {})",
                p.display(),
                p.display()
            );
        }
        for f in &out.exported.carmen_logs {
            println!("CARMEN log written to {}", f.display());
        }
        for m in &out.exported.maps {
            println!("{}", m.describe());
        }
        if let Some(m) = &out.exported.mcap {
            println!(
                "MCAP replay written to {} ({} messages, {} topics)",
                m.path.display(),
                m.stats.messages,
                m.stats.channels
            );
        }
    }
    if let Some(dir) = r.trajectories {
        let files = record::write_trajectories(dir, &out.localization)?;
        if !r.quiet {
            println!(
                "{} trajectory files written to {}",
                files.len(),
                dir.display()
            );
        }
    }
    if let Some(p) = r.log {
        let mut text = String::new();
        for (t, robot, what) in &out.log {
            let who = if robot.is_empty() { "-" } else { robot };
            text += &format!("{t:9.2} {who:<12} {what}\n");
        }
        write_file(p, "log", text)?;
    }
    if let Some(p) = r.summary {
        let json = serde_json::to_string_pretty(&out.summary)?;
        write_file(p, "summary", json + "\n")?;
    }
    if out.interrupted {
        return Err(crate::interrupt::Interrupted {
            sim_time_s: out.summary.sim_time_s,
        }
        .into());
    }
    Ok(())
}
