//! `sim replay` from the command line: a recording replays to the live run's estimates (the TUM
//! files are identical), the bundled recording in replays/ localizes and its replay writes an
//! .rrd that opens in Rerun.

use crate::common::*;
use std::path::Path;

fn sim_replay(args: &[&str]) -> Result<(), String> {
    use sim::replay::{ReplayArgs, replay_command};
    let a: ReplayArgs = sim::options::parse_args(args).map_err(|e| e.to_string())?;
    replay_command(&a).map_err(|e| format!("{e:#}"))
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn a_replay_writes_the_live_runs_estimates_to_the_last_digit() {
    let dir = tempfile::tempdir().unwrap();
    let p = |f: &str| dir.path().join(f).to_str().unwrap().to_string();
    let scenario = repo_file("../replays/hospital_r1.toml");
    let sc = scenario.to_str().unwrap();
    sim_run(&[
        sc,
        "--duration",
        "8",
        "--no-rrd",
        "--quiet",
        "--mcap",
        &p("r1.mcap"),
        "--trajectories",
        &p("live"),
    ])
    .unwrap();
    sim_replay(&[
        &p("r1.mcap"),
        "--no-rrd",
        "--quiet",
        "--trajectories",
        &p("replay"),
    ])
    .unwrap();
    for loc in ["mcl", "markov_grid"] {
        let file = format!("r1/{loc}.tum");
        let live = read(&dir.path().join("live").join(&file));
        assert!(live.lines().count() > 10, "{file}: {live}");
        assert_eq!(live, read(&dir.path().join("replay").join(&file)), "{file}");
    }
}

#[test]
fn the_bundled_recording_replays_localizes_and_opens_in_rerun() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("r1.rrd");
    let summary = dir.path().join("s.json");
    let file = repo_file("../replays/hospital_r1-seed0.mcap");
    sim_replay(&[
        file.to_str().unwrap(),
        "--quiet",
        "--rrd",
        rrd.to_str().unwrap(),
        "--summary",
        summary.to_str().unwrap(),
    ])
    .unwrap();
    let s: serde_json::Value = serde_json::from_str(&read(&summary)).unwrap();
    assert_eq!(s["scenario"], "hospital_r1");
    assert!((s["sim_time_s"].as_f64().unwrap() - 20.0).abs() < 1e-9);
    let loc = &s["robots"][0]["localization"];
    for name in ["mcl", "markov_grid"] {
        let ate = loc[name]["ate_rmse_m"].as_f64().unwrap();
        assert!(ate < 0.15, "{name}: ATE {ate} m");
    }
    let Some(v) = check_rrd(&rrd) else {
        return;
    };
    let paths = entity_paths(&v);
    for want in [
        "/robots/r1/truth",
        "/robots/r1/odometry",
        "/robots/r1/scan",
        "/robots/r1/estimate/mcl",
        "/robots/r1/error/markov_grid",
    ] {
        assert!(paths.iter().any(|p| p == want), "{want} not in {paths:?}");
    }
}
