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
use crate::batch::sets::plan_sets;
use crate::options::check_duration;
use crate::scenario::Scenario;
use crate::scenario::load::scenario_path;
use crate::scenario::source::Source;
use crate::stats::median;
use crate::{RunOptions, run_scenario};
use rayon::prelude::*;
use serde::Serialize;
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

/// How a localizer starts, which decides the targets it is held to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Start {
    /// From the robot's known start pose (tracking).
    Pose,
    /// Anywhere on the map (global localization).
    Global,
    /// Not in the map: integrates its own motion estimate (DE odometry, SLAM).
    Odometry,
}

impl Start {
    fn as_str(self) -> &'static str {
        match self {
            Start::Pose => "pose",
            Start::Global => "global",
            Start::Odometry => "odometry",
        }
    }
}

/// One localizer of one robot in one run.
#[derive(Clone, Debug, Serialize)]
pub struct LocalizerRun {
    pub seed: u64,
    pub robot: String,
    pub localizer: String,
    pub kind: String,
    pub start: Start,
    pub estimates: usize,
    /// Share of the whole run tracked (within 0.2 m and 5°).
    pub tracked_fraction: Option<f64>,
    pub final_error_m: Option<f64>,
    /// Origin-aligned ATE (the figure for odometry).
    pub ate_rmse_m: Option<f64>,
    /// Ground-truth distance the robot drove (m).
    pub distance_m: f64,
    /// Final position error per metre driven (odometry only).
    pub drift_per_m: Option<f64>,
    #[serde(flatten)]
    pub tracking: TrackingRecord,
}

/// One run as a whole.
#[derive(Clone, Debug, Serialize)]
pub struct RunFacts {
    pub seed: u64,
    pub sim_time_s: f64,
    pub collisions: u32,
    pub wall_collisions: u32,
    pub robot_collisions: u32,
    pub person_collisions: u32,
}

/// A row of the table: one localizer over every robot-run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocalizerRow {
    pub localizer: String,
    pub kind: String,
    pub start: Start,
    pub robot_runs: usize,
    pub converged_runs: usize,
    pub convergence_median_s: Option<f64>,
    pub convergence_worst_s: Option<f64>,
    /// Over the whole run (%).
    pub tracked_median_percent: Option<f64>,
    pub tracked_min_percent: Option<f64>,
    /// From convergence on (%).
    pub tracked_after_median_percent: Option<f64>,
    pub tracked_after_min_percent: Option<f64>,
    pub longest_untracked_worst_s: Option<f64>,
    /// Map-frame ATE after convergence (m); origin-aligned for odometry.
    pub ate_median_m: Option<f64>,
    pub ate_worst_m: Option<f64>,
    /// Odometry: final error per metre driven (%).
    pub drift_median_percent: Option<f64>,
    pub drift_worst_percent: Option<f64>,
    /// Robot-runs with at least one lost episode, the episodes, and how many of them the
    /// localizer noticed and recovered from.
    pub lost_runs: usize,
    pub lost_episodes: usize,
    pub lost_noticed: usize,
    pub lost_recovered: usize,
    /// The longest lost episode that ended (s).
    pub recovery_worst_s: Option<f64>,
    /// Robot-runs whose last estimate is more than 0.5 m off.
    pub ending_off_runs: usize,
}

/// The row about the runs themselves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunsRow {
    pub runs: usize,
    pub robot_runs: usize,
    pub jobs: usize,
    pub collisions: u32,
    pub runs_with_collisions: usize,
    pub wall_collisions: u32,
    pub robot_collisions: u32,
    pub person_collisions: u32,
    /// Wall-clock time of all the runs (s), and the simulated time per run and wall second
    /// with `jobs` runs at a time: Σ simulated / (wall × jobs). Runs share the worker
    /// threads (a worker waiting inside one run may step another), so a run's own wall time
    /// says nothing; this is the experiment's throughput per run.
    pub wall_time_s: f64,
    pub real_time_factor_per_run: f64,
}

/// One target and whether it is met.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Target {
    /// The localizer it is about, or "runs".
    pub subject: String,
    pub what: String,
    pub want: String,
    pub got: String,
    pub met: bool,
    /// Speed targets depend on the machine and `--jobs`; the others do not.
    pub timing: bool,
}

