//! `sim bench swarm`: real-time factor and rays/s for swarms of wandering robots, each with a
//! laser at 10 Hz, on the hospital map tiled 4 × 4 (so the swarm does not jam). Two lasers: Stage's
//! benchmark ranger (180 beams over 180°, 8 m) and a SICK LMS100 (1081 beams over 270°, 20 m).

use crate::scenario::resolve::default_diff_drive;
use crate::scenario::{RecordConfig, RobotConfig, Scenario, assets_dir};
use crate::{RunOptions, run_scenario};
use rand::RngExt;
use serde::Serialize;
use std::collections::BTreeMap;
use systems::body::{Footprint, Kinematics};
use systems::core::{Pose2, stream_rng};
use systems::navigation::BehaviourKind;
use systems::sensors::LaserSpec;
use systems::world::{OccupancyGrid, load_map};

pub struct SwarmOptions {
    pub json: bool,
    pub robots: Vec<usize>,
    pub beams: Vec<usize>,
    pub duration: f64,
    pub threads: usize,
}

#[derive(Serialize)]
struct SwarmResult {
    bench: &'static str,
    robots: usize,
    beams: usize,
    fov_deg: f64,
    max_range_m: f64,
    laser_rate_hz: f64,
    dt_s: f64,
    threads: usize,
    sim_time_s: f64,
    wall_time_s: f64,
    real_time_factor: f64,
    rays_per_s: f64,
    map: String,
}

/// The laser of a swarm robot with `beams` beams at 10 Hz.
pub fn swarm_laser(beams: usize) -> LaserSpec {
    let mut spec = if beams == 1081 {
        LaserSpec::sick_lms100()
    } else {
        LaserSpec {
            fov: std::f64::consts::PI,
            increment: std::f64::consts::PI / (beams.max(2) - 1) as f64,
            min_range: 0.1,
            max_range: 8.0,
            rate: 10.0,
            noise_std: 0.01,
            dropout: 0.0,
            mount: Pose2::IDENTITY,
        }
    };
    if beams != 1081 {
        spec.increment = spec.fov / (beams.max(2) - 1) as f64;
    }
    spec.rate = 10.0;
    spec
}

/// A swarm scenario: `n` wandering robots at random free places of `grid`.
pub fn swarm_scenario(grid: &OccupancyGrid, n: usize, beams: usize, duration: f64) -> Scenario {
    let mut rng = stream_rng(0, "swarm", "placement");
    let b = grid.bounds();
    let mut robots: Vec<RobotConfig> = Vec::with_capacity(n);
    let mut tries = 0;
    while robots.len() < n && tries < n * 10_000 {
        tries += 1;
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        if !grid.disc_is_clear(x, y, 0.6) || grid.cell_of(x, y).is_none() {
            continue;
        }
        let (c, r) = grid.cell_of(x, y).unwrap_or((0, 0));
        if grid.get(c, r) != systems::world::Cell::Free {
            continue;
        }
        if robots
            .iter()
            .any(|o| o.start.distance(&Pose2::new(x, y, 0.0)) < 1.5)
        {
            continue;
        }
        let theta = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        robots.push(RobotConfig {
            name: format!("r{:04}", robots.len()),
            start: Pose2::new(x, y, theta),
            footprint: Footprint::Circle { radius: 0.25 },
            kinematics: Kinematics::DiffDrive(default_diff_drive()),
            behaviour: BehaviourKind::Wander,
            speed: 0.8,
            tolerance: 0.4,
            laser: Some(swarm_laser(beams)),
            encoder: None,
            sonar: None,
            localizers: Vec::new(),
            navigation: None,
            gps: None,
            compass: None,
            camera: None,
            route: None,
        });
    }
    Scenario {
        name: format!("swarm-{n}-{beams}"),
        description: "benchmark swarm".into(),
        seed: 0,
        dt: 0.05,
        duration,
        source: "sim bench swarm".into(),
        grid: grid.clone(),
        places: BTreeMap::new(),
        record: RecordConfig::default(),
        robots,
        events: Vec::new(),
        doors: Vec::new(),
        end_when_done: false,
        people: Vec::new(),
        roads: None,
        zones: Vec::new(),
    }
}

/// The benchmark world: the hospital tiled 4 × 4.
pub fn swarm_world() -> anyhow::Result<OccupancyGrid> {
    let path = assets_dir().join("maps/hospital/hospital.yaml");
    let g = load_map(&path)?;
    Ok(g.tiled(4, 4))
}

pub fn run_swarm_bench(o: &SwarmOptions) -> anyhow::Result<()> {
    let grid = swarm_world()?;
    let b = grid.bounds();
    let map = format!(
        "hospital tiled 4x4 ({:.0} x {:.0} m)",
        b[2] - b[0],
        b[3] - b[1]
    );
    if !o.json {
        println!("swarm benchmark on {map}, lasers at 10 Hz, dt 0.05 s");
        println!("machine: {}", crate::machine::describe());
        println!(
            "{:>7} {:>6} {:>9} {:>10} {:>12} {:>14}",
            "robots", "beams", "sim s", "wall s", "× real time", "rays/s"
        );
    }
    for &beams in &o.beams {
        for &n in &o.robots {
            let sc = swarm_scenario(&grid, n, beams, o.duration);
            let spec = swarm_laser(beams);
            let out = run_scenario(
                &sc,
                &RunOptions {
                    rrd: None,
                    threads: o.threads,
                    progress: false,
                    trajectory_period: None,
                },
            )?;
            let s = &out.summary;
            let scans_per_robot = (s.sim_time_s * spec.rate + 1e-9).floor() + 1.0;
            let rays = sc.robots.len() as f64 * scans_per_robot * spec.beams() as f64;
            let threads = if o.threads == 0 {
                std::thread::available_parallelism().map_or(1, |n| n.get())
            } else {
                o.threads
            };
            let r = SwarmResult {
                bench: "swarm",
                robots: sc.robots.len(),
                beams: spec.beams(),
                fov_deg: spec.fov.to_degrees(),
                max_range_m: spec.max_range,
                laser_rate_hz: spec.rate,
                dt_s: sc.dt,
                threads,
                sim_time_s: s.sim_time_s,
                wall_time_s: s.wall_time_s,
                real_time_factor: s.real_time_factor,
                rays_per_s: rays / s.wall_time_s.max(1e-9),
                map: map.clone(),
            };
            if o.json {
                println!("{}", crate::machine::json_line(&r)?);
            } else {
                println!(
                    "{:>7} {:>6} {:>9.1} {:>10.2} {:>12.1} {:>14.3e}",
                    r.robots,
                    r.beams,
                    r.sim_time_s,
                    r.wall_time_s,
                    r.real_time_factor,
                    r.rays_per_s
                );
            }
        }
    }
    Ok(())
}
