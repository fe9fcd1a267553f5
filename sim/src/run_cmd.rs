//! `sim run`: its arguments and what it does with them (the binary's `main.rs` only dispatches).

use crate::runner::{RunOptions, run_scenario_exporting};
use crate::scenario::{
    DEFAULT_SCENARIO, Scenario, bundled_scenarios, find_scenario, load_scenario,
};
use crate::{RunExports, record};
use std::path::PathBuf;

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
    /// Where to write the Rerun recording (default: <scenario>-seed<N>.rrd here).
    #[arg(long, conflicts_with = "no_rrd")]
    pub rrd: Option<PathBuf>,
    /// Do not write a recording.
    #[arg(long)]
    pub no_rrd: bool,
    /// Write the summary as JSON to this file.
    #[arg(long)]
    pub summary: Option<PathBuf>,
    /// Worker threads for parallel kernels (0 = one per core). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// No progress bar and no table, only errors.
    #[arg(long)]
    pub quiet: bool,
    /// Write ground truth and every localizer's estimates here in TUM format (for evo).
    #[arg(long)]
    pub trajectories: Option<PathBuf>,
    /// Write the event log here: scenario events and navigation events (task started,
    /// stops, re-plans, giving way, failures), one `time robot text` line each.
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Export the run as a CARMEN log (ODOM, TRUEPOS, ROBOTLASER1) per robot with a laser and
    /// encoders; several robots: `-<robot>` after the file's stem.
    #[arg(long)]
    pub carmen_out: Option<PathBuf>,
    /// Save the maps as map_server YAML + PGM: every SLAM system's, and a known-pose map per
    /// robot with a laser and no SLAM; several: `-<robot>-<name>` after the stem.
    #[arg(long)]
    pub save_map: Option<PathBuf>,
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
    let arg = arg.unwrap_or(DEFAULT_SCENARIO);
    let path = find_scenario(arg).ok_or_else(|| {
        let names: Vec<String> = bundled_scenarios().into_iter().map(|(n, _)| n).collect();
        anyhow::anyhow!(
            "{arg}: no such file and no bundled scenario of that name (bundled: {})",
            names.join(", ")
        )
    })?;
    Ok(load_scenario(&path)?)
}

/// `--duration`: a positive number of seconds.
pub fn check_duration(d: f64) -> anyhow::Result<f64> {
    if !(d.is_finite() && d > 0.0) {
        anyhow::bail!("--duration: expected a positive number of seconds, got {d}");
    }
    Ok(d)
}

fn write_file(p: &PathBuf, what: &str, text: String) -> anyhow::Result<()> {
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
    let rrd_path = if a.no_rrd {
        None
    } else {
        Some(
            a.rrd
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}-seed{}.rrd", sc.name, sc.seed))),
        )
    };
    if !a.quiet {
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
        &RunOptions {
            rrd: rrd_path.clone(),
            threads: a.threads,
            progress: !a.quiet,
            trajectory_period: None,
        },
        &RunExports {
            carmen_out: a.carmen_out.clone(),
            save_map: a.save_map.clone(),
        },
    )?;
    if !a.quiet {
        print!("{}", out.summary.table());
        if let Some(p) = &rrd_path {
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
    }
    if let Some(dir) = &a.trajectories {
        let files = record::write_trajectories(dir, &out.localization)?;
        if !a.quiet {
            println!(
                "{} trajectory files written to {}",
                files.len(),
                dir.display()
            );
        }
    }
    if let Some(p) = &a.log {
        let mut text = String::new();
        for (t, robot, what) in &out.log {
            let who = if robot.is_empty() { "-" } else { robot };
            text += &format!("{t:9.2} {who:<12} {what}\n");
        }
        write_file(p, "log", text)?;
    }
    if let Some(p) = &a.summary {
        let json = serde_json::to_string_pretty(&out.summary)?;
        write_file(p, "summary", json + "\n")?;
    }
    Ok(())
}
