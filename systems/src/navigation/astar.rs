//! Global planner: A* (Hart, Nilsson & Raphael, "A Formal Basis for the Heuristic Determination
//! of Minimum Cost Paths", IEEE Trans. SSC 4(2), 1968) on the navigation [`Costmap`].
//!
//! - 8-connected grid; a move costs its length (1 or √2 cells) × (1 + `cost_weight` · c / 252),
//!   c the cost byte of the cell moved into, so the planner trades path length against distance
//!   from walls along the costmap's inflation gradient.
//! - Cells costing [`INSCRIBED`] or more are impassable (the robot would touch an obstacle), and a
//!   diagonal move needs both cells beside it passable: no cutting corners of blocked cells.
//! - Heuristic: the octile distance, max(|dx|, |dy|) + (√2 − 1)·min(|dx|, |dy|), the exact
//!   length of the shortest 8-connected path on an empty grid. Every step multiplier is ≥ 1, so
//!   it is admissible and consistent, and the first expansion of the goal is optimal.
//! - Deterministic tie-breaking: among open nodes the lowest f is expanded first, then the
//!   highest g (the one nearest the goal, which keeps plateaus from being flooded), then the
//!   lowest cell index. No hashing, no floating-point sums in varying order: the same map and
//!   query always give the same path.
//! - Scratch (g, parent, per-cell marks, the open list: a binary heap over buckets of f, see
//!   [`super::open_list`]) lives in [`Planner`] and is reused between queries; a generation counter marks which entries belong to the current query, so
//!   no O(cells) clearing happens per query.
//!
//! The grid path is then shortened by line of sight ([`super::shortcut`]) into world-frame
//! waypoints in metres: the exact start, the corners that are needed, the exact goal.

use super::costmap::{Costmap, INSCRIBED};
use super::open_list::{Entry, OpenList};
use super::shortcut;

/// Planner settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannerParams {
    /// How much the costmap gradient weighs against length: a cell of cost 252 makes moving
    /// through it (1 + `cost_weight`) times as expensive as through a free cell. ≥ 0.
    pub cost_weight: f32,
    /// Shortened segments may cross cells up to this cost, or up to the highest cost on the stretch
    /// of grid path they replace if that is higher (see [`shortcut::shorten`]).
    pub shortcut_max_cost: u8,
}

impl Default for PlannerParams {
    fn default() -> Self {
        PlannerParams {
            cost_weight: 3.0,
            shortcut_max_cost: 64,
        }
    }
}

/// A planned path.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    /// World-frame waypoints (m): the start, the corners, the goal.
    pub waypoints: Vec<[f64; 2]>,
    /// The A* grid path (col, row), start cell to goal cell.
    pub cells: Vec<(usize, usize)>,
    /// Length of the waypoint polyline (m).
    pub length: f64,
    /// A* cost of the grid path, in metres weighted by the step multipliers.
    pub cost: f64,
    /// Cells expanded by the search.
    pub expanded: usize,
}

/// Why a query has no path.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("start ({x:.3}, {y:.3}) m is outside the costmap")]
    StartOutside { x: f64, y: f64 },
    #[error("goal ({x:.3}, {y:.3}) m is outside the costmap")]
    GoalOutside { x: f64, y: f64 },
    #[error(
        "start ({x:.3}, {y:.3}) m is in an obstacle or within the robot radius of one (cell cost {cost})"
    )]
    StartBlocked { x: f64, y: f64, cost: u8 },
    #[error(
        "goal ({x:.3}, {y:.3}) m is in an obstacle or within the robot radius of one (cell cost {cost})"
    )]
    GoalBlocked { x: f64, y: f64, cost: u8 },
    #[error(
        "goal ({gx:.3}, {gy:.3}) m is unreachable from start ({sx:.3}, {sy:.3}) m: no collision-free path ({expanded} cells searched)"
    )]
    Unreachable {
        sx: f64,
        sy: f64,
        gx: f64,
        gy: f64,
        expanded: usize,
    },
}

