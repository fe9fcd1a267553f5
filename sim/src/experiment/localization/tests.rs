//! The rows and targets from hand-made robot-runs.

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
