//! The fleet board and the yield rule. Hospital robots report to a fleet manager; here every
//! navigator publishes its BELIEVED pose, its radius, its priority, what it is doing and the next
//! few metres of its path on a shared board (no ground truth), and reads the others' entries to
//! settle encounters.
//!
//! The yield rule (two robots blocking each other must never wait forever):
//! 1. A robot that is stopped by an obstacle checks the board for another robot in the band in
//!    front of it. If that robot is parked (waiting at a place, idle) it is an ordinary obstacle.
//! 2. If it is driving towards us too (its path comes back through our position), the robot with
//!    the LOWER priority yields: the higher `priority` number, ties broken by the higher robot
//!    index. The yielding robot drives to the nearest free spot that is clear of the other
//!    robot's path by both radii plus a margin (a passing bay, a doorway, the far side of a wide
//!    corridor; found by [`yield_spot`]), waits there until the other robot's path no longer
//!    passes it, then re-plans to its goal.
//! 3. A robot that finds no such spot within reach says so on the board (`cannot_yield`); the
//!    other robot then yields instead. Only if neither can yield do both wait (and re-plan
//!    around each other after their wait time, like for any obstacle).
//!
//! The rule is asymmetric (a strict order of robots), so exactly one robot of a blocked pair
//! moves aside.

use super::costmap::{Costmap, INSCRIBED};
use super::follower::distance_to_polyline;
use super::shortcut;
use crate::core::Pose2;
use bevy_ecs::prelude::Resource;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// What a robot is doing, as far as the others need to know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FleetActivity {
    /// Standing still at a place or with nothing to do: an obstacle like any other.
    Parked,
    /// Driving along its path (or stopped on it by an obstacle).
    Driving,
    /// Moving aside for robot `for_robot` (`parked` false), or waiting aside (true).
    Yielding { for_robot: u32, parked: bool },
}

#[derive(Clone, Debug, PartialEq)]
pub struct FleetEntry {
    pub index: u32,
    pub pose: Pose2,
    pub radius: f64,
    pub priority: u32,
    pub activity: FleetActivity,
    /// The robot's path ahead, starting at its position (at most a few metres).
    pub path_ahead: Vec<[f64; 2]>,
    pub cannot_yield: bool,
}

/// Every navigating robot's entry, by robot index (None for robots that do not navigate).
#[derive(Resource, Clone, Debug, Default)]
pub struct Fleet {
    pub entries: Vec<Option<FleetEntry>>,
}

impl Fleet {
    pub fn get(&self, index: u32) -> Option<&FleetEntry> {
        self.entries.get(index as usize).and_then(Option::as_ref)
    }

    /// The nearest other robot whose disc reaches into the band `half_width` wide and `reach`
    /// long in front of `me` (belief poses).
    pub fn robot_ahead(&self, me: &FleetEntry, half_width: f64, reach: f64) -> Option<&FleetEntry> {
        let (s, c) = me.pose.theta.sin_cos();
        let mut best: Option<(f64, &FleetEntry)> = None;
        for o in self.entries.iter().flatten() {
            if o.index == me.index {
                continue;
            }
            let (dx, dy) = (o.pose.x - me.pose.x, o.pose.y - me.pose.y);
            let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
            if lx <= 0.0 || lx - o.radius > reach || ly.abs() > half_width + o.radius {
                continue;
            }
            if best.is_none_or(|(d, _)| lx < d) {
                best = Some((lx, o));
            }
        }
        best.map(|(_, o)| o)
    }
}

/// True if `other`'s path ahead passes within `clearance` of `me`'s position: it is coming
/// this way.
pub fn comes_through(other: &FleetEntry, me: &FleetEntry, clearance: f64) -> bool {
    other.activity == FleetActivity::Driving
        && other.path_ahead.len() >= 2
        && distance_to_polyline(&other.path_ahead, [me.pose.x, me.pose.y]) < clearance
}

