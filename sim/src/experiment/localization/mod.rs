//! `sim experiment localization`: whether the localizers of a scenario (by default the bundled
//! `hospital_patrol`, four robots × five localizers on identical scans) find their robot and
//! hold it, over many seeds. One row per localizer over every robot-run: convergence, the time
//! tracked after it, lost episodes (and whether the localizer noticed and recovered), map-frame
//! error after convergence, and DE odometry's drift per metre; one row for the runs
//! (collisions, speed); and the targets the figures are held to ([`targets`]).
//!
//! Runs go in parallel, one per worker, each single-threaded and deterministic, so every figure
//! but the speed is independent of `--jobs`.

use crate::batch::args::parse_seeds;
use crate::batch::runner::{on_workers, worker_count};
use crate::batch::sets::plan_sets;
use crate::options::check_duration;
use crate::scenario::Scenario;
use crate::scenario::load::scenario_path;
use crate::scenario::source::Source;
use crate::stats::median;
use crate::{RunOptions, run_scenario};
use systems::eval::localization_metrics::CONVERGENCE_HOLD_S;
use systems::eval::tracking::{LostEpisode, TrackingRecord, tracking_record};
use systems::eval::trajectory;

/// `sim experiment localization`.
#[derive(clap::Args, Clone, Debug)]
pub struct LocalizationOptions {
    /// A scenario file or the name of a bundled scenario.
    #[arg(long, default_value = "hospital_patrol")]
    pub scenario: String,
    /// Seeds to run, `A..B` (B excluded).
    #[arg(long, default_value = "0..20")]
    pub seeds: String,
    /// Simulate this many seconds per run instead of the scenario's duration.
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Override a scenario key in every run, as `sim batch --set` (repeatable). An index one
    /// past the end of an array of tables adds an item:
    /// `robots.0.localization.5={type="de_mc", init="global"}`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Runs at the same time (0 = one per core). Only the speed figures depend on it.
    #[arg(long, default_value_t = 0,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new()
              .range(0..=crate::batch::args::MAX_WORKERS))]
    pub jobs: usize,
    /// Print progress to stderr (not a flag: on unless `--json`).
    #[arg(skip)]
    pub progress: bool,
}

/// A position error beyond this at the end of a run counts as ending off (m).
pub const ENDING_OFF_M: f64 = 0.5;

/// The most seeds one experiment runs.
pub const MAX_SEEDS: u64 = 100_000;

/// The scenario with the options' overrides and duration applied.
fn prepare(o: &LocalizationOptions) -> anyhow::Result<(Scenario, std::ops::Range<u64>)> {
    let seeds = parse_seeds(&o.seeds)?;
    if seeds.end - seeds.start > MAX_SEEDS {
        anyhow::bail!(
            "--seeds {}: at most {MAX_SEEDS} seeds, got {}",
            o.seeds,
            seeds.end - seeds.start
        );
    }
    let plan = plan_sets(&o.sets, &[], &[])?;
    let source = Source::load(&scenario_path(Some(&o.scenario))?)?;
    let mut scenario = source
        .scenario(&plan.sets[0])
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    if let Some(d) = o.duration {
        scenario.duration = check_duration(d)?;
    }
    if !scenario.robots.iter().any(|r| !r.localizers.is_empty()) {
        anyhow::bail!(
            "{}: no robot has a localizer (`[[robots.localization]]`)",
            o.scenario
        );
    }
    Ok((scenario, seeds))
}

