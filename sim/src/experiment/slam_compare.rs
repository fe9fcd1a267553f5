//! `sim experiment maze-slam`: the maze run of [Hospital thesis] (poses from consecutive scan pairs drift by integration; the fix proposed is to
//! match each scan against the map built so far) and the hospital loop, with every odometry and SLAM
//! method we have on identical data:
//!
//! * `wheel_odometry` — the encoders alone;
//! * `de_scan_to_scan` — differential-evolution scan-to-scan odometry (the thesis's method,
//!   [`systems::localization::de_odometry`]);
//! * `scan_to_map_de` — scan_to_map with the DE matcher instead of Gauss-Newton;
//! * `scan_to_map`, `rbpf`, `graph` — the three SLAM families [SLAM thesis] compares
//!   (Hector-style, GMapping-style, Cartographer-style), with their default settings.
//!
//! Each scenario is simulated once and exported as a CARMEN log (as `sim run --carmen-out`);
//! every method then runs on that log (as `sim slam --carmen`). Each method's trajectory is
//! judged at the same evaluation poses — the scans where the true robot has moved
//! [`EVAL_SPACING_M`] since the previous one (the thesis's maze run had 76 scan poses) — a
//! method's pose between its own updates being its last pose carried by the wheel odometry: ATE
//! (RMSE of positions), RPE between consecutive evaluation poses, and the quality of the map
//! built by inserting the scans at the evaluation poses where the method put them (known-pose
//! mapping, so every method's map is judged the same way) against the scenario's true map.

use super::scan_pairs::bundled;
use crate::build::new_scan_estimator;
use crate::formats::carmen::{CarmenReadOptions, ScanRecord, read_carmen};
use crate::log_slam::eval::TruthTrack;
use crate::log_slam::feed::feed_scans;
use crate::scenario::Scenario;
use crate::scenario::slam_file::resolve_slam_config;
use crate::{RunExports, RunOptions, run_scenario_exporting};
use serde::Serialize;
use systems::core::{KernelPool, Pose2, stream_rng};
use systems::eval::TrajectoryMetrics;
use systems::localization::de_odometry::{DeOdometry, DeOdometryConfig};
use systems::mapping::matched_map::base_points;
use systems::mapping::{LogOddsMap, OccupancyParams, map_quality};

/// True travel between evaluation poses (m).
pub const EVAL_SPACING_M: f64 = 0.5;

/// The bundled scenarios of the experiment.
pub const SCENARIOS: [&str; 2] = ["maze_run", "hospital_loop"];

/// The methods, in table order.
pub const METHODS: [&str; 6] = [
    "wheel_odometry",
    "de_scan_to_scan",
    "scan_to_map",
    "scan_to_map_de",
    "rbpf",
    "graph",
];

/// `sim experiment maze-slam`.
#[derive(clap::Args, Clone, Debug)]
pub struct SlamExperimentOptions {
    /// Scenarios: bundled names or paths.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = SCENARIOS.map(String::from))]
    pub scenarios: Vec<String>,
    /// Methods to run.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = METHODS.map(String::from))]
    pub methods: Vec<String>,
    /// Kernel threads (0 = one per core; at most 1024). Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Print progress to stderr (not a flag: on unless `--json`).
    #[arg(skip)]
    pub progress: bool,
}

impl Default for SlamExperimentOptions {
    fn default() -> Self {
        SlamExperimentOptions {
            scenarios: SCENARIOS.iter().map(|s| s.to_string()).collect(),
            methods: METHODS.iter().map(|s| s.to_string()).collect(),
            threads: 0,
            progress: true,
        }
    }
}

/// Map quality in the JSON object.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MapScore {
    pub precision: f64,
    pub recall: f64,
}

/// One row of the table (the JSON object of `--json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlamRow {
    pub scenario: String,
    pub method: String,
    /// Evaluation poses judged.
    pub poses: usize,
    pub ate_rmse_m: Option<f64>,
    pub rpe_trans_m: Option<f64>,
    pub rpe_rot_rad: Option<f64>,
    pub map_quality: MapScore,
    /// Position error at the last evaluation pose (m).
    pub final_error_m: Option<f64>,
    /// Wall time of the method over the whole log (s).
    pub wall_time_s: f64,
}

