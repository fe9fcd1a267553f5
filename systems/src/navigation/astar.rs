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
//!   lowest cell index (row-major; the padded grid's index orders cells the same way). No
//!   hashing, no floating-point sums in varying order: the same map and query always give the
//!   same path.
//! - Scratch lives in [`Planner`] and is reused between queries: a copy of the costmap padded
//!   with a border of lethal cells (neighbour loops need no bounds tests), per cell g and a tag
//!   (generation, closed bit, direction to the parent) side by side, and the open list (buckets
//!   of f, see [`super::open_list`]). The generation in the tag marks which cells belong to the
//!   current query, so no O(cells) clearing happens per query.
//!
//! Cost per query on the hospital map (1280 × 640 cells of 5 cm; `cargo bench -p systems --bench
//! planner`, CPU time per query, medians of 6 runs of 20 queries on the shared 2-core CI machine):
//! room to room across the building (228 k and 235 k expansions) 17.9 and 18.4 ms, down from 35
//! and 36 ms measured the same way before the padded grid, packed node state, stale-entry
//! filtering and sorted buckets; corridor end to end 3.1 ms (from 4.1; half of it is the
//! line-of-sight shortening), wing to wing 5.6 ms (from 10.8). Paths, costs and expansion counts
//! are bit-identical to before. Criterion's wall-clock medians on a quiet machine: 16.8 and
//! 17.2 ms cross-building, 2.6 ms corridor, 5.1 ms wing to wing. About 80 ns per expansion remain: a third in the neighbour loop
//! (mostly waiting for node state), a quarter pushing the ~2 entries per expansion, the rest
//! filtering and sorting buckets.
//!
//! The grid path is then shortened by line of sight ([`super::shortcut`]) into world-frame
//! waypoints in metres: the exact start, the corners that are needed, the exact goal.

use super::costmap::{Costmap, INSCRIBED, LETHAL};
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

/// Per-cell search state, g and tag side by side so one relaxation touches one cache line.
/// `tag` = generation << 4 | closed << 3 | direction from the parent (index into [`Moves`]);
/// a tag of another generation means "not reached in this query".
#[derive(Clone, Copy, Debug, Default)]
struct Node {
    g: f32,
    tag: u32,
}

const CLOSED: u32 = 8;
/// Generations run up to here (the tag keeps 28 bits of it), then all tags are cleared.
const MAX_GENERATION: u32 = (1 << 28) - 1;

/// The eight moves on the padded grid of row length `pw`, in relaxation order: E, W, N, S, NE,
/// NW, SE, SW. Offsets are added to a padded index (wrapping, as W and S are negative).
struct Moves {
    offset: [usize; 8],
}

impl Moves {
    fn new(pw: usize) -> Self {
        let m = |dc: isize, dr: isize| (dr * pw as isize + dc) as usize;
        Moves {
            offset: [
                m(1, 0),
                m(-1, 0),
                m(0, 1),
                m(0, -1),
                m(1, 1),
                m(-1, 1),
                m(1, -1),
                m(-1, -1),
            ],
        }
    }
}

