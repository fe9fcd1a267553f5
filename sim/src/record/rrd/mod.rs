//! Rerun recording (.rrd, file sink, no viewer needed) with the entity paths of `systems/ARCHITECTURE.md` on the
//! `sim_time` timeline, at configurable rates so long runs stay small:
//! - `world/map`: the occupancy grid (GridMap, ROS conventions, RViz colours), static;
//! - `robots/<name>/truth`: ground-truth pose (arrow) and driven path (line strip);
//! - `robots/<name>/body`: the footprint outline;
//! - `robots/<name>/odometry`: wheel-odometry pose and path;
//! - `robots/<name>/scan`: the latest scan's endpoints in the world frame;
//! - `robots/<name>/sonar`: the latest sonar readings, each finite one drawn as its beam's
//!   outline (sensor → arc across the cone at the measured range), at the scan rate;
//! - `robots/<name>/estimate/<localizer>`: each localizer's pose (arrow, at every estimate it
//!   publishes) and its estimate path (line strip, at the path rate, like the odometry's);
//!   `…/estimate/<localizer>/covariance`: the 2-σ ellipse of the (x, y) covariance and the ±2σ
//!   heading wedge;
//! - `robots/<name>/particles/<localizer>`: MCL particles, DE populations and the Markov grid's
//!   belief cells (see [`belief`] for colours and subsampling). A set is logged only
//!   after a filter update and at most `particle_rate` times per second (default 2: every
//!   0.5 s of simulated time, or at every update when the filter updates more rarely), with at
//!   most `particle_points` points (default 1000; 0 turns particles off), so a 100 000-particle
//!   filter costs the same ~16 kB per set as a small one;
//! - `robots/<name>/error/<localizer>`: position error (m) of every published estimate against
//!   ground truth at its timestamp (the pairs the summary's metrics use), as a scalar series
//!   named `<name> <localizer>`; `robots/<name>/heading_error/<localizer>`: the absolute heading
//!   error (rad), in a subtree of its own so metres and radians never share a plot. The
//!   recorder reads ground truth; the localizers never do. A robot keeps one colour across its
//!   entities, its localizers as shades of it.
//!
//! - `people/<name>`: each walking person as a flat disc of its radius on the floor, labelled
//!   with its name, at the pose rate, and `people/<name>/trail`: its last few metres;
//! - `events` and `robots/<name>/collisions`: the run's events as text-log lines
//!   ([`events`]); `robots/<name>/localization`: when each localizer converged and when it
//!   lost its robot ([`localizer_status`]).
//!
//! Everything is 3-D (z up): the maps below z = 0 (`world/map` at [`MAP_Z`]), everything else
//! on or just above it, so a view from above shows the overlays over the floor plan.

pub mod belief;
pub mod blueprint;
pub mod events;
pub mod localizer_status;
pub mod log_slam;
pub mod navigation;
pub mod outdoor;
mod plugin;
pub mod rows;
pub mod slam;
pub mod stream;

pub use plugin::RrdPlugin;

use crate::record::axis_scale::AxisScale;
use crate::record::path_trace::PathTrace;
use crate::scenario::RecordConfig;
use belief::Cloud;
use bevy_ecs::prelude::*;
use std::collections::VecDeque;
use std::path::Path;
use stream::RrdStream;
use systems::body::{Footprint, Person, PersonId, PersonIndex, TruePose};
use systems::core::clock::RateTimer;
use systems::core::{Pose2, RobotId, RobotIndex, SimClock, wrap_angle};
use systems::eval::LocalizationSamples;
use systems::localization::{Localizer, Localizers, PoseEstimate, WheelOdometry};
use systems::sensors::{LaserScans, LaserTruth, SonarReadings, SonarTruth, Sonars};
use systems::world::{Cell, OccupancyGrid};

/// Height of `world/map`: the map is the floor, everything else is drawn above it (far enough
/// for the depth buffer of a view from 200 m up: overlays a few centimetres above the map
/// flicker into it).
pub const MAP_Z: f64 = -0.3;

/// Points kept in a person's trail (at the pose rate: 3 s at the default 10 Hz).
const TRAIL_POINTS: usize = 30;

