//! Real-time correlative scan matching by branch-and-bound: the loop-closure matcher of
//! Cartographer ([SLAM thesis §3.3.2]: loop closure by branch-and-bound scan matching over a
//! search window with a minimum score threshold).
//!
//! Sources: W. Hess, D. Kohler, H. Rapp, D. Andor, "Real-Time Loop Closure in 2D LIDAR SLAM",
//! ICRA 2016, §V; E. Olson, "Real-time correlative scan matching", ICRA 2009 (exhaustive search
//! of a rasterized map over a discretized window; a coarse table holding the maximum of the fine
//! cells it covers gives an upper bound of the fine score).
//!
//! * Objective (Hess eq. 6): the pose ξ in the window maximizing the mean map value at the scan
//!   points transformed by ξ, the map read at the cell containing each point (M_nearest).
//! * Window (§V-A): angular step δθ from the scan's farthest point d_max so no point moves more
//!   than one cell r per step, δθ = arccos(1 − r²/(2·d_max²)) (eq. 7); w_x = ⌈W_x/r⌉,
//!   w_y = ⌈W_y/r⌉, w_θ = ⌈W_θ/δθ⌉ (eq. 8); candidates ξ₀ + (r·j_x, r·j_y, δθ·j_θ) with
//!   |j_x| ≤ w_x, |j_y| ≤ w_y, |j_θ| ≤ w_θ (eqs. 9–10). Translations by whole cells move every
//!   point's cell by exactly (j_x, j_y), so each angle's scan is discretized once.
//! * Search (§V-B, Algorithm 3, a depth-first instance of the generic Algorithm 2): a node of
//!   height h stands for the 2^h × 2^h translations [j_x, j_x + 2^h) × [j_y, j_y + 2^h) at one
//!   angle (eqs. 11–12); it branches into its (up to) four children of height h − 1. Children
//!   are visited best bound first, and a node is pruned when its bound is below the best score
//!   so far, which starts at the `min_score` threshold — so a query that cannot reach it ends
//!   early with `None`.
//! * Bounds (§V-C, eqs. 14–15): the [`PrecomputedGrids`] of height h, summed at the node's
//!   cells; never below any leaf's score and equal to it at h = 0.
//!
//! Determinism and exactness: scores are integer sums of the u8-quantized map (see
//! [`PrecomputedGrids`]); equal scores are ordered by a fixed key (closest to the initial guess
//! in angle, then in translation, then by the signed offsets), and pruning is strict (`<`), so
//! the result is exactly [`match_exhaustive`]'s (Hess Algorithm 1) over the same window.

mod precomputed;
#[cfg(test)]
mod tests;

pub use precomputed::PrecomputedGrids;

use crate::core::Pose2;
use precomputed::Level;
use std::f64::consts::PI;

/// Half-widths of the search window around the initial pose: ±`x`, ±`y` metres, ±`theta` rad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BnbWindow {
    pub x: f64,
    pub y: f64,
    pub theta: f64,
}

/// The best pose in the window and its score: the mean P(occupied) at the transformed points
/// (quantized to 1/255), in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BnbMatch {
    pub pose: Pose2,
    pub score: f64,
}

/// Hess eq. 7: the angular step that moves a point at `max_range` by at most one cell of
/// `resolution`, δθ = arccos(1 − r²/(2·d_max²)); π for a degenerate range.
pub fn angular_step(resolution: f64, max_range: f64) -> f64 {
    let c = 1.0 - resolution * resolution / (2.0 * max_range * max_range);
    if c.is_nan() {
        PI
    } else {
        c.clamp(-1.0, 1.0).acos()
    }
}

/// The discretized search (eqs. 7–10): every angle's scan as map cells at zero translation.
struct Discretized {
    origin: Pose2,
    resolution: f64,
    step: f64,
    wx: i32,
    wy: i32,
    wt: i32,
    /// Points per scan.
    k: usize,
    /// Angle index a (j_θ = a − w_θ): cells `cells[a·k .. (a+1)·k]`.
    cells: Vec<[i32; 2]>,
    /// The smallest integer score reaching `min_score`.
    min_sum: u32,
}

