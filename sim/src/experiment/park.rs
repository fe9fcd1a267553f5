//! `sim experiment park`: the park runs of [Park thesis] (its experiments: the 350 m route, where the thesis's car took a wrong turn in 2 of 3 runs one way and
//! recovered by re-localization and re-planning, and the 190 m route that avoids a U-turn, all
//! runs reaching the goal). Each route runs N times with seeds 0..N, once navigating by the
//! thesis's road-grid localization and once by the road MCL; both localizers run in every run,
//! so each is judged on every run. Runs go in parallel, one per worker; each run is
//! single-threaded and deterministic, so the table does not depend on the thread count.

use super::scan_pairs::bundled;
use crate::batch::runner::on_workers;
use crate::run::summary::road::RoadSummary;
use crate::scenario::Scenario;
use crate::scenario::outdoor_robot::RoadLocalizerKind;
use crate::{RunOptions, run_scenario};
use serde::Serialize;

/// The routes of the experiment (bundled scenarios).
pub const ROUTES: [&str; 2] = ["park_route_long", "park_route_short"];

/// `sim experiment park`.
#[derive(clap::Args, Clone, Debug)]
pub struct ParkOptions {
    /// Routes (bundled scenario names or paths; each once).
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = ROUTES.map(String::from))]
    pub routes: Vec<String>,
    /// Runs per route and localizer (at most 100000).
    #[arg(long, default_value_t = 20)]
    pub runs: u64,
    /// Worker threads (0 = one per core; at most 1024). Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Print progress to stderr (not a flag: on unless `--json`).
    #[arg(skip)]
    pub progress: bool,
}

/// One run's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct ParkRun {
    pub route: String,
    pub navigate_by: String,
    pub seed: u64,
    /// The robot (a run judges every robot that has a route).
    pub robot: String,
    pub sim_time_s: f64,
    pub road: RoadSummary,
}

/// One row of the table: a route driven by one localizer over all seeds. A route with several
/// robots judges each of them: `robot_runs` = runs × robots with a route, and the counts and
/// percentages below are over robot runs.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ParkRow {
    pub route: String,
    pub navigate_by: String,
    /// Simulation runs (seeds).
    pub runs: u64,
    /// Robots judged over all runs.
    pub robot_runs: u32,
    /// Robot runs that reached their goal.
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

/// The most runs per route and localizer `--runs` accepts.
pub const MAX_RUNS: u64 = 100_000;

