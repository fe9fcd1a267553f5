//! Synthetic pose graphs with their ground truth, for tests and benchmarks: noisy odometry edges
//! between consecutive poses, loop-closure edges measured with a small noise, nodes initialized
//! by dead reckoning (composing the odometry measurements), node 0 fixed at its true pose.
//!
//! * [`square_laps`] — laps of a square, each pose closed to the same pose one lap earlier;
//! * [`manhattan`] — a random walk on a street grid in the style of E. Olson's "Manhattan
//!   world" M3500 benchmark (Olson, Leonard, Teller, "Fast Iterative Alignment of Pose Graphs
//!   with Poor Initial Estimates", ICRA 2006): unit steps, turns at intersections, closures to
//!   earlier visits of the same place.

use super::{Edge, EdgeKind, PoseGraph, information_from_sigmas};
use crate::core::{Pose2, SimRng};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::FRAC_PI_2;

/// Standard deviations (m, m, rad) of odometry (per step) and loop-closure measurements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    pub odometry: [f64; 3],
    pub closure: [f64; 3],
}

impl Default for Noise {
    /// Wheel odometry over a 1 m step: 2 cm and 0.01 rad (0.6°); a scan-matched closure: 1 cm
    /// and 0.005 rad.
    fn default() -> Self {
        Noise {
            odometry: [0.02, 0.02, 0.01],
            closure: [0.01, 0.01, 0.005],
        }
    }
}

/// A graph to optimize and the true poses of its nodes.
#[derive(Clone, Debug)]
pub struct SyntheticGraph {
    pub graph: PoseGraph,
    pub truth: Vec<Pose2>,
}

fn noisy(z: Pose2, sigma: &[f64; 3], rng: &mut SimRng) -> Pose2 {
    let mut n = [0.0; 3];
    for (v, s) in n.iter_mut().zip(sigma) {
        let g: f64 = rng.sample(StandardNormal);
        *v = g * s;
    }
    Pose2::new(z.x + n[0], z.y + n[1], z.theta + n[2])
}

fn edge(from: usize, to: usize, z: Pose2, sigma: &[f64; 3], kind: EdgeKind) -> Edge {
    Edge {
        from,
        to,
        measurement: z,
        information: information_from_sigmas(sigma[0], sigma[1], sigma[2]),
        kind,
        huber: None,
    }
}

/// Odometry edges along `truth` and dead-reckoned initial nodes.
fn odometry_graph(truth: &[Pose2], noise: &Noise, rng: &mut SimRng) -> PoseGraph {
    let mut nodes = vec![truth[0]];
    let mut edges = Vec::with_capacity(truth.len() * 3 / 2);
    for k in 1..truth.len() {
        let z = noisy(truth[k - 1].between(&truth[k]), &noise.odometry, rng);
        nodes.push(nodes[k - 1].compose(&z));
        edges.push(edge(k - 1, k, z, &noise.odometry, EdgeKind::Odometry));
    }
    PoseGraph {
        nodes,
        edges,
        fixed: vec![0],
    }
}

fn closure(truth: &[Pose2], from: usize, to: usize, noise: &Noise, rng: &mut SimRng) -> Edge {
    let z = noisy(truth[from].between(&truth[to]), &noise.closure, rng);
    edge(from, to, z, &noise.closure, EdgeKind::LoopClosure)
}

/// `laps` laps of a square of `side` steps of `step` metres per side (turning left 90° at each
/// corner): 1 + 4·laps·side nodes; every pose from the end of the first lap on is closed to
/// itself one lap earlier (the first closure: back at the start, to node 0).
pub fn square_laps(
    laps: usize,
    side: usize,
    step: f64,
    noise: &Noise,
    rng: &mut SimRng,
) -> SyntheticGraph {
    let lap = 4 * side;
    let mut truth = vec![Pose2::IDENTITY];
    for k in 0..laps * lap {
        let turn = if (k + 1) % side == 0 { FRAC_PI_2 } else { 0.0 };
        let last = truth[truth.len() - 1];
        truth.push(last.compose(&Pose2::new(step, 0.0, turn)));
    }
    let mut graph = odometry_graph(&truth, noise, rng);
    for k in lap..truth.len() {
        graph.edges.push(closure(&truth, k - lap, k, noise, rng));
    }
    SyntheticGraph { graph, truth }
}

/// A random walk of `n` nodes (1 m steps) on a street grid with intersections every 5 m, in a
/// square of side ≈ √(5n/6) m (about 3 steps per street point, so places are revisited): at an
/// intersection it goes straight (½), left or right (¼ each), turning at the border. A node on
/// a place visited before, more than 10 steps ago, gets a closure to one of those visits
/// (drawn uniformly) with probability 0.8: about 1.5 edges per node, as M3500 (3500 poses,
/// 5453 edges).
pub fn manhattan(n: usize, noise: &Noise, rng: &mut SimRng) -> SyntheticGraph {
    const BLOCK: i64 = 5;
    let size = (BLOCK * ((5.0 * n as f64 / 6.0).sqrt() / BLOCK as f64).round() as i64).max(BLOCK);
    let dirs = [(1i64, 0i64), (0, 1), (-1, 0), (0, -1)];
    let (mut x, mut y, mut h) = (0i64, 0i64, 0usize);
    let mut truth = vec![Pose2::IDENTITY];
    let mut cells: Vec<(i64, i64)> = vec![(0, 0)];
    while truth.len() < n {
        if x % BLOCK == 0 && y % BLOCK == 0 {
            let r: f64 = rng.random();
            h = if r < 0.5 {
                h
            } else if r < 0.75 {
                (h + 1) % 4
            } else {
                (h + 3) % 4
            };
        }
        // stay inside: turn left until the next step is inside (a corner needs two turns)
        while !(0..=size).contains(&(x + dirs[h].0)) || !(0..=size).contains(&(y + dirs[h].1)) {
            h = (h + 1) % 4;
        }
        x += dirs[h].0;
        y += dirs[h].1;
        truth.push(Pose2::new(x as f64, y as f64, h as f64 * FRAC_PI_2));
        cells.push((x, y));
    }
    let mut graph = odometry_graph(&truth, noise, rng);
    let mut visits: rustc_hash::FxHashMap<(i64, i64), Vec<usize>> = Default::default();
    for (k, &cell) in cells.iter().enumerate() {
        let seen = visits.entry(cell).or_default();
        let earlier: Vec<usize> = seen.iter().copied().filter(|&j| j + 10 < k).collect();
        if !earlier.is_empty() && rng.random::<f64>() < 0.8 {
            let j = earlier[rng.random_range(0..earlier.len())];
            graph.edges.push(closure(&truth, j, k, noise, rng));
        }
        seen.push(k);
    }
    SyntheticGraph { graph, truth }
}
