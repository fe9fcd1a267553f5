//! [`Simulation`]: a scenario's world that a program loads, steps, reads and commands between
//! ticks: the simulator as a library. `sim run`, `sim batch` and `sim replay` drive this same
//! type (`run_world`), so a program gets their schedule, determinism, recordings and
//! summary.
//!
//! ```no_run
//! use sim::Simulation;
//!
//! let mut s = Simulation::load("hospital_patrol").seed(4).duration(30.0).build()?;
//! s.run_for(5.0)?;
//! let r1 = s.robot("r1")?;
//! println!("r1 at {:?}, odometry {:?}", r1.pose(), r1.odometry());
//! let done = s.run()?;
//! println!("{} robots, {:.1} s", done.summary.robots.len(), done.summary.sim_time_s);
//! # anyhow::Ok(())
//! ```

use super::attach::{attach_controllers, attach_estimators};
use super::command::{SimError, names};
use super::controller::{Controller, UserControllers};
use super::exports::{Exported, RunExports};
use super::outputs::{self, OutputsFailed};
use super::summary::{Summary, collect};
use super::view::{DoorView, PersonView, RobotView};
use crate::build::{BuildMode, Reusable, SimWorld, build_world_with};
use crate::cache::MapCache;
use crate::formats::tum::RobotLocalization;
use crate::options::check_duration;
use crate::scenario::overrides::Override;
use crate::scenario::source::Source;
use crate::scenario::{Scenario, load_scenario, scenario_path};
use bevy_ecs::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;
use systems::body::{PersonId, TruePose, Walker};
use systems::core::pool::KernelPool;
use systems::localization::{Filter, MapLocalizer, ScanEstimator};
use systems::navigation::Navigator;
use systems::navigation::road_drive::{RoadNavigator, RoadPhase};
use systems::raycast::Doors;

/// A running simulation of one scenario.
pub struct Simulation {
    sim: SimWorld,
    scenario: Scenario,
    exports: RunExports,
    /// Whether a recording or export is being written (a restart would overwrite it).
    writes_files: bool,
    threads: usize,
    /// The cache of map-derived structures the world was built with, for a restart.
    cache: MapCache,
    /// The user's estimators as given (before any scan), for a restart.
    estimators: Vec<(String, String, Filter)>,
    /// Ticks run so far.
    ticks: u64,
    /// When the first tick started (the summary's wall time counts from there).
    started: Option<Instant>,
}

/// What a finished simulation leaves: its summary (what `--summary` writes), every robot's
/// estimates beside the truth, the event log and the files exported.
pub struct Finished {
    /// What `--summary` writes.
    pub summary: Summary,
    /// Every robot's localizer estimates beside its true poses, in robot order.
    pub localization: Vec<RobotLocalization>,
    /// Scenario and navigation events in time order: (time, robot or "" for the world, text).
    pub log: Vec<(f64, String, String)>,
    /// The files exported (CARMEN logs, maps, the MCAP replay).
    pub exported: Exported,
}

enum Input {
    /// A bundled scenario's name or a file.
    Named(String),
    /// Scenario TOML, with the label errors name it by and the folder its relative paths
    /// start from.
    Toml {
        text: String,
        label: String,
        base_dir: PathBuf,
    },
    /// A scenario made in code.
    Built(Box<Scenario>),
}

/// How to make a [`Simulation`]: the scenario, its overrides and the outputs to write.
pub struct SimulationBuilder {
    input: Input,
    sets: Vec<(String, String)>,
    seed: Option<u64>,
    duration: Option<f64>,
    threads: usize,
    /// `None`: the process's ([`crate::cache::process_cache`]).
    cache: Option<MapCache>,
    /// `None`: a pool of `threads` workers of the simulation's own.
    pool: Option<KernelPool>,
    rrd: Option<PathBuf>,
    exports: RunExports,
    /// User controllers by robot name.
    controllers: Vec<(String, Box<dyn Controller>)>,
    /// User estimators: robot name, the estimator's name, the estimator.
    estimators: Vec<(String, String, Filter)>,
}

impl SimulationBuilder {
    fn new(input: Input) -> Self {
        SimulationBuilder {
            input,
            sets: Vec::new(),
            seed: None,
            duration: None,
            threads: 0,
            cache: None,
            pool: None,
            rrd: None,
            exports: RunExports::default(),
            controllers: Vec::new(),
            estimators: Vec::new(),
        }
    }