/// One run: its facts and every localizer's record.
fn one_run(scenario: &Scenario, seed: u64) -> anyhow::Result<(RunFacts, Vec<LocalizerRun>)> {
    let mut s = scenario.clone();
    s.seed = seed;
    let opts = RunOptions {
        rrd: None,
        threads: 1,
        progress: false,
        trajectory_period: None,
    };
    let out = run_scenario(&s, &opts)?;
    let sum = &out.summary;
    let facts = RunFacts {
        seed,
        sim_time_s: sum.sim_time_s,
        collisions: sum.robots.iter().map(|r| r.collisions).sum(),
        wall_collisions: sum.robots.iter().map(|r| r.wall_collisions).sum(),
        robot_collisions: sum.robots.iter().map(|r| r.robot_collisions).sum(),
        person_collisions: sum.robots.iter().map(|r| r.person_collisions).sum(),
    };
    let mut records = Vec::new();
    for ((robot, config), summary) in out.localization.iter().zip(&s.robots).zip(&sum.robots) {
        for (name, samples) in &robot.localizers {
            let Some(cfg) = config.localizers.iter().find(|l| &l.name == name) else {
                continue;
            };
            let start = match cfg.starts_global() {
                Some(true) => Start::Global,
                Some(false) => Start::Pose,
                None => Start::Odometry,
            };
            let metrics = summary.localization.get(name);
            let final_error_m = samples.last().map(trajectory::Sample::position_error);
            records.push(LocalizerRun {
                seed,
                robot: robot.robot.clone(),
                localizer: name.clone(),
                kind: metrics.map_or_else(String::new, |m| m.kind.clone()),
                start,
                estimates: samples.len(),
                tracked_fraction: trajectory::tracked_fraction(samples),
                final_error_m,
                ate_rmse_m: trajectory::ate_align_origin(samples),
                distance_m: summary.distance_m,
                drift_per_m: (start == Start::Odometry && summary.distance_m > 1.0)
                    .then(|| final_error_m.map(|e| e / summary.distance_m))
                    .flatten(),
                // odometry is not expected to stay within tracking bounds of the truth
                tracking: match start {
                    Start::Odometry => TrackingRecord::default(),
                    _ => tracking_record(samples, CONVERGENCE_HOLD_S),
                },
            });
        }
    }
    Ok((facts, records))
}

/// Runs the experiment.
pub fn run_localization_experiment(o: &LocalizationOptions) -> anyhow::Result<LocalizationResult> {
    let (scenario, seeds) = prepare(o)?;
    let jobs = worker_count(o.jobs, (seeds.end - seeds.start) as usize);
    let started = std::time::Instant::now();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = (seeds.end - seeds.start) as usize;
    let seeds: Vec<u64> = seeds.collect();
    let runs = on_workers(&seeds, jobs, |_, &seed| {
        let r = one_run(&scenario, seed)
            .map_err(|e| anyhow::anyhow!("{} seed {seed}: {e}", scenario.name));
        let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if o.progress {
            match &r {
                Ok((f, _)) => eprintln!("[{n}/{total}] seed {seed}: {} collisions", f.collisions),
                Err(_) => eprintln!("[{n}/{total}] seed {seed}: failed"),
            }
        }
        r
    })?;
    let mut facts = Vec::new();
    let mut per_run = Vec::new();
    for r in runs {
        let (f, recs) = r?;
        facts.push(f);
        per_run.extend(recs);
    }
    let rows = rows(&per_run);
    let wall = started.elapsed().as_secs_f64();
    let runs = runs_row(&facts, per_run_robots(&per_run), jobs, wall);
    let targets = targets(&rows, &runs);
    Ok(LocalizationResult {
        rows,
        runs,
        targets,
        per_run,
        run_facts: facts,
    })
}

/// Robot-runs: distinct (seed, robot) pairs.
fn per_run_robots(per_run: &[LocalizerRun]) -> usize {
    let mut seen: Vec<(u64, &str)> = per_run.iter().map(|r| (r.seed, r.robot.as_str())).collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

fn med(mut v: Vec<f64>) -> Option<f64> {
    (!v.is_empty()).then(|| median(&mut v))
}

fn worst(v: impl Iterator<Item = f64>) -> Option<f64> {
    v.fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
}

fn least(v: impl Iterator<Item = f64>) -> Option<f64> {
    v.fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.min(x))))
}

