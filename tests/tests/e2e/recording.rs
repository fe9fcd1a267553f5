//! The written .rrd opens with the Rerun 0.36.3 tools and holds the entity paths of `systems/ARCHITECTURE.md` on
//! the `sim_time` timeline, including every localizer's estimate, particle set and error series.

use crate::common::*;
use sim::scenario::LocalizerKind;
use sim::scenario::load_scenario;
use sim::{RunOptions, run_scenario};
use std::process::Command;

#[test]
fn rrd_opens_in_rerun_and_has_the_entity_paths() {
    let Some(rerun) = test_tool(TestTool::Rerun) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("patrol.rrd");
    let mut s = load_scenario(&bundled("hospital_patrol")).unwrap();
    s.duration = 5.0;
    run_scenario(
        &s,
        &RunOptions {
            rrd: Some(path.clone()),
            threads: 2,
            progress: false,
            trajectory_period: None,
        },
    )
    .unwrap();
    let v = check_rrd_with(&rerun, &path);
    let stats = Command::new(rerun.join("bin/rerun"))
        .args(["rrd", "stats"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        stats.status.success(),
        "{}",
        String::from_utf8_lossy(&stats.stderr)
    );
    let paths = entity_paths(&v);
    let mut want = vec!["/world/map".to_string()];
    for r in &s.robots {
        for leaf in ["truth", "odometry", "scan"] {
            want.push(format!("/robots/{}/{leaf}", r.name));
        }
    }
    // walking people: a disc and a trail each
    assert!(!s.people.is_empty(), "the patrol has people");
    for p in &s.people {
        want.push(format!("/people/{}", p.name));
        want.push(format!("/people/{}/trail", p.name));
    }
    let mut localizers = 0;
    for r in &s.robots {
        for l in &r.localizers {
            localizers += 1;
            let base = format!("/robots/{}", r.name);
            want.push(format!("{base}/estimate/{}", l.name));
            want.push(format!("{base}/estimate/{}/covariance", l.name));
            want.push(format!("{base}/error/{}", l.name));
            want.push(format!("{base}/heading_error/{}", l.name));
            // DE odometry keeps no population
            if !matches!(l.kind, LocalizerKind::DeOdometry(_)) {
                want.push(format!("{base}/particles/{}", l.name));
            }
        }
    }
    assert!(localizers >= 4, "the scenario should carry localizers");
    for w in &want {
        assert!(paths.contains(w), "missing {w} in {paths:?}");
    }
    // the error series: one value per published estimate, plausible for every localizer, and
    // small for MCL tracking from the known start pose
    let scalars = &v["scalars"];
    for r in &s.robots {
        for l in &r.localizers {
            let pos = &scalars[format!("/robots/{}/error/{}", r.name, l.name)];
            let head = &scalars[format!("/robots/{}/heading_error/{}", r.name, l.name)];
            let f = |x: &serde_json::Value, k: &str| x[k].as_f64().unwrap_or(f64::NAN);
            assert!(f(pos, "count") >= 3.0, "{} {}: {pos}", r.name, l.name);
            assert_eq!(pos["count"], head["count"], "{} {}", r.name, l.name);
            assert!(f(pos, "min") >= 0.0 && f(pos, "max") < 100.0, "{pos}");
            assert!(
                f(head, "min") >= 0.0 && f(head, "max") <= std::f64::consts::PI + 1e-9,
                "{head}"
            );
            assert!(f(pos, "first_t") >= 0.0 && f(pos, "last_t") <= s.duration + 1e-6);
            if l.name == "mcl" {
                assert!(
                    f(pos, "max") < 0.5 && f(head, "max") < 0.2,
                    "{}: mcl from the start pose should track: {pos} {head}",
                    r.name
                );
            }
        }
    }
    // every series is named after its robot and localizer, and no position series holds radians
    for r in &s.robots {
        for l in &r.localizers {
            let want = format!("{} {}", r.name, l.name);
            for family in ["error", "heading_error"] {
                let path = format!("/robots/{}/{family}/{}", r.name, l.name);
                assert_eq!(
                    v["series_names"][&path],
                    serde_json::json!([want]),
                    "{path}"
                );
            }
        }
    }
    assert!(
        !paths
            .iter()
            .any(|p| p.contains("/error/") && p.ends_with("/heading")),
        "{paths:?}"
    );
    let timelines = v["timelines"].as_array().unwrap();
    assert!(timelines.iter().any(|t| t == "sim_time"), "{timelines:?}");
}

/// A user controller that panics ends the run with an error naming the robot and the tick, and
/// the recording written up to then is finished: Rerun's own tools read it.
#[test]
fn a_panicking_controller_leaves_a_finished_recording() {
    use sim::prelude::{Observation, SimError, Simulation, Twist};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crash.rrd");
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [5.0, 5.0, 0.0]\n\
         [robots.sensors.laser]\n[robots.sensors.encoder]\n"
    )
    .replace("duration = 1.0", "duration = 5.0");
    let err = Simulation::from_toml(&text, "crash")
        .rrd(&path)
        .controller("r1", |o: &Observation| {
            assert!(o.tick < 30, "the controller gave up");
            Twist { v: 0.3, w: 0.0 }
        })
        .build()
        .unwrap()
        .run()
        .err()
        .expect("the run fails");
    assert!(
        matches!(err.downcast_ref::<SimError>(), Some(SimError::ControllerFailed { robot, tick: 30, .. }) if robot == "r1"),
        "{err}"
    );
    assert!(std::fs::metadata(&path).unwrap().len() > 0);
    if let Some(report) = check_rrd(&path) {
        let text = report.to_string();
        assert!(text.contains("robots/r1"), "{text}");
    }
}