/// Runs the experiment: rows in route, then localizer order, and every robot's run.
pub fn run_park_experiment(o: &ParkOptions) -> anyhow::Result<(Vec<ParkRow>, Vec<ParkRun>)> {
    if !(1..=MAX_RUNS).contains(&o.runs) {
        anyhow::bail!("--runs: expected 1 to {MAX_RUNS}, got {}", o.runs);
    }
    let mut scenarios: Vec<Scenario> = Vec::new();
    for name in &o.routes {
        let scenario = match std::path::Path::new(name).exists() {
            true => crate::load_scenario(std::path::Path::new(name))?,
            false => bundled(name)?,
        };
        if !scenario.robots.iter().any(|r| r.route.is_some()) {
            anyhow::bail!("{name}: no robot has a `[robots.route]`");
        }
        if scenarios.iter().any(|s| s.name == scenario.name) {
            anyhow::bail!(
                "--routes: route `{}` is given twice ({name}); give each route once",
                scenario.name
            );
        }
        scenarios.push(scenario);
    }
    // (route, localizer, seed); each run's scenario is made when it starts
    let jobs: Vec<(&Scenario, RoadLocalizerKind, u64)> = scenarios
        .iter()
        .flat_map(|s| {
            RoadLocalizerKind::ALL
                .into_iter()
                .flat_map(move |kind| (0..o.runs).map(move |seed| (s, kind, seed)))
        })
        .collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = jobs.len();
    let runs = on_workers(&jobs, o.threads, |_, &(route, kind, seed)| {
        let opts = RunOptions {
            rrd: None,
            threads: 1,
            progress: false,
            trajectory_period: None,
        };
        let out = run_scenario(&with_navigator(route, kind, seed), &opts)?;
        let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if o.progress {
            eprintln!(
                "[{n}/{total}] {} by {} seed {seed}",
                route.name,
                kind.as_str()
            );
        }
        anyhow::Ok(
            out.summary
                .robots
                .iter()
                .filter_map(|r| Some((r.name.clone(), r.road.clone()?)))
                .map(|(robot, road)| ParkRun {
                    route: route.name.clone(),
                    navigate_by: kind.as_str().to_string(),
                    seed,
                    robot,
                    sim_time_s: out.summary.sim_time_s,
                    road,
                })
                .collect::<Vec<_>>(),
        )
    })?;
    let mut all = Vec::new();
    for r in runs {
        all.extend(r?);
    }
    let mut rows = Vec::new();
    for scenario in &scenarios {
        for kind in RoadLocalizerKind::ALL {
            let these: Vec<&ParkRun> = all
                .iter()
                .filter(|r| r.route == scenario.name && r.navigate_by == kind.as_str())
                .collect();
            rows.push(row(&scenario.name, kind.as_str(), o.runs, &these));
        }
    }
    Ok((rows, all))
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The row of `route` by localizer `by`: `seeds` runs, whose robots are `runs`.
fn row(route: &str, by: &str, seeds: u64, runs: &[&ParkRun]) -> ParkRow {
    let reached = runs.iter().filter(|r| r.road.reached).count() as u32;
    let mut times: Vec<f64> = runs
        .iter()
        .filter(|r| r.road.reached)
        .filter_map(|r| r.road.arrival_time_s)
        .collect();
    let loc =
        |name: &str,
         f: &dyn Fn(&crate::run::summary::road::RoadLocalizerSummary) -> Option<f64>| {
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
        runs: seeds,
        robot_runs: runs.len() as u32,
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
        "{:<18} {:<10} {:>5} {:>6} {:>8} {:>6} {:>6} {:>8} | {:>22} | {:>22} | {:>8}\n",
        "route",
        "nav by",
        "runs",
        "robot",
        "reached",
        "wrong",
        "recov",
        "median",
        "road_grid err m / wrong%",
        "road_mcl err m / wrong%",
        "off-road"
    );
    s += &format!(
        "{:<18} {:<10} {:>5} {:>6} {:>8} {:>6} {:>6} {:>8} | {:>22} | {:>22} | {:>8}\n",
        "",
        "",
        "",
        "runs",
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
            "{:<18} {:<10} {:>5} {:>6} {:>8.1} {:>6} {:>6} {:>8} | {:>6} {:>6} {:>8} | {:>6} {:>6} {:>8} | {:>8.1}\n",
            r.route,
            r.navigate_by,
            r.runs,
            r.robot_runs,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn robot_run(robot: &str, reached: bool) -> ParkRun {
        ParkRun {
            route: "three".into(),
            navigate_by: "road_grid".into(),
            seed: 0,
            robot: robot.into(),
            sim_time_s: 10.0,
            road: RoadSummary {
                goal: "g".into(),
                reached,
                arrival_time_s: reached.then_some(5.0),
                final_distance_m: None,
                planned_length_m: None,
                wrong_turns: 1,
                recoveries: 0,
                replans: 0,
                plan_failures: 0,
                junctions_left_right_compass: [0; 3],
                off_road_time_s: 0.0,
                sonar_stop_time_s: 0.0,
                navigated_by: "road_grid".into(),
                localizers: Default::default(),
            },
        }
    }

    #[test]
    fn a_row_counts_runs_as_runs_and_robots_apart() {
        // one run of a route with three robots, two of which arrive
        let runs = [
            robot_run("r1", true),
            robot_run("r2", true),
            robot_run("r3", false),
        ];
        let r = row("three", "road_grid", 1, &runs.iter().collect::<Vec<_>>());
        assert_eq!((r.runs, r.robot_runs, r.reached), (1, 3, 2));
        assert!((r.reached_percent - 200.0 / 3.0).abs() < 1e-9);
        assert_eq!(r.wrong_turns, 3);
        let table = table(&[r]);
        assert!(table.contains("robot"), "{table}");
    }
}