/// An open-list entry for a node with these f and g (cells): the key packs f (high half) and
/// the complement of g (low half). Both are finite and ≥ 0, where an f32's bits order like its
/// value, so comparing keys compares f, then prefers the higher g; equal keys go by lower index.
fn entry(f: f32, g: f32, idx: usize) -> Entry {
    Entry {
        key: (f.to_bits() as u64) << 32 | !g.to_bits() as u64,
        idx: idx as u32,
    }
}

/// The g of an entry.
fn entry_g(e: &Entry) -> f32 {
    f32::from_bits(!(e.key as u32))
}

const SQRT2: f32 = std::f32::consts::SQRT_2;

/// A* planner with scratch buffers reused between queries (any costmap size; buffers grow to the
/// largest map seen).
#[derive(Clone, Debug)]
pub struct Planner {
    pub params: PlannerParams,
    /// Step multiplier per cost byte; infinite for impassable costs.
    step: [f32; 256],
    g: Vec<f32>,
    parent: Vec<u32>,
    /// 2·generation: opened in this query; 2·generation + 1: closed in this query.
    mark: Vec<u32>,
    generation: u32,
    open_list: OpenList,
    /// Largest increase of f along one move (cells), for the open list's buckets.
    spread: f32,
}

impl Planner {
    pub fn new(params: PlannerParams) -> Self {
        let w = if params.cost_weight.is_finite() {
            params.cost_weight.max(0.0)
        } else {
            0.0
        };
        let step = std::array::from_fn(|c| {
            if c >= INSCRIBED as usize {
                f32::INFINITY
            } else {
                1.0 + w * c as f32 / (INSCRIBED - 1) as f32
            }
        });
        Planner {
            params,
            step,
            g: Vec::new(),
            parent: Vec::new(),
            mark: Vec::new(),
            generation: 0,
            open_list: OpenList::default(),
            spread: SQRT2 * (2.0 + w),
        }
    }

    /// Starts a query on a map of `n` cells: sizes the buffers, advances the generation.
    fn begin(&mut self, n: usize) {
        if self.mark.len() < n {
            self.g.resize(n, 0.0);
            self.parent.resize(n, 0);
            self.mark.resize(n, 0);
        }
        self.generation += 1;
        if self.generation >= u32::MAX / 2 {
            self.mark.fill(0);
            self.generation = 1;
        }
    }

    /// The least-cost path from world point `start` to `goal` (m) on `map`.
    pub fn plan(
        &mut self,
        map: &Costmap,
        start: [f64; 2],
        goal: [f64; 2],
    ) -> Result<Path, PlanError> {
        let (sx, sy) = (start[0], start[1]);
        let (gx, gy) = (goal[0], goal[1]);
        let s = map
            .cell_of(sx, sy)
            .ok_or(PlanError::StartOutside { x: sx, y: sy })?;
        let t = map
            .cell_of(gx, gy)
            .ok_or(PlanError::GoalOutside { x: gx, y: gy })?;
        let cost = map.cost(s.0, s.1);
        if cost >= INSCRIBED {
            return Err(PlanError::StartBlocked { x: sx, y: sy, cost });
        }
        let cost = map.cost(t.0, t.1);
        if cost >= INSCRIBED {
            return Err(PlanError::GoalBlocked { x: gx, y: gy, cost });
        }
        let (g_goal, expanded) = self.search(map, s, t);
        let Some(g_goal) = g_goal else {
            return Err(PlanError::Unreachable {
                sx,
                sy,
                gx,
                gy,
                expanded,
            });
        };
        // the grid path, start to goal
        let (si, ti) = (map.index(s.0, s.1), map.index(t.0, t.1));
        let mut idx = vec![ti];
        let mut i = ti;
        while i != si {
            i = self.parent[i] as usize;
            idx.push(i);
        }
        idx.reverse();
        let cells: Vec<(usize, usize)> = idx
            .iter()
            .map(|&i| (i % map.width, i / map.width))
            .collect();
        let mut points: Vec<[f64; 2]> = cells.iter().map(|&(c, r)| map.cell_center(c, r)).collect();
        if points.len() == 1 {
            // start and goal share a cell
            points = vec![start, goal];
            idx.push(ti);
        } else {
            points[0] = start;
            let last = points.len() - 1;
            points[last] = goal;
        }
        let keep = shortcut::shorten(map, &points, &idx, self.params.shortcut_max_cost);
        let waypoints: Vec<[f64; 2]> = keep.iter().map(|&k| points[k]).collect();
        let length = waypoints
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum();
        Ok(Path {
            waypoints,
            cells,
            length,
            cost: g_goal as f64 * map.resolution,
            expanded,
        })
    }

