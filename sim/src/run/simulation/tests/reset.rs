//! A reset equals a fresh simulation of that seed; a shared or inline kernel pool gives the same
//! run; a simulation writing files refuses to reset.

use super::*;

#[test]
fn a_reset_equals_a_fresh_simulation_with_that_seed() {
    // a navigating robot (costmaps reused) and localizers (distance field reused)
    let text = COURIER.replace(
        "[[robots.tasks]]",
        "[[robots.localization]]\nname = \"mcl\"\ntype = \"mcl\"\ninit = \"pose\"\n[[robots.tasks]]",
    );
    let mut s = from_text(&text, "courier").build().unwrap();
    s.run_for(2.0).unwrap();
    s.reset(9).unwrap();
    assert_eq!((s.ticks(), s.time(), s.scenario().seed), (0, 0.0, 9));
    let mut fresh = from_text(&text, "courier").seed(9).build().unwrap();
    for _ in 0..2 {
        s.run_for(1.5).unwrap();
        fresh.run_for(1.5).unwrap();
        assert_eq!(
            navigation_fingerprint(&mut s),
            navigation_fingerprint(&mut fresh)
        );
    }
    let (a, b) = (s.finish().unwrap(), fresh.finish().unwrap());
    assert_eq!(summary_json(&a), summary_json(&b));
}

/// Worlds on a shared pool, or running their kernels inline on a pool stepping them side by
/// side, give the run of a simulation with a pool of its own; a reset keeps the pool.
#[test]
fn a_given_kernel_pool_gives_the_same_run() {
    let text = COURIER.replace(
        "[[robots.tasks]]",
        "[[robots.localization]]\nname = \"mcl\"\ntype = \"mcl\"\ninit = \"pose\"\n[[robots.tasks]]",
    );
    let mut own = from_text(&text, "courier").threads(1).build().unwrap();
    own.run_for(3.0).unwrap();
    let want = summary_json(&own.finish().unwrap());
    let shared = KernelPool::new(2).unwrap();
    let mut worlds: Vec<Simulation> = [shared.clone(), shared, KernelPool::inline()]
        .into_iter()
        .map(|pool| {
            from_text(&text, "courier")
                .kernel_pool(pool)
                .build()
                .unwrap()
        })
        .collect();
    let outer = KernelPool::new(2).unwrap();
    outer.install(|| {
        use rayon::prelude::*;
        worlds.par_iter_mut().for_each(|w| {
            w.run_for(1.0).unwrap();
            let seed = w.scenario().seed;
            w.reset(seed).unwrap();
            w.run_for(3.0).unwrap();
        })
    });
    for w in worlds {
        assert_eq!(summary_json(&w.finish().unwrap()), want);
    }
}

#[test]
fn a_simulation_writing_files_refuses_to_reset() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = from_text(COURIER, "courier")
        .rrd(dir.path().join("a.rrd"))
        .build()
        .unwrap();
    let e = s.reset(2).unwrap_err().to_string();
    assert!(e.contains("writes recordings"), "{e}");
}
