//! `sim run`: its arguments and what it does with them.

use crate::RunExports;
use crate::batch::sets::plan_sets;
use crate::options::check_duration;
use crate::report::data::RunReport;
use crate::run::report::{OutputArgs, report_run};
use crate::run::{OutputsFailed, run_scenario_exporting};
use crate::scenario::source::Source;
use crate::scenario::{scenario_arg, scenario_path};
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
    /// Override a scenario key, as `sim batch --set` does
    /// (`robots.0.behaviour.speed=0.8`, `robots[name=r2].sensors.laser.rate=5`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
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
    /// Write an HTML report into this folder (created if missing): report.html, one page with
    /// inline figures (the map with every robot's true and estimated paths, error over time,
    /// the task timeline) and the summary tables, and report.json, its data for `sim report`.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
}

/// `sim run`.
pub fn run_command(a: &RunArgs) -> anyhow::Result<()> {
    let mut sc = if a.sets.is_empty() {
        scenario_arg(a.scenario.as_deref())?
    } else {
        let overrides = plan_sets(&a.sets, &[], &[])?;
        Source::load(&scenario_path(a.scenario.as_deref())?)?
            .scenario(&overrides.sets[0])
            .map_err(anyhow::Error::msg)?
    };
    if let Some(s) = a.seed {
        sc.seed = s;
    }
    if let Some(d) = a.duration {
        sc.duration = check_duration(d)?;
    }
    if let Some(dir) = &a.report {
        crate::report::prepare_dir(dir)?;
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
    let mut opts = a.out.run_options(rrd_path.clone());
    if a.report.is_some() {
        // the true paths of the report's map
        opts.trajectory_period = Some(REPORT_TRUTH_PERIOD_S);
    }
    let run = run_scenario_exporting(
        &sc,
        &opts,
        &RunExports {
            carmen_out: a.carmen_out.clone(),
            save_map: a.out.save_map.clone(),
            mcap: a.mcap.clone(),
        },
    );
    // an output that failed does not stop the others, nor the files written from the summary
    let (out, failures) = OutputsFailed::split(run)?;
    let mut report = a.out.report(rrd_path.as_deref(), a.log.as_deref());
    if failures.recording {
        report.rrd = None;
    }
    let mut written = report_run(&out, &report);
    if let Some(dir) = &a.report {
        let page = RunReport::of_run(&sc, &out).and_then(|r| crate::report::write_run(dir, &r));
        match page {
            Ok(page) if !a.out.quiet => println!("report written to {}", page.display()),
            Ok(_) => {}
            Err(e) => written = written.and(Err(e)),
        }
    }
    failures.or(written)
}

/// Seconds between the true poses a report's map draws.
const REPORT_TRUTH_PERIOD_S: f64 = 0.1;
