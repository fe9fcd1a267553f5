//! `sim bench record`: what recording costs. The same scenario runs with no recording, with the
//! .rrd, with the MCAP replay and with both, at the scenario's recording rates (the MCAP holds
//! every reading); the median wall time of N repetitions of each (run in turn, so drifting
//! machine load hits every mode alike), and the overhead of each mode against no recording.
//! The time is that of the whole run as `sim run` does it: world building, ticks and finishing
//! the files.

use crate::options::check_duration;
use crate::run::{RunOptions, run_scenario_exporting};
use crate::scenario::scenario_arg;
use crate::{RunExports, stats};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `sim bench record`: run time with no recording, with the .rrd, with the MCAP replay and with
/// both (median of `--reps` runs each), and the overhead of each against no recording.
#[derive(clap::Args, Clone, Debug)]
pub struct RecordBenchOptions {
    /// One JSON object per scenario and mode, one per line.
    #[arg(long)]
    pub json: bool,
    /// Scenarios: bundled names or paths.
    #[arg(long = "scenario", value_delimiter = ',', num_args = 1.., default_values_t = SCENARIOS.map(String::from))]
    pub scenarios: Vec<String>,
    /// Runs per mode (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
    /// Simulated seconds per run (default: 10 s of hospital_patrol, a scenario's own
    /// duration otherwise).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Kernel threads (0 = one per core; at most 1024).
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
}

/// The scenarios measured by default.
pub const SCENARIOS: [&str; 2] = ["hospital_patrol", "park_route_short"];

/// Simulated seconds of a bundled scenario's run, so one takes some 5–20 s on the 2-core CI
/// machine; the scenario's own duration for the others (park_route_short: its whole route,
/// about 200 s).
pub fn default_duration(name: &str) -> Option<f64> {
    match name {
        "hospital_patrol" => Some(10.0),
        _ => None,
    }
}

/// The four modes.
const MODES: [(&str, bool, bool); 4] = [
    ("none", false, false),
    ("rrd", true, false),
    ("mcap", false, true),
    ("both", true, true),
];

#[derive(Serialize, Clone, Debug)]
pub struct RecordBenchRow {
    pub bench: &'static str,
    pub scenario: String,
    pub mode: &'static str,
    pub sim_time_s: f64,
    pub reps: usize,
    /// Median wall time of a run (s).
    pub wall_time_s: f64,
    /// Against `none` (%).
    pub overhead_percent: f64,
    pub rrd_bytes: u64,
    pub mcap_bytes: u64,
    pub mcap_messages: u64,
}

fn size(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(0, |m| m.len())
}

/// A scratch folder for the files, removed afterwards.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs the benchmark and prints the table (or JSON lines); returns the rows.
pub fn run_record_bench(o: &RecordBenchOptions) -> anyhow::Result<Vec<RecordBenchRow>> {
    if o.reps == 0 {
        anyhow::bail!("--reps: expected at least 1");
    }
    // every scenario and duration is checked before the table's header and the first run
    let mut scenarios = Vec::with_capacity(o.scenarios.len());
    for name in &o.scenarios {
        let mut sc = scenario_arg(Some(name))?;
        if let Some(d) = o.duration.or_else(|| default_duration(&sc.name)) {
            sc.duration = check_duration(d)?;
        }
        scenarios.push(sc);
    }
    let dir = std::env::temp_dir().join(format!("sim-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    let _scratch = Scratch(dir.clone());
    let mut rows = Vec::new();
    if !o.json {
        println!(
            "{:<20} {:>5} {:>7} {:>10} {:>10} {:>10} {:>10} {:>10}",
            "scenario", "mode", "sim s", "wall s", "overhead", "rrd MB", "mcap MB", "messages"
        );
    }
    for sc in &scenarios {
        let mut times = vec![Vec::new(); MODES.len()];
        let mut last = vec![(0.0, 0, 0, 0); MODES.len()];
        for _ in 0..o.reps {
            for (m, &(mode, rrd, mcap)) in MODES.iter().enumerate() {
                let rrd_path = dir.join(format!("{mode}.rrd"));
                let mcap_path = dir.join(format!("{mode}.mcap"));
                // the previous repetition's files go first: truncating them inside the timed
                // run would charge it for freeing their pages
                let _ = std::fs::remove_file(&rrd_path);
                let _ = std::fs::remove_file(&mcap_path);
                let started = Instant::now();
                let out = run_scenario_exporting(
                    sc,
                    &RunOptions {
                        rrd: rrd.then(|| rrd_path.clone()),
                        threads: o.threads,
                        progress: false,
                        trajectory_period: None,
                    },
                    &RunExports {
                        mcap: mcap.then(|| mcap_path.clone()),
                        ..Default::default()
                    },
                )?;
                times[m].push(started.elapsed().as_secs_f64());
                let messages = out.exported.mcap.as_ref().map_or(0, |w| w.stats.messages);
                last[m] = (
                    out.summary.sim_time_s,
                    if rrd { size(&rrd_path) } else { 0 },
                    if mcap { size(&mcap_path) } else { 0 },
                    messages,
                );
            }
        }
        let medians: Vec<f64> = times.iter_mut().map(|t| stats::median(t)).collect();
        for (m, &(mode, ..)) in MODES.iter().enumerate() {
            let (sim_time_s, rrd_bytes, mcap_bytes, mcap_messages) = last[m];
            let row = RecordBenchRow {
                bench: "record",
                scenario: sc.name.clone(),
                mode,
                sim_time_s,
                reps: o.reps,
                wall_time_s: medians[m],
                overhead_percent: 100.0 * (medians[m] / medians[0].max(1e-9) - 1.0),
                rrd_bytes,
                mcap_bytes,
                mcap_messages,
            };
            if o.json {
                println!("{}", crate::bench::machine::json_line(&row)?);
            } else {
                println!(
                    "{:<20} {:>5} {:>7.1} {:>10.2} {:>9.1}% {:>10.2} {:>10.2} {:>10}",
                    row.scenario,
                    row.mode,
                    row.sim_time_s,
                    row.wall_time_s,
                    row.overhead_percent,
                    row.rrd_bytes as f64 / 1e6,
                    row.mcap_bytes as f64 / 1e6,
                    row.mcap_messages
                );
            }
            rows.push(row);
        }
    }
    Ok(rows)
}
