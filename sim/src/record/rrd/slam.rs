//! SLAM systems in the recording, for `sim run` and `sim slam` alike. Under
//! `robots/<name>/slam` — or `robots/<name>/slam/<slam name>` when the robot runs several SLAM
//! systems ([`slam_entity`]):
//!
//! - `…/map`: the map built so far (GridMap in the SLAM's map frame, P(occupied) as ROS
//!   percentages with RViz colours, never-observed cells unknown), every [`MAP_PERIOD_S`] of
//!   simulated time (`[record] slam_rate`, `sim slam --slam-rate`) and at the end, so it grows
//!   over the timeline;
//! - `…/trajectory`: the SLAM's best trajectory so far (line strip; optimized for graph SLAM);
//! - `…/graph`: the pose-graph edges, for systems that keep a graph: sequential and local edges
//!   thin grey, accepted loop closures thick bright green, rejected candidates red; and
//!   `…/graph/nodes`, the node poses;
//! - `…/scan`: the latest scan's end points placed by the SLAM's own pose (map frame), at the
//!   scan rate.
//!
//! Map, trajectory and graph share one cadence: each is re-logged whole, so their cost is one
//! copy of the map every 2 s however fast the SLAM runs — plus whatever the SLAM system spends
//! to produce its map: graph SLAM rebuilds its map from every node's scan after each
//! optimization, which doubles the CPU time of a recorded hospital_loop run at the default rate
//! (lower `slam_rate` for long graph SLAM runs).

use super::stream::RrdStream;
use super::{RrdRecorder, grid_map, scan_cloud};
use bevy_ecs::prelude::*;
use systems::core::clock::RateTimer;
use systems::core::{Pose2, RobotId, RobotIndex, SimClock};
use systems::localization::{Filter, GraphEdgeKind, GraphView, Localizers, ScanEstimator};
use systems::matching::ProbGrid;
use systems::sensors::{Laser, LaserScan, LaserScans};

/// Default seconds of simulated (or log) time between two logs of a SLAM's map, trajectory and
/// graph (`[record] slam_rate` sets it in scenarios).
pub const MAP_PERIOD_S: f64 = 2.0;

/// Height of SLAM maps: above `world/map` and the costmap, below everything else.
const MAP_Z: f64 = -0.15;

/// The entity path of a robot's SLAM system: `robots/<robot>/slam` when it is the robot's only
/// one, `robots/<robot>/slam/<slam>` when the robot runs `count` > 1.
pub fn slam_entity(robot: &str, slam: &str, count: usize) -> String {
    if count > 1 {
        format!("robots/{robot}/slam/{slam}")
    } else {
        format!("robots/{robot}/slam")
    }
}

/// A probability map as ROS `nav_msgs/OccupancyGrid` bytes: P(occupied) in percent, 255
/// (−1, unknown) for cells never observed (P = 0.5 exactly, log-odds 0).
pub fn map_bytes(map: &ProbGrid) -> Vec<u8> {
    map.p
        .iter()
        .map(|&p| {
            if p == 0.5 || !p.is_finite() {
                255
            } else {
                (p.clamp(0.0, 1.0) * 100.0).round() as u8
            }
        })
        .collect()
}

/// Edge colour and line radius (UI points) by kind: loop closures stand out.
pub fn edge_style(kind: GraphEdgeKind) -> ([u8; 3], f32) {
    match kind {
        GraphEdgeKind::Sequential | GraphEdgeKind::Local => ([150, 150, 150], 0.5),
        GraphEdgeKind::LoopClosure => ([40, 230, 90], 2.0),
        GraphEdgeKind::Rejected => ([220, 40, 40], 1.0),
    }
}

fn xyz(p: &Pose2) -> [f32; 3] {
    [p.x as f32, p.y as f32, 0.0]
}

/// Logs map, trajectory and graph of `est` under `base` at the stream's current time.
pub fn log_slam_state(
    rec: &mut RrdStream,
    base: &str,
    est: &dyn ScanEstimator,
) -> rerun::RecordingStreamResult<()> {
    if let Some(map) = est.map() {
        let grid = grid_map(
            map_bytes(&map),
            [map.width, map.height],
            map.resolution,
            [map.origin[0], map.origin[1], MAP_Z],
            rerun::components::Colormap::RvizMap,
        );
        rec.log(format!("{base}/map"), &grid)?;
    }
    let path: Vec<[f32; 3]> = est.trajectory().iter().map(|(_, p)| xyz(p)).collect();
    if path.len() >= 2 {
        let strip = rerun::LineStrips3D::new([path])
            .with_colors([rerun::Color::from_rgb(255, 200, 40)])
            .with_radii([rerun::components::Radius::new_ui_points(1.0)]);
        rec.log(format!("{base}/trajectory"), &strip)?;
    }
    if let Some(g) = est.graph() {
        log_graph(rec, base, &g)?;
    }
    Ok(())
}

