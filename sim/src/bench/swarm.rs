//! `sim bench swarm`: real-time factor and rays/s for swarms of wandering robots, each with a
//! laser at 10 Hz, on the hospital map tiled 4 × 4 (so the swarm does not jam), or, with
//! `--per-hospital`, tiled with the robot count so the density stays constant. Two lasers:
//! Stage's benchmark ranger (180 beams over 180°, 8 m) and a SICK LMS100 (1081 beams over 270°,
//! 20 m).

use crate::options::check_duration;
use crate::scenario::localizers::{LocalizerConfig, LocalizerKind};
use crate::scenario::resolve::default_diff_drive;
use crate::scenario::{RecordConfig, RobotConfig, Scenario, assets_dir};
use crate::{RunOptions, run_scenario};
use rand::RngExt;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use systems::body::{Footprint, Kinematics};
use systems::core::{Pose2, stream_rng};
use systems::localization::MclConfig;
use systems::localization::mcl::InitialBelief;
use systems::navigation::BehaviourKind;
use systems::sensors::{EncoderSpec, LaserSpec};
use systems::world::{Cell, OccupancyGrid, load_map};

/// `sim bench swarm`: real-time factor and rays/s for swarms of wandering robots with lasers at
/// 10 Hz.
#[derive(clap::Args, Clone, Debug)]
pub struct SwarmOptions {
    /// One JSON object per population and laser, one per line.
    #[arg(long)]
    pub json: bool,
    /// Populations to run.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [1usize, 10, 100, 1000])]
    pub robots: Vec<usize>,
    /// Beams per scan.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [180usize, 1081])]
    pub beams: Vec<usize>,
    /// Simulated seconds per configuration (default: 4000 s divided by the robot count, at
    /// least 10 s, a tenth of that with `--mcl`: about a second of wall time for every
    /// population, where 10 s of one robot take a few milliseconds, too short to time).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Worker threads (0 = one per core; at most 1024).
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Step the world's schedule directly instead of through the library facade
    /// (`sim::Simulation`, which `sim run` uses): measures what the facade costs.
    #[arg(long)]
    pub direct: bool,
    /// Every robot also localizes with MCL on its laser and wheel encoders, starting around
    /// its true pose, with ROS AMCL's parameter defaults (`amcl`, the default: 100 to 5000
    /// particles, 30 beams, resampling every second update) or sim's (`sim`: 500 to 5000
    /// particles, 60 beams, the scan proposal and its challenge).
    #[arg(long, num_args = 0..=1, default_missing_value = "amcl", value_name = "DEFAULTS")]
    pub mcl: Option<MclDefaults>,
    /// Constant density: each population gets the hospital tiled k × k, k = ⌈√(robots / N)⌉,
    /// so every copy of the hospital holds about N robots (exactly N when robots / N is a
    /// square), instead of one 4 × 4 map for all. The cost per robot-step should then not grow
    /// with the robot count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=400))]
    pub per_hospital: Option<u64>,
}

/// Whose parameter defaults the benchmark's MCL takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MclDefaults {
    /// ROS AMCL's ([`MclConfig::amcl`]).
    Amcl,
    /// sim's own ([`MclConfig::default`]).
    Sim,
}

impl MclDefaults {
    pub fn config(self) -> MclConfig {
        match self {
            MclDefaults::Amcl => MclConfig::amcl(),
            MclDefaults::Sim => MclConfig::default(),
        }
    }

    /// The benchmark row's `localizer`.
    pub fn label(self) -> &'static str {
        match self {
            MclDefaults::Amcl => "mcl-amcl",
            MclDefaults::Sim => "mcl-sim",
        }
    }
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
    /// "facade" (as `sim run`) or "schedule" (`--direct`).
    stepped_by: &'static str,
    /// "mcl-amcl" or "mcl-sim" with `--mcl`, else "none".
    localizer: &'static str,
    sim_time_s: f64,
    wall_time_s: f64,
    real_time_factor: f64,
    rays_per_s: f64,
    /// Wall time per robot and tick (µs).
    us_per_robot_step: f64,
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