/// Runs the experiment; rows in scenario, then method order.
pub fn run_slam_experiment(o: &SlamExperimentOptions) -> anyhow::Result<Vec<SlamRow>> {
    for m in &o.methods {
        if !METHODS.contains(&m.as_str()) {
            anyhow::bail!("--methods: unknown method `{m}`; expected one of {METHODS:?}");
        }
    }
    let pool = KernelPool::new(o.threads)
        .map_err(|e| anyhow::anyhow!("cannot start {} kernel threads: {e}", o.threads))?;
    // every scenario loads and has a robot to log before the first (long) simulation
    let mut scenarios = Vec::new();
    for name in &o.scenarios {
        let scenario = match std::path::Path::new(name).exists() {
            true => crate::load_scenario(std::path::Path::new(name))?,
            false => bundled(name)?,
        };
        if crate::formats::carmen::export::exported_robots(&scenario).is_empty() {
            anyhow::bail!(
                "--scenarios: {name}: no robot with a laser and wheel encoders (the methods run \
                 on its laser scans and odometry)"
            );
        }
        scenarios.push(scenario);
    }
    let mut rows = Vec::new();
    for scenario in scenarios {
        let log = simulate(&scenario, o)?;
        rows.extend(judge_methods(
            &scenario, &log, &o.methods, &pool, o.progress,
        )?);
    }
    Ok(rows)
}

/// The scenario's first robot with a laser and encoders, simulated and exported as a CARMEN
/// log (read back).
pub fn simulate(
    scenario: &Scenario,
    o: &SlamExperimentOptions,
) -> anyhow::Result<crate::formats::carmen::CarmenLog> {
    let dir = std::env::temp_dir().join(format!(
        "sim-slam-experiment-{}-{}",
        std::process::id(),
        scenario.name
    ));
    std::fs::create_dir_all(&dir)?;
    let out = dir.join("run.log");
    if o.progress {
        eprintln!("simulating {} ({} s)…", scenario.name, scenario.duration);
    }
    let exports = RunExports {
        carmen_out: Some(out.clone()),
        ..Default::default()
    };
    let opts = RunOptions {
        threads: o.threads,
        ..RunOptions::default()
    };
    let result = run_scenario_exporting(scenario, &opts, &exports).and_then(|r| {
        let first = r
            .exported
            .carmen_logs
            .first()
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("{}: nothing exported", scenario.name))?;
        Ok(read_carmen(&first, &CarmenReadOptions::default())?)
    });
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// Runs and judges every method on `log`.
pub fn judge_methods(
    scenario: &Scenario,
    log: &crate::formats::carmen::CarmenLog,
    methods: &[String],
    pool: &KernelPool,
    progress: bool,
) -> anyhow::Result<Vec<SlamRow>> {
    let scans = log.front_scans();
    let Some(first) = scans.first() else {
        anyhow::bail!("{}: the run logged no scans", scenario.name);
    };
    let truth = TruthTrack::new(&log.truth);
    let eval = evaluation_scans(&scans, &truth);
    let robot = scenario
        .robots
        .first()
        .map_or("robot".to_string(), |r| r.name.clone());
    let mut rows = Vec::new();
    for method in methods {
        if progress {
            eprintln!("{}: {method} on {} scans…", scenario.name, scans.len());
        }
        let started = std::time::Instant::now();
        let trajectory: Vec<(f64, Pose2)> = match method.as_str() {
            "wheel_odometry" => scans.iter().map(|s| (s.timestamp, s.robot_pose)).collect(),
            "de_scan_to_scan" => {
                let config = DeOdometryConfig {
                    start: first.robot_pose,
                    ..DeOdometryConfig::default()
                };
                let rng = stream_rng(scenario.seed, &robot, "localizer/de_scan_to_scan");
                let mut de = DeOdometry::new(config, rng);
                let mut out = Vec::new();
                for s in &scans {
                    let points = base_points(&s.to_laser_scan(), &s.mount, 1);
                    if pool.install(|| de.update(&points, &s.robot_pose))
                        && let Some(e) = de.estimate
                    {
                        out.push((s.timestamp, e.pose));
                    }
                }
                out
            }
            slam => {
                // scan_to_map_de: scan_to_map with the DE matcher
                let (kind, keys) = match slam.strip_suffix("_de") {
                    Some(k) => (k, Some(("--methods", "matcher = \"de\"\n"))),
                    None => (slam, None),
                };
                let config = resolve_slam_config(Some(kind), keys, &first.robot_pose)?;
                let rng = stream_rng(scenario.seed, &robot, &format!("localizer/{slam}"));
                let mut est = new_scan_estimator(&config.kind, rng)?;
                feed_scans(est.as_mut(), &scans, pool, |_, _, _, _| {}).trajectory
            }
        };
        let wall_time_s = started.elapsed().as_secs_f64();
        let at_eval = carried(&trajectory, &scans, &eval);
        rows.push(judge(
            scenario,
            method,
            &scans,
            &eval,
            &at_eval,
            &truth,
            wall_time_s,
        ));
    }
    Ok(rows)
}