/// Window half-width in steps (eq. 8); negative or NaN widths give 0.
fn steps(width: f64, step: f64) -> i32 {
    // (a hair below the ceiling, so ±3 m at 5 cm is 60 steps whatever the rounding of 3/0.05)
    let n = (width / step - 1e-9).ceil();
    if n.is_nan() || n <= 0.0 {
        0
    } else {
        n.min(1e6) as i32
    }
}

impl Discretized {
    fn new(
        grids: &PrecomputedGrids,
        points: &[[f32; 2]],
        origin: Pose2,
        window: &BnbWindow,
        min_score: f64,
    ) -> Option<Self> {
        let k = points.len();
        if k == 0 {
            return None;
        }
        let res = grids.resolution;
        let d_max = points
            .iter()
            .map(|p| (p[0] as f64).hypot(p[1] as f64))
            .fold(0.0, f64::max);
        let step = angular_step(res, d_max);
        // never more than one turn of candidates
        let wt = steps(window.theta, step).min((PI / step).floor() as i32);
        let (wx, wy) = (steps(window.x, res), steps(window.y, res));
        let mut cells = Vec::with_capacity(k * (2 * wt as usize + 1));
        let [ox, oy] = grids.origin;
        let to_cell = |v: f64| v.floor().clamp(-1e9, 1e9) as i32;
        for jt in -wt..=wt {
            let (s, c) = (origin.theta + jt as f64 * step).sin_cos();
            cells.extend(points.iter().map(|p| {
                let (px, py) = (p[0] as f64, p[1] as f64);
                [
                    to_cell((origin.x + c * px - s * py - ox) / res),
                    to_cell((origin.y + s * px + c * py - oy) / res),
                ]
            }));
        }
        let need = min_score * 255.0 * k as f64 - 1e-9;
        let min_sum = if need.is_nan() || need <= 0.0 {
            0
        } else {
            need.ceil().min(u32::MAX as f64) as u32
        };
        Some(Discretized {
            origin,
            resolution: res,
            step,
            wx,
            wy,
            wt,
            k,
            cells,
            min_sum,
        })
    }

    fn scan(&self, a: u32) -> &[[i32; 2]] {
        &self.cells[a as usize * self.k..(a as usize + 1) * self.k]
    }

    /// Sum of a level at one angle's cells shifted by (jx, jy): a node's bound (eq. 14), or a
    /// leaf's score at level 0.
    fn sum(&self, level: &Level, a: u32, jx: i32, jy: i32) -> u32 {
        self.scan(a)
            .iter()
            .map(|&[c, r]| level.get(c + jx, r + jy) as u32)
            .sum()
    }

    fn result(&self, best: &Candidate) -> BnbMatch {
        let jt = best.a as i32 - self.wt;
        BnbMatch {
            pose: Pose2::new(
                self.origin.x + best.jx as f64 * self.resolution,
                self.origin.y + best.jy as f64 * self.resolution,
                self.origin.theta + jt as f64 * self.step,
            ),
            score: best.sum as f64 / (255.0 * self.k as f64),
        }
    }
}

/// A search node (height implied by the recursion): angle index, lower-left translation, score
/// or bound.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    a: u32,
    jx: i32,
    jy: i32,
    sum: u32,
}

impl Candidate {
    /// Tie order among equal scores: nearest to the initial guess in angle, then in
    /// translation, then the signed offsets.
    fn key(&self, wt: i32) -> (u32, u32, i32, i32, i32) {
        let jt = self.a as i32 - wt;
        let d2 = (self.jx * self.jx + self.jy * self.jy) as u32;
        (jt.unsigned_abs(), d2, jt, self.jy, self.jx)
    }
}

/// The running best leaf: strictly greater score wins, an equal score wins with a smaller key.
struct Best {
    sum: u32,
    leaf: Option<Candidate>,
    wt: i32,
}