#[derive(Resource)]
pub struct RrdRecorder {
    pub(super) rec: RrdStream,
    pose_timer: RateTimer,
    scan_timer: RateTimer,
    path_timer: RateTimer,
    truth_paths: Vec<PathTrace>,
    odom_paths: Vec<PathTrace>,
    /// Per person (by index): the last poses logged.
    trails: Vec<VecDeque<[f32; 3]>>,
    /// Per robot (by index), per localizer (in the robot's order).
    tracks: Vec<Vec<Track>>,
    particle_period: f64,
    particle_points: usize,
    /// The first logging error, reported when the run ends.
    pub error: Option<String>,
    due: Vec<f64>,
    /// What the blueprint is made from: the known part of the map (min x, min y, max x,
    /// max y), the localizer the map shows, and the spread of the plotted errors.
    bounds: Option<[f64; 4]>,
    map_localizer: Option<String>,
    pub(super) position_scale: AxisScale,
    heading_scale: AxisScale,
    drift_scale: AxisScale,
    pub(super) goal_scale: AxisScale,
    /// Per robot (by index): whether its drift series' style was logged.
    drift_styled: Vec<bool>,
}

/// What the recorder keeps per localizer.
#[derive(Default)]
struct Track {
    path: PathTrace,
    /// Simulated time of the last logged particle set.
    particles_at: Option<f64>,
    /// Whether the series styles were logged.
    styled: bool,
    /// Converged or not, for the text log.
    status: localizer_status::Status,
}

/// Robot `index`'s colour ([`crate::record::colours`]).
pub(super) fn colour(index: u32) -> rerun::Color {
    let [r, g, b] = crate::record::colours::robot(index);
    rerun::Color::from_rgb(r, g, b)
}

impl RrdRecorder {
    /// Opens `path` for writing and logs the static map.
    pub fn create(
        path: &Path,
        scenario_name: &str,
        grid: &OccupancyGrid,
        config: &RecordConfig,
    ) -> anyhow::Result<Self> {
        let mut r = RrdRecorder {
            rec: open_recording(path, scenario_name)?,
            pose_timer: RateTimer::new(config.rate, 0.0),
            scan_timer: RateTimer::new(config.scan_rate, 0.0),
            path_timer: RateTimer::new(config.path_rate, 0.0),
            truth_paths: Vec::new(),
            odom_paths: Vec::new(),
            trails: Vec::new(),
            tracks: Vec::new(),
            particle_period: 1.0 / config.particle_rate,
            particle_points: config.particle_points,
            error: None,
            due: Vec::new(),
            bounds: known_bounds(grid),
            map_localizer: config.map_localizer.clone(),
            position_scale: AxisScale::default(),
            heading_scale: AxisScale::default(),
            drift_scale: AxisScale::default(),
            goal_scale: AxisScale::default(),
            drift_styled: Vec::new(),
        };
        r.log_static_world(grid);
        Ok(r)
    }

    pub(super) fn check(&mut self, res: rerun::RecordingStreamResult<()>) {
        if let Err(e) = res {
            self.error.get_or_insert_with(|| e.to_string());
        }
    }

    fn log_static_world(&mut self, grid: &OccupancyGrid) {
        // ROS nav_msgs/OccupancyGrid values, row 0 at the origin corner, as GridMap expects
        let data: Vec<u8> = grid
            .cells
            .iter()
            .map(|c| match c {
                Cell::Free => 0,
                Cell::Occupied => 100,
                Cell::Unknown => 255,
            })
            .collect();
        let map = grid_map(
            data,
            [grid.width, grid.height],
            grid.resolution,
            [grid.origin[0], grid.origin[1], MAP_Z],
            rerun::components::Colormap::RvizMap,
        );
        let res = self.rec.log_static("world/map", &map);
        self.check(res);
    }

    /// Sends the default layout ([`blueprint`]), flushes everything to disk; returns the first
    /// error seen.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        let paths = self.rec.entity_paths();
        let layout = blueprint::default_layout(&blueprint::Inputs {
            paths: &paths,
            map_localizer: self.map_localizer.as_deref(),
            bounds: self.bounds,
            position_axis: self.position_scale.top(0.75, 0.5),
            heading_axis: self.heading_scale.top(0.75, 0.2),
            drift_axis: self.drift_scale.top(1.0, 0.5),
            goal_axis: self.goal_scale.top(1.0, 1.0),
            time_span: Some([0.0, self.rec.latest_secs()]),
        });
        if let Err(e) = blueprint::send(&self.rec, &layout) {
            self.error.get_or_insert_with(|| format!("{e:#}"));
        }
        close_recording(&mut self.rec, self.error.take())
    }
}

