//! The run loop: steps the schedule for the scenario's duration as fast as the CPU allows, shows
//! progress (simulated time and real-time factor), records, and gathers the summary. A stop
//! asked for by Ctrl-C or SIGTERM ([`crate::interrupt`]) ends the loop after the current tick;
//! the recordings and exports are then finished as after the last tick, and the summary covers
//! the ticks run.

use crate::build::{SimWorld, build_world};
use crate::mcap_out::{McapExport, record_mcap};
use crate::record::frames::{
    FrameOutputs, RecordedFrames, collect_frames, log_frames_rrd, record_frames_rrd,
};
use crate::record::outdoor::{OutdoorRecording, record_outdoor};
use crate::record::slam::{SlamRecording, record_slam, record_slam_final};
use crate::record::{RrdRecorder, record_navigation, record_rrd};
use crate::run_exports::{Exported, RunExports};
use crate::scans::ScanRecord;
use crate::scenario::Scenario;
use crate::summary::{NavigationFailure, NavigationSummary, RobotSummary, Summary};
use bevy_ecs::prelude::*;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use systems::body::TruePose;
use systems::core::{Pose2, RobotId, RobotIndex, SimClock, SimSet};
use systems::eval::road_metrics::RoadRunMetrics;
use systems::eval::{
    LocalizationSamples, LocalizerMetrics, NavOutcome, RobotMetrics, Sample, TrajectoryMetrics,
    pair_with_truth,
};
use systems::localization::road_wiring::RoadLocalization;
use systems::localization::{Filter, Localizers};
use systems::navigation::road_drive::{RoadNavigator, RoadPhase};
use systems::navigation::{Behaviour, NavStatus, Navigator};
use systems::sensors::{Camera, LaserScans, LaserTruth};
use systems::world::roads::RoadMap;

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

/// Laser scans to collect during a run, with the true sensor pose of each (SCANS files, scan
/// matching experiments). Passed to [`run_scenario_capturing`]; a separate argument rather than
/// a [`RunOptions`] field so existing `RunOptions { .. }` literals keep compiling.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanCapture {
    /// Keep one scan per robot every `period_s` seconds of simulated time: the first scan whose
    /// stamp reaches each multiple of the period (every scan if the laser is slower).
    pub period_s: f64,
    /// Only these robots (by name); `None` = every robot with a laser.
    pub robots: Option<Vec<String>>,
}

pub struct RunOutput {
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

/// True when the scenario asks to end once every robot with tasks is done, and they are.
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

fn event_log(w: &mut World) -> Vec<(f64, String, String)> {
    let mut log = w
        .get_resource::<crate::script::EventQueue>()
        .map(|q| q.fired.clone())
        .unwrap_or_default();
    let mut q = w.query::<(&RobotIndex, &RobotId, &Navigator, &NavOutcome)>();
    let mut navs: Vec<_> = q.iter(w).collect();
    navs.sort_by_key(|(i, ..)| **i);
    for (_, id, n, o) in navs {
        log.extend(
            n.events
                .iter()
                .map(|e| (e.time, id.0.clone(), e.text.clone())),
        );
        log.extend(
            o.collision_log
                .iter()
                .map(|(t, e)| (*t, id.0.clone(), e.clone())),
        );
    }
    let mut q = w.query::<(&RobotIndex, &RobotId, &RoadNavigator)>();
    let mut navs: Vec<_> = q.iter(w).collect();
    navs.sort_by_key(|(i, ..)| **i);
    for (_, id, n) in navs {
        log.extend(n.events.iter().map(|(t, e)| (*t, id.0.clone(), e.clone())));
    }
    // stable: same-time lines keep world events first, then robots in index order
    log.sort_by(|a, b| a.0.total_cmp(&b.0));
    log
}

/// The estimate/truth samples of one robot's localizers.
#[derive(Clone, Debug)]
pub struct RobotLocalization {
    pub robot: String,
    /// (localizer name, samples) in the order of the scenario.
    pub localizers: Vec<(String, Vec<Sample>)>,
}

fn truth_poses(w: &mut World) -> Vec<Pose2> {
    let mut q = w.query::<(&RobotIndex, &TruePose)>();
    let mut v: Vec<(RobotIndex, Pose2)> = q.iter(w).map(|(i, t)| (*i, t.pose)).collect();
    v.sort_by_key(|(i, _)| *i);
    v.into_iter().map(|(_, p)| p).collect()
}

/// Runs a scenario to its end.
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

/// Per-robot state of a scan capture.
struct Capturer<'a> {
    capture: &'a ScanCapture,
    /// (robot index → next multiple of the period to take)
    next: Vec<u64>,
    scans: Vec<ScanRecord>,
}