/// Least distance between two robots' starting points (m).
const SPACING: f64 = 1.5;
/// Placement gives up after this many random draws in a row that found no room.
const MAX_MISSES: usize = 100_000;

/// A swarm scenario: `n` wandering robots at random free places of `grid`, at least
/// `SPACING` apart; an error if they do not fit.
pub fn swarm_scenario(
    grid: &OccupancyGrid,
    n: usize,
    beams: usize,
    duration: f64,
) -> anyhow::Result<Scenario> {
    // a robot needs more than a square metre of free floor (discs of SPACING / 2 packed at best)
    let free_m2 = grid.cells.iter().filter(|c| **c == Cell::Free).count() as f64
        * grid.resolution
        * grid.resolution;
    if n as f64 > free_m2 {
        anyhow::bail!(
            "--robots {n}: the swarm map has {free_m2:.0} m² of free floor, and robots \
             {SPACING} m apart need more than 1 m² each"
        );
    }
    let mut rng = stream_rng(0, "swarm", "placement");
    let b = grid.bounds();
    let mut robots: Vec<RobotConfig> = Vec::with_capacity(n);
    // robots by SPACING-sized bucket, so the spacing test looks at 3 × 3 buckets
    let mut buckets: HashMap<(i64, i64), Vec<Pose2>> = HashMap::new();
    let bucket = |x: f64, y: f64| ((x / SPACING).floor() as i64, (y / SPACING).floor() as i64);
    let mut misses = 0;
    while robots.len() < n {
        if misses == MAX_MISSES {
            anyhow::bail!(
                "--robots {n}: only {} robots fit on the swarm map {SPACING} m apart \
                 ({MAX_MISSES} random places in a row found no room)",
                robots.len()
            );
        }
        misses += 1;
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        let Some((c, r)) = grid.cell_of(x, y) else {
            continue;
        };
        if !grid.disc_is_clear(x, y, 0.6) || grid.get(c, r) != Cell::Free {
            continue;
        }
        let here = Pose2::new(x, y, 0.0);
        let (bx, by) = bucket(x, y);
        let crowded = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                buckets
                    .get(&(bx + dx, by + dy))
                    .is_some_and(|v| v.iter().any(|o| o.distance(&here) < SPACING))
            })
        });
        if crowded {
            continue;
        }
        misses = 0;
        buckets.entry((bx, by)).or_default().push(here);
        let theta = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        robots.push(RobotConfig {
            name: format!("r{:04}", robots.len()),
            start: Pose2::new(x, y, theta),
            footprint: Footprint::Circle { radius: 0.25 },
            kinematics: Kinematics::DiffDrive(default_diff_drive()),
            behaviour: BehaviourKind::Wander,
            behaviour_localizer: None,
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
    Ok(Scenario {
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
    })
}

/// Gives every robot of `sc` wheel encoders and an MCL localizer with AMCL's defaults (500 to
/// 5000 particles with KLD sampling, likelihood field, 60 beams, updates after 0.2 m or 30°),
/// its particles drawn around the robot's start with AMCL's default initial spread (0.5 m, and
/// π/12 in heading): a one-robot world with a working localizer, as AMCL users run it.
pub fn localize_with_mcl(sc: &mut Scenario, defaults: MclDefaults) {
    for r in &mut sc.robots {
        r.encoder = Some(EncoderSpec::default());
        r.localizers = vec![LocalizerConfig {
            name: "mcl".into(),
            kind: LocalizerKind::Mcl(MclConfig {
                init: InitialBelief::Gaussian {
                    pose: r.start,
                    sd: [0.5, 0.5, std::f64::consts::PI / 12.0],
                },
                ..defaults.config()
            }),
        }];
    }
}

/// A `--beams` value: 2 to [`LaserSpec::MAX_BEAMS`] beams per scan.
pub fn check_beams(beams: usize) -> anyhow::Result<()> {
    let max = LaserSpec::MAX_BEAMS;
    if !(2..=max).contains(&beams) {
        anyhow::bail!("--beams: expected 2 to {max} beams per scan, got {beams}");
    }
    Ok(())
}

/// The benchmark world: the hospital tiled 4 × 4.
pub fn swarm_world() -> anyhow::Result<OccupancyGrid> {
    Ok(hospital()?.tiled(4, 4))
}

fn hospital() -> anyhow::Result<OccupancyGrid> {
    Ok(load_map(&assets_dir().join("maps/hospital/hospital.yaml"))?)
}

/// Copies of the hospital per side for `robots` robots at `per_hospital` robots per copy.
pub fn tiles_per_side(robots: usize, per_hospital: usize) -> usize {
    let copies = robots.div_ceil(per_hospital.max(1));
    let mut k = (copies as f64).sqrt() as usize;
    while k * k < copies {
        k += 1;
    }
    k.max(1)
}

/// The map of one population: the 4 × 4 world, or the hospital tiled with the robot count.
struct SwarmMaps {
    hospital: OccupancyGrid,
    fixed: Option<OccupancyGrid>,
    per_hospital: Option<usize>,
}

impl SwarmMaps {
    fn new(per_hospital: Option<usize>) -> anyhow::Result<Self> {
        let hospital = hospital()?;
        let fixed = per_hospital.is_none().then(|| hospital.tiled(4, 4));
        Ok(SwarmMaps {
            hospital,
            fixed,
            per_hospital,
        })
    }

    /// The grid and its description for `robots` robots.
    fn for_robots(&self, robots: usize) -> (std::borrow::Cow<'_, OccupancyGrid>, String) {
        let (grid, k) = match (&self.fixed, self.per_hospital) {
            (Some(g), _) => (std::borrow::Cow::Borrowed(g), 4),
            (None, per) => {
                let k = tiles_per_side(robots, per.unwrap_or(1));
                (std::borrow::Cow::Owned(self.hospital.tiled(k, k)), k)
            }
        };
        let b = grid.bounds();
        let map = format!(
            "hospital tiled {k}x{k} ({:.0} x {:.0} m)",
            b[2] - b[0],
            b[3] - b[1]
        );
        (grid, map)
    }
}

/// Simulated seconds for `robots` robots: `--duration`, else the default of [`SwarmOptions`].
fn duration_for(o: &SwarmOptions, robots: usize) -> f64 {
    default_duration(o.duration, o.mcl.is_some(), robots)
}

fn default_duration(given: Option<f64>, mcl: bool, robots: usize) -> f64 {
    given.unwrap_or_else(|| {
        let total = if mcl { 400.0 } else { 4000.0 };
        (total / robots.max(1) as f64).max(10.0)
    })
}

pub fn run_swarm_bench(o: &SwarmOptions) -> anyhow::Result<()> {
    if let Some(d) = o.duration {
        check_duration(d)?;
    }
    if let Some(n) = o.robots.iter().find(|n| **n == 0) {
        anyhow::bail!("--robots: expected populations of at least 1 robot, got {n}");
    }
    for &b in &o.beams {
        check_beams(b)?;
    }
    let per_hospital = o.per_hospital.map(|n| n as usize);
    let maps = SwarmMaps::new(per_hospital)?;
    let runs: Vec<(usize, usize)> = o
        .beams
        .iter()
        .flat_map(|&b| o.robots.iter().map(move |&n| (b, n)))
        .collect();
    // every population is placed before the first one runs, so one that does not fit fails at
    // once; at constant density, where each population has its own map and they are placed as
    // they run, one copy of the hospital must hold its share
    let mut placed: Vec<Option<Scenario>> = match per_hospital {
        Some(per) => {
            swarm_scenario(&maps.hospital, per, 180, duration_for(o, per))
                .map_err(|e| anyhow::anyhow!("--per-hospital {per}: {e}"))?;
            runs.iter().map(|_| None).collect()
        }
        None => {
            let (grid, _) = maps.for_robots(0);
            runs.iter()
                .map(|&(beams, n)| swarm_scenario(&grid, n, beams, duration_for(o, n)).map(Some))
                .collect::<anyhow::Result<_>>()?
        }
    };
    if !o.json {
        match per_hospital {
            Some(per) => println!(
                "swarm benchmark at {per} robots per copy of the hospital, lasers at 10 Hz, dt 0.05 s"
            ),
            None => println!(
                "swarm benchmark on {}, lasers at 10 Hz, dt 0.05 s",
                maps.for_robots(0).1
            ),
        }
        match o.mcl {
            Some(MclDefaults::Amcl) => println!(
                "every robot localizes with MCL, ROS AMCL's defaults (100 to 5000 particles, 30 beams)"
            ),
            Some(MclDefaults::Sim) => println!(
                "every robot localizes with MCL, sim's defaults (500 to 5000 particles, 60 beams, scan proposal)"
            ),
            None => {}
        }
        println!("machine: {}", crate::bench::machine::describe());
        println!(
            "{:>7} {:>6} {:>9} {:>10} {:>12} {:>14} {:>12}  map",
            "robots", "beams", "sim s", "wall s", "× real time", "rays/s", "µs/robot-step"
        );
    }
    for (k, &(beams, n)) in runs.iter().enumerate() {
        let (grid, map) = maps.for_robots(n);
        let mut sc = match placed[k].take() {
            Some(sc) => sc,
            None => swarm_scenario(&grid, n, beams, duration_for(o, n))?,
        };
        drop(grid);
        if let Some(d) = o.mcl {
            localize_with_mcl(&mut sc, d);
        }
        let spec = swarm_laser(beams);
        let (sim_time_s, wall_time_s) = if o.direct {
            run_direct(&sc, o.threads)?
        } else {
            let out = run_scenario(
                &sc,
                &RunOptions {
                    rrd: None,
                    threads: o.threads,
                    progress: false,
                    trajectory_period: None,
                },
            )?;
            (out.summary.sim_time_s, out.summary.wall_time_s)
        };
        let scans_per_robot = (sim_time_s * spec.rate + 1e-9).floor() + 1.0;
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
            stepped_by: if o.direct { "schedule" } else { "facade" },
            localizer: o.mcl.map_or("none", MclDefaults::label),
            sim_time_s,
            wall_time_s,
            real_time_factor: sim_time_s / wall_time_s.max(1e-9),
            rays_per_s: rays / wall_time_s.max(1e-9),
            us_per_robot_step: wall_time_s * 1e6 * sc.dt
                / (sim_time_s.max(1e-9) * sc.robots.len() as f64),
            map,
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&r)?);
        } else {
            println!(
                "{:>7} {:>6} {:>9.1} {:>10.2} {:>12.1} {:>14.3e} {:>12.2}  {}",
                r.robots,
                r.beams,
                r.sim_time_s,
                r.wall_time_s,
                r.real_time_factor,
                r.rays_per_s,
                r.us_per_robot_step,
                r.map
            );
        }
    }
    Ok(())
}