/// The extent of the grid's known cells (free or occupied), or None when all are unknown.
fn known_bounds(grid: &OccupancyGrid) -> Option<[f64; 4]> {
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    for (k, c) in grid.cells.iter().enumerate() {
        if *c != Cell::Unknown {
            let (x, y) = (k % grid.width, k / grid.width);
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
    }
    (lo[0] <= hi[0]).then(|| {
        let at = |i: usize, axis: usize| grid.origin[axis] + i as f64 * grid.resolution;
        [
            at(lo[0], 0),
            at(lo[1], 1),
            at(hi[0] + 1, 0),
            at(hi[1] + 1, 1),
        ]
    })
}

/// Ends a recording: everything flushed to the file, the footer written; returns `error` (the
/// first logging error seen) or the file's, naming the file.
pub(super) fn close_recording(rec: &mut RrdStream, error: Option<String>) -> anyhow::Result<()> {
    let closed = rec.close();
    match error.map_or(closed, Err) {
        Err(e) => Err(anyhow::anyhow!("{e}")),
        Ok(()) => Ok(()),
    }
}

/// A scan's end points (+Inf and other non-returns left out) taken from `sensor`, the laser's
/// pose in the frame drawn.
pub(super) fn scan_cloud(
    scan: &systems::sensors::LaserScan,
    sensor: &Pose2,
    c: rerun::Color,
) -> rerun::Points3D {
    rerun::Points3D::new(scan_points(scan, sensor))
        .with_radii([rerun::components::Radius::new_ui_points(1.5)])
        .with_colors([c])
}

/// A scan's end points in the frame drawn (`sensor`: the laser's pose in it).
fn scan_points<'a>(
    scan: &'a systems::sensors::LaserScan,
    sensor: &'a Pose2,
) -> impl Iterator<Item = [f32; 3]> + 'a {
    scan.points().map(|p| {
        let w = sensor.transform_point([p[0] as f64, p[1] as f64]);
        [w[0] as f32, w[1] as f32, 0.0]
    })
}

/// Opens an .rrd file for writing, z up (the floor plan seen from above).
pub fn open_recording(path: &Path, name: &str) -> anyhow::Result<RrdStream> {
    // Chunks are cut by size, not by wall time (the default flushes every 200 ms of wall
    // time, which gives a fast run thousands of tiny chunks of mostly metadata): a quarter
    // of the file size for a run with localizers, and the same chunks whatever the speed.
    let batcher = rerun::log::ChunkBatcherConfig {
        flush_tick: std::time::Duration::from_secs(3600),
        flush_num_bytes: 1024 * 1024,
        ..rerun::log::ChunkBatcherConfig::DEFAULT
    };
    let (sink, file) = stream::file_sink::create(path)?;
    // the SDK starts its batcher and forwarding threads here: at background priority
    let rec = crate::record::priority::in_background(|| {
        rerun::RecordingStreamBuilder::new("sim")
            .recording_name(name)
            .batcher_config(batcher)
            .set_sinks(vec![Box::new(sink) as Box<dyn rerun::sink::LogSink>])
    })
    .map_err(|e| anyhow::anyhow!("{}: cannot create the recording: {e}", path.display()))?;
    rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())
        .map_err(|e| anyhow::anyhow!("{}: cannot write the recording: {e}", path.display()))?;
    Ok(RrdStream::writing_to(rec, file))
}

/// A GridMap of one byte per cell (row 0 at the origin corner, as ROS and GridMap expect).
pub(super) fn grid_map(
    data: Vec<u8>,
    size: [usize; 2],
    resolution: f64,
    origin: [f64; 3],
    colormap: rerun::components::Colormap,
) -> rerun::GridMap {
    rerun::GridMap::new(
        data,
        rerun::components::ImageFormat::from_color_model(
            [size[0] as u32, size[1] as u32],
            rerun::ColorModel::L,
            rerun::ChannelDatatype::U8,
        ),
        resolution as f32,
    )
    .with_translation([origin[0] as f32, origin[1] as f32, origin[2] as f32])
    .with_colormap(colormap)
}