/// A* planner with scratch buffers reused between queries (any costmap size; buffers grow to the
/// largest map seen).
#[derive(Clone, Debug)]
pub struct Planner {
    pub params: PlannerParams,
    /// Step multiplier per cost byte; infinite for impassable costs.
    step: [f32; 256],
    /// The costmap with a one-cell border of [`LETHAL`] all round, row length width + 2: every
    /// expanded cell then has eight neighbours in the array and the border blocks the moves
    /// that would leave the map, so the inner loop has no bounds tests.
    padded: Vec<u8>,
    /// Search state per padded cell.
    nodes: Vec<Node>,
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
            padded: Vec::new(),
            nodes: Vec::new(),
            generation: 0,
            open_list: OpenList::default(),
            spread: SQRT2 * (2.0 + w),
        }
    }

    /// Starts a query on `map`: copies it into the padded grid, sizes the buffers, advances the
    /// generation.
    fn begin(&mut self, map: &Costmap) {
        let (w, h) = (map.width, map.height);
        let pw = w + 2;
        let n = pw * (h + 2);
        // a copy per query (under a millisecond) rather than trusting a cached one to be current
        self.padded.clear();
        self.padded.resize(pw, LETHAL);
        for row in map.costs.chunks_exact(w) {
            self.padded.push(LETHAL);
            self.padded.extend_from_slice(row);
            self.padded.push(LETHAL);
        }
        self.padded.resize(n, LETHAL);
        if self.nodes.len() < n {
            self.nodes.resize(n, Node::default());
        }
        self.generation += 1;
        if self.generation >= MAX_GENERATION {
            self.nodes.fill(Node::default());
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
        // the grid path, start to goal, followed back through the parent directions
        let pw = map.width + 2;
        let moves = Moves::new(pw);
        let padded = |(c, r): (usize, usize)| (r + 1) * pw + c + 1;
        let (ps, pt) = (padded(s), padded(t));
        let mut cells = vec![t];
        let mut p = pt;
        while p != ps {
            let dir = (self.nodes[p].tag & 7) as usize;
            p = p.wrapping_sub(moves.offset[dir]);
            cells.push((p % pw - 1, p / pw - 1));
        }
        cells.reverse();
        let mut idx: Vec<usize> = cells.iter().map(|&(c, r)| map.index(c, r)).collect();
        let mut points: Vec<[f64; 2]> = cells.iter().map(|&(c, r)| map.cell_center(c, r)).collect();
        if points.len() == 1 {
            // start and goal share a cell
            points = vec![start, goal];
            idx.push(idx[0]);
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
        self.begin(map);
        let pw = map.width + 2;
        let open = self.generation << 4;
        let closed = open | CLOSED;
        let moves = Moves::new(pw);
        let off = moves.offset;
        // padded coordinates: (c + 1, r + 1)
        let (tc, tr) = (t.0 as i64 + 1, t.1 as i64 + 1);
        let octile = |dx: f32, dy: f32| dx.max(dy) + (SQRT2 - 1.0) * dx.min(dy);
        let si = (s.1 + 1) * pw + s.0 + 1;
        let ti = (t.1 + 1) * pw + t.0 + 1;
        let h0 = octile(
            (s.0 as i64 + 1 - tc).unsigned_abs() as f32,
            (s.1 as i64 + 1 - tr).unsigned_abs() as f32,
        );
        self.nodes[si] = Node { g: 0.0, tag: open };
        self.open_list.reset(self.spread, h0);
        self.open_list.push(entry(h0, 0.0, si));
        let step = &self.step;
        let costs = &self.padded[..];
        let nodes = &mut self.nodes[..];
        let open_list = &mut self.open_list;
        let mut expanded = 0;
        // entries whose node has been closed or reached with a lower g since are dropped when their
        // bucket comes up, before they are heaped
        let live = |e: &Entry, nodes: &[Node]| {
            let n = nodes[e.idx as usize];
            n.tag & CLOSED == 0 && entry_g(e) <= n.g
        };
        while let Some(e) = open_list.pop(|e| live(e, nodes)) {
            let i = e.idx as usize;
            let node_g = entry_g(&e);
            let here = nodes[i];
            if here.tag == closed | (here.tag & 7) || node_g > here.g {
                continue; // a stale entry
            }
            nodes[i].tag = here.tag | CLOSED;
            expanded += 1;
            if i == ti {
                return (Some(node_g), expanded);
            }
            let (c, r) = ((i % pw) as i64, (i / pw) as i64);
            // |dx| to the goal for the columns c + 1, c − 1, c; |dy| for rows r + 1, r − 1, r
            let dx = [c + 1 - tc, c - 1 - tc, c - tc].map(|d| d.unsigned_abs() as f32);
            let dy = [r + 1 - tr, r - 1 - tr, r - tr].map(|d| d.unsigned_abs() as f32);
            // passability of the four orthogonal neighbours (needed for the diagonal rule); the
            // border makes every neighbour index valid
            let pass = |j: usize| costs[j] < INSCRIBED;
            let mut relax = |dir: usize, len: f32, h: f32| {
                let j = i.wrapping_add(off[dir]);
                let n = nodes[j];
                if n.tag & !7 == closed {
                    return;
                }
                let g = node_g + len * step[costs[j] as usize];
                if n.tag & !7 != open || g < n.g {
                    nodes[j] = Node {
                        g,
                        tag: open | dir as u32,
                    };
                    open_list.push(entry(g + h, g, j));
                }
            };
            let pe = pass(i.wrapping_add(off[0]));
            let pw_ = pass(i.wrapping_add(off[1]));
            let pn = pass(i.wrapping_add(off[2]));
            let ps = pass(i.wrapping_add(off[3]));
            if pe {
                relax(0, 1.0, octile(dx[0], dy[2]));
            }
            if pw_ {
                relax(1, 1.0, octile(dx[1], dy[2]));
            }
            if pn {
                relax(2, 1.0, octile(dx[2], dy[0]));
            }
            if ps {
                relax(3, 1.0, octile(dx[2], dy[1]));
            }
            if pn && pe && pass(i.wrapping_add(off[4])) {
                relax(4, SQRT2, octile(dx[0], dy[0]));
            }
            if pn && pw_ && pass(i.wrapping_add(off[5])) {
                relax(5, SQRT2, octile(dx[1], dy[0]));
            }
            if ps && pe && pass(i.wrapping_add(off[6])) {
                relax(6, SQRT2, octile(dx[0], dy[1]));
            }
            if ps && pw_ && pass(i.wrapping_add(off[7])) {
                relax(7, SQRT2, octile(dx[1], dy[1]));
            }
        }
        (None, expanded)
    }
}

#[cfg(test)]
mod tests;