    /// The folder relative paths of scenario TOML text ([`Simulation::from_toml`]) start from.
    pub fn relative_to(mut self, dir: impl Into<PathBuf>) -> Self {
        if let Input::Toml { base_dir, .. } = &mut self.input {
            *base_dir = dir.into();
        }
        self
    }

    /// The scenario's seed instead of the file's.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = Some(seed);
        self
    }

    /// The scenario's duration (simulated seconds) instead of the file's.
    pub fn duration(mut self, seconds: f64) -> Self {
        self.duration = Some(seconds);
        self
    }

    /// Overrides a key of the scenario file, as `sim batch --set KEY=VALUE` does
    /// (`robots[name=r1].sensors.laser.rate`, `"20"`); the value is TOML (a bare word is a
    /// string). Not for scenarios built in code: change their fields.
    pub fn set(mut self, key: &str, value: &str) -> Self {
        self.sets.push((key.to_string(), value.to_string()));
        self
    }

    /// Worker threads of the parallel kernels (0, the default: one per core). Results do not
    /// depend on it.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// Reads and writes the structures that depend on the map alone (ray caster, costmaps,
    /// likelihood field, road raster) through `cache` ([`MapCache::in_dir`], or
    /// [`crate::cache::from_env`] for the commands' folder); results are the same with any
    /// cache or none. Default: the process's ([`crate::cache::process_cache`]), which is none
    /// unless the command line set it.
    pub fn cache(mut self, cache: MapCache) -> Self {
        self.cache = Some(cache);
        self
    }

    /// Runs the world's kernels on `pool` instead of a pool of its own (`threads` then does
    /// not apply): one pool shared by several simulations, or [`KernelPool::inline`] for
    /// worlds that are themselves stepped side by side on another pool's workers. Results do
    /// not depend on it.
    pub fn kernel_pool(mut self, pool: KernelPool) -> Self {
        self.pool = Some(pool);
        self
    }

    /// Writes a Rerun recording, as `sim run --rrd` does.
    pub fn rrd(mut self, path: impl Into<PathBuf>) -> Self {
        self.rrd = Some(path.into());
        self
    }

    /// Writes an MCAP replay, as `sim run --mcap` does.
    pub fn mcap(mut self, path: impl Into<PathBuf>) -> Self {
        self.exports.mcap = Some(path.into());
        self
    }

    /// Writes CARMEN logs, as `sim run --carmen-out` does.
    pub fn carmen(mut self, path: impl Into<PathBuf>) -> Self {
        self.exports.carmen_out = Some(path.into());
        self
    }

    /// Saves the maps at the end, as `sim run --save-map` does.
    pub fn save_map(mut self, path: impl Into<PathBuf>) -> Self {
        self.exports.save_map = Some(path.into());
        self
    }

    /// Drives robot `robot` with the user's `controller` instead of its behaviour or navigator
    /// (see [`Controller`]); a held velocity command
    /// ([`Command::Drive`](super::command::Command::Drive)) still overrides it.
    pub fn controller(mut self, robot: &str, controller: impl Controller) -> Self {
        self.controllers
            .push((robot.to_string(), Box::new(controller)));
        self
    }

    /// Adds a user's SLAM system (or any estimator fed with scans and odometry) called `name`
    /// to robot `robot`: it runs in the Map set after the scenario's own, and is evaluated,
    /// summarised, recorded and exported like them under `name`. The robot needs a laser and
    /// wheel encoders.
    pub fn slam(
        mut self,
        robot: &str,
        name: &str,
        estimator: impl ScanEstimator + 'static,
    ) -> Self {
        self.estimators.push((
            robot.to_string(),
            name.to_string(),
            Filter::Scan(Box::new(estimator)),
        ));
        self
    }

    /// Adds a user's localizer (see [`MapLocalizer`]) called `name` to robot `robot`: it runs in
    /// the Estimate set beside the scenario's own localizers, on the same scans, odometry and
    /// map, and is evaluated, summarised, recorded and exported like them under `name`. The
    /// robot needs a laser and wheel encoders. Without localizers in the scenario, the map's
    /// distance field reaches 2 m from obstacles (AMCL's default `laser_likelihood_max_dist`).
    pub fn localizer(
        mut self,
        robot: &str,
        name: &str,
        localizer: impl MapLocalizer + 'static,
    ) -> Self {
        self.estimators.push((
            robot.to_string(),
            name.to_string(),
            Filter::Map(Box::new(localizer)),
        ));
        self
    }

    /// The scenario with every override applied and validated.
    pub fn scenario(&self) -> anyhow::Result<Scenario> {
        let overrides = self
            .sets
            .iter()
            .map(|(k, v)| Override::new("set", k, v))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let mut sc = match &self.input {
            Input::Named(name) if overrides.is_empty() => {
                load_scenario(&scenario_path(Some(name))?)?
            }
            Input::Named(name) => Source::load(&scenario_path(Some(name))?)?
                .scenario(&overrides)
                .map_err(anyhow::Error::msg)?,
            Input::Toml {
                text,
                label,
                base_dir,
            } => Source::from_text(text, label, base_dir, "scenario")?
                .scenario(&overrides)
                .map_err(anyhow::Error::msg)?,
            Input::Built(sc) if overrides.is_empty() => (**sc).clone(),
            Input::Built(_) => anyhow::bail!(
                "set {}: a scenario built in code has no file to override; change its fields",
                self.sets[0].0
            ),
        };
        if let Some(s) = self.seed {
            sc.seed = s;
        }
        if let Some(d) = self.duration {
            sc.duration = check_duration(d)?;
        }
        Ok(sc)
    }

    /// Builds the world, opens the outputs' files and adds their recorders to the schedule.
    pub fn build(self) -> anyhow::Result<Simulation> {
        let scenario = self.scenario()?;
        let cache = self.cache.unwrap_or_else(crate::cache::process_cache);
        let mut world = build_world_with(
            &scenario,
            self.threads,
            BuildMode::Live,
            Reusable::with_pool(self.pool),
            &cache,
        )?;
        attach_estimators(&mut world, &scenario, self.estimators.clone())?;
        attach_controllers(&mut world, &scenario, self.controllers)?;
        let mut sim = Simulation::from_world(world, scenario, self.rrd.as_deref(), &self.exports)?;
        sim.threads = self.threads;
        sim.cache = cache;
        sim.estimators = self.estimators;
        Ok(sim)
    }
}