impl Capturer<'_> {
    /// Takes the scans of this tick (robots in index order).
    fn collect(&mut self, w: &mut World) {
        let mut q = w.query::<(&RobotIndex, &RobotId, &LaserScans, &LaserTruth)>();
        let mut rows: Vec<_> = q.iter(w).collect();
        rows.sort_by_key(|(i, ..)| **i);
        let period = self.capture.period_s;
        // a scan at k·period may carry rounding (0.30000000000000004): accept it a hair early
        let eps = 1e-6 * period.max(1e-3);
        for (i, id, scans, truth) in rows {
            if let Some(names) = &self.capture.robots
                && !names.contains(&id.0)
            {
                continue;
            }
            let slot = i.0 as usize;
            if self.next.len() <= slot {
                self.next.resize(slot + 1, 0);
            }
            for (scan, pose) in scans.scans.iter().zip(&truth.poses) {
                if scan.stamp + eps < self.next[slot] as f64 * period {
                    continue;
                }
                self.next[slot] = ((scan.stamp + eps) / period).floor() as u64 + 1;
                self.scans.push(ScanRecord {
                    index: self.scans.len() as u64,
                    robot: id.0.clone(),
                    stamp: scan.stamp,
                    pose: *pose,
                    angle_min: scan.angle_min,
                    angle_increment: scan.angle_increment,
                    range_min: scan.range_min,
                    range_max: scan.range_max,
                    ranges: scan.ranges.clone(),
                });
            }
        }
    }
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

