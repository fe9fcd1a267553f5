//! The written .rrd opens with the Rerun 0.36.3 tools and holds the entity paths of DESIGN.md on
//! the `sim_time` timeline.

use crate::common::*;
use sim::scenario::load_scenario;
use sim::{RunOptions, run_scenario};
use std::process::Command;

#[test]
fn rrd_opens_in_rerun_and_has_the_entity_paths() {
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
    let venv = rerun_venv();
    let rerun = venv.join("bin/rerun");
    let verify = Command::new(&rerun)
        .args(["rrd", "verify"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        verify.status.success(),
        "rerun rrd verify failed:\n{}\n{}",
        String::from_utf8_lossy(&verify.stdout),
        String::from_utf8_lossy(&verify.stderr)
    );
    let stats = Command::new(&rerun)
        .args(["rrd", "stats"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        stats.status.success(),
        "{}",
        String::from_utf8_lossy(&stats.stderr)
    );
    let out = Command::new(venv.join("bin/python"))
        .arg(repo_file("check_rrd.py"))
        .arg(&path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let paths: Vec<&str> = v["entity_paths"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p.as_str())
        .collect();
    let mut want = vec!["/world/map".to_string()];
    for r in &s.robots {
        for leaf in ["truth", "odometry", "scan"] {
            want.push(format!("/robots/{}/{leaf}", r.name));
        }
    }
    for w in &want {
        assert!(paths.contains(&w.as_str()), "missing {w} in {paths:?}");
    }
    let timelines = v["timelines"].as_array().unwrap();
    assert!(timelines.iter().any(|t| t == "sim_time"), "{timelines:?}");
}
