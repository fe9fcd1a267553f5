//! The facade's tests, by what they check: the builder and stepping, scripted commands against
//! the same events in the scenario file, resets and kernel pools, a program's own systems.
//! Shared here: the scenarios they start from and what a run leaves behind.

mod builder;
mod commands;
mod extension;
mod reset;

use super::*;
use crate::run::{Command, RunOptions, Target, run_scenario};
use crate::scenario::{SensorName, assets_dir, find_scenario};
use systems::core::Pose2;
use systems::core::pool::KernelPool;

/// hospital_patrol's file without its own events (they start at 40 s anyway).
fn patrol_text() -> String {
    let text = std::fs::read_to_string(find_scenario("hospital_patrol").unwrap()).unwrap();
    let cut = text.find("# --- events").expect("the events section");
    text[..cut].to_string()
}

/// Scenario TOML whose relative paths are those of the bundled scenarios.
fn from_text(text: &str, label: &str) -> SimulationBuilder {
    Simulation::from_toml(text, label).relative_to(assets_dir().join("scenarios"))
}

/// What a run leaves that must not depend on how its events were given: the summary (wall
/// time aside), every robot's true pose, odometry and localizer estimates, the event log.
fn fingerprint(s: &mut Simulation) -> String {
    let mut out = String::new();
    for r in s.robots() {
        let locs: Vec<_> = r.localizers().iter().map(|l| l.estimate).collect();
        out += &format!(
            "{} {:?} {:?} {:?}\n",
            r.name(),
            r.pose(),
            r.odometry(),
            locs
        );
    }
    out
}

fn summary_json(done: &Finished) -> String {
    let v = serde_json::to_value(done.summary.deterministic_part()).unwrap();
    format!("{v}\n{:?}", done.log)
}

/// One navigating robot in the hospital, on a trip to the west corridor.
const COURIER: &str = r#"
name = "courier"
seed = 5
duration = 20.0
[map]
file = "../maps/hospital/hospital.yaml"
places = "../maps/hospital/places.toml"
[[robots]]
name = "r1"
start = "charger_1"
footprint = { circle = 0.3 }
navigation = { speed = 0.8 }
[robots.sensors.laser]
preset = "sick_lms100"
[robots.sensors.encoder]
[[robots.tasks]]
type = "go"
to = "corridor_main_w"
"#;

fn navigation_fingerprint(s: &mut Simulation) -> String {
    let r = s.robot("r1").unwrap();
    let n = r.navigation().unwrap();
    let nav = format!("{} {} {}", n.tasks(), n.tasks_done(), n.status());
    format!("{}{nav}", fingerprint(s))
}