fn run_world(
    mut sim: SimWorld,
    scenario: &Scenario,
    opts: &RunOptions,
    capture: Option<&ScanCapture>,
    exports: &RunExports,
) -> anyhow::Result<RunOutput> {
    let mut capturer = capture.map(|capture| Capturer {
        capture,
        next: Vec::new(),
        scans: Vec::new(),
    });
    if let Some(path) = &opts.rrd {
        let rec = RrdRecorder::create(path, &scenario.name, &scenario.grid, &scenario.record)?;
        sim.world.insert_resource(rec);
        sim.world.insert_resource(SlamRecording::new(
            scenario.record.scan_rate,
            scenario.record.slam_rate,
        ));
        sim.world.insert_resource(OutdoorRecording::new(
            scenario.record.rate,
            scenario.record.particle_rate,
        ));
        sim.schedule.add_systems(
            (record_rrd, record_navigation, record_slam, record_outdoor)
                .chain()
                .in_set(SimSet::Record),
        );
    }
    exports.install(&mut sim, scenario)?;
    install_frames(&mut sim, scenario, opts, exports)?;
    let ticks = (scenario.duration / scenario.dt).round().max(1.0) as u64;
    let bar = if opts.progress {
        let b = ProgressBar::new(ticks);
        b.set_style(
            ProgressStyle::with_template(
                "{bar:40.cyan/blue} {percent:>3}%  {msg}  [{elapsed_precise} < {eta}]",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let started = Instant::now();
    let mut trajectory = Vec::new();
    let mut next_sample = 0.0;
    let update_every = (ticks / 500).max(1);
    let mut ticks_run = ticks;
    let mut interrupted = false;
    for tick in 0..ticks {
        if crate::interrupt::requested() {
            interrupted = true;
            ticks_run = tick;
            break;
        }
        if let Some(period) = opts.trajectory_period {
            let t = sim.time();
            if t + 1e-9 >= next_sample {
                trajectory.push((t, truth_poses(&mut sim.world)));
                next_sample += period;
            }
        }
        sim.step();
        if let Some(c) = capturer.as_mut() {
            c.collect(&mut sim.world);
        }
        if tick % update_every == 0 || tick + 1 == ticks {
            let sim_t = (tick + 1) as f64 * scenario.dt;
            let wall = started.elapsed().as_secs_f64().max(1e-9);
            bar.set_position(tick + 1);
            bar.set_message(format!(
                "sim {sim_t:.1}/{:.1} s  {:.1}× real time",
                scenario.duration,
                sim_t / wall
            ));
        }
        if scenario.end_when_done && tasks_all_done(&mut sim.world) {
            ticks_run = tick + 1;
            break;
        }
    }
    bar.finish_and_clear();
    finish_slam(&mut sim.world);
    let frame_error = finish_frames(&mut sim.world);
    let wall_time_s = started.elapsed().as_secs_f64();
    if sim.world.contains_resource::<RrdRecorder>() {
        record_slam_final(&mut sim.world);
    }
    if let Some(mut rec) = sim.world.remove_resource::<RrdRecorder>() {
        rec.finish()?;
    }
    let exported = exports.finish(&mut sim.world, scenario)?;
    if opts.trajectory_period.is_some() {
        trajectory.push((sim.time(), truth_poses(&mut sim.world)));
    }
    if let Some(e) = frame_error {
        anyhow::bail!("recording camera frames: {e}");
    }
    let sim_time_s = ticks_run as f64 * scenario.dt;
    let summary = Summary {
        scenario: scenario.name.clone(),
        seed: scenario.seed,
        sim_time_s,
        wall_time_s,
        real_time_factor: sim_time_s / wall_time_s.max(1e-9),
        robots: robot_summaries(&mut sim.world),
    };
    Ok(RunOutput {
        summary,
        trajectory,
        localization: robot_localization(&mut sim.world),
        scans: capturer.map(|c| c.scans).unwrap_or_default(),
        log: event_log(&mut sim.world),
        exported,
        interrupted,
    })
}

/// Renders whole camera frames for the recordings on a worker thread when a recording is
/// written and a robot carries a camera ([`crate::record::frames`]).
fn install_frames(
    sim: &mut SimWorld,
    scenario: &Scenario,
    opts: &RunOptions,
    exports: &RunExports,
) -> anyhow::Result<()> {
    let outputs = FrameOutputs {
        raw: exports.mcap.is_some(),
        jpeg: opts.rrd.is_some(),
    };
    let cameras = sim.world.query::<&Camera>().iter(&sim.world).count();
    if cameras == 0 || !(outputs.raw || outputs.jpeg) {
        return Ok(());
    }
    let frames = RecordedFrames::new(scenario.record.camera_rate, outputs)?;
    sim.world.insert_resource(frames);
    let collect = collect_frames.in_set(SimSet::Record).before(record_mcap);
    if outputs.jpeg {
        sim.schedule
            .add_systems((collect, record_frames_rrd.in_set(SimSet::Record)).chain());
    } else {
        sim.schedule.add_systems(collect);
    }
    Ok(())
}

/// The run is over: the camera frames still being rendered go to the recordings; the worker's
/// error, if any.
fn finish_frames(w: &mut World) -> Option<String> {
    let (mut frames, error) = w.remove_resource::<RecordedFrames>()?.finish();
    let now = w.resource::<SimClock>().now();
    if let Some(mut r) = w.get_resource_mut::<RrdRecorder>() {
        log_frames_rrd(&mut r, &mut frames, now);
    }
    if let Some(mut export) = w.get_resource_mut::<McapExport>() {
        export.write_frames(&mut frames);
    }
    error
}

/// The run is over: SLAM systems run their final optimization (before the recording's last
/// frame and the summary read their results).
fn finish_slam(w: &mut World) {
    let mut q = w.query::<&mut Localizers>();
    for mut locs in q.iter_mut(w) {
        for l in locs.items.iter_mut() {
            if let Filter::Scan(e) = &mut l.filter {
                e.finish();
            }
        }
    }
}

fn robot_summaries(w: &mut World) -> Vec<RobotSummary> {
    let mut q = w.query::<(
        &RobotIndex,
        &RobotId,
        &TruePose,
        &RobotMetrics,
        Option<&Behaviour>,
        Option<(&Localizers, &LocalizationSamples)>,
        Option<(&Navigator, &NavOutcome)>,
        Option<(&RoadNavigator, &RoadLocalization, &RoadRunMetrics)>,
    )>();
    let graph = w.get_resource::<RoadMap>().map(|r| r.0.clone());
    let mut rows: Vec<(RobotIndex, RobotSummary)> = q
        .iter(w)
        .map(|(i, id, truth, m, b, loc, nav, road)| {
            let localization = match loc {
                Some((locs, samples)) => locs
                    .items
                    .iter()
                    .map(|l| {
                        let s = samples
                            .per_localizer
                            .iter()
                            .find(|(n, _)| *n == l.name)
                            .map_or(&[][..], |(_, s)| &s[..]);
                        let mut m = LocalizerMetrics::from_samples(l.filter.kind(), s);
                        if let Filter::Scan(e) = &l.filter {
                            let paired = pair_with_truth(s, &e.trajectory());
                            m.final_trajectory = Some(TrajectoryMetrics::from_samples(&paired));
                        }
                        (l.name.clone(), m)
                    })
                    .collect(),
                None => Default::default(),
            };
            let p = truth.pose;
            (
                *i,
                RobotSummary {
                    name: id.0.clone(),
                    distance_m: m.distance_m,
                    collisions: m.collisions.total(),
                    wall_collisions: m.collisions.wall,
                    robot_collisions: m.collisions.robot,
                    person_collisions: m.collisions.person,
                    odometry_drift_m: m.odometry_drift_m,
                    max_odometry_drift_m: m.max_odometry_drift_m,
                    odometry_ate_m: m.odometry_ate_m(),
                    odometry_drift_percent: if m.distance_m > 0.0 {
                        100.0 * m.odometry_drift_m / m.distance_m
                    } else {
                        0.0
                    },
                    odometry_heading_error_rad: m.odometry_heading_error_rad,
                    waypoints_reached: b.map_or(0, |b| b.reached),
                    // a waypoint route's behaviour arrived, or a road route reached its goal
                    route_completed: b.is_some_and(|b| b.status == NavStatus::Arrived)
                        || road.is_some_and(|(_, _, rm)| rm.reached),
                    final_pose: [p.x, p.y, p.theta],
                    localization,
                    navigation: nav.map(|(n, o)| navigation_summary(n, o, m)),
                    road: road
                        .zip(graph.as_deref())
                        .map(|((n, l, rm), g)| crate::summary_road::road_summary(g, n, l, rm)),
                },
            )
        })
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    rows.into_iter().map(|(_, r)| r).collect()
}

fn navigation_summary(n: &Navigator, o: &NavOutcome, m: &RobotMetrics) -> NavigationSummary {
    let nm = &n.metrics;
    let times = &nm.delivery_times_s;
    NavigationSummary {
        tasks: n.tasks.len() as u32,
        tasks_completed: nm.tasks_completed,
        tasks_failed: nm.tasks_failed,
        all_tasks_done: n.finished(),
        deliveries_completed: nm.deliveries_completed,
        delivery_times_s: times.clone(),
        mean_delivery_time_s: (!times.is_empty())
            .then(|| times.iter().sum::<f64>() / times.len() as f64),
        legs: o.legs,
        path_length_m: o.driven_m,
        optimal_length_m: o.optimal_m,
        path_ratio: (o.optimal_m > 0.0).then(|| o.path_ratio()),
        collisions: m.collisions.total(),
        wall_collisions: m.collisions.wall,
        stops: nm.stops,
        waiting_time_s: nm.waiting_time_s,
        replans: nm.replans,
        yields: nm.yields,
        failures: nm
            .failures
            .iter()
            .map(|f| NavigationFailure {
                time_s: f.time,
                task: f.task.clone(),
                reason: f.reason.clone(),
            })
            .collect(),
    }
}

fn robot_localization(w: &mut World) -> Vec<RobotLocalization> {
    let mut q = w.query::<(&RobotIndex, &RobotId, &LocalizationSamples)>();
    let mut rows: Vec<(RobotIndex, RobotLocalization)> = q
        .iter(w)
        .map(|(i, id, s)| {
            (
                *i,
                RobotLocalization {
                    robot: id.0.clone(),
                    localizers: s.per_localizer.clone(),
                },
            )
        })
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    rows.into_iter().map(|(_, r)| r).collect()
}