/// A particle set's row.
fn log_cloud(rec: &mut RrdStream, path: &str, c: &Cloud) {
    let radius = rerun::components::Radius::new_ui_points(c.radius);
    rows::points(rec, path, c.points.iter().copied(), radius).with(
        rerun::Points3D::descriptor_colors(),
        c.colors
            .iter()
            .map(|k| rerun::Color::from_rgb(k[0], k[1], k[2])),
    );
}

/// The finite sonar readings in the world frame, from the true base pose at their firing: per
/// sonar, the sensor → an arc across its cone at the measured range → the sensor.
fn sonar_echoes(s: &Sonars, ranges: &[f32], base: &Pose2) -> Vec<Vec<[f32; 3]>> {
    const ARC: usize = 8;
    let cone = s.spec.cone;
    s.mounts
        .iter()
        .zip(ranges)
        .filter(|(_, r)| r.is_finite())
        .map(|(m, &r)| {
            let sensor = base.compose(m);
            let o = [sensor.x as f32, sensor.y as f32, 0.0];
            let arc = (0..=ARC).map(|k| {
                let a = cone * (k as f64 / ARC as f64 - 0.5);
                let w = sensor.transform_point([r as f64 * a.cos(), r as f64 * a.sin()]);
                [w[0] as f32, w[1] as f32, 0.0]
            });
            std::iter::once(o).chain(arc).chain([o]).collect()
        })
        .collect()
}

/// Colour of a robot's `k`-th localizer: a shade of the robot's ([`crate::record::colours`]).
pub(super) fn localizer_colour(robot: u32, k: usize) -> rerun::Color {
    let [r, g, b] = crate::record::colours::localizer(robot, k);
    rerun::Color::from_rgb(r, g, b)
}

impl RrdRecorder {
    /// Logs what localizer `k` of robot `robot` published this tick: estimate, covariance, error
    /// series and (when due) its particle set; the estimate path when `paths_due`.
    fn record_localizer(
        &mut self,
        base: &str,
        (robot, k): (usize, usize),
        l: &Localizer,
        samples: &[systems::eval::Sample],
        now: f64,
        paths_due: bool,
    ) {
        if self.tracks.len() <= robot {
            self.tracks.resize_with(robot + 1, Vec::new);
        }
        if self.tracks[robot].len() <= k {
            self.tracks[robot].resize_with(k + 1, Track::default);
        }
        let name = &l.name;
        let c = localizer_colour(robot as u32, k);
        let est_path = format!("{base}/estimate/{name}");
        let err_path = format!("{base}/error/{name}");
        let heading_path = format!("{base}/heading_error/{name}");
        if !self.tracks[robot][k].styled {
            self.tracks[robot][k].styled = true;
            // `robots/r1` → "r1 mcl": the legend names the robot and the localizer
            let label = format!("{} {name}", base.trim_start_matches("robots/"));
            for path in [&err_path, &heading_path] {
                let res = self.rec.log_static(
                    path.as_str(),
                    &rerun::SeriesLines::new()
                        .with_names([label.as_str()])
                        .with_colors([c]),
                );
                self.check(res);
            }
        }
        // the eval system paired this tick's estimates with ground truth: they are the tail
        let fresh = l.fresh.len();
        let paired = samples.len() >= fresh
            && l.fresh.last().map(|e| e.stamp) == samples.last().map(|s| s.t);
        if paired {
            for s in &samples[samples.len() - fresh..] {
                self.rec.set_duration_secs("sim_time", s.t);
                let e = s.position_error();
                rows::scalar(&mut self.rec, &err_path, e);
                let dth = wrap_angle(s.estimate.theta - s.truth.theta).abs();
                rows::scalar(&mut self.rec, &heading_path, dth);
                self.position_scale.push(e);
                self.heading_scale.push(dth);
                if let Some(change) = self.tracks[robot][k].status.update(s) {
                    let robot_name = base.trim_start_matches("robots/");
                    let level = match change {
                        localizer_status::Change::Converged { .. } => rerun::TextLogLevel::INFO,
                        localizer_status::Change::Lost { .. } => rerun::TextLogLevel::WARN,
                    };
                    let res = self.rec.log(
                        format!("{base}/localization"),
                        &rerun::TextLog::new(change.line(robot_name, name)).with_level(level),
                    );
                    self.check(res);
                }
            }
        }
        for e in &l.fresh {
            self.tracks[robot][k].path.push(&e.estimate.pose, e.stamp);
        }
        if let Some(e) = l.fresh.last() {
            self.rec.set_duration_secs("sim_time", e.stamp);
            self.log_estimate(&est_path, &e.estimate, c);
            let track = &self.tracks[robot][k];
            let particles_due = self.particle_points > 0
                && track
                    .particles_at
                    .is_none_or(|t| e.stamp - t >= self.particle_period - 1e-9);
            if particles_due
                && let Some(set) = belief::filter_cloud(&l.filter, self.particle_points)
            {
                self.tracks[robot][k].particles_at = Some(e.stamp);
                log_cloud(&mut self.rec, &format!("{base}/particles/{name}"), &set);
            }
        }
        self.rec.set_duration_secs("sim_time", now);
        if paths_due {
            let strips = self.tracks[robot][k].path.take_new();
            if !strips.is_empty() {
                rows::path(&mut self.rec, &format!("{est_path}/path"), strips, c);
            }
        }
    }

