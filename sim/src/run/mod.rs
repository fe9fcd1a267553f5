//! A run, in its phases (`run_world`): the outputs join the built world's schedule, the world
//! steps as fast as the CPU allows for the scenario's duration (with a progress bar), the
//! estimators and recordings are finished, and the summary is read. A stop
//! asked for by Ctrl-C or SIGTERM ([`crate::run::interrupt`]) ends the loop after the current tick;
//! the recordings and exports are then finished as after the last tick, and the summary covers
//! the ticks run.

// the library facade and what it returns: every public item is documented
#![warn(missing_docs)]

mod attach;
pub mod capture;
pub mod command;
pub mod controller;
pub mod exports;
pub mod interrupt;
mod outputs;
mod progress;
pub mod report;
pub mod simulation;
pub mod summary;
pub mod view;

use crate::build::{SimWorld, build_world};
use crate::formats::scans::ScanRecord;
use crate::run::exports::{Exported, RunExports};
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use capture::Capturer;
use std::path::PathBuf;
use std::time::Instant;
use summary::Summary;
use systems::body::TruePose;
use systems::core::{Pose2, RobotIndex};

pub use crate::formats::tum::RobotLocalization;
pub use capture::ScanCapture;
pub use command::{Command, SimError, Target};
pub use controller::{Controller, Observation};
pub use outputs::{Failures, OutputsFailed, output_plugins};
pub use simulation::{Finished, Simulation, SimulationBuilder};
pub use view::{
    DoorView, Estimate, LocalizerView, NavigationView, PersonView, RobotView, ScanView, Twist,
};

/// How [`run_scenario`] runs a scenario (the options of `sim run` that are not files).
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Write the .rrd here (None: no recording).
    pub rrd: Option<PathBuf>,
    /// Kernel threads (0 = all cores).
    pub threads: usize,
    /// Show a progress bar.
    pub progress: bool,
    /// Sample every robot's true pose at this period (s) into the output (tests, analysis).
    pub trajectory_period: Option<f64>,
}

/// What [`run_scenario`] leaves.
pub struct RunOutput {
    /// What `--summary` writes.
    pub summary: Summary,
    /// (time, true pose of each robot in index order), if requested.
    pub trajectory: Vec<(f64, Vec<Pose2>)>,
    /// Every robot's localizer estimates paired with the truth, in robot index order.
    pub localization: Vec<RobotLocalization>,
    /// Captured scans ([`run_scenario_capturing`]; empty otherwise), in time order, robots in
    /// index order within a tick; `index` counts from 0.
    pub scans: Vec<ScanRecord>,
    /// What happened, in time order: scenario events and every navigator's events
    /// (time, robot name or "" for world events, text).
    pub log: Vec<(f64, String, String)>,
    /// The files [`run_scenario_exporting`] wrote.
    pub exported: Exported,
    /// The run was stopped by Ctrl-C or SIGTERM before its end (`summary.sim_time_s` says
    /// where).
    pub interrupted: bool,
}

/// Runs a scenario to its end. When some output cannot be written (the recording, an export),
/// the others still are, and the error is an [`OutputsFailed`] holding the [`RunOutput`].
pub fn run_scenario(scenario: &Scenario, opts: &RunOptions) -> anyhow::Result<RunOutput> {
    run(scenario, opts, None, &RunExports::default())
}

/// Runs a scenario to its end and writes the exports asked for (CARMEN logs, maps).
pub fn run_scenario_exporting(
    scenario: &Scenario,
    opts: &RunOptions,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    run(scenario, opts, None, exports)
}

/// Runs a scenario to its end and collects laser scans as `capture` asks.
pub fn run_scenario_capturing(
    scenario: &Scenario,
    opts: &RunOptions,
    capture: &ScanCapture,
) -> anyhow::Result<RunOutput> {
    if !(capture.period_s.is_finite() && capture.period_s > 0.0) {
        anyhow::bail!(
            "scan capture period: expected a positive number of seconds, got {}",
            capture.period_s
        );
    }
    if let Some(names) = &capture.robots {
        for n in names {
            match scenario.robots.iter().find(|r| &r.name == n) {
                None => {
                    let all: Vec<&str> = scenario.robots.iter().map(|r| r.name.as_str()).collect();
                    anyhow::bail!(
                        "{}: no robot named `{n}` (robots: {})",
                        scenario.source,
                        all.join(", ")
                    );
                }
                Some(r) if r.laser.is_none() => {
                    anyhow::bail!("{}: robot `{n}` has no laser", scenario.source)
                }
                Some(_) => {}
            }
        }
    }
    run(scenario, opts, Some(capture), &RunExports::default())
}