/// The run's story is in text-log lines at the times things happened: every scenario event and
/// program command as it fires in `events` (a robot's lines led by its name), and a navigating
/// robot's collisions, with what it hit and where, in `robots/<name>/collisions`: the lines of
/// the run's own event log, at its times.
#[test]
fn events_and_collisions_are_text_log_lines_at_their_times() {
    use sim::run::{Command, Simulation};
    use sim::scenario::SensorName;
    let Some(rerun) = test_tool(TestTool::Rerun) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("delivery.rrd");
    let mut s = Simulation::load("hospital_delivery")
        .duration(6.0)
        .threads(2)
        .rrd(&path)
        .build()
        .unwrap();
    let fault = |active| Command::SensorFault {
        sensor: SensorName::Laser,
        active,
    };
    s.run_for(1.0).unwrap();
    s.command("r1", fault(true)).unwrap();
    s.set_door("fire_door_w", false).unwrap();
    s.run_for(1.0).unwrap();
    s.command("r1", fault(false)).unwrap();
    // r2 dropped onto r1: a collision between two navigating robots
    let p = s.robot("r1").unwrap().pose();
    let onto = systems::core::Pose2::new(p.x + 0.3, p.y, p.theta);
    s.command("r2", Command::Teleport(onto)).unwrap();
    s.run_for(1.0).unwrap();
    let robots: Vec<String> = s.robots().iter().map(|r| r.name().to_string()).collect();
    let done = s.finish().unwrap();

    let v = check_rrd_with(&rerun, &path);
    let lines = |entity: &str| -> Vec<(f64, String, String)> {
        v["text_logs"][entity]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|l| {
                        (
                            l[0].as_f64().unwrap(),
                            l[1].as_str().unwrap_or("").to_string(),
                            l[2].as_str().unwrap().to_string(),
                        )
                    })
                    .collect()
            })
            .unwrap_or_default()
    };
    let events = lines("/events");
    let texts: Vec<&str> = events.iter().map(|(_, _, t)| t.as_str()).collect();
    for want in [
        "r1: laser fault on",
        "door fire_door_w closed",
        "r1: laser fault off",
    ] {
        assert!(texts.contains(&want), "{want} not in {texts:?}");
    }
    assert!(
        texts.iter().any(|t| t.starts_with("r2: teleported")),
        "{texts:?}"
    );
    // each line is one of the run's log, at its time
    let in_log = |t: f64, robot: &str, text: &str| {
        done.log
            .iter()
            .any(|(lt, r, l)| (lt - t).abs() < 1e-6 && r == robot && l == text)
    };
    for (t, level, line) in &events {
        let (robot, text) = match line.split_once(": ") {
            Some((r, rest)) if robots.iter().any(|n| n == r) => (r, rest),
            _ => ("", line.as_str()),
        };
        assert!(in_log(*t, robot, text), "{t} {line} not in {:?}", done.log);
        assert_eq!(level, "INFO");
    }
    let collisions: Vec<_> = done
        .log
        .iter()
        .filter(|(_, _, l)| l.starts_with("collision with"))
        .collect();
    assert!(!collisions.is_empty(), "{:?}", done.log);
    for (t, robot, text) in collisions {
        let got = lines(&format!("/robots/{robot}/collisions"));
        assert!(
            got.iter()
                .any(|(gt, lv, l)| (gt - t).abs() < 1e-6 && lv == "WARN" && l == text),
            "{t} {robot} {text} not in {got:?}"
        );
    }
}