/// Indices of the evaluation scans: the first, then each where the true robot has moved
/// [`EVAL_SPACING_M`] since the previous one (scans without truth skipped).
fn evaluation_scans(scans: &[&ScanRecord], truth: &TruthTrack) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::new();
    let mut last: Option<Pose2> = None;
    for (k, s) in scans.iter().enumerate() {
        let Some(t) = truth.at(s.timestamp) else {
            continue;
        };
        if last.is_none_or(|l| l.distance(&t) >= EVAL_SPACING_M) {
            out.push(k);
            last = Some(t);
        }
    }
    out
}

/// The method's pose at each evaluation scan: its latest pose at or before the scan, carried to
/// the scan by the wheel odometry; None before its first pose.
fn carried(
    trajectory: &[(f64, Pose2)],
    scans: &[&ScanRecord],
    eval: &[usize],
) -> Vec<Option<Pose2>> {
    // the odometry at each trajectory stamp: the scans are in time order
    let odom_at = |t: f64| -> Pose2 {
        let i = scans
            .partition_point(|s| s.timestamp <= t)
            .saturating_sub(1);
        scans[i].robot_pose
    };
    eval.iter()
        .map(|&k| {
            let s = scans[k];
            let j = trajectory.partition_point(|(t, _)| *t <= s.timestamp);
            let (t, pose) = *trajectory.get(j.checked_sub(1)?)?;
            Some(pose.compose(&odom_at(t).between(&s.robot_pose)))
        })
        .collect()
}

fn judge(
    scenario: &Scenario,
    method: &str,
    scans: &[&ScanRecord],
    eval: &[usize],
    poses: &[Option<Pose2>],
    truth: &TruthTrack,
    wall_time_s: f64,
) -> SlamRow {
    let estimates: Vec<(f64, Pose2)> = eval
        .iter()
        .zip(poses)
        .filter_map(|(&k, p)| p.map(|p| (scans[k].timestamp, p)))
        .collect();
    let samples = truth.samples(&estimates);
    let m = TrajectoryMetrics::from_samples(&samples);
    let mut map = LogOddsMap::new(scenario.grid.resolution, OccupancyParams::slam());
    for (&k, p) in eval.iter().zip(poses) {
        if let Some(p) = p {
            let s = scans[k];
            map.insert_scan(&p.compose(&s.mount), &s.to_laser_scan());
        }
    }
    let q = map_quality(&map.to_occupancy(), &scenario.grid, &Pose2::IDENTITY);
    SlamRow {
        scenario: scenario.name.clone(),
        method: method.to_string(),
        poses: m.poses,
        ate_rmse_m: m.ate_rmse_m,
        rpe_trans_m: m.rpe_trans_m,
        rpe_rot_rad: m.rpe_rot_rad,
        map_quality: MapScore {
            precision: q.precision,
            recall: q.recall,
        },
        final_error_m: samples.last().map(|s| s.position_error()),
        wall_time_s,
    }
}

/// The text table.
pub fn table(rows: &[SlamRow]) -> String {
    let f = |v: Option<f64>, d: usize| v.map_or("-".to_string(), |v| format!("{v:.d$}"));
    let mut s = format!(
        "{:<14} {:<16} {:>6} {:>8} {:>8} {:>8} {:>8} {:>10} {:>10} {:>8}\n",
        "scenario",
        "method",
        "poses",
        "ATE m",
        "RPE m",
        "RPE rad",
        "final m",
        "map prec.",
        "map recall",
        "time s"
    );
    for r in rows {
        s += &format!(
            "{:<14} {:<16} {:>6} {:>8} {:>8} {:>8} {:>8} {:>10.3} {:>10.3} {:>8.1}\n",
            r.scenario,
            r.method,
            r.poses,
            f(r.ate_rmse_m, 3),
            f(r.rpe_trans_m, 4),
            f(r.rpe_rot_rad, 4),
            f(r.final_error_m, 3),
            r.map_quality.precision,
            r.map_quality.recall,
            r.wall_time_s
        );
    }
    s
}