/// Runs `scenario` and returns the scans `capture` asks for. Localizers are removed first: they
/// never influence motion or sensing (robots navigate on wheel odometry, every random stream is
/// per entity), so the scans are the same and the run is much cheaper. No recording is written.
pub fn capture_scans(
    scenario: &Scenario,
    capture: &ScanCapture,
    threads: usize,
    progress: bool,
) -> anyhow::Result<Vec<ScanRecord>> {
    let mut sc = scenario.clone();
    for r in &mut sc.robots {
        r.localizers.clear();
    }
    let out = run_scenario_capturing(
        &sc,
        &RunOptions {
            rrd: None,
            threads,
            progress,
            trajectory_period: None,
        },
        capture,
    )?;
    Ok(out.scans)
}

fn run(
    scenario: &Scenario,
    opts: &RunOptions,
    capture: Option<&ScanCapture>,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    let sim = build_world(scenario, opts.threads)?;
    run_world(sim, scenario, opts, capture, exports)
}

/// Runs a world built from `scenario` (e.g. a replay's) to the scenario's end, as a run does.
pub fn run_built(
    sim: SimWorld,
    scenario: &Scenario,
    opts: &RunOptions,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    run_world(sim, scenario, opts, None, exports)
}

/// The phases of a run, through the facade ([`Simulation`]): the outputs join the schedule, the
/// world steps to the end (with a progress bar, the trajectory samples and the scan capture
/// asked for), the estimators and recordings are finished, the summary is read.
fn run_world(
    sim: SimWorld,
    scenario: &Scenario,
    opts: &RunOptions,
    capture: Option<&ScanCapture>,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    let mut sim = Simulation::from_world(sim, scenario.clone(), opts.rrd.as_deref(), exports)?;
    let mut capturer = capture.map(Capturer::new);
    let stepped = step_to_end(&mut sim, opts, capturer.as_mut())?;
    let mut trajectory = stepped.trajectory;
    if opts.trajectory_period.is_some() {
        trajectory.push((sim.time(), truth_poses(sim.world_mut())));
    }
    let (done, failures) = OutputsFailed::split(sim.finish())?;
    let out = RunOutput {
        summary: done.summary,
        trajectory,
        localization: done.localization,
        scans: capturer.map(Capturer::into_scans).unwrap_or_default(),
        log: done.log,
        exported: done.exported,
        interrupted: stepped.interrupted,
    };
    OutputsFailed::check(out, failures)
}

/// How the stepping ended.
struct Stepped {
    /// Stopped by Ctrl-C or SIGTERM.
    interrupted: bool,
    /// True poses sampled at `RunOptions::trajectory_period`.
    trajectory: Vec<(f64, Vec<Pose2>)>,
}

/// Steps the world tick by tick until the scenario's end ([`Simulation::is_over`]) or a stop
/// asked for.
fn step_to_end(
    sim: &mut Simulation,
    opts: &RunOptions,
    mut capturer: Option<&mut Capturer>,
) -> Result<Stepped, SimError> {
    let (duration, dt) = (sim.scenario().duration, sim.scenario().dt);
    let bar = progress::Progress::new(opts.progress, sim.end_tick(), duration, dt);
    let started = Instant::now();
    let mut trajectory = Vec::new();
    let mut next_sample = 0.0;
    let mut interrupted = false;
    while !sim.is_over() {
        if interrupt::requested() {
            interrupted = true;
            break;
        }
        if let Some(period) = opts.trajectory_period {
            let t = sim.time();
            if t + 1e-9 >= next_sample {
                trajectory.push((t, truth_poses(sim.world_mut())));
                next_sample += period;
            }
        }
        let tick = sim.ticks();
        sim.step()?;
        if let Some(c) = capturer.as_deref_mut() {
            c.collect(sim.world_mut());
        }
        bar.tick(tick, started);
    }
    bar.finish();
    Ok(Stepped {
        interrupted,
        trajectory,
    })
}

fn truth_poses(w: &mut World) -> Vec<Pose2> {
    let mut q = w.query::<(&RobotIndex, &TruePose)>();
    let mut v: Vec<(RobotIndex, Pose2)> = q.iter(w).map(|(i, t)| (*i, t.pose)).collect();
    v.sort_by_key(|(i, _)| *i);
    v.into_iter().map(|(_, p)| p).collect()
}
