//! The profile: every system of the tick, timed by bevy's spans and nothing else.

use super::*;
use crate::scenario::load_scenario;

#[test]
fn the_span_timer_times_system_spans_only() {
    let timer = SpanTimer::default();
    let times = timer.times.clone();
    tracing::subscriber::with_default(timer, || {
        let a = tracing::info_span!("system", name = "my::system_a");
        let commands = tracing::info_span!("system_commands", name = "my::system_a");
        let other = tracing::info_span!("check_conditions", name = "my::system_a");
        for _ in 0..3 {
            let _in = a.enter();
            std::thread::sleep(Duration::from_millis(2));
        }
        {
            let _in = commands.enter();
            std::thread::sleep(Duration::from_millis(1));
        }
        let _in = other.enter();
        std::thread::sleep(Duration::from_millis(50));
    });
    let t = times.lock().unwrap();
    // the check_conditions span was never created
    assert_eq!(t.spans.len(), 2);
    let (time, runs) = t.of("my::system_a");
    assert_eq!(runs, 3, "commands do not count as runs");
    assert!(time >= Duration::from_millis(7), "{time:?}");
    // the 50 ms of the other span are not counted (a loaded machine may stretch the 7 ms)
    assert!(time < Duration::from_millis(50), "{time:?}");
    assert_eq!(t.of("my::other"), (Duration::ZERO, 0));
}

#[test]
fn a_profile_lists_every_system_of_the_tick_in_order() {
    let path = crate::scenario::find_scenario("maze_run").unwrap();
    let sc = load_scenario(&path).unwrap();
    let p = profile(&sc, "maze_run", 1.0).unwrap();
    assert_eq!(p.ticks, 20);
    let names: Vec<&str> = p.systems.iter().map(|s| s.system.as_str()).collect();
    let physics = names
        .iter()
        .position(|n| n.ends_with("physics_step"))
        .expect("the physics step");
    let lasers = names
        .iter()
        .position(|n| n.ends_with("sample_lasers"))
        .expect("the lasers");
    assert!(physics < lasers, "{names:?}");
    for s in &p.systems {
        // no system runs more than once a tick
        assert!(s.runs_per_tick <= 1.0, "{s:?}");
    }
    let step = &p.systems[physics];
    assert_eq!((step.set.as_str(), step.runs_per_tick), ("Physics", 1.0));
    assert!(step.us_per_tick > 0.0);
    // the systems' times fit in the profiled tick
    assert!(
        p.systems_us > 0.0 && p.systems_us <= p.profiled_tick_us,
        "{p:?}"
    );
    let shares: f64 = p.systems.iter().map(|s| s.share_percent).sum();
    assert!(shares <= 100.0 + 1e-9, "{shares}");
    let table = format_profile(&p);
    assert!(table.contains("body::physics::physics_step"), "{table}");
    assert!(table.contains("outside the systems"), "{table}");
}

#[test]
fn bad_options_are_errors() {
    let o = ProfileOptions {
        scenario: None,
        robots: Some(1),
        beams: 1,
        mcl: None,
        duration: 1.0,
        json: true,
    };
    let e = run_profile(&o).unwrap_err().to_string();
    assert!(e.contains("--beams"), "{e}");
    let o = ProfileOptions {
        duration: f64::NAN,
        beams: 180,
        ..o
    };
    assert!(run_profile(&o).is_err());
    let o = ProfileOptions {
        scenario: Some("no_such_scenario".into()),
        robots: None,
        duration: 1.0,
        ..o
    };
    let e = run_profile(&o).unwrap_err().to_string();
    assert!(e.contains("no_such_scenario"), "{e}");
}