impl Simulation {
    /// A bundled scenario by name (`hospital_patrol`), or a scenario file.
    pub fn load(name_or_file: &str) -> SimulationBuilder {
        SimulationBuilder::new(Input::Named(name_or_file.to_string()))
    }

    /// Scenario TOML text, called `label` in error messages; relative paths in it (maps, places)
    /// resolve against the current folder, or the one given to
    /// [`SimulationBuilder::relative_to`].
    pub fn from_toml(text: &str, label: &str) -> SimulationBuilder {
        SimulationBuilder::new(Input::Toml {
            text: text.to_string(),
            label: label.to_string(),
            base_dir: PathBuf::from("."),
        })
    }

    /// A scenario made in code.
    pub fn from_scenario(scenario: Scenario) -> SimulationBuilder {
        SimulationBuilder::new(Input::Built(Box::new(scenario)))
    }

    /// A world built from `scenario` (a run's, or a replay's) with the outputs asked for.
    pub(crate) fn from_world(
        mut sim: SimWorld,
        scenario: Scenario,
        rrd: Option<&Path>,
        exports: &RunExports,
    ) -> anyhow::Result<Simulation> {
        outputs::install(&mut sim, &scenario, rrd, exports)?;
        initialize_schedule(&mut sim)?;
        Ok(Simulation {
            sim,
            scenario,
            writes_files: rrd.is_some() || exports.writes_files(),
            exports: exports.clone(),
            threads: 0,
            cache: MapCache::disabled(),
            estimators: Vec::new(),
            ticks: 0,
            started: None,
        })
    }

