//! The DE optimiser on test functions: convergence, strategies, crossovers, bounds, stops,
//! determinism.

use super::*;
use rand::SeedableRng;

fn sphere(v: &Vector) -> f64 {
    (v[0] - 0.7).powi(2) + (v[1] + 1.2).powi(2) + wrap_angle(v[2] - 3.0).powi(2)
}

fn quick(strategy: Strategy, crossover: Crossover) -> DeParams {
    DeParams {
        population: 20,
        generations: 60,
        f: 0.6,
        cr: 0.9,
        strategy,
        crossover,
        parallel: false,
        ..DeParams::thesis_program()
    }
}

#[test]
fn every_strategy_and_crossover_improves_an_easy_problem() {
    let bounds = Bounds::window(3.0, std::f64::consts::PI);
    for strategy in Strategy::ALL {
        for crossover in [Crossover::Binomial, Crossover::Exponential] {
            let mut rng = SimRng::seed_from_u64(11);
            let p = quick(strategy, crossover);
            let out = minimize(&sphere, &bounds, &p, &[], &mut rng).unwrap();
            let initial = {
                // the same seed reproduces the same initial population
                let mut rng = SimRng::seed_from_u64(11);
                let p0 = DeParams {
                    generations: 0,
                    ..p.clone()
                };
                minimize(&sphere, &bounds, &p0, &[], &mut rng)
                    .unwrap()
                    .best_cost
            };
            assert_eq!(out.generations, 60, "{strategy} {crossover:?}");
            assert_eq!(out.evaluations, 20 * 61);
            assert!(
                out.best_cost < 0.25 * initial && out.best_cost < 0.05,
                "{strategy} {crossover:?}: {initial} -> {}",
                out.best_cost
            );
            assert!(out.population.iter().all(|m| bounds.contains(m)));
        }
    }
}

#[test]
fn theta_wraps_across_pi() {
    // optimum at θ = π − 0.01 reached from both sides of ±π
    let bounds = Bounds::window(1.0, std::f64::consts::PI);
    let cost = |v: &Vector| {
        v[0].powi(2) + v[1].powi(2) + wrap_angle(v[2] - (std::f64::consts::PI - 0.01)).powi(2)
    };
    let seeds = [[0.0, 0.0, -3.1], [0.1, 0.0, 3.1]];
    let p = DeParams {
        population: 12,
        generations: 80,
        f: 0.5,
        cr: 0.9,
        strategy: Strategy::Rand1,
        parallel: false,
        ..DeParams::thesis_program()
    };
    let out = minimize(&cost, &bounds, &p, &seeds, &mut SimRng::seed_from_u64(3)).unwrap();
    assert!(out.best_cost < 1e-4, "{}", out.best_cost);
    assert!(
        out.population
            .iter()
            .all(|m| m[2] > -std::f64::consts::PI && m[2] <= std::f64::consts::PI)
    );
}

#[test]
fn budget_stall_and_collapse_stop_early() {
    let bounds = Bounds::window(3.0, std::f64::consts::PI);
    let mut p = quick(Strategy::Rand1, Crossover::Binomial);
    p.generations = 10_000;
    p.max_evaluations = Some(20 * 11 + 5);
    let out = minimize(&sphere, &bounds, &p, &[], &mut SimRng::seed_from_u64(1)).unwrap();
    assert_eq!(
        (out.stop, out.generations, out.evaluations),
        (StopReason::Budget, 10, 220)
    );

    p.max_evaluations = None;
    p.collapse_tolerance = Some(1e-3);
    let out = minimize(&sphere, &bounds, &p, &[], &mut SimRng::seed_from_u64(1)).unwrap();
    assert_eq!(out.stop, StopReason::Collapsed);
    assert!(out.generations < 10_000 && out.best_cost < 1e-5);

    p.collapse_tolerance = None;
    p.stall = Some(StallStop {
        generations: 5,
        tolerance: 0.0,
    });
    // a flat cost never improves: stops after exactly 5 generations
    let out = minimize(
        &|_: &Vector| 1.0,
        &bounds,
        &p,
        &[],
        &mut SimRng::seed_from_u64(1),
    )
    .unwrap();
    assert_eq!((out.stop, out.generations), (StopReason::Stalled, 5));
}

#[test]
fn bad_parameters_are_errors() {
    let b = Bounds::window(1.0, 1.0);
    let run = |p: DeParams| minimize(&sphere, &b, &p, &[], &mut SimRng::seed_from_u64(0));
    let base = quick(Strategy::Rand2, Crossover::Binomial);
    assert!(matches!(
        run(DeParams {
            population: 5,
            ..base.clone()
        }),
        Err(MatchError::PopulationTooSmall { min: 6, .. })
    ));
    assert!(matches!(
        run(DeParams {
            population: 3,
            strategy: Strategy::Best1,
            ..base.clone()
        }),
        Err(MatchError::PopulationTooSmall { min: 4, .. })
    ));
    assert_eq!(
        run(DeParams {
            f: 0.0,
            ..base.clone()
        }),
        Err(MatchError::InvalidF(0.0))
    );
    assert!(matches!(
        run(DeParams {
            f: f64::NAN,
            ..base.clone()
        }),
        Err(MatchError::InvalidF(_))
    ));
    assert_eq!(
        run(DeParams {
            f: 2.5,
            ..base.clone()
        }),
        Err(MatchError::InvalidF(2.5))
    );
    assert!(
        run(DeParams {
            f: 2.0,
            ..base.clone()
        })
        .is_ok()
    );
    assert_eq!(
        run(DeParams {
            cr: 1.5,
            ..base.clone()
        }),
        Err(MatchError::InvalidCr(1.5))
    );
    assert!(matches!(
        run(DeParams {
            max_evaluations: Some(3),
            ..base.clone()
        }),
        Err(MatchError::BudgetTooSmall { .. })
    ));
    let bad = Bounds {
        lo: [1.0, 0.0, 0.0],
        hi: [0.0, 1.0, 1.0],
    };
    assert!(matches!(
        minimize(&sphere, &bad, &base, &[], &mut SimRng::seed_from_u64(0)),
        Err(MatchError::InvalidBounds { axis: 0, .. })
    ));
}

#[test]
fn same_seed_same_result_any_thread_count() {
    let bounds = Bounds::window(3.0, std::f64::consts::PI);
    let run = |threads: usize, parallel: bool| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let p = DeParams {
                parallel,
                strategy: Strategy::EitherOr,
                ..quick(Strategy::EitherOr, Crossover::Exponential)
            };
            minimize(&sphere, &bounds, &p, &[], &mut SimRng::seed_from_u64(99)).unwrap()
        })
    };
    let a = run(1, true);
    let b = run(2, true);
    let c = run(2, false);
    assert_eq!(a, b);
    assert_eq!(a, c);
    let other = {
        let p = quick(Strategy::EitherOr, Crossover::Exponential);
        minimize(&sphere, &bounds, &p, &[], &mut SimRng::seed_from_u64(100)).unwrap()
    };
    assert_ne!(a.population, other.population);
}
