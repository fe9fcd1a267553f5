//! A localizer of your own beside ours: a scan-fitting tracker (dead reckoning from the wheel
//! odometry, corrected at each update by a small grid search for the pose whose scan endpoints
//! lie closest to the map's walls) runs on the maze robot next to our MCL, on the same scans,
//! odometry and map, and both are judged by the same summary (ATE, final error).
//!
//! `cargo run --release -p sim --example custom_localizer [SECONDS]`

use sim::prelude::*;
use sim::scenario::find_scenario;
use std::any::Any;
use systems::localization::{BeamSubset, LocalizationMap};

/// The user's localizer: written against `MapLocalizer` only.
#[derive(Clone, Debug)]
struct ScanFit {
    pose: Pose2,
    last_odom: Option<Pose2>,
    estimate: Option<PoseEstimate>,
}

impl MapLocalizer for ScanFit {
    fn kind(&self) -> &'static str {
        "scan_fit"
    }

    /// 60 beams of each scan are plenty for a grid search.
    fn max_beams(&self) -> usize {
        60
    }

    /// Moves the pose by the odometry's motion since the last update; skips scans until the
    /// robot has moved 10 cm or turned 0.1 rad.
    fn predict(&mut self, odom: &Pose2) -> bool {
        if let Some(last) = self.last_odom {
            let d = last.between(odom);
            if d.x.hypot(d.y) < 0.1 && d.theta.abs() < 0.1 {
                return false;
            }
            self.pose = self.pose.compose(&d);
        }
        self.last_odom = Some(*odom);
        true
    }

    /// Tries the poses around the prediction (±10 cm, ±0.04 rad) and keeps the one whose scan
    /// endpoints are nearest the walls on average.
    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool {
        let points = beams.returns();
        if points.is_empty() {
            return false;
        }
        let misfit = |p: &Pose2| {
            let sum: f64 = points
                .iter()
                .map(|q| {
                    let w = p.transform_point([q[0] as f64, q[1] as f64]);
                    map.field.distance(w[0], w[1])
                })
                .sum();
            sum / points.len() as f64
        };
        let mut best = (self.pose, misfit(&self.pose));
        for i in -2..=2 {
            for j in -2..=2 {
                for k in -2..=2 {
                    let step = Pose2::new(0.05 * i as f64, 0.05 * j as f64, 0.02 * k as f64);
                    let p = self.pose.compose(&step);
                    let m = misfit(&p);
                    if m < best.1 {
                        best = (p, m);
                    }
                }
            }
        }
        self.pose = best.0;
        // a grid search of 5 cm and 0.02 rad steps: about a step's spread
        self.estimate = Some(PoseEstimate {
            pose: self.pose,
            covariance: [[0.0025, 0.0, 0.0], [0.0, 0.0025, 0.0], [0.0, 0.0, 0.0004]],
            weight: 1.0,
        });
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn box_clone(&self) -> Box<dyn MapLocalizer> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// Each localizer's ATE and final error (m), by name.
#[derive(Debug)]
struct Report {
    seconds: f64,
    results: Vec<(String, Option<f64>, Option<f64>)>,
}

fn run(seconds: f64) -> anyhow::Result<Report> {
    // the bundled maze run, with our MCL tracking from the known start added to its robot
    let path = find_scenario("maze_run")?;
    let text = std::fs::read_to_string(&path)?
        + "\n[[robots.localization]]\ntype = \"mcl\"\ninit = \"pose\"\n";
    let builder = Simulation::from_toml(&text, "maze_run + mcl")
        .relative_to(path.parent().unwrap_or(std::path::Path::new(".")))
        .duration(seconds);
    let start = builder.scenario()?.robots[0].start;
    let mine = ScanFit {
        pose: start,
        last_odom: None,
        estimate: None,
    };
    let done = builder
        .localizer("scout", "scan_fit", mine)
        .build()?
        .run()?;
    let scout = &done.summary.robots[0];
    Ok(Report {
        seconds: done.summary.sim_time_s,
        results: scout
            .localization
            .iter()
            .map(|(name, m)| (name.clone(), m.ate_rmse_m, m.final_error_m))
            .collect(),
    })
}

fn main() -> anyhow::Result<()> {
    let seconds = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 200.0,
    };
    let r = run(seconds)?;
    println!("after {:.0} s of the maze:", r.seconds);
    for (name, ate, last) in &r.results {
        println!("  {name:9} ATE {ate:?} m, final error {last:?} m");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_users_localizer_tracks_within_10_cm_beside_mcl() {
        let r = run(60.0).unwrap();
        let of = |name: &str| r.results.iter().find(|x| x.0 == name).unwrap().clone();
        // the bound: ATE and final error under 10 cm over the first minute of the maze
        let (_, ate, last) = of("scan_fit");
        assert!(ate.unwrap() < 0.1 && last.unwrap() < 0.1, "{r:?}");
        // our MCL, judged the same way in the same run, stays within half a metre
        let (_, mcl_ate, _) = of("mcl");
        assert!(mcl_ate.unwrap() < 0.5, "{r:?}");
    }
}