    /// Starts the same scenario again from its first tick with seed `seed`: the result equals
    /// a simulation built afresh with that seed. What does not depend on the seed (the
    /// localizers' distance field, the navigation costmaps) is reused unless a door has moved.
    /// The user's controllers are kept as they are (with their own state); the user's
    /// estimators start again as they were given. A simulation writing recordings or exports
    /// cannot restart (it would overwrite them): build a new one.
    pub fn reset(&mut self, seed: u64) -> anyhow::Result<()> {
        if self.writes_files {
            anyhow::bail!(
                "reset: this simulation writes recordings or exports; build a new one for \
                 another seed"
            );
        }
        let reuse = Reusable::take(&mut self.sim.world);
        let controllers = self
            .sim
            .world
            .remove_resource::<UserControllers>()
            .map(|c| {
                c.items
                    .into_iter()
                    .map(|c| (c.name, c.controller))
                    .collect()
            })
            .unwrap_or_default();
        let mut scenario = self.scenario.clone();
        scenario.seed = seed;
        let mut world =
            build_world_with(&scenario, self.threads, BuildMode::Live, reuse, &self.cache)?;
        attach_estimators(&mut world, &scenario, self.estimators.clone())?;
        attach_controllers(&mut world, &scenario, controllers)?;
        outputs::install(&mut world, &scenario, None, &RunExports::default())?;
        initialize_schedule(&mut world)?;
        self.sim = world;
        self.scenario = scenario;
        self.ticks = 0;
        self.started = None;
        Ok(())
    }

