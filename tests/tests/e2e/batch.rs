//! `sim batch`: per-run files with every metric, the aggregate table, determinism whatever
//! `--jobs`, a broken parameter set that fails alone, and shards that cover the batch (its
//! messages for bad arguments: sim/tests/cli/batch.rs).

use crate::common::*;
use serde_json::Value;
use sim::batch::{BatchArgs, BatchReport, batch_command};
use sim::options::parse_args;
use std::path::Path;

fn batch(args: &[&str]) -> Result<BatchReport, String> {
    let a: BatchArgs = parse_args(args).map_err(|e| e.to_string())?;
    batch_command(&a).map_err(|e| format!("{e:#}"))
}

fn jsonl(path: &Path) -> Vec<serde_json::Map<String, Value>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| match serde_json::from_str(l) {
            Ok(Value::Object(m)) => m,
            other => panic!("not a JSON object line: {l} ({other:?})"),
        })
        .collect()
}

/// A row without its wall-clock fields.
fn deterministic(mut row: serde_json::Map<String, Value>) -> serde_json::Map<String, Value> {
    for k in ["job", "job_wall_s", "wall_time_s", "real_time_factor"] {
        row.remove(k);
    }
    row
}

#[test]
fn batch_writes_every_metric_and_is_deterministic_whatever_the_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = repo_file("../assets/scenarios/hospital_patrol.toml");
    let scenario = scenario.to_str().unwrap();
    let (d2, d1) = (dir.path().join("j2"), dir.path().join("j1"));
    let r2 = batch(&[
        scenario,
        "--seeds",
        "0..3",
        "--jobs",
        "2",
        "--duration",
        "0.5",
        "--quiet",
        "--out",
        d2.to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!((r2.runs, r2.failed), (3, 0));
    // runs.csv: a header and one line per run, with the parameters and every summary metric
    let csv = std::fs::read_to_string(d2.join("runs.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 4, "{csv}");
    let header: Vec<&str> = lines[0].split(',').collect();
    for col in [
        "job",
        "set",
        "seed",
        "status",
        "error",
        "job_wall_s",
        "sim_time_s",
        "real_time_factor",
        "fleet.collisions",
        "fleet.distance_m",
        "fleet.localization.mcl.ate_rmse_m",
        "fleet.localization.mcl.ate_map_rmse_m",
        "robots.r1.distance_m",
        "robots.r4.odometry_drift_m",
        "robots.r1.localization.mcl.ate_rmse_m",
        "robots.r2.localization.markov_grid.final_error_m",
        "robots.r3.localization.de_filter.tracked_fraction",
        "robots.r1.final_pose.2",
    ] {
        assert!(header.contains(&col), "no column {col} in {header:?}");
    }
    let rows = jsonl(&d2.join("runs.jsonl"));
    assert_eq!(rows.len(), 3);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r["seed"], i as u64);
        assert_eq!(r["status"], "ok");
        assert_eq!(r["sim_time_s"].as_f64(), Some(0.5));
        assert!(r["robots.r1.distance_m"].as_f64().unwrap() > 0.0, "{r:?}");
    }
    // the seeds differ, so the runs do
    let metrics = |r: &serde_json::Map<String, Value>| -> Vec<Value> {
        r.iter()
            .filter(|(k, _)| k.starts_with("robots."))
            .map(|(_, v)| v.clone())
            .collect()
    };
    assert_ne!(metrics(&rows[0]), metrics(&rows[1]));
    // the aggregate table (printed) and aggregate.csv
    assert!(
        r2.table.starts_with("set 0: 3 runs, 0 failed"),
        "{}",
        r2.table
    );
    for m in [
        "mean",
        "std",
        "median",
        "p95",
        "fleet.distance_m",
        "fleet.localization.mcl.ate_rmse_m",
        "fleet.localization.mcl.ate_map_rmse_m",
        "real_time_factor",
    ] {
        assert!(r2.table.contains(m), "no {m} in:\n{}", r2.table);
    }
    let agg = std::fs::read_to_string(d2.join("aggregate.csv")).unwrap();
    assert!(
        agg.starts_with("set,runs,failed,metric,n,mean,std,median,p95\n"),
        "{agg}"
    );
    assert!(agg.contains("\n0,3,0,robots.r1.distance_m,3,"), "{agg}");
    // one run at a time gives the same rows, whatever else the batch holds
    let r1 = batch(&[
        scenario,
        "--seeds",
        "1..3",
        "--jobs",
        "1",
        "--duration",
        "0.5",
        "--quiet",
        "--out",
        d1.to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(r1.failed, 0);
    let one = jsonl(&d1.join("runs.jsonl"));
    assert_eq!(one.len(), 2);
    for (a, b) in rows.into_iter().skip(1).zip(one) {
        assert_eq!(deterministic(a), deterministic(b));
    }
}

#[test]
fn a_broken_parameter_set_fails_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b");
    let args = [
        "maze_run",
        "--seeds",
        "0..2",
        "--sweep",
        "duration=2,-1,1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    let r = batch(&args).unwrap();
    assert_eq!((r.runs, r.failed), (6, 2));
    // the binary exits non-zero (code 2) after writing every file
    let e = r.into_result().unwrap_err();
    assert!(e.is::<sim::batch::RunsFailed>());
    assert!(e.to_string().contains("2 of 6 runs failed"), "{e}");
    let rows = jsonl(&out.join("runs.jsonl"));
    assert_eq!(rows.len(), 6);
    let ok: Vec<_> = rows.iter().filter(|r| r["status"] == "ok").collect();
    assert_eq!(ok.len(), 4);
    assert!(
        ok.iter()
            .all(|r| r["set"] != 1 && r["sim_time_s"].as_f64().unwrap() > 0.5)
    );
    for r in rows.iter().filter(|r| r["set"] == 1) {
        assert_eq!(r["status"], "failed");
        let e = r["error"].as_str().unwrap();
        assert!(e.starts_with("--sweep duration=-1: "), "{e}");
        assert!(
            e.contains("maze_run.toml:9:1: `duration`: expected a number greater than 0, got -1"),
            "{e}"
        );
    }
    let agg = std::fs::read_to_string(out.join("aggregate.csv")).unwrap();
    assert!(agg.contains("\n0,2,2,0,sim_time_s,2,2,0,2,2\n"), "{agg}");
    assert!(agg.contains("\n2,1,2,0,sim_time_s,2,1,0,1,1\n"), "{agg}");
    assert!(!agg.contains("\n1,-1,"), "{agg}");
}

#[test]
fn shards_cover_the_batch_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let mut seen = Vec::new();
    for shard in ["0/2", "1/2"] {
        let out = dir.path().join(shard.replace('/', "of"));
        let r = batch(&[
            "maze_run",
            "--seeds",
            "3..6",
            "--sweep",
            "duration=0.5,1",
            "--shard",
            shard,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .unwrap();
        assert_eq!((r.runs, r.failed), (3, 0));
        for row in jsonl(&out.join("runs.jsonl")) {
            let key = |k: &str| row[k].as_f64().unwrap();
            seen.push((
                key("job") as u64,
                key("set") as u64,
                key("seed") as u64,
                key("sim_time_s"),
            ));
        }
    }
    seen.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let want: Vec<(u64, u64, u64, f64)> = (0..6)
        .map(|j| (j, j / 3, 3 + j % 3, if j < 3 { 0.5 } else { 1.0 }))
        .collect();
    assert_eq!(seen, want);
    // batch-merge joins them in job order, with the statistics of both sets
    let merged = dir.path().join("merged");
    let (s0, s1) = (dir.path().join("0of2"), dir.path().join("1of2"));
    let merge = |shards: &[&Path]| {
        let mut args = vec![merged.to_str().unwrap(), "--quiet"];
        args.extend(shards.iter().map(|p| p.to_str().unwrap()));
        let a: sim::batch::merge::MergeArgs = parse_args(&args).unwrap();
        sim::batch::merge::merge_command(&a).map_err(|e| format!("{e:#}"))
    };
    let r = merge(&[&s1, &s0]).unwrap();
    assert_eq!((r.runs, r.failed), (6, 0));
    let jobs: Vec<u64> = jsonl(&merged.join("runs.jsonl"))
        .iter()
        .map(|r| r["job"].as_u64().unwrap())
        .collect();
    assert_eq!(jobs, [0, 1, 2, 3, 4, 5]);
    let csv = std::fs::read_to_string(merged.join("runs.csv")).unwrap();
    assert!(
        csv.starts_with("job,set,set.duration,seed,status,error,job_wall_s,sim_time_s,"),
        "{csv}"
    );
    let agg = std::fs::read_to_string(merged.join("aggregate.csv")).unwrap();
    assert!(
        agg.contains("\n0,0.5,3,0,sim_time_s,3,0.5,0,0.5,0.5\n"),
        "{agg}"
    );
    assert!(agg.contains("\n1,1,3,0,sim_time_s,3,1,0,1,1\n"), "{agg}");
}