/// Rule 2 and 3 of the module doc: does `me` give way to `other`?
pub fn gives_way(me: &FleetEntry, other: &FleetEntry) -> bool {
    match (me.cannot_yield, other.cannot_yield) {
        (false, true) => true,
        (true, false) => false,
        _ => (me.priority, me.index) > (other.priority, other.index),
    }
}

/// The nearest place to step aside to: a path (world points, starting at `from`) through cells
/// the robot may occupy (cost below [`INSCRIBED`], not within `blocked_radius` of `other`) to the
/// first cell whose distance from `keep_clear` (the other robot's position and path) is at least
/// `clearance`, searching at most `max_dist` metres of path. Dijkstra over the 8-connected grid
/// with the planner's cost weighting (so the way there keeps off walls), ties broken by cell
/// index, so the spot is deterministic. None if there is no such spot.
pub fn yield_spot(
    map: &Costmap,
    from: [f64; 2],
    other: [f64; 2],
    blocked_radius: f64,
    keep_clear: &[[f64; 2]],
    clearance: f64,
    max_dist: f64,
) -> Option<Vec<[f64; 2]>> {
    let (c0, r0) = map.cell_of(from[0], from[1])?;
    let (w, h) = (map.width, map.height);
    let res = map.resolution;
    let start = r0 * w + c0;
    let max_steps = (max_dist / res * 10.0 * 4.0) as u32;
    let blocked_r2 = blocked_radius * blocked_radius;
    let mut dist = std::collections::HashMap::<usize, (u32, usize)>::new();
    let mut heap = BinaryHeap::new();
    dist.insert(start, (0, usize::MAX));
    heap.push(Reverse((0u32, start)));
    let mut clear_pts = Vec::with_capacity(keep_clear.len() + 1);
    clear_pts.push(other);
    clear_pts.extend_from_slice(keep_clear);
    let mut found = None;
    while let Some(Reverse((d, i))) = heap.pop() {
        if dist.get(&i).is_some_and(|&(best, _)| best < d) {
            continue;
        }
        let (c, r) = (i % w, i / w);
        let p = map.cell_center(c, r);
        if distance_to_polyline(&clear_pts, p) >= clearance && map.costs[i] < INSCRIBED {
            found = Some(i);
            break;
        }
        if d > max_steps {
            continue;
        }
        for (dc, dr, step) in [
            (1i64, 0i64, 10u32),
            (-1, 0, 10),
            (0, 1, 10),
            (0, -1, 10),
            (1, 1, 14),
            (1, -1, 14),
            (-1, 1, 14),
            (-1, -1, 14),
        ] {
            let (nc, nr) = (c as i64 + dc, r as i64 + dr);
            if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                continue;
            }
            let j = nr as usize * w + nc as usize;
            if map.costs[j] >= INSCRIBED {
                continue;
            }
            if dc != 0 && dr != 0 {
                // no corner cutting
                let a = r * w + nc as usize;
                let b = nr as usize * w + c;
                if map.costs[a] >= INSCRIBED || map.costs[b] >= INSCRIBED {
                    continue;
                }
            }
            let q = map.cell_center(nc as usize, nr as usize);
            let (ox, oy) = (q[0] - other[0], q[1] - other[1]);
            if ox * ox + oy * oy < blocked_r2 {
                continue;
            }
            // weighted like the planner's moves: keep away from walls where there is room
            let nd = d + step * (252 + 3 * map.costs[j] as u32) / 252;
            if dist.get(&j).is_none_or(|&(best, _)| nd < best) {
                dist.insert(j, (nd, i));
                heap.push(Reverse((nd, j)));
            }
        }
    }
    let goal = found?;
    let mut cells = vec![goal];
    let mut i = goal;
    while i != start {
        i = dist.get(&i)?.1;
        cells.push(i);
    }
    cells.reverse();
    let mut points: Vec<[f64; 2]> = cells
        .iter()
        .map(|&i| map.cell_center(i % w, i / w))
        .collect();
    points[0] = from;
    // shortcuts no closer to walls than the grid path already goes (or 64: a wide berth)
    let keep = shortcut::shorten(map, &points, &cells, 64);
    Some(keep.into_iter().map(|k| points[k]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigation::costmap::CostmapParams;
    use crate::world::{Cell, OccupancyGrid};

    /// A 1.2 m wide corridor along x from 0 to 12 m with a passing bay (1.5 m deep) at x 5–7 on
    /// the north side.
    fn corridor() -> Costmap {
        let res = 0.05;
        let mut g = OccupancyGrid::new(260, 80, res, [-0.5, -1.0], Cell::Occupied);
        let free = |g: &mut OccupancyGrid, x0: f64, y0: f64, x1: f64, y1: f64| {
            for r in 0..g.height {
                for c in 0..g.width {
                    let x = -0.5 + (c as f64 + 0.5) * res;
                    let y = -1.0 + (r as f64 + 0.5) * res;
                    if x > x0 && x < x1 && y > y0 && y < y1 {
                        g.set(c, r, Cell::Free);
                    }
                }
            }
        };
        free(&mut g, 0.0, -0.6, 12.0, 0.6);
        free(&mut g, 5.0, 0.0, 7.0, 2.1);
        Costmap::from_grid(
            &g,
            &CostmapParams {
                robot_radius: 0.3,
                inflation_radius: 0.6,
                ..Default::default()
            },
        )
    }

    fn entry(index: u32, x: f64, theta: f64, path: Vec<[f64; 2]>) -> FleetEntry {
        FleetEntry {
            index,
            pose: Pose2::new(x, 0.0, theta),
            radius: 0.3,
            priority: 0,
            activity: FleetActivity::Driving,
            path_ahead: path,
            cannot_yield: false,
        }
    }

    #[test]
    fn the_yielding_robot_finds_the_passing_bay() {
        let map = corridor();
        // we are at x = 5 heading east; the other robot at x = 6.4 comes west along the axis
        let other_path = vec![[6.4, 0.0], [0.5, 0.0]];
        let spot =
            yield_spot(&map, [5.0, 0.0], [6.4, 0.0], 0.6, &other_path, 0.85, 15.0).expect("a spot");
        let end = *spot.last().unwrap();
        assert!(end[1] > 0.8 && end[0] > 5.0 && end[0] < 7.0, "{end:?}");
        assert_eq!(spot[0], [5.0, 0.0]);
        // with the other robot at the bay's mouth there is no way in
        assert!(
            yield_spot(
                &map,
                [4.0, 0.0],
                [5.2, 0.0],
                0.6,
                &[[5.2, 0.0], [0.5, 0.0]],
                0.85,
                15.0
            )
            .is_none()
        );
    }

    #[test]
    fn no_spot_in_a_plain_corridor() {
        let map = corridor();
        // the other robot comes east from x = 8.8: the bay is behind it, the corridor's east
        // end is on its path
        let other_path = vec![[8.8, 0.0], [11.5, 0.0]];
        assert!(yield_spot(&map, [10.0, 0.0], [8.8, 0.0], 0.6, &other_path, 0.85, 15.0).is_none());
    }

    #[test]
    fn the_order_is_strict_and_cannot_yield_swaps_it() {
        let a = entry(0, 0.0, 0.0, vec![[0.0, 0.0], [5.0, 0.0]]);
        let mut b = entry(1, 2.0, std::f64::consts::PI, vec![[2.0, 0.0], [-3.0, 0.0]]);
        assert!(!gives_way(&a, &b) && gives_way(&b, &a));
        b.cannot_yield = true;
        assert!(gives_way(&a, &b) && !gives_way(&b, &a));
        let fleet = Fleet {
            entries: vec![Some(a.clone()), Some(b.clone())],
        };
        assert_eq!(fleet.robot_ahead(&a, 0.4, 2.0).map(|e| e.index), Some(1));
        assert!(comes_through(&b, &a, 0.7));
        assert!(fleet.robot_ahead(&b, 0.4, 1.0).is_none(), "too far");
    }
}
