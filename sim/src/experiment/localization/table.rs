//! The table `sim experiment localization` prints.

use super::records::LocalizationResult;

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