/// The rows, one per localizer name in order of first appearance.
pub fn rows(per_run: &[LocalizerRun]) -> Vec<LocalizerRow> {
    let mut names: Vec<&str> = Vec::new();
    for r in per_run {
        if !names.contains(&r.localizer.as_str()) {
            names.push(&r.localizer);
        }
    }
    names
        .into_iter()
        .map(|name| {
            let these: Vec<&LocalizerRun> =
                per_run.iter().filter(|r| r.localizer == name).collect();
            row(name, &these)
        })
        .collect()
}

fn row(name: &str, runs: &[&LocalizerRun]) -> LocalizerRow {
    let first = runs[0];
    let odometry = first.start == Start::Odometry;
    let conv: Vec<f64> = runs
        .iter()
        .filter_map(|r| r.tracking.converged_after_s)
        .collect();
    let pct = |v: f64| 100.0 * v;
    let tracked = runs.iter().filter_map(|r| r.tracked_fraction).map(pct);
    let after = runs
        .iter()
        .filter_map(|r| r.tracking.tracked_after_convergence)
        .map(pct);
    let ate: Vec<f64> = runs
        .iter()
        .filter_map(|r| {
            if odometry {
                r.ate_rmse_m
            } else {
                r.tracking.ate_after_convergence_m
            }
        })
        .collect();
    let drift: Vec<f64> = runs.iter().filter_map(|r| r.drift_per_m).map(pct).collect();
    let episodes: Vec<&LostEpisode> = runs.iter().flat_map(|r| &r.tracking.lost).collect();
    LocalizerRow {
        localizer: name.to_string(),
        kind: first.kind.clone(),
        start: first.start,
        robot_runs: runs.len(),
        converged_runs: conv.len(),
        convergence_median_s: med(conv.clone()),
        convergence_worst_s: worst(conv.into_iter()),
        tracked_median_percent: med(tracked.clone().collect()),
        tracked_min_percent: least(tracked),
        tracked_after_median_percent: med(after.clone().collect()),
        tracked_after_min_percent: least(after),
        longest_untracked_worst_s: worst(
            runs.iter()
                .filter(|r| r.tracking.converged_after_s.is_some())
                .map(|r| r.tracking.longest_untracked_s),
        ),
        ate_median_m: med(ate.clone()),
        ate_worst_m: worst(ate.into_iter()),
        drift_median_percent: med(drift.clone()),
        drift_worst_percent: worst(drift.into_iter()),
        lost_runs: runs.iter().filter(|r| !r.tracking.lost.is_empty()).count(),
        lost_episodes: episodes.len(),
        lost_noticed: episodes.iter().filter(|e| e.noticed).count(),
        lost_recovered: episodes.iter().filter(|e| e.recovered).count(),
        recovery_worst_s: worst(
            episodes
                .iter()
                .filter(|e| e.recovered)
                .map(|e| e.duration_s),
        ),
        ending_off_runs: runs
            .iter()
            .filter(|r| !odometry && r.final_error_m.is_some_and(|e| e > ENDING_OFF_M))
            .count(),
    }
}

fn runs_row(facts: &[RunFacts], robot_runs: usize, jobs: usize, wall_time_s: f64) -> RunsRow {
    let simulated: f64 = facts.iter().map(|f| f.sim_time_s).sum();
    RunsRow {
        runs: facts.len(),
        robot_runs,
        jobs,
        collisions: facts.iter().map(|f| f.collisions).sum(),
        runs_with_collisions: facts.iter().filter(|f| f.collisions > 0).count(),
        wall_collisions: facts.iter().map(|f| f.wall_collisions).sum(),
        robot_collisions: facts.iter().map(|f| f.robot_collisions).sum(),
        person_collisions: facts.iter().map(|f| f.person_collisions).sum(),
        wall_time_s,
        real_time_factor_per_run: simulated / (wall_time_s * jobs as f64).max(1e-9),
    }
}

mod records;
mod table;
mod targets;
#[cfg(test)]
mod tests;

pub use records::{
    LocalizationResult, LocalizerRow, LocalizerRun, RunFacts, RunsRow, Start, Target,
};
pub use table::table;
pub use targets::{ODOMETRY_DRIFT_WORST_PERCENT, targets};