/// The scenario's ticks stepped on the bare schedule, timed from the first tick to the last as
/// the facade's summary times them: (simulated s, wall s).
fn run_direct(sc: &Scenario, threads: usize) -> anyhow::Result<(f64, f64)> {
    let mut world = crate::build::build_world(sc, threads)?;
    let ticks = (sc.duration / sc.dt).round().max(1.0) as u64;
    let started = std::time::Instant::now();
    for _ in 0..ticks {
        world.step();
    }
    Ok((ticks as f64 * sc.dt, started.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 6 × 6 m room: its free middle holds a handful of robots 1.5 m apart, not 20.
    fn room() -> OccupancyGrid {
        let mut g = OccupancyGrid::new(120, 120, 0.05, [0.0, 0.0], Cell::Free);
        for i in 0..120 {
            for (c, r) in [(i, 0), (i, 119), (0, i), (119, i)] {
                g.set(c, r, Cell::Occupied);
            }
        }
        g
    }

    /// Without `--duration`, small populations run long enough to time (4000 robot-seconds,
    /// a tenth with MCL) and large ones at least 10 s; a given duration is kept.
    #[test]
    fn the_default_duration_follows_the_population() {
        assert_eq!(default_duration(None, false, 1), 4000.0);
        assert_eq!(default_duration(None, false, 10), 400.0);
        assert_eq!(default_duration(None, false, 1000), 10.0);
        assert_eq!(default_duration(None, true, 1), 400.0);
        assert_eq!(default_duration(None, true, 100), 10.0);
        assert_eq!(default_duration(Some(0.3), false, 1), 0.3);
        assert_eq!(default_duration(Some(7.0), true, 5000), 7.0);
    }

    #[test]
    fn robots_are_placed_apart_on_free_floor() {
        let g = room();
        let sc = swarm_scenario(&g, 6, 180, 1.0).expect("six robots fit");
        assert_eq!(sc.robots.len(), 6);
        for (i, a) in sc.robots.iter().enumerate() {
            assert!(g.disc_is_clear(a.start.x, a.start.y, 0.6), "{:?}", a.start);
            for b in &sc.robots[i + 1..] {
                assert!(a.start.distance(&b.start) >= SPACING, "{a:?} {b:?}");
            }
        }
        let again = swarm_scenario(&g, 6, 180, 1.0).expect("six robots fit");
        let starts = |s: &Scenario| s.robots.iter().map(|r| r.start).collect::<Vec<_>>();
        assert_eq!(starts(&sc), starts(&again), "placement is seeded");
    }

    /// With `--mcl`, every wandering robot localizes from its start and tracks itself on the
    /// hospital: the benchmark times a working localizer, not one that is lost.
    #[test]
    fn swarm_robots_with_mcl_track_their_poses() {
        let g = load_map(&assets_dir().join("maps/hospital/hospital.yaml")).unwrap();
        let mut sc = swarm_scenario(&g, 2, 180, 20.0).expect("two robots fit");
        localize_with_mcl(&mut sc, MclDefaults::Amcl);
        let out = run_scenario(
            &sc,
            &RunOptions {
                rrd: None,
                threads: 1,
                progress: false,
                trajectory_period: None,
            },
        )
        .unwrap();
        for r in &out.summary.robots {
            let m = &r.localization["mcl"];
            assert!(m.estimates >= 20, "{}: {} estimates", r.name, m.estimates);
            // the start's spread (0.5 m) settles within a few updates
            let ate = m.ate_rmse_m.expect("estimates were judged");
            assert!(ate < 0.5, "{}: ATE {ate} m", r.name);
            let tracked = m.tracked_fraction.expect("estimates were judged");
            assert!(tracked >= 0.9, "{}: tracked {tracked}", r.name);
        }
    }

    /// Constant density: the copies of the hospital per side grow with the square root of the
    /// robot count, exactly when the count over the density is a square.
    #[test]
    fn tiles_grow_with_the_robot_count() {
        for (robots, per, k) in [
            (1, 100, 1),
            (100, 100, 1),
            (101, 100, 2),
            (400, 100, 2),
            (1000, 100, 4),
            (10_000, 100, 10),
            (3, 1, 2),
        ] {
            assert_eq!(tiles_per_side(robots, per), k, "{robots} at {per}");
        }
    }

    #[test]
    fn a_population_that_does_not_fit_is_an_error() {
        let e = swarm_scenario(&room(), 20, 180, 1.0).expect_err("20 robots do not fit");
        let e = e.to_string();
        assert!(e.contains("--robots 20: only"), "{e}");
        assert!(e.contains("fit on the swarm map"), "{e}");
    }
}
