//! The run summary: printed as a table and written as JSON with `--summary`.

pub mod collect;
pub mod road;

use serde::Serialize;
use std::collections::BTreeMap;
use systems::eval::LocalizerMetrics;

/// A run's results, as `--summary` writes them.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct Summary {
    /// The scenario's name.
    pub scenario: String,
    /// The run's seed.
    pub seed: u64,
    /// Simulated time run (s).
    pub sim_time_s: f64,
    /// Wall-clock time from the first tick to the last (s).
    pub wall_time_s: f64,
    /// Simulated over wall-clock time.
    pub real_time_factor: f64,
    /// Each robot, in scenario order.
    pub robots: Vec<RobotSummary>,
    /// What the run cost in wall-clock time, part by part.
    pub timing: Timing,
}

/// Wall-clock measurements of a run. Like `wall_time_s` they describe the machine, not the run:
/// `deterministic_part` clears them.
#[derive(Serialize, Clone, Debug, Default, PartialEq)]
pub struct Timing {
    /// Each localizer's cost per update, robot by robot in scenario order.
    pub localizers: Vec<LocalizerTiming>,
}

/// One localizer's cost per update (one update = one scan consumed).
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct LocalizerTiming {
    /// The robot's name.
    pub robot: String,
    /// The localizer's name.
    pub localizer: String,
    /// Its type.
    pub kind: String,
    /// Scans consumed.
    pub updates: u64,
    /// Their total wall-clock time (s).
    pub total_s: f64,
    /// Mean per update (µs).
    pub mean_update_us: f64,
    /// The dearest update (µs).
    pub max_update_us: f64,
}

/// One robot's results.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct RobotSummary {
    /// The robot's name.
    pub name: String,
    /// Ground-truth distance driven (m).
    pub distance_m: f64,
    /// Contact starts with walls, other robots and walking people.
    pub collisions: u32,
    /// Of those, with walls.
    pub wall_collisions: u32,
    /// Of those, with other robots.
    pub robot_collisions: u32,
    /// Of those, with walking people.
    pub person_collisions: u32,
    /// Final wheel-odometry position error (m).
    pub odometry_drift_m: f64,
    /// Largest wheel-odometry position error during the run (m).
    pub max_odometry_drift_m: f64,
    /// RMSE of the wheel odometry's position error over the run (its ATE, m).
    pub odometry_ate_m: f64,
    /// Final drift per distance driven (%).
    pub odometry_drift_percent: f64,
    /// Final wheel-odometry heading error (rad).
    pub odometry_heading_error_rad: f64,
    /// Waypoints of its route reached (counted again on each loop).
    pub waypoints_reached: u32,
    /// The robot's route ended at its goal: the last waypoint of a waypoint route, or the goal
    /// node of a road route.
    pub route_completed: bool,
    /// Final true pose [x, y, yaw].
    pub final_pose: [f64; 3],
    /// Accuracy of each localizer, by name.
    pub localization: BTreeMap<String, LocalizerMetrics>,
    /// Task-driven navigation outcomes (robots with tasks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub navigation: Option<NavigationSummary>,
    /// Outdoor drive on the road network (robots with a route only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub road: Option<crate::run::summary::road::RoadSummary>,
}

/// A navigating robot's tasks and how they went.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct NavigationSummary {
    /// Tasks given (at the start and by events or commands).
    pub tasks: u32,
    /// Tasks done.
    pub tasks_completed: u32,
    /// Tasks given up.
    pub tasks_failed: u32,
    /// Every task done or failed.
    pub all_tasks_done: bool,
    /// Delivery tasks done.
    pub deliveries_completed: u32,
    /// Each completed delivery, from taking the task to the end of unloading (s).
    pub delivery_times_s: Vec<f64>,
    /// Their mean (s); None without a completed delivery.
    pub mean_delivery_time_s: Option<f64>,
    /// Legs (drives to a goal) completed.
    pub legs: u32,
    /// True distance driven on those legs (m) ...
    pub path_length_m: f64,
    /// ... against the A* optimum from the true start of each leg (m) ...
    pub optimal_length_m: f64,
    /// ... and their ratio.
    pub path_ratio: Option<f64>,
    /// Contact starts with walls and with other robots during the run.
    pub collisions: u32,
    /// Of those, with walls.
    pub wall_collisions: u32,
    /// Stops for obstacles.
    pub stops: u32,
    /// Time spent stopped or waiting aside (s).
    pub waiting_time_s: f64,
    /// Routes planned again (a blocked path, a door closed, a robot in the way).
    pub replans: u32,
    /// Times the robot gave way to another robot.
    pub yields: u32,
    /// Each failed task, with why.
    pub failures: Vec<NavigationFailure>,
}

