//! `sim bench slam`: the real-time factor of each SLAM mode on the hospital loop run (SICK
//! LMS100 at 10 Hz) and the time per scan.
//!
//! The bundled hospital_loop scenario is simulated once and exported as a CARMEN log (as
//! `sim run --carmen-out`); each mode then runs on its scans (as `sim slam --carmen`) on a
//! kernel pool of `--threads` threads (default one: "on one core"). Every update is timed: the
//! real-time factor is the log's duration over the summed update times (plus graph SLAM's final
//! optimization); per scan, the median, 95th percentile and mean.

use crate::build::new_scan_estimator;
use crate::experiment::scan_pairs::bundled;
use crate::experiment::slam_compare::{SlamExperimentOptions, simulate};
use crate::log_slam::feed::feed_scans;
use crate::scenario::slam_file::resolve_slam_config;
use crate::stats::{median, quantile};
use serde::Serialize;
use systems::core::{KernelPool, stream_rng};

/// The SLAM modes `--modes` accepts (all of them by default).
pub const MODES: [&str; 3] = ["scan_to_map", "graph", "rbpf"];

/// `sim bench slam`: real-time factor and time per scan of each SLAM mode on the hospital loop
/// run.
#[derive(clap::Args, Clone, Debug)]
pub struct SlamBenchOptions {
    /// One JSON object per mode, one per line.
    #[arg(long)]
    pub json: bool,
    /// SLAM modes to time.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = MODES.map(String::from))]
    pub modes: Vec<String>,
    /// Kernel threads the SLAM runs on (0 = one per core; at most 1024; the targets are for
    /// one core).
    #[arg(long, default_value_t = 1, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Simulate only this many seconds of the scenario (quick checks; at most its 600 s).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
}

/// One mode's figures (the JSON object of `--json`).
#[derive(Clone, Debug, Serialize)]
pub struct SlamBenchRow {
    pub mode: String,
    pub threads: usize,
    pub scans: usize,
    pub log_duration_s: f64,
    pub compute_s: f64,
    pub real_time_factor: f64,
    pub median_ms_per_scan: f64,
    pub p95_ms_per_scan: f64,
    pub mean_ms_per_scan: f64,
    /// Graph SLAM's final optimization (ms).
    pub finish_ms: f64,
    /// The target (× real time), if it sets one for this mode.
    pub target: Option<f64>,
}

pub fn run_slam_bench(o: &SlamBenchOptions) -> anyhow::Result<Vec<SlamBenchRow>> {
    let mut scenario = bundled("hospital_loop")?;
    if let Some(d) = o.duration {
        let d = crate::options::check_duration(d)?;
        if d > scenario.duration {
            anyhow::bail!(
                "--duration: hospital_loop lasts {} s; expected at most that, got {d}",
                scenario.duration
            );
        }
        scenario.duration = d;
    }
    // every mode is known before the (long) simulation
    let known = MODES.join(", ");
    if o.modes.is_empty() {
        anyhow::bail!("--modes: expected at least one of {known}");
    }
    for mode in &o.modes {
        if !MODES.contains(&mode.as_str()) {
            anyhow::bail!("--modes: unknown mode `{mode}`; expected one of {known}");
        }
    }
    let log = simulate(
        &scenario,
        &SlamExperimentOptions {
            threads: 0,
            progress: !o.json,
            ..SlamExperimentOptions::default()
        },
    )?;
    let scans = log.front_scans();
    let (Some(first), Some(last)) = (scans.first(), scans.last()) else {
        anyhow::bail!("hospital_loop logged no scans");
    };
    let duration = last.timestamp - first.timestamp;
    let pool = KernelPool::new(o.threads)
        .map_err(|e| anyhow::anyhow!("cannot start {} kernel threads: {e}", o.threads))?;
    let mut rows = Vec::new();
    for mode in &o.modes {
        let config = resolve_slam_config(Some(mode), None, &first.robot_pose)
            .map_err(|e| anyhow::anyhow!("--modes: {e}"))?;
        let rng = stream_rng(scenario.seed, "mapper", &format!("localizer/{mode}"));
        let mut est = new_scan_estimator(&config.kind, rng)?;
        if !o.json {
            eprintln!("{mode}: {} scans over {duration:.0} s…", scans.len());
        }
        let run = feed_scans(est.as_mut(), &scans, &pool, |_, _, _, _| {});
        let mut ms = run.update_ms.clone();
        let compute_s = (ms.iter().sum::<f64>() + run.finish_ms) / 1e3;
        let row = SlamBenchRow {
            mode: mode.clone(),
            threads: pool.threads(),
            scans: scans.len(),
            log_duration_s: duration,
            compute_s,
            real_time_factor: duration / compute_s.max(1e-9),
            median_ms_per_scan: median(&mut ms),
            p95_ms_per_scan: quantile(&mut ms, 0.95),
            mean_ms_per_scan: ms.iter().sum::<f64>() / ms.len().max(1) as f64,
            finish_ms: run.finish_ms,
            target: match mode.as_str() {
                "scan_to_map" => Some(50.0),
                "graph" => Some(10.0),
                _ => None,
            },
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&row)?);
        }
        rows.push(row);
    }
    if !o.json {
        print!("{}", table(&rows));
    }
    Ok(rows)
}

pub fn table(rows: &[SlamBenchRow]) -> String {
    let mut s = format!(
        "{:<12} {:>7} {:>6} {:>9} {:>9} {:>8} {:>9} {:>9} {:>9} {:>10} {:>7}\n",
        "mode",
        "threads",
        "scans",
        "log s",
        "compute s",
        "× RT",
        "median ms",
        "p95 ms",
        "mean ms",
        "finish ms",
        "target"
    );
    for r in rows {
        s += &format!(
            "{:<12} {:>7} {:>6} {:>9.1} {:>9.2} {:>8.1} {:>9.3} {:>9.3} {:>9.3} {:>10.1} {:>7}\n",
            r.mode,
            r.threads,
            r.scans,
            r.log_duration_s,
            r.compute_s,
            r.real_time_factor,
            r.median_ms_per_scan,
            r.p95_ms_per_scan,
            r.mean_ms_per_scan,
            r.finish_ms,
            r.target.map_or("-".to_string(), |t| format!("≥{t:.0}×"))
        );
    }
    s
}