/// What the experiment found.
#[derive(Clone, Debug, Serialize)]
pub struct LocalizationResult {
    pub rows: Vec<LocalizerRow>,
    pub runs: RunsRow,
    pub targets: Vec<Target>,
    #[serde(skip)]
    pub per_run: Vec<LocalizerRun>,
    #[serde(skip)]
    pub run_facts: Vec<RunFacts>,
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.jobs)
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start {} threads: {e}", o.jobs))?;
    let jobs = pool.current_num_threads();
    let started = std::time::Instant::now();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = (seeds.end - seeds.start) as usize;
    let seeds: Vec<u64> = seeds.collect();
    let runs: Vec<anyhow::Result<(RunFacts, Vec<LocalizerRun>)>> = pool.install(|| {
        seeds
            .par_iter()
            .map(|&seed| {
                let r = one_run(&scenario, seed)
                    .map_err(|e| anyhow::anyhow!("{} seed {seed}: {e}", scenario.name));
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if o.progress {
                    match &r {
                        Ok((f, _)) => {
                            eprintln!("[{n}/{total}] seed {seed}: {} collisions", f.collisions)
                        }
                        Err(_) => eprintln!("[{n}/{total}] seed {seed}: failed"),
                    }
                }
                r
            })
            .collect()
    });
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

/// Map-frame ATE after convergence a global localizer is held to, median and worst run (m):
/// the Markov grid's cells (0.25 m) allow it twice the median of the others.
fn global_ate_targets(kind: &str) -> (f64, f64) {
    match kind {
        "markov_grid" => (0.06, 0.10),
        _ => (0.03, 0.10),
    }
}

/// The worst DE-odometry drift per metre driven allowed (%): the worst run of the bundled patrol
/// over seeds 0–19 when the experiment was introduced (docs/benchmarks.md).
pub const ODOMETRY_DRIFT_WORST_PERCENT: f64 = 0.58;

/// Every target the figures are held to.
pub fn targets(rows: &[LocalizerRow], runs: &RunsRow) -> Vec<Target> {
    let mut t = Vec::new();
    let f = |v: Option<f64>, unit: &str, p: usize| {
        v.map_or_else(|| "none".to_string(), |v| format!("{v:.p$}{unit}"))
    };
    let at_most = |v: Option<f64>, limit: f64| v.is_some_and(|v| v <= limit);
    let at_least = |v: Option<f64>, limit: f64| v.is_some_and(|v| v >= limit);
    for r in rows {
        let mut add = |what: &str, want: String, got: String, met: bool| {
            t.push(Target {
                subject: r.localizer.clone(),
                what: what.to_string(),
                want,
                got,
                met,
                timing: false,
            })
        };
        match r.start {
            Start::Pose => {
                add(
                    "tracked in every run (min)",
                    "100 %".into(),
                    f(r.tracked_min_percent, " %", 2),
                    at_least(r.tracked_min_percent, 100.0),
                );
                add(
                    "map-frame ATE median",
                    "≤ 0.020 m".into(),
                    f(r.ate_median_m, " m", 3),
                    at_most(r.ate_median_m, 0.02),
                );
                add(
                    "map-frame ATE worst run",
                    "≤ 0.050 m".into(),
                    f(r.ate_worst_m, " m", 3),
                    at_most(r.ate_worst_m, 0.05),
                );
            }
            Start::Global => {
                let (ate_med, ate_worst) = global_ate_targets(&r.kind);
                add(
                    "converged runs",
                    format!("{} of {}", r.robot_runs, r.robot_runs),
                    format!("{} of {}", r.converged_runs, r.robot_runs),
                    r.converged_runs == r.robot_runs,
                );
                add(
                    "convergence median",
                    "≤ 10 s".into(),
                    f(r.convergence_median_s, " s", 1),
                    at_most(r.convergence_median_s, 10.0),
                );
                add(
                    "convergence worst run",
                    "≤ 30 s".into(),
                    f(r.convergence_worst_s, " s", 1),
                    at_most(r.convergence_worst_s, 30.0),
                );
                add(
                    "tracked after convergence (min)",
                    "≥ 99.5 %".into(),
                    f(r.tracked_after_min_percent, " %", 2),
                    at_least(r.tracked_after_min_percent, 99.5),
                );
                add(
                    "longest untracked span",
                    "≤ 2 s".into(),
                    f(r.longest_untracked_worst_s, " s", 1),
                    at_most(r.longest_untracked_worst_s, 2.0),
                );
                add(
                    "map-frame ATE median after convergence",
                    format!("≤ {ate_med:.3} m"),
                    f(r.ate_median_m, " m", 3),
                    at_most(r.ate_median_m, ate_med),
                );
                add(
                    "map-frame ATE worst run after convergence",
                    format!("≤ {ate_worst:.3} m"),
                    f(r.ate_worst_m, " m", 3),
                    at_most(r.ate_worst_m, ate_worst),
                );
                add(
                    "lost episodes noticed and recovered within 15 s",
                    format!("{0} of {0}", r.lost_episodes),
                    format!(
                        "{} noticed, {} recovered, worst {}",
                        r.lost_noticed,
                        r.lost_recovered,
                        f(r.recovery_worst_s, " s", 1)
                    ),
                    r.lost_noticed == r.lost_episodes
                        && r.lost_recovered == r.lost_episodes
                        && r.recovery_worst_s.is_none_or(|s| s <= 15.0),
                );
            }
            Start::Odometry => add(
                "drift per metre, worst run",
                format!("≤ {ODOMETRY_DRIFT_WORST_PERCENT:.1} %"),
                f(r.drift_worst_percent, " %", 2),
                at_most(r.drift_worst_percent, ODOMETRY_DRIFT_WORST_PERCENT),
            ),
        }
    }
    t.push(Target {
        subject: "runs".into(),
        what: "collisions (walls, robots, people)".into(),
        want: "0".into(),
        got: format!(
            "{} in {} of {} runs ({} wall, {} robot, {} person)",
            runs.collisions,
            runs.runs_with_collisions,
            runs.runs,
            runs.wall_collisions,
            runs.robot_collisions,
            runs.person_collisions
        ),
        met: runs.collisions == 0,
        timing: false,
    });
    let (want, need) = if runs.jobs > 1 {
        ("≥ 10× per run", 10.0)
    } else {
        ("≥ 20×", 20.0)
    };
    t.push(Target {
        subject: "runs".into(),
        what: format!("real-time factor per run ({} at a time)", runs.jobs),
        want: want.into(),
        got: format!("{:.1}×", runs.real_time_factor_per_run),
        met: runs.real_time_factor_per_run >= need,
        timing: true,
    });
    t
}

