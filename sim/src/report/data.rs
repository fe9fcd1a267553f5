//! What a run's report shows, as data: written beside the page as `report.json` so that
//! `sim report` draws the same page again later without the run. Paths are simplified as the
//! recording's are (1 cm, broken at jumps), error series keep each time bucket's largest error
//! (a spike stays visible), and the map keeps its occupied cells on a grid of at most
//! [`MAP_CELLS`] cells along its longer side: a report of a long run stays a few hundred kB.

use crate::formats::tum::RobotLocalization;
use crate::record::path_trace::PathTrace;
use crate::run::RunOutput;
use crate::scenario::Scenario;
use serde::{Deserialize, Serialize};
use systems::world::{Cell, OccupancyGrid};

/// The `format` of the data files `--report` writes.
pub const FORMAT: &str = "sim-report/1";
/// Largest map side in the report (cells).
pub const MAP_CELLS: usize = 400;
/// Error values per localizer at most.
pub const SERIES_POINTS: usize = 1000;

/// A run's report.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct RunReport {
    /// [`FORMAT`].
    pub format: String,
    /// The run summary (`--summary`'s JSON).
    pub summary: serde_json::Value,
    /// The map's occupied cells, if the scenario has a map.
    pub map: Option<MapCells>,
    /// Outdoors: the road network, each road as a polyline and its width (m).
    #[serde(default)]
    pub roads: Vec<RoadLine>,
    /// Each robot, in scenario order.
    pub robots: Vec<RobotTrace>,
}

/// Occupied cells of a (coarsened) map as runs along its rows.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct MapCells {
    /// World position of the grid's corner (m).
    pub origin: [f64; 2],
    /// Cell side (m).
    pub resolution: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// `[row, first column, one past the last column]` of each run of occupied cells.
    pub occupied: Vec<[u32; 3]>,
}

/// A road of the network.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct RoadLine {
    pub width: f64,
    pub points: Vec<[f32; 2]>,
}

/// One robot's paths, errors and tasks.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct RobotTrace {
    pub name: String,
    /// The true path, as strips (broken at teleports).
    pub truth: Vec<Vec<[f32; 2]>>,
    pub localizers: Vec<LocalizerTrace>,
    /// Navigation tasks, in start order.
    pub tasks: Vec<TaskSpan>,
}

/// One localizer's estimated path and position error over time.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct LocalizerTrace {
    pub name: String,
    pub path: Vec<Vec<[f32; 2]>>,
    /// `[time (s), position error (m)]`.
    pub error: Vec<[f64; 2]>,
}

/// How a task ended.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    Done,
    Failed,
    /// Still running when the run ended.
    Unfinished,
}

impl Outcome {
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Done => "done",
            Outcome::Failed => "failed",
            Outcome::Unfinished => "unfinished",
        }
    }
}

/// A navigation task from its start to its end.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct TaskSpan {
    pub task: String,
    pub start: f64,
    pub end: f64,
    pub outcome: Outcome,
}

impl RunReport {
    /// The report of `out`, a finished run of `scenario`. The true paths need
    /// `RunOptions::trajectory_period`; without it the map shows the estimates only.
    pub fn of_run(scenario: &Scenario, out: &RunOutput) -> anyhow::Result<RunReport> {
        let summary = serde_json::to_value(&out.summary)?;
        let robots = scenario
            .robots
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let mut truth = PathTrace::default();
                for (t, poses) in &out.trajectory {
                    if let Some(p) = poses.get(i) {
                        truth.push(p, *t);
                    }
                }
                let localizers = out
                    .localization
                    .iter()
                    .find(|l| l.robot == r.name)
                    .map(localizer_traces)
                    .unwrap_or_default();
                RobotTrace {
                    name: r.name.clone(),
                    truth: flat(truth.strips()),
                    localizers,
                    tasks: task_spans(&out.log, &r.name, out.summary.sim_time_s),
                }
            })
            .collect();
        let roads = scenario.roads.as_ref().map_or_else(Vec::new, |r| {
            let g = &r.graph;
            g.roads
                .iter()
                .map(|road| RoadLine {
                    width: road.width,
                    points: road
                        .nodes
                        .iter()
                        .map(|&n| [g.nodes[n].pos[0] as f32, g.nodes[n].pos[1] as f32])
                        .collect(),
                })
                .collect()
        });
        Ok(RunReport {
            format: FORMAT.to_string(),
            summary,
            map: Some(map_cells(&scenario.grid)),
            roads,
            robots,
        })
    }

    /// A report of a summary alone (`--summary`'s JSON): the tables, no figures.
    pub fn of_summary(summary: serde_json::Value) -> RunReport {
        RunReport {
            format: FORMAT.to_string(),
            summary,
            map: None,
            roads: Vec::new(),
            robots: Vec::new(),
        }
    }
}

