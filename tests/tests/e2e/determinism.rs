//! Same scenario + seed ⇒ identical summaries (but wall-clock fields) and identical ground-truth
//! trajectories, whatever the number of kernel threads.

use crate::common::*;
use sim::scenario::load_scenario;
use sim::{RunOptions, run_scenario};

fn run(threads: usize, seed: u64) -> sim::RunOutput {
    let mut s = load_scenario(&bundled("hospital_patrol")).unwrap();
    s.duration = 20.0;
    s.seed = seed;
    run_scenario(
        &s,
        &RunOptions {
            rrd: None,
            threads,
            progress: false,
            trajectory_period: Some(0.5),
        },
    )
    .unwrap()
}

#[test]
fn threads_do_not_change_results() {
    let a = run(1, 7);
    let b = run(2, 7);
    assert_eq!(
        a.summary.deterministic_part(),
        b.summary.deterministic_part()
    );
    assert_eq!(a.trajectory.len(), b.trajectory.len());
    for (x, y) in a.trajectory.iter().zip(&b.trajectory) {
        assert_eq!(x, y, "trajectories differ at t = {}", x.0);
    }
    // the robots really moved, and noise really depends on the seed
    assert!(
        a.summary.robots.iter().all(|r| r.distance_m > 5.0),
        "{:?}",
        a.summary
    );
    let c = run(2, 8);
    assert_ne!(
        a.summary.deterministic_part(),
        c.summary.deterministic_part()
    );
}