/// A task given up.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct NavigationFailure {
    /// When (simulated s).
    pub time_s: f64,
    /// The task's name.
    pub task: String,
    /// Why.
    pub reason: String,
}

impl Summary {
    /// The summary without its wall-clock fields (the part determinism guarantees).
    pub fn deterministic_part(&self) -> Summary {
        Summary {
            wall_time_s: 0.0,
            real_time_factor: 0.0,
            timing: Timing::default(),
            ..self.clone()
        }
    }

    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "scenario {}  seed {}  simulated {:.1} s in {:.2} s ({:.1}× real time)\n",
            self.scenario, self.seed, self.sim_time_s, self.wall_time_s, self.real_time_factor
        );
        s += &format!(
            "{:<16} {:>11} {:>10} {:>6} {:>7} {:>7} {:>13} {:>8} {:>10}\n",
            "robot",
            "distance m",
            "collisions",
            "walls",
            "robots",
            "people",
            "odom drift m",
            "drift %",
            "waypoints"
        );
        for r in &self.robots {
            s += &format!(
                "{:<16} {:>11.2} {:>10} {:>6} {:>7} {:>7} {:>13.3} {:>8.2} {:>10}\n",
                r.name,
                r.distance_m,
                r.collisions,
                r.wall_collisions,
                r.robot_collisions,
                r.person_collisions,
                r.odometry_drift_m,
                r.odometry_drift_percent,
                r.waypoints_reached
            );
        }
        let with_nav: Vec<(&str, &NavigationSummary)> = self
            .robots
            .iter()
            .filter_map(|r| r.navigation.as_ref().map(|n| (r.name.as_str(), n)))
            .collect();
        if !with_nav.is_empty() {
            s += &format!(
                "\n{:<16} {:>7} {:>6} {:>11} {:>10} {:>9} {:>7} {:>6} {:>9} {:>8} {:>7}\n",
                "robot",
                "tasks",
                "failed",
                "deliveries",
                "mean s",
                "path m",
                "ratio",
                "stops",
                "waited s",
                "replans",
                "yields"
            );
            for (name, n) in &with_nav {
                s += &format!(
                    "{:<16} {:>7} {:>6} {:>11} {:>10} {:>9.1} {:>7} {:>6} {:>9.1} {:>8} {:>7}\n",
                    name,
                    format!("{}/{}", n.tasks_completed, n.tasks),
                    n.tasks_failed,
                    n.deliveries_completed,
                    n.mean_delivery_time_s
                        .map_or("-".to_string(), |v| format!("{v:.1}")),
                    n.path_length_m,
                    n.path_ratio.map_or("-".to_string(), |v| format!("{v:.3}")),
                    n.stops,
                    n.waiting_time_s,
                    n.replans,
                    n.yields
                );
                for f in &n.failures {
                    s += &format!(
                        "  {name}: task {} failed at {:.1} s: {}\n",
                        f.task, f.time_s, f.reason
                    );
                }
            }
        }
        let with_loc: Vec<&RobotSummary> = self
            .robots
            .iter()
            .filter(|r| !r.localization.is_empty())
            .collect();
        if !with_loc.is_empty() {
            s += &format!(
                "\n{:<16} {:<14} {:>9} {:>10} {:>10} {:>12} {:>11} {:>9} {:>10}\n",
                "robot",
                "localizer",
                "estimates",
                "ATE m",
                "RPE m",
                "RPE rad",
                "converged s",
                "tracked %",
                "µs/update"
            );
            let opt = |v: Option<f64>, prec: usize| match v {
                Some(v) => format!("{v:.prec$}"),
                None => "-".to_string(),
            };
            for r in with_loc {
                for (name, m) in &r.localization {
                    let cost = self
                        .timing
                        .localizers
                        .iter()
                        .find(|t| t.robot == r.name && t.localizer == *name)
                        .filter(|t| t.updates > 0)
                        .map(|t| t.mean_update_us);
                    s += &format!(
                        "{:<16} {:<14} {:>9} {:>10} {:>10} {:>12} {:>11} {:>9} {:>10}\n",
                        r.name,
                        name,
                        m.estimates,
                        opt(m.headline_ate(), 3),
                        opt(m.rpe_trans_m, 4),
                        opt(m.rpe_rot_rad, 4),
                        opt(m.converged_after_s, 1),
                        opt(m.tracked_fraction.map(|f| 100.0 * f), 1),
                        opt(cost, 0),
                    );
                }
            }
            s += "ATE: in the map frame for localizers in the map, aligned at the first pose for \
                  odometry and SLAM; µs/update: wall-clock cost of one scan\n";
        }
        s
    }
}