    /// The scenario being run.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Simulated time (s): the start of the next tick.
    pub fn time(&self) -> f64 {
        self.sim.time()
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The ticks of the scenario's duration.
    pub fn end_tick(&self) -> u64 {
        (self.scenario.duration / self.scenario.dt).round().max(1.0) as u64
    }

    /// One tick of the schedule. An error once a user controller has failed (the run can
    /// still be [finished](Simulation::finish), its recordings complete up to that tick).
    pub fn step(&mut self) -> Result<(), SimError> {
        self.failure()?;
        self.started.get_or_insert_with(Instant::now);
        self.sim.step();
        self.ticks += 1;
        self.failure()
    }

    fn failure(&self) -> Result<(), SimError> {
        match self.sim.world.get_resource::<UserControllers>() {
            Some(UserControllers {
                failure: Some(e), ..
            }) => Err(e.clone()),
            _ => Ok(()),
        }
    }

    /// The scenario's duration is over, or it ends when every task is done and they are.
    pub fn is_over(&mut self) -> bool {
        // a run has at least one tick
        self.ticks >= self.end_tick()
            || (self.ticks > 0
                && self.scenario.end_when_done
                && tasks_all_done(&mut self.sim.world))
    }

    /// Steps `seconds` of simulated time (rounded to whole ticks), even past the scenario's
    /// duration.
    pub fn run_for(&mut self, seconds: f64) -> Result<(), SimError> {
        for _ in 0..self.ticks_in(seconds)? {
            self.step()?;
        }
        Ok(())
    }

    /// Steps until `done` holds (checked before every tick) or `max_seconds` have passed;
    /// whether `done` held.
    pub fn run_until(
        &mut self,
        mut done: impl FnMut(&Simulation) -> bool,
        max_seconds: f64,
    ) -> Result<bool, SimError> {
        for _ in 0..self.ticks_in(max_seconds)? {
            if done(self) {
                return Ok(true);
            }
            self.step()?;
        }
        Ok(done(self))
    }

    fn ticks_in(&self, seconds: f64) -> Result<u64, SimError> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(SimError::BadValue {
                what: "simulated time".into(),
                expected: "a finite number of seconds >= 0",
                got: seconds.to_string(),
            });
        }
        Ok((seconds / self.scenario.dt).round() as u64)
    }

    /// Steps to the scenario's end, then [`Simulation::finish`]. If a user controller fails,
    /// the run is finished where it stopped (recordings written) and the error returned.
    pub fn run(mut self) -> anyhow::Result<Finished> {
        while !self.is_over() {
            if let Err(e) = self.step() {
                self.finish()?;
                return Err(e.into());
            }
        }
        self.finish()
    }

    /// Ends the run where it is: the estimators and recordings are finished, the files
    /// written, and the summary read (covering the ticks run). A file that cannot be written
    /// does not stop the others; the error is then an [`OutputsFailed`] holding the
    /// [`Finished`] run (taken back with [`OutputsFailed::split`]).
    pub fn finish(mut self) -> anyhow::Result<Finished> {
        let world = &mut self.sim.world;
        let frame_error = outputs::finish_estimators_and_frames(world);
        let wall_time_s = self.started.map_or(0.0, |s| s.elapsed().as_secs_f64());
        let (exported, mut failures) = outputs::finish_files(world, &self.scenario, &self.exports);
        if let Some(e) = frame_error {
            failures
                .errors
                .push(format!("recording camera frames: {e}"));
        }
        let sim_time_s = self.ticks as f64 * self.scenario.dt;
        let summary = Summary {
            scenario: self.scenario.name.clone(),
            seed: self.scenario.seed,
            sim_time_s,
            wall_time_s,
            real_time_factor: sim_time_s / wall_time_s.max(1e-9),
            robots: collect::robot_summaries(world),
            timing: collect::timing(world),
        };
        let done = Finished {
            summary,
            localization: collect::robot_localization(world),
            log: collect::event_log(world),
            exported,
        };
        OutputsFailed::check(done, failures)
    }

    /// The robot called `name`.
    pub fn robot(&self, name: &str) -> Result<RobotView<'_>, SimError> {
        let index = self.robot_index(name)?;
        Ok(self.view(index))
    }

    /// Every robot, in the scenario's order.
    pub fn robots(&self) -> Vec<RobotView<'_>> {
        (0..self.sim.robots.len()).map(|i| self.view(i)).collect()
    }

    fn view(&self, index: usize) -> RobotView<'_> {
        RobotView {
            world: &self.sim.world,
            entity: self.sim.robots[index],
            name: &self.scenario.robots[index].name,
            index,
        }
    }

    fn robot_index(&self, name: &str) -> Result<usize, SimError> {
        self.scenario
            .robots
            .iter()
            .position(|r| r.name == name)
            .ok_or_else(|| SimError::UnknownRobot {
                name: name.to_string(),
                known: names(self.scenario.robots.iter().map(|r| r.name.as_str())),
            })
    }

    /// The walking people, in the scenario's order.
    pub fn people(&self) -> Vec<PersonView<'_>> {
        let w = &self.sim.world;
        self.sim
            .people
            .iter()
            .filter_map(|&e| {
                Some(PersonView {
                    name: &w.get::<PersonId>(e)?.0,
                    pose: w.get::<TruePose>(e)?.pose,
                    next_point: w.get::<Walker>(e)?.next,
                })
            })
            .collect()
    }

    /// The world's doors and whether each is open.
    pub fn doors(&self) -> Vec<DoorView> {
        self.sim
            .world
            .get_resource::<Doors>()
            .map_or(Vec::new(), |d| {
                d.doors
                    .iter()
                    .map(|d| DoorView {
                        name: d.name.clone(),
                        open: d.open,
                    })
                    .collect()
            })
    }

    /// The ECS world, for programs that read what no view offers.
    pub fn world(&self) -> &World {
        &self.sim.world
    }

    /// The ECS world and the tick's schedule, for programs that add their own components,
    /// resources or systems (in a [`systems::core::SimSet`]) before the first tick.
    pub fn world_and_schedule(&mut self) -> (&mut World, &mut Schedule) {
        (&mut self.sim.world, &mut self.sim.schedule)
    }

    /// The ECS world.
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.sim.world
    }
}

/// Builds the schedule's executable form now, before the first tick, which would otherwise
/// build it (about 20 ms) inside the run's wall time. Systems a program adds later rebuild it at
/// the next tick.
fn initialize_schedule(sim: &mut SimWorld) -> anyhow::Result<()> {
    let SimWorld {
        world, schedule, ..
    } = sim;
    if let Err(e) = schedule.initialize(world) {
        anyhow::bail!(
            "the tick's schedule: {}",
            e.to_string(schedule.graph(), world)
        );
    }
    Ok(())
}

/// True when some robot has tasks and every such robot is done with them.
fn tasks_all_done(w: &mut World) -> bool {
    let mut q = w.query::<&Navigator>();
    let mut any = false;
    for n in q.iter(w) {
        any = true;
        if !n.finished() {
            return false;
        }
    }
    let mut q = w.query::<&RoadNavigator>();
    for n in q.iter(w) {
        any = true;
        if n.phase != RoadPhase::Arrived {
            return false;
        }
    }
    any
}

mod commands;

#[cfg(test)]
mod tests;
