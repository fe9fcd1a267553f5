//! `sim experiment park`: the park runs of 004_95e533f2514531b8.txt (SEEDS.md, "Experiments":
//! the 350 m route, where the thesis's car took a wrong turn in 2 of 3 runs one way and
//! recovered by re-localization and re-planning, and the 190 m route that avoids a U-turn, all
//! runs reaching the goal). Each route runs N times with seeds 0..N, once navigating by the
//! thesis's road-grid localization and once by the road MCL; both localizers run in every run,
//! so each is judged on every run. Runs go in parallel, one per worker; each run is
//! single-threaded and deterministic, so the table does not depend on the thread count.

use super::scan_pairs::bundled;
use crate::scenario::Scenario;
use crate::scenario::outdoor_robot::RoadLocalizerKind;
use crate::summary_road::RoadSummary;
use crate::{RunOptions, run_scenario};
use rayon::prelude::*;
use serde::Serialize;

/// The routes of the experiment (bundled scenarios).
pub const ROUTES: [&str; 2] = ["park_route_long", "park_route_short"];

#[derive(Clone, Debug)]
pub struct ParkOptions {
    pub routes: Vec<String>,
    pub runs: u64,
    /// Worker threads (0 = one per core).
    pub threads: usize,
    pub progress: bool,
}

/// One run's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct ParkRun {
    pub route: String,
    pub navigate_by: String,
    pub seed: u64,
    pub sim_time_s: f64,
    pub road: RoadSummary,
}

/// One row of the table: a route driven by one localizer over all seeds.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ParkRow {
    pub route: String,
    pub navigate_by: String,
    pub runs: u32,
    pub reached: u32,
    pub reached_percent: f64,
    pub wrong_turns: u32,
    pub recoveries: u32,
    /// Median arrival time of the runs that arrived (s).
    pub median_time_s: Option<f64>,
    /// Mean over runs of each localizer's mean position error (m), its worst error, and its
    /// share of updates on the wrong edge (%): road_grid then road_mcl.
    pub grid_mean_error_m: Option<f64>,
    pub grid_max_error_m: Option<f64>,
    pub grid_wrong_edge_percent: Option<f64>,
    pub mcl_mean_error_m: Option<f64>,
    pub mcl_max_error_m: Option<f64>,
    pub mcl_wrong_edge_percent: Option<f64>,
    pub off_road_time_s: f64,
}

fn with_navigator(s: &Scenario, kind: RoadLocalizerKind, seed: u64) -> Scenario {
    let mut s = s.clone();
    s.seed = seed;
    for r in &mut s.robots {
        if let Some(route) = &mut r.route {
            route.navigate_by = kind;
        }
    }
    s
}