fn log_graph(rec: &mut RrdStream, base: &str, g: &GraphView) -> rerun::RecordingStreamResult<()> {
    // accepted closures last, so they are drawn over the others
    let mut edges: Vec<_> = g
        .edges
        .iter()
        .filter(|e| e.from < g.nodes.len() && e.to < g.nodes.len())
        .collect();
    edges.sort_by_key(|e| matches!(e.kind, GraphEdgeKind::LoopClosure));
    let strips = edges
        .iter()
        .map(|e| [xyz(&g.nodes[e.from]), xyz(&g.nodes[e.to])]);
    let styles: Vec<_> = edges.iter().map(|e| edge_style(e.kind)).collect();
    let lines = rerun::LineStrips3D::new(strips)
        .with_colors(
            styles
                .iter()
                .map(|(c, _)| rerun::Color::from_rgb(c[0], c[1], c[2])),
        )
        .with_radii(
            styles
                .iter()
                .map(|(_, r)| rerun::components::Radius::new_ui_points(*r)),
        );
    rec.log(format!("{base}/graph"), &lines)?;
    let nodes = rerun::Points3D::new(g.nodes.iter().map(xyz))
        .with_radii([rerun::components::Radius::new_ui_points(1.5)])
        .with_colors([rerun::Color::from_rgb(255, 200, 40)]);
    rec.log(format!("{base}/graph/nodes"), &nodes)
}

/// Logs the end points of `scan`, taken from `sensor` (the laser's pose in the SLAM's map frame).
pub fn log_slam_scan(
    rec: &mut RrdStream,
    base: &str,
    scan: &LaserScan,
    sensor: &Pose2,
) -> rerun::RecordingStreamResult<()> {
    let orange = rerun::Color::from_rgb(255, 140, 0);
    rec.log(format!("{base}/scan"), &scan_cloud(scan, sensor, orange))
}

/// When a SLAM system's state was last logged, and how often it is.
#[derive(Clone, Debug)]
pub struct SlamTrack {
    /// Seconds between logs (infinite: only at the end).
    period: f64,
    state_at: Option<f64>,
}

impl SlamTrack {
    /// Logs `rate` times per second (0: none until the end).
    pub fn new(rate: f64) -> Self {
        SlamTrack {
            period: if rate > 0.0 {
                1.0 / rate
            } else {
                f64::INFINITY
            },
            state_at: None,
        }
    }

    /// True (and remembered) when the state is due at time `t`.
    pub fn state_due(&mut self, t: f64) -> bool {
        if self.period.is_infinite() {
            return false;
        }
        let due = self.state_at.is_none_or(|a| t - a >= self.period - 1e-9);
        if due {
            self.state_at = Some(t);
        }
        due
    }
}

/// What `sim run` keeps to record its robots' SLAM systems.
#[derive(Resource)]
pub struct SlamRecording {
    scan_timer: RateTimer,
    slam_rate: f64,
    due: Vec<f64>,
    /// (robot index, localizer index) → track.
    tracks: Vec<((u32, usize), SlamTrack)>,
}

impl SlamRecording {
    /// Scans at `scan_rate` per second, the rest at `slam_rate` (the scenario's `[record]`).
    pub fn new(scan_rate: f64, slam_rate: f64) -> Self {
        SlamRecording {
            scan_timer: RateTimer::new(scan_rate, 0.0),
            slam_rate,
            due: Vec::new(),
            tracks: Vec::new(),
        }
    }

    fn track(&mut self, key: (u32, usize)) -> &mut SlamTrack {
        let i = match self.tracks.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                self.tracks.push((key, SlamTrack::new(self.slam_rate)));
                self.tracks.len() - 1
            }
        };
        &mut self.tracks[i].1
    }
}