    fn log_estimate(&mut self, path: &str, e: &PoseEstimate, c: rerun::Color) {
        rows::arrow(&mut self.rec, path, &e.pose, 0.45, c);
        let p = &e.pose;
        let strips: Vec<Vec<[f32; 3]>> = [
            belief::ellipse_2sigma(p.x, p.y, &e.covariance, 36),
            belief::heading_wedge(p.x, p.y, p.theta, e.covariance[2][2], 0.6),
        ]
        .into_iter()
        .flatten()
        .collect();
        if !strips.is_empty() {
            rows::strips(&mut self.rec, &format!("{path}/covariance"), strips, c);
        }
    }
}

/// Record: log poses, paths and scans when their timers are due, and what the localizers
/// published this tick.
#[allow(clippy::type_complexity)]
pub fn record_rrd(
    clock: Res<SimClock>,
    mut r: ResMut<RrdRecorder>,
    robots: Query<(
        &RobotIndex,
        &RobotId,
        &TruePose,
        &Footprint,
        Option<&WheelOdometry>,
        Option<(&LaserScans, &LaserTruth)>,
        Option<(&Localizers, &LocalizationSamples)>,
        Option<(&Sonars, &SonarReadings, &SonarTruth)>,
    )>,
    people: Query<(&PersonIndex, &PersonId, &Person, &TruePose)>,
) {
    let r = &mut *r;
    let (start, now) = (clock.start(), clock.now());
    let mut due = std::mem::take(&mut r.due);
    r.pose_timer.due(start, now, &mut due);
    let poses_due = !due.is_empty();
    r.scan_timer.due(start, now, &mut due);
    let scans_due = !due.is_empty();
    r.path_timer.due(start, now, &mut due);
    let paths_due = !due.is_empty();
    r.due = due;
    let published = robots.iter().any(|q| {
        q.6.is_some_and(|(l, _)| l.items.iter().any(|l| !l.fresh.is_empty()))
    });
    if !(poses_due || scans_due || paths_due || published) {
        return;
    }
    r.rec.set_duration_secs("sim_time", now);
    if poses_due {
        record_people(r, &people);
    }
    let mut sorted: Vec<_> = robots.iter().collect();
    sorted.sort_by_key(|(i, ..)| **i);
    for (idx, id, truth, footprint, odom, laser, locs, sonar) in sorted {
        let i = idx.0 as usize;
        if r.truth_paths.len() <= i {
            r.truth_paths.resize_with(i + 1, PathTrace::default);
            r.odom_paths.resize_with(i + 1, PathTrace::default);
        }
        let base = format!("robots/{}", id.0);
        if let Some((locs, samples)) = locs {
            for (k, l) in locs.items.iter().enumerate() {
                let s = samples
                    .per_localizer
                    .get(k)
                    .filter(|(n, _)| *n == l.name)
                    .map_or(&[][..], |(_, s)| &s[..]);
                r.record_localizer(&base, (i, k), l, s, now, paths_due);
            }
        }
        if !(poses_due || scans_due || paths_due) {
            continue;
        }
        r.truth_paths[i].push(&truth.pose, now);
        if let Some(o) = odom {
            r.odom_paths[i].push(&o.pose, now);
        }
        let c = colour(idx.0);
        let grey = rerun::Color::from_rgb(150, 150, 150);
        if poses_due {
            rows::arrow(&mut r.rec, &format!("{base}/truth"), &truth.pose, 0.5, c);
            let outline = footprint.outline(&truth.pose);
            let closed = outline
                .iter()
                .chain(outline.first())
                .map(|p| [p[0] as f32, p[1] as f32, 0.0]);
            rows::strips(&mut r.rec, &format!("{base}/body"), [closed], c).with(
                rerun::LineStrips3D::descriptor_labels(),
                [rerun::components::Text::from(id.0.as_str())],
            );
            if let Some(o) = odom {
                rows::arrow(&mut r.rec, &format!("{base}/odometry"), &o.pose, 0.4, grey);
                let drift = (o.pose.x - truth.pose.x).hypot(o.pose.y - truth.pose.y);
                let drift_path = format!("{base}/odometry/drift");
                if !r.drift_styled.get(i).copied().unwrap_or(false) {
                    if r.drift_styled.len() <= i {
                        r.drift_styled.resize(i + 1, false);
                    }
                    r.drift_styled[i] = true;
                    let res = r.rec.log_static(
                        drift_path.as_str(),
                        &rerun::SeriesLines::new()
                            .with_names([format!("{} odometry", id.0)])
                            .with_colors([c]),
                    );
                    r.check(res);
                }
                rows::scalar(&mut r.rec, &drift_path, drift);
                r.drift_scale.push(drift);
            }
        }
        if paths_due {
            let strips = r.truth_paths[i].take_new();
            if !strips.is_empty() {
                rows::path(&mut r.rec, &format!("{base}/truth/path"), strips, c);
            }
            if odom.is_some() {
                let strips = r.odom_paths[i].take_new();
                if !strips.is_empty() {
                    rows::path(&mut r.rec, &format!("{base}/odometry/path"), strips, grey);
                }
            }
        }
        if scans_due
            && let Some((scans, lt)) = laser
            && let (Some(scan), Some(pose)) = (scans.latest(), &lt.latest)
        {
            rows::points(
                &mut r.rec,
                &format!("{base}/scan"),
                scan_points(scan, pose),
                rerun::components::Radius::new_ui_points(1.5),
            )
            .with(rerun::Points3D::descriptor_colors(), [c]);
        }
        if scans_due
            && let Some((sonars, readings, st)) = sonar
            && let Some(pose) = &st.latest
        {
            let echoes = sonar_echoes(sonars, &readings.latest, pose);
            rows::strips(&mut r.rec, &format!("{base}/sonar"), echoes, c);
        }
    }
}

