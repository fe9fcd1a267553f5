//! What a run or a replay writes and prints when it ends: the options they share (recording,
//! summary, trajectories, maps, threads) and the report of a finished run.

use super::RunOutput;
use crate::formats::tum::{Estimates, write_trajectories};
use crate::run::RunOptions;
use std::path::{Path, PathBuf};

// the field docs are the --help text: <placeholders> are not HTML
#[allow(rustdoc::invalid_html_tags)]
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
    /// With --trajectories: every estimate from the first, before convergence too (default:
    /// from convergence on, the estimates the summary's ATE and RPE judge).
    #[arg(long, requires = "trajectories")]
    pub all_estimates: bool,
    /// Save the maps as map_server YAML + PGM: every SLAM system's, and a known-pose map per
    /// robot with a laser and no SLAM; several: `-<robot>-<name>` after the stem.
    #[arg(long)]
    pub save_map: Option<PathBuf>,
    /// Worker threads for parallel kernels (0 = one per core; at most 1024). Results do not
    /// depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
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
            estimates: if self.all_estimates {
                Estimates::All
            } else {
                Estimates::FromConvergence
            },
            summary: self.summary.as_deref(),
            log,
        }
    }
}

fn write_file(p: &Path, what: &str, text: String) -> anyhow::Result<()> {
    std::fs::write(p, text)
        .map_err(|e| anyhow::anyhow!("{}: cannot write the {what}: {e}", p.display()))
}

/// What to print and write after a run or a replay.
pub struct RunReport<'a> {
    /// Print nothing but errors.
    pub quiet: bool,
    /// The recording written.
    pub rrd: Option<&'a Path>,
    /// Where to write the trajectories (TUM files, a folder).
    pub trajectories: Option<&'a Path>,
    /// Which estimates the trajectories hold.
    pub estimates: Estimates,
    /// Where to write the summary (JSON).
    pub summary: Option<&'a Path>,
    /// Where to write the event log.
    pub log: Option<&'a Path>,
}

/// Prints the summary table and what was written, writes the trajectories, the log and the
/// summary asked for (each whatever became of the others; the failures are then the error);
/// an interrupted run is then an error (exit code 130).
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
    // each file is written whatever became of the others
    let mut failed = Vec::new();
    if let Some(dir) = r.trajectories {
        match write_trajectories(dir, &out.localization, r.estimates) {
            Ok(files) if !r.quiet => println!(
                "{} trajectory files written to {}",
                files.len(),
                dir.display()
            ),
            Ok(_) => {}
            Err(e) => failed.push(format!("{e:#}")),
        }
    }
    if let Some(p) = r.log {
        let mut text = String::new();
        for (t, robot, what) in &out.log {
            let who = if robot.is_empty() { "-" } else { robot };
            text += &format!("{t:9.2} {who:<12} {what}\n");
        }
        if let Err(e) = write_file(p, "log", text) {
            failed.push(format!("{e:#}"));
        }
    }
    if let Some(p) = r.summary {
        let json = serde_json::to_string_pretty(&out.summary)?;
        if let Err(e) = write_file(p, "summary", json + "\n") {
            failed.push(format!("{e:#}"));
        }
    }
    if !failed.is_empty() {
        anyhow::bail!("{}", failed.join("\n"));
    }
    if out.interrupted {
        return Err(crate::run::interrupt::Interrupted {
            sim_time_s: out.summary.sim_time_s,
        }
        .into());
    }
    Ok(())
}