/// What the recorder reads of a robot (query data).
type SlamRobot = (
    &'static RobotIndex,
    &'static RobotId,
    &'static Localizers,
    Option<(&'static LaserScans, &'static Laser)>,
);

/// One row of that query.
type SlamRow<'a> = (
    &'a RobotIndex,
    &'a RobotId,
    &'a Localizers,
    Option<(&'a LaserScans, &'a Laser)>,
);

/// The SLAM systems of a robot: (localizer index, estimator).
fn slams(locs: &Localizers) -> Vec<(usize, &dyn ScanEstimator)> {
    locs.items
        .iter()
        .enumerate()
        .filter_map(|(k, l)| match &l.filter {
            Filter::Scan(e) => Some((k, e.as_ref())),
            _ => None,
        })
        .collect()
}

/// Record: every SLAM system's map, trajectory and graph when due, and its view of the latest
/// scan at the scan rate. With `all_now`, every state is logged (the end of the run).
fn record(
    r: &mut RrdRecorder,
    s: &mut SlamRecording,
    now: f64,
    scans_due: bool,
    all_now: bool,
    robots: &mut [SlamRow],
) {
    robots.sort_by_key(|(i, ..)| **i);
    r.rec.set_duration_secs("sim_time", now);
    for (idx, id, locs, laser) in robots.iter() {
        let list = slams(locs);
        for &(k, est) in &list {
            let base = slam_entity(&id.0, &locs.items[k].name, list.len());
            if all_now | s.track((idx.0, k)).state_due(now) {
                let res = log_slam_state(&mut r.rec, &base, est);
                r.check(res);
            }
            if scans_due
                && let Some((scans, laser)) = laser
                && let (Some(scan), Some(e)) = (scans.latest(), est.estimate())
            {
                let res =
                    log_slam_scan(&mut r.rec, &base, scan, &e.pose.compose(&laser.spec.mount));
                r.check(res);
            }
        }
    }
}

/// Record set: the SLAM systems' entities (installed with the recorder when a robot has SLAM).
pub fn record_slam(
    clock: Res<SimClock>,
    mut r: ResMut<RrdRecorder>,
    mut s: ResMut<SlamRecording>,
    robots: Query<SlamRobot>,
) {
    let (start, now) = (clock.start(), clock.now());
    let s = &mut *s;
    let mut due = std::mem::take(&mut s.due);
    s.scan_timer.due(start, now, &mut due);
    let scans_due = !due.is_empty();
    s.due = due;
    let mut rows: Vec<_> = robots.iter().collect();
    record(&mut r, s, now, scans_due, false, &mut rows);
}

/// Logs every SLAM system's final state (after the last tick, before the recording closes).
pub fn record_slam_final(world: &mut World) {
    let now = world.resource::<SimClock>().start();
    world.resource_scope(|world, mut r: Mut<RrdRecorder>| {
        world.resource_scope(|world, mut s: Mut<SlamRecording>| {
            let mut q = world.query::<SlamRobot>();
            let mut rows: Vec<_> = q.iter(world).collect();
            record(&mut r, &mut s, now, false, true, &mut rows);
        });
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entity_paths_and_styles() {
        assert_eq!(slam_entity("r1", "scan_to_map", 1), "robots/r1/slam");
        assert_eq!(slam_entity("r1", "g", 2), "robots/r1/slam/g");
        let (grey, thin) = edge_style(GraphEdgeKind::Sequential);
        let (green, thick) = edge_style(GraphEdgeKind::LoopClosure);
        let (red, _) = edge_style(GraphEdgeKind::Rejected);
        assert!(thick > thin && grey != green && red[0] > red[1]);
        let mut g = ProbGrid::new(3, 1, 0.1, [0.0, 0.0], 0.5);
        g.p[1] = 0.2;
        g.p[2] = 0.97;
        assert_eq!(map_bytes(&g), vec![255, 20, 97]);
    }

    #[test]
    fn state_is_due_every_period() {
        let mut t = SlamTrack::new(1.0 / MAP_PERIOD_S);
        let due: Vec<bool> = [0.0, 1.0, 1.99999999999, 2.5, 4.0]
            .iter()
            .map(|&x| t.state_due(x))
            .collect();
        assert_eq!(due, vec![true, false, true, false, true]);
        let mut end_only = SlamTrack::new(0.0);
        assert!(!end_only.state_due(0.0) && !end_only.state_due(100.0));
    }
}
