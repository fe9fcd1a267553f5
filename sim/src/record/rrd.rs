//! Rerun recording (.rrd, file sink, no viewer needed) with the entity paths of DESIGN.md on the
//! `sim_time` timeline, at configurable rates so long runs stay small:
//! - `world/map`: the occupancy grid (GridMap, ROS conventions, RViz colours), static;
//! - `robots/<name>/truth`: ground-truth pose (arrow) and driven path (line strip);
//! - `robots/<name>/body`: the footprint outline;
//! - `robots/<name>/odometry`: wheel-odometry pose and path;
//! - `robots/<name>/scan`: the latest scan's endpoints in the world frame.
//!
//! Everything is 3-D with z = 0 (z up), so the default 3-D view shows the floor plan from above.

use crate::scenario::RecordConfig;
use bevy_ecs::prelude::*;
use std::path::Path;
use systems::body::{Footprint, TruePose};
use systems::core::clock::RateTimer;
use systems::core::{Pose2, RobotId, RobotIndex, SimClock};
use systems::localization::WheelOdometry;
use systems::sensors::{LaserScans, LaserTruth};
use systems::world::{Cell, OccupancyGrid};

/// Minimum spacing of recorded path points (m).
const PATH_SPACING: f64 = 0.05;

#[derive(Resource)]
pub struct RrdRecorder {
    rec: rerun::RecordingStream,
    pose_timer: RateTimer,
    scan_timer: RateTimer,
    path_timer: RateTimer,
    truth_paths: Vec<Vec<[f32; 3]>>,
    odom_paths: Vec<Vec<[f32; 3]>>,
    /// The first logging error, reported when the run ends.
    pub error: Option<String>,
    due: Vec<f64>,
}

fn colour(index: u32) -> rerun::Color {
    const PALETTE: [[u8; 3]; 8] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [23, 190, 207],
    ];
    let c = PALETTE[index as usize % PALETTE.len()];
    rerun::Color::from_rgb(c[0], c[1], c[2])
}

fn push_point(path: &mut Vec<[f32; 3]>, p: &Pose2) {
    let q = [p.x as f32, p.y as f32, 0.0];
    match path.last() {
        Some(l) if ((l[0] - q[0]).powi(2) + (l[1] - q[1]).powi(2)).sqrt() < PATH_SPACING as f32 => {
        }
        _ => path.push(q),
    }
}

impl RrdRecorder {
    /// Opens `path` for writing and logs the static map.
    pub fn create(
        path: &Path,
        scenario_name: &str,
        grid: &OccupancyGrid,
        config: &RecordConfig,
    ) -> anyhow::Result<Self> {
        let rec = rerun::RecordingStreamBuilder::new("sim")
            .recording_name(scenario_name)
            .save(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot create the recording: {e}", path.display()))?;
        let mut r = RrdRecorder {
            rec,
            pose_timer: RateTimer::new(config.rate, 0.0),
            scan_timer: RateTimer::new(config.scan_rate, 0.0),
            path_timer: RateTimer::new(config.path_rate, 0.0),
            truth_paths: Vec::new(),
            odom_paths: Vec::new(),
            error: None,
            due: Vec::new(),
        };
        r.log_static_world(grid);
        Ok(r)
    }

    fn check(&mut self, res: rerun::RecordingStreamResult<()>) {
        if let Err(e) = res {
            self.error.get_or_insert_with(|| e.to_string());
        }
    }

    fn log_static_world(&mut self, grid: &OccupancyGrid) {
        let res = self
            .rec
            .log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP());
        self.check(res);
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
        let map = rerun::GridMap::new(
            data,
            rerun::components::ImageFormat::from_color_model(
                [grid.width as u32, grid.height as u32],
                rerun::ColorModel::L,
                rerun::ChannelDatatype::U8,
            ),
            grid.resolution as f32,
        )
        .with_translation([grid.origin[0] as f32, grid.origin[1] as f32, -0.01])
        .with_colormap(rerun::components::Colormap::RvizMap);
        let res = self.rec.log_static("world/map", &map);
        self.check(res);
    }

    /// Flushes everything to disk; returns the first error seen.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        let res = self.rec.flush_blocking();
        if let Err(e) = res {
            self.error.get_or_insert_with(|| e.to_string());
        }
        match self.error.take() {
            Some(e) => Err(anyhow::anyhow!("writing the recording failed: {e}")),
            None => Ok(()),
        }
    }
}

fn arrow(p: &Pose2, len: f32, c: rerun::Color) -> rerun::Arrows3D {
    rerun::Arrows3D::from_vectors([[len * p.theta.cos() as f32, len * p.theta.sin() as f32, 0.0]])
        .with_origins([[p.x as f32, p.y as f32, 0.0]])
        .with_colors([c])
}

/// Record: log poses, paths and scans when their timers are due.
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
    )>,
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
    if !(poses_due || scans_due || paths_due) {
        return;
    }
    r.rec.set_duration_secs("sim_time", now);
    let mut sorted: Vec<_> = robots.iter().collect();
    sorted.sort_by_key(|(i, ..)| **i);
    for (idx, id, truth, footprint, odom, laser) in sorted {
        let i = idx.0 as usize;
        if r.truth_paths.len() <= i {
            r.truth_paths.resize_with(i + 1, Vec::new);
            r.odom_paths.resize_with(i + 1, Vec::new);
        }
        push_point(&mut r.truth_paths[i], &truth.pose);
        if let Some(o) = odom {
            push_point(&mut r.odom_paths[i], &o.pose);
        }
        let c = colour(idx.0);
        let base = format!("robots/{}", id.0);
        if poses_due {
            let res = r
                .rec
                .log(format!("{base}/truth"), &arrow(&truth.pose, 0.5, c));
            r.check(res);
            let mut outline: Vec<[f32; 3]> = footprint
                .outline(&truth.pose)
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32, 0.0])
                .collect();
            outline.push(outline[0]);
            let body = rerun::LineStrips3D::new([outline])
                .with_colors([c])
                .with_labels([id.0.as_str()]);
            let res = r.rec.log(format!("{base}/body"), &body);
            r.check(res);
            if let Some(o) = odom {
                let grey = rerun::Color::from_rgb(150, 150, 150);
                let res = r
                    .rec
                    .log(format!("{base}/odometry"), &arrow(&o.pose, 0.4, grey));
                r.check(res);
            }
        }
        if paths_due {
            let strip = rerun::LineStrips3D::new([r.truth_paths[i].clone()]).with_colors([c]);
            let res = r.rec.log(format!("{base}/truth"), &strip);
            r.check(res);
            if odom.is_some() {
                let strip = rerun::LineStrips3D::new([r.odom_paths[i].clone()])
                    .with_colors([rerun::Color::from_rgb(150, 150, 150)]);
                let res = r.rec.log(format!("{base}/odometry"), &strip);
                r.check(res);
            }
        }
        if scans_due
            && let Some((scans, lt)) = laser
            && let (Some(scan), Some(pose)) = (&scans.latest, &lt.latest)
        {
            let pts: Vec<[f32; 3]> = scan
                .points()
                .map(|p| {
                    let w = pose.transform_point([p[0] as f64, p[1] as f64]);
                    [w[0] as f32, w[1] as f32, 0.0]
                })
                .collect();
            let cloud = rerun::Points3D::new(pts)
                .with_radii([0.03])
                .with_colors([c]);
            let res = r.rec.log(format!("{base}/scan"), &cloud);
            r.check(res);
        }
    }
}