fn flat(strips: Vec<Vec<[f32; 3]>>) -> Vec<Vec<[f32; 2]>> {
    strips
        .into_iter()
        .filter(|s| s.len() >= 2)
        .map(|s| s.into_iter().map(|p| [p[0], p[1]]).collect())
        .collect()
}

fn localizer_traces(r: &RobotLocalization) -> Vec<LocalizerTrace> {
    r.localizers
        .iter()
        .map(|(name, samples)| {
            let mut path = PathTrace::default();
            for s in samples {
                path.push(&s.estimate, s.t);
            }
            let errors: Vec<[f64; 2]> = samples.iter().map(|s| [s.t, s.position_error()]).collect();
            LocalizerTrace {
                name: name.clone(),
                path: flat(path.strips()),
                error: bucket_max(&errors, SERIES_POINTS),
            }
        })
        .collect()
}

/// At most `n` points of a time series: the series cut into `n` equal stretches of time, the
/// largest value of each at its time (all of them when there are at most `n`).
pub fn bucket_max(series: &[[f64; 2]], n: usize) -> Vec<[f64; 2]> {
    if series.len() <= n || n == 0 {
        return series.to_vec();
    }
    let (t0, t1) = (series[0][0], series[series.len() - 1][0]);
    let width = ((t1 - t0) / n as f64).max(f64::MIN_POSITIVE);
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(n);
    let mut bucket = usize::MAX;
    for &p in series {
        let b = (((p[0] - t0) / width) as usize).min(n - 1);
        match out.last_mut() {
            Some(last) if b == bucket => {
                if p[1] > last[1] {
                    *last = p;
                }
            }
            _ => {
                out.push(p);
                bucket = b;
            }
        }
    }
    out
}

/// The map coarsened to at most [`MAP_CELLS`] cells a side (a coarse cell is occupied when any
/// of its cells is), as runs of occupied cells.
pub fn map_cells(grid: &OccupancyGrid) -> MapCells {
    let factor = grid.width.max(grid.height).div_ceil(MAP_CELLS).max(1);
    let (w, h) = (grid.width.div_ceil(factor), grid.height.div_ceil(factor));
    let mut occupied = vec![false; w * h];
    for (k, c) in grid.cells.iter().enumerate() {
        if *c == Cell::Occupied {
            let (x, y) = (k % grid.width / factor, k / grid.width / factor);
            occupied[y * w + x] = true;
        }
    }
    let mut runs = Vec::new();
    for y in 0..h {
        let row = &occupied[y * w..(y + 1) * w];
        let mut x = 0;
        while x < w {
            if row[x] {
                let start = x;
                while x < w && row[x] {
                    x += 1;
                }
                runs.push([y as u32, start as u32, x as u32]);
            } else {
                x += 1;
            }
        }
    }
    MapCells {
        origin: grid.origin,
        resolution: grid.resolution * factor as f64,
        size: [w, h],
        occupied: runs,
    }
}

/// Robot `robot`'s tasks from the run's event log (the navigator's lines `task started: NAME:
/// …`, `task NAME completed`, `task NAME FAILED: …`); a task still open at `end` is unfinished.
pub fn task_spans(log: &[(f64, String, String)], robot: &str, end: f64) -> Vec<TaskSpan> {
    let mut spans: Vec<TaskSpan> = Vec::new();
    for (t, _, text) in log.iter().filter(|(_, who, _)| who == robot) {
        if let Some(rest) = text.strip_prefix("task started: ") {
            let name = rest.split(':').next().unwrap_or(rest).trim().to_string();
            spans.push(TaskSpan {
                task: name,
                start: *t,
                end,
                outcome: Outcome::Unfinished,
            });
            continue;
        }
        let Some(rest) = text.strip_prefix("task ") else {
            continue;
        };
        let ended = if let Some(name) = rest.strip_suffix(" completed") {
            Some((name, Outcome::Done))
        } else {
            rest.split_once(" FAILED")
                .map(|(name, _)| (name, Outcome::Failed))
        };
        if let Some((name, outcome)) = ended
            && let Some(span) = spans
                .iter_mut()
                .rev()
                .find(|s| s.task == name && s.outcome == Outcome::Unfinished)
        {
            span.end = *t;
            span.outcome = outcome;
        }
    }
    spans
}
