//! The run summary: printed as a table and written as JSON with `--summary`.

use serde::Serialize;
use std::collections::BTreeMap;
use systems::eval::LocalizerMetrics;

#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct Summary {
    pub scenario: String,
    pub seed: u64,
    pub sim_time_s: f64,
    pub wall_time_s: f64,
    pub real_time_factor: f64,
    pub robots: Vec<RobotSummary>,
}

#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct RobotSummary {
    pub name: String,
    /// Ground-truth distance driven (m).
    pub distance_m: f64,
    /// Contact starts with walls, other robots and walking people.
    pub collisions: u32,
    pub wall_collisions: u32,
    pub robot_collisions: u32,
    pub person_collisions: u32,
    /// Final wheel-odometry position error (m).
    pub odometry_drift_m: f64,
    pub max_odometry_drift_m: f64,
    /// Final drift per distance driven (%).
    pub odometry_drift_percent: f64,
    pub odometry_heading_error_rad: f64,
    pub waypoints_reached: u32,
    pub route_completed: bool,
    /// Final true pose [x, y, yaw].
    pub final_pose: [f64; 3],
    /// Accuracy of each localizer, by name.
    pub localization: BTreeMap<String, LocalizerMetrics>,
}

impl Summary {
    /// The summary without its wall-clock fields (the part determinism guarantees).
    pub fn deterministic_part(&self) -> Summary {
        Summary {
            wall_time_s: 0.0,
            real_time_factor: 0.0,
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
        let with_loc: Vec<&RobotSummary> = self
            .robots
            .iter()
            .filter(|r| !r.localization.is_empty())
            .collect();
        if !with_loc.is_empty() {
            s += &format!(
                "\n{:<16} {:<14} {:>9} {:>10} {:>10} {:>12} {:>11} {:>9}\n",
                "robot",
                "localizer",
                "estimates",
                "ATE m",
                "RPE m",
                "RPE rad",
                "converged s",
                "tracked %"
            );
            let opt = |v: Option<f64>, prec: usize| match v {
                Some(v) => format!("{v:.prec$}"),
                None => "-".to_string(),
            };
            for r in with_loc {
                for (name, m) in &r.localization {
                    s += &format!(
                        "{:<16} {:<14} {:>9} {:>10} {:>10} {:>12} {:>11} {:>9}\n",
                        r.name,
                        name,
                        m.estimates,
                        opt(m.ate_rmse_m, 3),
                        opt(m.rpe_trans_m, 4),
                        opt(m.rpe_rot_rad, 4),
                        opt(m.converged_after_s, 1),
                        opt(m.tracked_fraction.map(|f| 100.0 * f), 1),
                    );
                }
            }
        }
        s
    }
}