impl Best {
    fn offer(&mut self, c: Candidate) {
        let better = c.sum > self.sum
            || (c.sum == self.sum && self.leaf.is_none_or(|b| c.key(self.wt) < b.key(self.wt)));
        if better {
            self.sum = c.sum;
            self.leaf = Some(c);
        }
    }
}

/// Best bound first; equal bounds in key order, so the visiting order is fixed.
fn sort_candidates(c: &mut [Candidate], wt: i32) {
    c.sort_unstable_by(|p, q| q.sum.cmp(&p.sum).then(p.key(wt).cmp(&q.key(wt))));
}

/// Hess Algorithm 3 below one set of sibling nodes of height `h`.
fn descend(
    d: &Discretized,
    grids: &PrecomputedGrids,
    nodes: &mut [Candidate],
    h: usize,
    best: &mut Best,
) {
    sort_candidates(nodes, d.wt);
    for node in nodes.iter() {
        // sorted: no later sibling can reach the best either
        if node.sum < best.sum {
            break;
        }
        if h == 0 {
            best.offer(*node);
            continue;
        }
        let half = 1i32 << (h - 1);
        let level = &grids.levels[h - 1];
        let mut kids = [*node; 4];
        let mut n = 0;
        for (dx, dy) in [(0, 0), (half, 0), (0, half), (half, half)] {
            let (jx, jy) = (node.jx + dx, node.jy + dy);
            // eq. 12: only translations inside the window
            if jx > d.wx || jy > d.wy {
                continue;
            }
            let sum = d.sum(level, node.a, jx, jy);
            if sum >= best.sum {
                kids[n] = Candidate {
                    a: node.a,
                    jx,
                    jy,
                    sum,
                };
                n += 1;
            }
        }
        descend(d, grids, &mut kids[..n], h - 1, best);
    }
}

/// The best pose within `window` of `initial` for the robot-frame `points` against the map of
/// `grids`, by branch-and-bound; `None` when no candidate's score reaches `min_score` (or the
/// scan is empty).
pub fn match_bnb(
    grids: &PrecomputedGrids,
    points: &[[f32; 2]],
    initial: Pose2,
    window: &BnbWindow,
    min_score: f64,
) -> Option<BnbMatch> {
    let d = Discretized::new(grids, points, initial, window, min_score)?;
    let top = grids.depth() - 1;
    let span = 1usize << top;
    let level = &grids.levels[top];
    let mut roots = Vec::new();
    for a in 0..(2 * d.wt + 1) as u32 {
        for jy in (-d.wy..=d.wy).step_by(span) {
            for jx in (-d.wx..=d.wx).step_by(span) {
                let sum = d.sum(level, a, jx, jy);
                if sum >= d.min_sum {
                    roots.push(Candidate { a, jx, jy, sum });
                }
            }
        }
    }
    let mut best = Best {
        sum: d.min_sum,
        leaf: None,
        wt: d.wt,
    };
    descend(&d, grids, &mut roots, top, &mut best);
    best.leaf.map(|b| d.result(&b))
}

/// The same search by scoring every candidate of the window (Hess Algorithm 1): the reference
/// [`match_bnb`] must equal, and what it is benchmarked against.
pub fn match_exhaustive(
    grids: &PrecomputedGrids,
    points: &[[f32; 2]],
    initial: Pose2,
    window: &BnbWindow,
    min_score: f64,
) -> Option<BnbMatch> {
    let d = Discretized::new(grids, points, initial, window, min_score)?;
    let mut best = Best {
        sum: d.min_sum,
        leaf: None,
        wt: d.wt,
    };
    for a in 0..(2 * d.wt + 1) as u32 {
        for jy in -d.wy..=d.wy {
            for jx in -d.wx..=d.wx {
                let sum = d.sum(&grids.levels[0], a, jx, jy);
                best.offer(Candidate { a, jx, jy, sum });
            }
        }
    }
    best.leaf.map(|b| d.result(&b))
}