/// The table `sim experiment localization` prints.
pub fn table(r: &LocalizationResult) -> String {
    let f = |v: Option<f64>, p: usize| v.map_or("-".to_string(), |v| format!("{v:.p$}"));
    let mut s = format!(
        "{:<12} {:<8} {:>5} | {:>5} {:>6} {:>6} | {:>7} {:>7} | {:>7} {:>7} {:>6} | {:>6} {:>6} {:>6} | {:>5} {:>4} {:>4} {:>4} {:>6} | {:>4}\n",
        "localizer",
        "start",
        "runs",
        "conv",
        "med s",
        "worst",
        "track%",
        "min",
        "after%",
        "min",
        "gap s",
        "ATE m",
        "worst",
        "drift%",
        "lost",
        "eps",
        "ntc",
        "rec",
        "rec s",
        "off"
    );
    for row in &r.rows {
        s += &format!(
            "{:<12} {:<8} {:>5} | {:>5} {:>6} {:>6} | {:>7} {:>7} | {:>7} {:>7} {:>6} | {:>6} {:>6} {:>6} | {:>5} {:>4} {:>4} {:>4} {:>6} | {:>4}\n",
            row.localizer,
            row.start.as_str(),
            row.robot_runs,
            row.converged_runs,
            f(row.convergence_median_s, 1),
            f(row.convergence_worst_s, 1),
            f(row.tracked_median_percent, 1),
            f(row.tracked_min_percent, 1),
            f(row.tracked_after_median_percent, 2),
            f(row.tracked_after_min_percent, 2),
            f(row.longest_untracked_worst_s, 1),
            f(row.ate_median_m, 3),
            f(row.ate_worst_m, 3),
            f(row.drift_worst_percent, 2),
            row.lost_runs,
            row.lost_episodes,
            row.lost_noticed,
            row.lost_recovered,
            f(row.recovery_worst_s, 1),
            row.ending_off_runs,
        );
    }
    s += "\nATE: map-frame RMSE after convergence (m), median and worst run; for odometry the \
          origin-aligned ATE. drift: odometry's final error per metre driven, worst run. gap: the longest untracked span after convergence. lost: \
          robot-runs with an untracked span over 2 s; eps/ntc/rec: those spans, how many the \
          localizer noticed (spread > 0.2 m), how many ended tracked. off: runs ending > 0.5 m \
          off.\n";
    let u = &r.runs;
    s += &format!(
        "\n{} runs ({} robot-runs, {} at a time): {} collisions in {} runs ({} wall, {} robot, \
         {} person); {:.0} s of wall time, {:.1}× real time per run\n",
        u.runs,
        u.robot_runs,
        u.jobs,
        u.collisions,
        u.runs_with_collisions,
        u.wall_collisions,
        u.robot_collisions,
        u.person_collisions,
        u.wall_time_s,
        u.real_time_factor_per_run
    );
    s += "\ntargets:\n";
    for t in &r.targets {
        s += &format!(
            "  [{}] {:<12} {}: want {}, got {}\n",
            if t.met { "met" } else { "NOT MET" },
            t.subject,
            t.what,
            t.want,
            t.got
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(seed: u64, name: &str, start: Start, record: TrackingRecord) -> LocalizerRun {
        LocalizerRun {
            seed,
            robot: "r1".into(),
            localizer: name.into(),
            kind: "mcl".into(),
            start,
            estimates: 100,
            tracked_fraction: Some(1.0),
            final_error_m: Some(0.01),
            ate_rmse_m: Some(0.05),
            distance_m: 50.0,
            drift_per_m: (start == Start::Odometry).then_some(0.002),
            tracking: record,
        }
    }

    fn converged(at: f64, ate: f64) -> TrackingRecord {
        TrackingRecord {
            converged_after_s: Some(at),
            tracked_after_convergence: Some(1.0),
            longest_untracked_s: 0.0,
            ate_after_convergence_m: Some(ate),
            lost: Vec::new(),
        }
    }

    fn facts(seed: u64, collisions: u32) -> RunFacts {
        RunFacts {
            seed,
            sim_time_s: 120.0,
            collisions,
            wall_collisions: 0,
            robot_collisions: collisions,
            person_collisions: 0,
        }
    }

    #[test]
    fn a_global_localizer_that_loses_its_robot_misses_the_targets_that_say_so() {
        let mut lost = converged(4.0, 0.02);
        lost.tracked_after_convergence = Some(0.9);
        lost.longest_untracked_s = 12.0;
        lost.lost.push(LostEpisode {
            start_s: 50.0,
            duration_s: 12.0,
            max_error_m: 8.0,
            recovered: true,
            noticed: false,
        });
        let per_run = vec![
            run(0, "g", Start::Global, converged(3.0, 0.02)),
            run(1, "g", Start::Global, lost),
            run(2, "g", Start::Global, TrackingRecord::default()),
            run(0, "odo", Start::Odometry, TrackingRecord::default()),
        ];
        let rows = rows(&per_run);
        assert_eq!(rows.len(), 2);
        let g = &rows[0];
        assert_eq!((g.robot_runs, g.converged_runs), (3, 2));
        assert_eq!(g.convergence_median_s, Some(3.5));
        assert_eq!(g.tracked_after_min_percent, Some(90.0));
        assert_eq!((g.lost_runs, g.lost_episodes), (1, 1));
        assert_eq!((g.lost_noticed, g.lost_recovered), (0, 1));
        assert_eq!(g.recovery_worst_s, Some(12.0));
        assert_eq!(rows[1].drift_worst_percent, Some(0.2));
        // 360 s simulated in 9 s by two at a time: 20× per run
        let runs = runs_row(&[facts(0, 0), facts(1, 2), facts(2, 0)], 3, 2, 9.0);
        assert!((runs.real_time_factor_per_run - 20.0).abs() < 1e-9);
        assert_eq!((runs.collisions, runs.runs_with_collisions), (2, 1));
        let t = targets(&rows, &runs);
        let missed: Vec<&str> = t
            .iter()
            .filter(|t| !t.met)
            .map(|t| t.what.as_str())
            .collect();
        assert_eq!(
            missed,
            [
                "converged runs",
                "tracked after convergence (min)",
                "longest untracked span",
                "lost episodes noticed and recovered within 15 s",
                "collisions (walls, robots, people)",
            ]
        );
        assert!(
            t.iter().any(|t| t.timing && t.met),
            "20× per run in a batch of two"
        );
        let printed = table(&LocalizationResult {
            rows,
            runs,
            targets: t,
            per_run,
            run_facts: Vec::new(),
        });
        assert!(printed.contains("NOT MET"), "{printed}");
    }
}