    /// A* from cell `s` to cell `t` (both passable). Returns the goal's g (cells) if reached, and
    /// the number of expansions.
    fn search(
        &mut self,
        map: &Costmap,
        s: (usize, usize),
        t: (usize, usize),
    ) -> (Option<f32>, usize) {
        let (w, h) = (map.width, map.height);
        self.begin(w * h);
        let open = 2 * self.generation;
        let closed = open + 1;
        let (tc, tr) = (t.0 as i64, t.1 as i64);
        let heuristic = |i: usize| {
            let dx = ((i % w) as i64 - tc).unsigned_abs() as f32;
            let dy = ((i / w) as i64 - tr).unsigned_abs() as f32;
            dx.max(dy) + (SQRT2 - 1.0) * dx.min(dy)
        };
        let si = map.index(s.0, s.1);
        let ti = map.index(t.0, t.1);
        self.g[si] = 0.0;
        self.parent[si] = si as u32;
        self.mark[si] = open;
        self.open_list.reset(self.spread, heuristic(si));
        self.open_list.push(entry(heuristic(si), 0.0, si));
        let costs = &map.costs;
        let mut expanded = 0;
        while let Some(node) = self.open_list.pop() {
            let i = node.idx as usize;
            let node_g = entry_g(&node);
            if self.mark[i] == closed || node_g > self.g[i] {
                continue; // a stale entry
            }
            self.mark[i] = closed;
            expanded += 1;
            if i == ti {
                return (Some(node_g), expanded);
            }
            let (c, r) = (i % w, i / w);
            let west = c > 0;
            let east = c + 1 < w;
            let south = r > 0;
            let north = r + 1 < h;
            // passability of the four orthogonal neighbours (needed for the diagonal rule)
            let pass = |j: usize| costs[j] < INSCRIBED;
            let pw = west && pass(i - 1);
            let pe = east && pass(i + 1);
            let ps = south && pass(i - w);
            let pn = north && pass(i + w);
            let relax = |j: usize, len: f32, this: &mut Self| {
                if this.mark[j] == closed {
                    return;
                }
                let g = node_g + len * this.step[costs[j] as usize];
                if this.mark[j] != open || g < this.g[j] {
                    this.g[j] = g;
                    this.parent[j] = i as u32;
                    this.mark[j] = open;
                    this.open_list.push(entry(g + heuristic(j), g, j));
                }
            };
            if pe {
                relax(i + 1, 1.0, self);
            }
            if pw {
                relax(i - 1, 1.0, self);
            }
            if pn {
                relax(i + w, 1.0, self);
            }
            if ps {
                relax(i - w, 1.0, self);
            }
            if pn && pe && pass(i + w + 1) {
                relax(i + w + 1, SQRT2, self);
            }
            if pn && pw && pass(i + w - 1) {
                relax(i + w - 1, SQRT2, self);
            }
            if ps && pe && pass(i - w + 1) {
                relax(i - w + 1, SQRT2, self);
            }
            if ps && pw && pass(i - w - 1) {
                relax(i - w - 1, SQRT2, self);
            }
        }
        (None, expanded)
    }
}

#[cfg(test)]
mod tests;
