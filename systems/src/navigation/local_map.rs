//! What the navigator asks of the costmap and of what its sensors see: the distance along the
//! band the path sweeps to an obstacle point, whether a path still fits the costmap, the nearest
//! cell the robot may occupy, whether a sonar echo is just a wall the map knows, and a costmap
//! copy with seen obstacles marked for planning around.

use super::costmap::{Costmap, INSCRIBED, LETHAL};
use crate::core::Pose2;

/// Arc length along `band` (a polyline) of the projection of `p`, if `p` lies within
/// `half_width` of it (ahead of its start).
pub(crate) fn along_band(band: &[[f64; 2]], p: [f64; 2], half_width: f64) -> Option<f64> {
    let mut walked = 0.0;
    let mut best: Option<f64> = None;
    for w in band.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        if len > 1e-9 {
            let t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len;
            let lateral = ((p[0] - a[0]) * dy - (p[1] - a[1]) * dx).abs() / len;
            if t > 0.0 && t <= len && lateral < half_width {
                let at = walked + t;
                best = Some(best.map_or(at, |b: f64| b.min(at)));
            }
        }
        walked += len;
    }
    best
}

/// True if a sonar echo at `range` (m) from `sensor` (world pose of the transducer, on the
/// belief) is explained by the map: some ray of a fan of `rays` across the `cone` (rad) meets a
/// lethal cell within `range + tolerance`. A sonar only reports its nearest echo somewhere in a
/// wide cone, so an echo the map explains (a door frame beside the robot, the wall at the end of
/// a corridor) says nothing about unknown obstacles; one clearly short of every known wall does.
/// This is the map-consistency test of sonar readings in Thrun, Burgard & Fox, "Probabilistic
/// Robotics" (2005), §6.3 (expected range from the map), reduced to a yes/no per echo.
pub(crate) fn echo_explained(
    map: &Costmap,
    sensor: &Pose2,
    cone: f64,
    rays: usize,
    range: f64,
    tolerance: f64,
) -> bool {
    let reach = range + tolerance;
    let step = map.resolution * 0.5;
    let n = rays.max(2);
    (0..n).any(|k| {
        let a = sensor.theta - cone / 2.0 + cone * k as f64 / (n - 1) as f64;
        let (s, c) = a.sin_cos();
        let mut d = 0.0;
        while d <= reach {
            match map.cell_of(sensor.x + c * d, sensor.y + s * d) {
                Some((col, row)) if map.cost(col, row) >= LETHAL => return true,
                Some(_) => {}
                None => return true, // off the map: the map's edge is a wall
            }
            d += step;
        }
        false
    })
}

/// The centre of the nearest cell within `max_dist` of `p` that the robot may occupy.
pub(crate) fn nearest_free(map: &Costmap, p: [f64; 2], max_dist: f64) -> Option<[f64; 2]> {
    let (c0, r0) = map.cell_of(p[0], p[1])?;
    let reach = (max_dist / map.resolution).ceil() as i64;
    let mut best: Option<(i64, [f64; 2])> = None;
    for dr in -reach..=reach {
        for dc in -reach..=reach {
            let d2 = dc * dc + dr * dr;
            if d2 > reach * reach || best.is_some_and(|(b, _)| b <= d2) {
                continue;
            }
            let (c, r) = (c0 as i64 + dc, r0 as i64 + dr);
            if c < 0 || r < 0 || c >= map.width as i64 || r >= map.height as i64 {
                continue;
            }
            if map.cost(c as usize, r as usize) < INSCRIBED {
                best = Some((d2, map.cell_center(c as usize, r as usize)));
            }
        }
    }
    best.map(|(_, q)| q)
}

/// True if the path from segment `from` on crosses a cell the robot cannot occupy.
pub fn path_blocked(map: &Costmap, path: &[[f64; 2]], from: usize) -> bool {
    let start = from.min(path.len().saturating_sub(1));
    path.get(start..)
        .unwrap_or(&[])
        .windows(2)
        .any(|w| !super::shortcut::segment_clear(map, w[0], w[1], INSCRIBED - 1))
}

/// A copy of `map` with every obstacle point in free space (static cost below [`INSCRIBED`])
/// marked lethal and inflated: cells within `hard` of a point become [`INSCRIBED`] (the robot's
/// centre may not go there), cells between `hard` and `soft` get a cost falling linearly from
/// [`BERTH_COST`] to half of it, so a plan keeps a wide berth of what the robot sees (people walk
/// on, doors swing) where the corridor has room and squeezes past at `hard` where it has not.
/// Points within `hard` of `robot` are skipped (the robot's own cell must stay free to plan from).
pub fn mark_obstacles(
    map: &Costmap,
    points: &[[f64; 2]],
    hard: f64,
    soft: f64,
    robot: [f64; 2],
) -> Costmap {
    let mut out = map.clone();
    let res = map.resolution;
    let soft = soft.max(hard);
    let reach = (soft / res).ceil() as i64;
    let (hard2, soft2) = ((hard / res).powi(2), (soft / res).powi(2));
    for &p in points {
        if (p[0] - robot[0]).hypot(p[1] - robot[1]) < hard {
            continue;
        }
        let Some((c, r)) = map.cell_of(p[0], p[1]) else {
            continue;
        };
        if map.cost(c, r) >= INSCRIBED {
            continue; // a wall the map knows
        }
        out.costs[map.index(c, r)] = LETHAL;
        for dr in -reach..=reach {
            for dc in -reach..=reach {
                let d2 = (dc * dc + dr * dr) as f64;
                if d2 > soft2 {
                    continue;
                }
                let (nc, nr) = (c as i64 + dc, r as i64 + dr);
                if nc < 0 || nr < 0 || nc >= map.width as i64 || nr >= map.height as i64 {
                    continue;
                }
                let cost = if d2 <= hard2 {
                    INSCRIBED
                } else {
                    let f = (d2.sqrt() * res - hard) / (soft - hard);
                    (BERTH_COST as f64 * (1.0 - 0.5 * f)).round() as u8
                };
                let i = map.index(nc as usize, nr as usize);
                if out.costs[i] < cost {
                    out.costs[i] = cost;
                }
            }
        }
    }
    // never wall the robot in: its own cell stays as it was
    if let Some((c, r)) = map.cell_of(robot[0], robot[1]) {
        let i = map.index(c, r);
        out.costs[i] = map.costs[i];
    }
    out
}

/// Cost of the cells just outside the hard margin round a seen obstacle (see [`mark_obstacles`]).
pub const BERTH_COST: u8 = 200;
