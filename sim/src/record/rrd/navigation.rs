//! Navigation in the Rerun recording:
//! - `world/costmap`: the navigation costmap as a GridMap in ROS `costmap_2d` publisher values
//!   (0 free … 99 inscribed, 100 lethal; RViz "costmap" colours), logged at the start and
//!   again whenever a door changes it;
//! - `robots/<name>/path`: the planned path (line strip), whenever the navigator gets a new one;
//! - `robots/<name>/goal`: the current goal (a labelled point);
//! - `robots/<name>/task`: the task status as a text log line whenever it changes, and every
//!   navigation event (stops, re-plans, giving way, failures) as a text log line with a level;
//! - `robots/<name>/stops`: a point where the robot stopped for an obstacle;
//! - `robots/<name>/goal_distance`: the distance left to the current goal along the planned
//!   path (m; nav2's `distance_remaining`), a series named `<name> to goal`, every
//!   [`PROGRESS_PERIOD_S`] while the robot has a goal.
//!
//! Positions are the robot's BELIEF (what it navigates by), like the planner sees them.

use super::RrdRecorder;
use bevy_ecs::prelude::*;
use rerun::components::Radius;
use systems::core::{RobotId, RobotIndex, SimClock};
use systems::localization::NavBelief;
use systems::navigation::{Costmap, NavCostmaps, Navigator};

/// Simulated seconds between two values of a robot's distance to its goal.
pub const PROGRESS_PERIOD_S: f64 = 0.5;

/// What has been logged already.
#[derive(Resource, Default)]
pub struct NavRecordState {
    costmap_version: Option<u64>,
    /// Per robot index: (path serial, events logged, last status text).
    robots: Vec<(u64, usize, String)>,
    /// Per robot index: when its distance to the goal is due next (None before its first).
    progress_due: Vec<Option<f64>>,
}

/// The length of `path` from the vertex nearest to `at`, plus the distance to that vertex.
pub fn distance_remaining(path: &[[f64; 2]], at: [f64; 2]) -> Option<f64> {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let (k, first) = path
        .iter()
        .enumerate()
        .map(|(k, p)| (k, d(*p, at)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(first + path[k..].windows(2).map(|w| d(w[0], w[1])).sum::<f64>())
}

/// ROS `costmap_2d` publisher translation of a cost byte to an OccupancyGrid value.
fn ros_value(cost: u8) -> u8 {
    match cost {
        0 => 0,
        253 => 99,
        254 => 100,
        255 => 255,
        c => (1 + (97 * (c as u32 - 1)) / 251) as u8,
    }
}

fn costmap_grid(map: &Costmap) -> rerun::GridMap {
    let data: Vec<u8> = map.costs.iter().map(|&c| ros_value(c)).collect();
    super::grid_map(
        data,
        [map.width, map.height],
        map.resolution,
        [map.origin[0], map.origin[1], -0.2],
        rerun::components::Colormap::RvizCostmap,
    )
}

/// Record: the navigation entities of every robot with tasks.
pub fn record_navigation(
    clock: Res<SimClock>,
    mut r: ResMut<RrdRecorder>,
    mut state: Local<NavRecordState>,
    costmaps: Option<Res<NavCostmaps>>,
    robots: Query<(&RobotIndex, &RobotId, &Navigator, &NavBelief)>,
) {
    let Some(costmaps) = costmaps else {
        return;
    };
    let r = &mut *r;
    let now = clock.now();
    if state.costmap_version != Some(costmaps.version) {
        state.costmap_version = Some(costmaps.version);
        r.rec.set_duration_secs("sim_time", now);
        let res = r.rec.log("world/costmap", &costmap_grid(costmaps.get(0)));
        r.check(res);
    }
    let mut sorted: Vec<_> = robots.iter().collect();
    sorted.sort_by_key(|(i, ..)| **i);
    for (idx, id, nav, belief) in sorted {
        let i = idx.0 as usize;
        if state.robots.len() <= i {
            state.robots.resize(i + 1, (0, 0, String::new()));
            state.progress_due.resize(i + 1, None);
        }
        let base = format!("robots/{}", id.0);
        let due = state.progress_due[i];
        if nav.goal.is_some()
            && due.is_none_or(|t| now >= t - 1e-9)
            && let Some(left) = distance_remaining(&nav.path, [belief.pose.x, belief.pose.y])
        {
            let path = format!("{base}/goal_distance");
            if due.is_none() {
                let res = r.rec.log_static(
                    path.as_str(),
                    &rerun::SeriesLines::new()
                        .with_names([format!("{} to goal", id.0)])
                        .with_colors([super::colour(idx.0)]),
                );
                r.check(res);
            }
            state.progress_due[i] = Some(now + PROGRESS_PERIOD_S);
            r.rec.set_duration_secs("sim_time", now);
            super::rows::scalar(&mut r.rec, &path, left);
            r.goal_scale.push(left);
        }
        let status = nav.status_text();
        let (serial, logged, last) = &mut state.robots[i];
        let changed = *serial != nav.path_serial || *logged < nav.events.len() || *last != status;
        if !changed {
            continue;
        }
        r.rec.set_duration_secs("sim_time", now);
        if *serial != nav.path_serial {
            *serial = nav.path_serial;
            let pts: Vec<[f32; 3]> = nav
                .path
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32, 0.02])
                .collect();
            let res = r.rec.log(
                format!("{base}/path"),
                &rerun::LineStrips3D::new([pts])
                    .with_radii([Radius::new_ui_points(1.5)])
                    .with_colors([rerun::Color::from_rgb(40, 200, 80)]),
            );
            r.check(res);
            if let Some(g) = &nav.goal {
                let res = r.rec.log(
                    format!("{base}/goal"),
                    &rerun::Points3D::new([[g.pose.x as f32, g.pose.y as f32, 0.02]])
                        .with_radii([Radius::new_ui_points(5.0)])
                        .with_labels([g.name.as_str()]),
                );
                r.check(res);
            }
        }
        for e in &nav.events[*logged..] {
            let level = if e.text.contains("FAILED") {
                rerun::TextLogLevel::ERROR
            } else if e.text.starts_with("stop") || e.text.contains("blocked") {
                rerun::TextLogLevel::WARN
            } else {
                rerun::TextLogLevel::INFO
            };
            let res = r.rec.log(
                format!("{base}/task"),
                &rerun::TextLog::new(e.text.as_str()).with_level(level),
            );
            r.check(res);
            if e.text.starts_with("stop") {
                let p = belief.pose;
                let res = r.rec.log(
                    format!("{base}/stops"),
                    &rerun::Points3D::new([[p.x as f32, p.y as f32, 0.03]])
                        .with_radii([Radius::new_ui_points(3.5)])
                        .with_colors([rerun::Color::from_rgb(230, 60, 40)]),
                );
                r.check(res);
            }
        }
        *logged = nav.events.len();
        if *last != status {
            let res = r.rec.log(
                format!("{base}/task"),
                &rerun::TextLog::new(status.as_str()).with_level(rerun::TextLogLevel::DEBUG),
            );
            r.check(res);
            *last = status;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_distance_left_runs_along_the_path_from_the_nearest_vertex() {
        let path = [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]];
        // beside the second vertex: 1 m to it, then 3 m
        assert_eq!(distance_remaining(&path, [4.0, -1.0]), Some(4.0));
        // at the start: the whole path
        assert_eq!(distance_remaining(&path, [0.0, 0.0]), Some(7.0));
        assert_eq!(distance_remaining(&[], [0.0, 0.0]), None);
    }
}
