//! A world made entirely in code, with no scenario or map file: a room with a wall, boxes and a
//! pillar, and three robots with lasers and wheel encoders from presets: one wanders, two follow
//! waypoints, and one of those localizes itself with Monte Carlo localization (MCL).
//!
//! ```text
//! cargo run --release -p sim --example built_in_code [DURATION_S]
//! ```

use sim::prelude::*;
use sim::scenario::{LaserFile, LocalizerFile, LocalizerType};

/// The room's walls run along these bounds (x0, y0, x1, y1; m).
const ROOM: [f64; 4] = [0.0, 0.0, 12.0, 8.0];

/// The world: a 12 × 8 m room split by a wall with a 2 m gap, two boxes and a round pillar.
fn scenario(duration_s: f64) -> anyhow::Result<Scenario> {
    let [x0, y0, x1, y1] = ROOM;
    let scenario = Scenario::builder("built_in_code")
        .seed(1)
        .duration(duration_s)
        // the shapes are drawn into an occupancy grid of this cell size (m)
        .resolution(0.05)
        .room([x0, y0], [x1, y1])
        .wall([6.0, 0.0], [6.0, 3.0]) // the dividing wall, open from y = 3 to 5
        .wall([6.0, 5.0], [6.0, 8.0])
        .box_shape([2.5, 6.0], [1.2, 0.8])
        .box_shape([9.5, 2.0], [0.8, 0.8])
        .disc([9.0, 6.0], 0.3)
        // wanders at random, turning away from what its laser sees
        .robot(
            RobotConfig::builder("wanderer", [2.0, 2.0, 0.0])
                .circle(0.25)
                .laser(LaserFile::preset("hokuyo_urg04lx"))
                .encoder(Default::default())
                .wander()
                .speed(0.5),
        )
        // patrols both halves through the gap, localizing itself with MCL on the room's map
        .robot(
            RobotConfig::builder("patrol", [3.0, 4.0, 0.0])
                .circle(0.25)
                .laser(LaserFile::preset("sick_lms100"))
                .encoder(Default::default())
                .localizer(LocalizerFile {
                    max_particles: Some(1000),
                    ..LocalizerFile::of_type(LocalizerType::Mcl)
                })
                .waypoints([[9.0, 4.0], [10.5, 6.5], [3.0, 4.0], [1.5, 1.5]], true)
                .speed(0.6),
        )
        // shuttles up and down the east half
        .robot(
            RobotConfig::builder("shuttle", [11.0, 1.0, 1.57])
                .circle(0.25)
                .laser(LaserFile::preset("hokuyo_urg04lx"))
                .encoder(Default::default())
                .waypoints([[11.0, 7.0], [11.0, 1.0]], true)
                .speed(0.4),
        )
        .build()?;
    Ok(scenario)
}

/// One robot at the end of the run.
#[derive(Debug)]
struct RobotReport {
    name: String,
    pose: Pose2,
    distance_m: f64,
    collisions: u32,
    /// Distance between the MCL estimate and the true position (m), for the robot with MCL.
    mcl_error_m: Option<f64>,
}

/// Runs the world for `duration_s` simulated seconds and reports every robot.
fn run(duration_s: f64) -> anyhow::Result<Vec<RobotReport>> {
    let mut sim = Simulation::from_scenario(scenario(duration_s)?).build()?;
    sim.run_for(duration_s)?;
    let reports = sim
        .robots()
        .iter()
        .map(|r| {
            let pose = r.pose();
            // the localizer's latest estimate against the ground truth (robots without MCL
            // have none)
            let mcl_error_m = r
                .localizer("mcl")
                .ok()
                .and_then(|l| l.estimate)
                .map(|e| (e.pose.x - pose.x).hypot(e.pose.y - pose.y));
            RobotReport {
                name: r.name().to_string(),
                pose,
                distance_m: r.distance(),
                collisions: r.collisions().total(),
                mcl_error_m,
            }
        })
        .collect();
    // ends the run: estimators and any recordings are finished
    sim.finish()?;
    Ok(reports)
}

fn main() -> anyhow::Result<()> {
    // optional argument: the simulated seconds to run
    let duration_s = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 120.0,
    };
    for r in run(duration_s)? {
        let mcl = r
            .mcl_error_m
            .map_or(String::new(), |e| format!(", MCL error {e:.3} m"));
        println!(
            "{:<8} at ({:.2}, {:.2}): {:.1} m driven, {} collisions{mcl}",
            r.name, r.pose.x, r.pose.y, r.distance_m, r.collisions
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_world_built_in_code_runs_and_its_robots_move() {
        let reports = run(60.0).unwrap();
        assert_eq!(reports.len(), 3);
        let [x0, y0, x1, y1] = ROOM;
        for r in &reports {
            assert!(r.distance_m > 5.0, "{r:?} hardly moved");
            let p = r.pose;
            assert!(
                p.x > x0 && p.x < x1 && p.y > y0 && p.y < y1,
                "{r:?} left the room"
            );
        }
        // MCL tracks the patrol robot to within 0.3 m
        let patrol = reports.iter().find(|r| r.name == "patrol").unwrap();
        let error = patrol.mcl_error_m.expect("patrol has an MCL estimate");
        assert!(error < 0.3, "{patrol:?}");
    }
}