pub fn run_park_experiment(o: &ParkOptions) -> anyhow::Result<(Vec<ParkRow>, Vec<ParkRun>)> {
    if o.runs == 0 {
        anyhow::bail!("--runs: expected at least 1");
    }
    let mut jobs = Vec::new();
    for name in &o.routes {
        let scenario = match std::path::Path::new(name).exists() {
            true => crate::load_scenario(std::path::Path::new(name))?,
            false => bundled(name)?,
        };
        if !scenario.robots.iter().any(|r| r.route.is_some()) {
            anyhow::bail!("{name}: no robot has a `[robots.route]`");
        }
        for kind in RoadLocalizerKind::ALL {
            for seed in 0..o.runs {
                jobs.push((
                    scenario.name.clone(),
                    with_navigator(&scenario, kind, seed),
                    kind,
                ));
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads)
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start {} threads: {e}", o.threads))?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = jobs.len();
    let runs: Vec<anyhow::Result<Vec<ParkRun>>> = pool.install(|| {
        jobs.par_iter()
            .map(|(route, s, kind)| {
                let opts = RunOptions {
                    rrd: None,
                    threads: 1,
                    progress: false,
                    trajectory_period: None,
                };
                let out = run_scenario(s, &opts)?;
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if o.progress {
                    eprintln!("[{n}/{total}] {route} by {} seed {}", kind.as_str(), s.seed);
                }
                Ok(out
                    .summary
                    .robots
                    .iter()
                    .filter_map(|r| r.road.clone())
                    .map(|road| ParkRun {
                        route: route.clone(),
                        navigate_by: kind.as_str().to_string(),
                        seed: s.seed,
                        sim_time_s: out.summary.sim_time_s,
                        road,
                    })
                    .collect())
            })
            .collect()
    });
    let mut all = Vec::new();
    for r in runs {
        all.extend(r?);
    }
    let mut rows = Vec::new();
    for name in &o.routes {
        let route_name = all
            .iter()
            .find(|r| {
                r.route == *name
                    || std::path::Path::new(name)
                        .file_stem()
                        .is_some_and(|s| s == r.route.as_str())
            })
            .map(|r| r.route.clone())
            .unwrap_or_else(|| name.clone());
        for kind in RoadLocalizerKind::ALL {
            let these: Vec<&ParkRun> = all
                .iter()
                .filter(|r| r.route == route_name && r.navigate_by == kind.as_str())
                .collect();
            rows.push(row(&route_name, kind.as_str(), &these));
        }
    }
    Ok((rows, all))
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn row(route: &str, by: &str, runs: &[&ParkRun]) -> ParkRow {
    let reached = runs.iter().filter(|r| r.road.reached).count() as u32;
    let mut times: Vec<f64> = runs
        .iter()
        .filter(|r| r.road.reached)
        .filter_map(|r| r.road.arrival_time_s)
        .collect();
    let loc =
        |name: &str, f: &dyn Fn(&crate::summary_road::RoadLocalizerSummary) -> Option<f64>| {
            mean(
                runs.iter()
                    .filter_map(|r| r.road.localizers.get(name))
                    .filter_map(f),
            )
        };
    let worst = |name: &str| {
        runs.iter()
            .filter_map(|r| r.road.localizers.get(name)?.max_error_m)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
    };
    ParkRow {
        route: route.to_string(),
        navigate_by: by.to_string(),
        runs: runs.len() as u32,
        reached,
        reached_percent: if runs.is_empty() {
            0.0
        } else {
            100.0 * reached as f64 / runs.len() as f64
        },
        wrong_turns: runs.iter().map(|r| r.road.wrong_turns).sum(),
        recoveries: runs.iter().map(|r| r.road.recoveries).sum(),
        median_time_s: (!times.is_empty()).then(|| crate::stats::median(&mut times)),
        grid_mean_error_m: loc("road_grid", &|l| l.mean_error_m),
        grid_max_error_m: worst("road_grid"),
        grid_wrong_edge_percent: loc("road_grid", &|l| l.wrong_edge_percent),
        mcl_mean_error_m: loc("road_mcl", &|l| l.mean_error_m),
        mcl_max_error_m: worst("road_mcl"),
        mcl_wrong_edge_percent: loc("road_mcl", &|l| l.wrong_edge_percent),
        off_road_time_s: runs.iter().map(|r| r.road.off_road_time_s).sum(),
    }
}

/// The table `sim experiment park` prints.
pub fn table(rows: &[ParkRow]) -> String {
    let f = |v: Option<f64>, p: usize| v.map_or("-".to_string(), |v| format!("{v:.p$}"));
    let mut s = format!(
        "{:<18} {:<10} {:>5} {:>8} {:>6} {:>6} {:>8} | {:>22} | {:>22} | {:>8}\n",
        "route",
        "nav by",
        "runs",
        "reached",
        "wrong",
        "recov",
        "median",
        "road_grid err m / wrong%",
        "road_mcl err m / wrong%",
        "off-road"
    );
    s += &format!(
        "{:<18} {:<10} {:>5} {:>8} {:>6} {:>6} {:>8} | {:>22} | {:>22} | {:>8}\n",
        "",
        "",
        "",
        "%",
        "turns",
        "",
        "time s",
        "mean  max  wrong-edge",
        "mean  max  wrong-edge",
        "s"
    );
    for r in rows {
        s += &format!(
            "{:<18} {:<10} {:>5} {:>8.1} {:>6} {:>6} {:>8} | {:>6} {:>6} {:>8} | {:>6} {:>6} {:>8} | {:>8.1}\n",
            r.route,
            r.navigate_by,
            r.runs,
            r.reached_percent,
            r.wrong_turns,
            r.recoveries,
            f(r.median_time_s, 1),
            f(r.grid_mean_error_m, 2),
            f(r.grid_max_error_m, 1),
            f(r.grid_wrong_edge_percent, 1),
            f(r.mcl_mean_error_m, 2),
            f(r.mcl_max_error_m, 1),
            f(r.mcl_wrong_edge_percent, 1),
            r.off_road_time_s,
        );
    }
    s
}
