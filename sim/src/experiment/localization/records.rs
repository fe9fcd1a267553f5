//! What the experiment records and reports: plain data, serialised as its JSON rows.

use serde::Serialize;
use systems::eval::tracking::TrackingRecord;

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
    pub fn as_str(self) -> &'static str {
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
    /// with `jobs` runs at a time: Σ simulated / (wall × jobs), the experiment's throughput
    /// per run, as `sim batch` reports it (each run has a worker to itself from start to end).
    pub wall_time_s: f64,
    pub real_time_factor_per_run: f64,
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