/// Logs every person (in index order) as a flat disc of its radius on the floor, labelled with
/// its name, and its recent trail.
fn record_people(
    r: &mut RrdRecorder,
    people: &Query<(&PersonIndex, &PersonId, &Person, &TruePose)>,
) {
    let mut sorted: Vec<_> = people.iter().collect();
    sorted.sort_by_key(|(i, ..)| **i);
    let c = rerun::Color::from_rgb(230, 90, 40);
    for (idx, id, person, truth) in sorted {
        let i = idx.0 as usize;
        if r.trails.len() <= i {
            r.trails.resize_with(i + 1, VecDeque::new);
        }
        let p = [truth.pose.x as f32, truth.pose.y as f32, 0.0];
        let trail = &mut r.trails[i];
        if trail.len() == TRAIL_POINTS {
            trail.pop_front();
        }
        trail.push_back(p);
        let base = format!("people/{}", id.0);
        let radius = person.radius as f32;
        r.rec
            .row(&base)
            .with(
                rerun::Ellipsoids3D::descriptor_centers(),
                [rerun::components::Translation3D::from(p)],
            )
            .with(
                rerun::Ellipsoids3D::descriptor_half_sizes(),
                [rerun::components::HalfSize3D::from([radius, radius, 0.02])],
            )
            .with(
                rerun::Ellipsoids3D::descriptor_fill_mode(),
                [rerun::components::FillMode::Solid],
            )
            .with(rerun::Ellipsoids3D::descriptor_colors(), [c])
            .with(
                rerun::Ellipsoids3D::descriptor_labels(),
                [rerun::components::Text::from(id.0.as_str())],
            );
        if trail.len() >= 2 {
            let strip: Vec<[f32; 3]> = trail.iter().copied().collect();
            rows::strips(&mut r.rec, &format!("{base}/trail"), [strip], c);
        }
    }
}
