//! Sparse pose adjustment on SE(2): the back end of graph-based SLAM ([SLAM thesis §3.3.2]:
//! Cartographer's global SLAM, sparse pose adjustment with a Huber loss).
//!
//! Sources: K. Konolige, G. Grisetti, R. Kümmerle, W. Burgard, B. Limketkai, R. Vincent,
//! "Efficient Sparse Pose Adjustment for 2D Mapping", IROS 2010 (SPA: the 2-D error function and
//! its Jacobians, Levenberg-Marquardt on the sparse system with Marquardt's diagonal damping);
//! G. Grisetti, R. Kümmerle, C. Stachniss, W. Burgard, "A Tutorial on Graph-Based SLAM", IEEE
//! ITS Magazine 2010, §IV–V: F(x) = Σ eᵢⱼᵀ Ωᵢⱼ eᵢⱼ, the linearization
//! eᵢⱼ(x + Δx) ≈ eᵢⱼ + Jᵢⱼ Δx, b = Σ Jᵢⱼᵀ Ωᵢⱼ eᵢⱼ, H = Σ Jᵢⱼᵀ Ωᵢⱼ Jᵢⱼ and the step H Δx* = −b;
//! the sparse block structure (an edge ⟨i, j⟩ adds Aᵢⱼᵀ Ω Aᵢⱼ, Aᵢⱼᵀ Ω Bᵢⱼ, Bᵢⱼᵀ Ω Bᵢⱼ to the
//! blocks ii, ij, jj and Aᵢⱼᵀ Ω e, Bᵢⱼᵀ Ω e to bᵢ, bⱼ); the gauge fixed by keeping the first
//! pose constant.
//!
//! * Error of an edge i → j with measurement zᵢⱼ (the pose of j in the frame of i), as in SPA:
//!   ẑᵢⱼ = (Rᵢᵀ (tⱼ − tᵢ), θⱼ − θᵢ), e = ẑᵢⱼ − zᵢⱼ with the angle wrapped to (−π, π].
//!   Jacobians: ∂e/∂tᵢ = −Rᵢᵀ, ∂e/∂θᵢ = (∂Rᵢᵀ/∂θᵢ)(tⱼ − tᵢ) and −1 for the angle row,
//!   ∂e/∂tⱼ = Rᵢᵀ, ∂e/∂θⱼ = 1 (checked against finite differences in the tests).
//! * Robust kernel: Huber on the squared whitened error s = eᵀΩe, as Ceres' `HuberLoss(δ)`
//!   that Cartographer's optimization problem puts on its constraints: ρ(s) = s for s ≤ δ²,
//!   2δ√s − δ² beyond. Minimized by iteratively reweighted least squares: each linearization
//!   weights the edge by ρ'(s) = min(1, δ/√s), so a loop closure 5 m off pulls with a force that
//!   no longer grows with its error.
//! * Levenberg-Marquardt: (H + λ·diag H) Δx = −b; a step is kept only if the robust cost
//!   Σρ drops (then λ /= 10), otherwise λ ×= 10 and the same linearization is solved again.
//!   λ = 0 starts as plain Gauss-Newton.
//!
//! Linear algebra: [faer](https://docs.rs/faer) 0.24 sparse Cholesky (see `linear`): AMD
//! fill-reducing ordering, supernodal or simplicial factorization chosen by faer, symbolic
//! analysis done once per `optimize` call and reused by every iteration. Chosen over
//! nalgebra-sparse 0.12, whose `CscCholesky` would cost next to nothing to build (nalgebra is
//! already in the tree through rapier2d) but has no fill-reducing ordering (its docs advise
//! against it for serious use): in chronological order, the loop closures of a 3500-node
//! Manhattan graph fill the factor to ~17.5 M nonzeros, against 0.25 M for faer with AMD.
//! faer is built with `default-features = false, features = ["sparse-linalg"]` (no
//! std/rayon/npy/rand: sequential, so results do not depend on a thread count; `std` measured
//! no faster here); MSRV 1.84; about 185 CPU-seconds added to a clean release build.

mod linear;
pub mod synthetic;
#[cfg(test)]
mod tests;

use crate::core::{Pose2, wrap_angle};
use linear::{Mat3, System};

/// What produced an edge (kept for display and statistics; the solver treats all alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    Odometry,
    ScanMatch,
    LoopClosure,
}

/// A relative-pose constraint: `measurement` is the pose of node `to` in the frame of node
/// `from`, `information` the inverse of its covariance (x, y, θ order; symmetric positive
/// semi-definite). `huber`: the Huber δ in whitened units (√(eᵀΩe)), None for plain least
/// squares.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    pub from: usize,
    pub to: usize,
    pub measurement: Pose2,
    pub information: [[f64; 3]; 3],
    pub kind: EdgeKind,
    pub huber: Option<f64>,
}

/// Nodes (poses in the map frame) and edges. `fixed` nodes never move (the gauge; every
/// connected part of the graph needs one); [`PoseGraph::new`] fixes node 0.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseGraph {
    pub nodes: Vec<Pose2>,
    pub edges: Vec<Edge>,
    pub fixed: Vec<usize>,
}

/// Solver settings. `tolerance`: stop when an accepted step lowers the cost by less than this
/// fraction of it. `lm_lambda`: the initial Levenberg-Marquardt damping (0 = Gauss-Newton).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OptimizeParams {
    pub max_iterations: usize,
    pub tolerance: f64,
    pub lm_lambda: f64,
}

impl Default for OptimizeParams {
    fn default() -> Self {
        OptimizeParams {
            max_iterations: 50,
            tolerance: 1e-6,
            lm_lambda: 1e-4,
        }
    }
}

/// `iterations`: linearizations done; chi² values are the robust cost Σρ(eᵀΩe) (the plain χ²
/// when no edge has a Huber δ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OptimizeReport {
    pub iterations: usize,
    pub initial_chi2: f64,
    pub final_chi2: f64,
    pub converged: bool,
}

/// Diagonal information matrix from standard deviations (m, m, rad).
pub fn information_from_sigmas(sx: f64, sy: f64, st: f64) -> [[f64; 3]; 3] {
    [
        [1.0 / (sx * sx), 0.0, 0.0],
        [0.0, 1.0 / (sy * sy), 0.0],
        [0.0, 0.0, 1.0 / (st * st)],
    ]
}

impl PoseGraph {
    /// A graph over `nodes` with no edges and node 0 fixed.
    pub fn new(nodes: Vec<Pose2>) -> Self {
        PoseGraph {
            nodes,
            edges: Vec::new(),
            fixed: vec![0],
        }
    }

    /// The robust cost Σρ(eᵀΩe) at the current poses.
    pub fn chi2(&self) -> f64 {
        cost(&self.nodes, &self.edges)
    }
}

/// SPA's error of an edge at the given poses (angle wrapped).
pub fn edge_error(xi: &Pose2, xj: &Pose2, z: &Pose2) -> [f64; 3] {
    let (s, c) = xi.theta.sin_cos();
    let (dx, dy) = (xj.x - xi.x, xj.y - xi.y);
    [
        c * dx + s * dy - z.x,
        -s * dx + c * dy - z.y,
        wrap_angle(xj.theta - xi.theta - z.theta),
    ]
}

/// ∂e/∂xᵢ and ∂e/∂xⱼ (rows: e_x, e_y, e_θ; columns: x, y, θ).
fn jacobians(xi: &Pose2, xj: &Pose2) -> (Mat3, Mat3) {
    let (s, c) = xi.theta.sin_cos();
    let (dx, dy) = (xj.x - xi.x, xj.y - xi.y);
    let a = [
        [-c, -s, -s * dx + c * dy],
        [s, -c, -c * dx - s * dy],
        [0.0, 0.0, -1.0],
    ];
    let b = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
    (a, b)
}

fn quad(e: &[f64; 3], w: &Mat3) -> f64 {
    (0..3)
        .map(|r| e[r] * (0..3).map(|k| w[r][k] * e[k]).sum::<f64>())
        .sum()
}

/// Huber: (ρ(s), ρ'(s)) for squared whitened error s.
fn huber(s: f64, delta: Option<f64>) -> (f64, f64) {
    match delta {
        Some(d) if s > d * d => {
            let r = s.sqrt();
            (2.0 * d * r - d * d, d / r)
        }
        _ => (s, 1.0),
    }
}

fn cost(nodes: &[Pose2], edges: &[Edge]) -> f64 {
    edges
        .iter()
        .map(|e| {
            let err = edge_error(&nodes[e.from], &nodes[e.to], &e.measurement);
            huber(quad(&err, &e.information), e.huber).0
        })
        .sum()
}

/// Mᵀ · W · N for 3 × 3 matrices.
fn at_w_b(m: &Mat3, w: &Mat3, n: &Mat3) -> Mat3 {
    let mut wn = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            wn[r][c] = (0..3).map(|k| w[r][k] * n[k][c]).sum();
        }
    }
    let mut out = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = (0..3).map(|k| m[k][r] * wn[k][c]).sum();
        }
    }
    out
}

/// Assembles H (into `sys`) and b at `nodes` (Grisetti et al. §IV–V), IRLS-weighted.
fn linearize(
    nodes: &[Pose2],
    edges: &[Edge],
    slots: &[Option<usize>],
    n_slots: usize,
    sys: &mut System,
) -> Vec<f64> {
    sys.clear();
    let mut b = vec![0.0; 3 * n_slots];
    for (k, e) in edges.iter().enumerate() {
        let (xi, xj) = (&nodes[e.from], &nodes[e.to]);
        let err = edge_error(xi, xj, &e.measurement);
        let (_, weight) = huber(quad(&err, &e.information), e.huber);
        let mut w = e.information;
        w.iter_mut().flatten().for_each(|v| *v *= weight);
        let (ja, jb) = jacobians(xi, xj);
        let we: [f64; 3] = std::array::from_fn(|r| (0..3).map(|c| w[r][c] * err[c]).sum());
        for (slot, j) in [(slots[e.from], &ja), (slots[e.to], &jb)] {
            if let Some(s) = slot {
                sys.add_diagonal(s, &at_w_b(j, &w, j));
                for c in 0..3 {
                    b[3 * s + c] += (0..3).map(|r| j[r][c] * we[r]).sum::<f64>();
                }
            }
        }
        sys.add_edge(k, &at_w_b(&ja, &w, &jb));
    }
    b
}

/// Minimizes the robust cost over the non-fixed nodes by Levenberg-Marquardt with IRLS Huber
/// weights; the nodes are updated in place.
///
/// # Panics
/// If an edge names a node that does not exist (a programming error of the front end).
pub fn optimize(graph: &mut PoseGraph, params: &OptimizeParams) -> OptimizeReport {
    let n = graph.nodes.len();
    for e in &graph.edges {
        assert!(
            e.from < n && e.to < n,
            "pose graph edge {} → {} names a node beyond the {n} nodes",
            e.from,
            e.to
        );
    }
    let initial = graph.chi2();
    let mut report = OptimizeReport {
        iterations: 0,
        initial_chi2: initial,
        final_chi2: initial,
        converged: false,
    };
    // Variables: nodes that are not fixed and appear in an edge.
    let mut is_var = vec![false; n];
    for e in &graph.edges {
        is_var[e.from] = true;
        is_var[e.to] = true;
    }
    let fixed: &[usize] = if graph.fixed.is_empty() {
        &[0]
    } else {
        &graph.fixed
    };
    for &f in fixed {
        if f < n {
            is_var[f] = false;
        }
    }
    let mut next = 0;
    let slots: Vec<Option<usize>> = is_var
        .iter()
        .map(|&v| {
            v.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    if next == 0 || initial == 0.0 {
        report.converged = true;
        return report;
    }
    let pairs: Vec<(usize, usize)> = graph.edges.iter().map(|e| (e.from, e.to)).collect();
    let Ok(mut sys) = System::new(&slots, next, &pairs) else {
        return report;
    };
    let mut cost_now = initial;
    let mut lambda = params.lm_lambda.max(0.0);
    let mut candidate = graph.nodes.clone();
    'outer: while report.iterations < params.max_iterations {
        report.iterations += 1;
        let b = linearize(&graph.nodes, &graph.edges, &slots, next, &mut sys);
        let mut solved = false;
        for _attempt in 0..12 {
            let mut delta: Vec<f64> = b.iter().map(|v| -v).collect();
            if sys.solve(lambda, &mut delta) {
                solved = true;
                for (k, node) in graph.nodes.iter().enumerate() {
                    candidate[k] = match slots[k] {
                        Some(s) => Pose2::new(
                            node.x + delta[3 * s],
                            node.y + delta[3 * s + 1],
                            node.theta + delta[3 * s + 2],
                        ),
                        None => *node,
                    };
                }
                let cost_new = cost(&candidate, &graph.edges);
                if cost_new <= cost_now {
                    std::mem::swap(&mut graph.nodes, &mut candidate);
                    let decrease = cost_now - cost_new;
                    cost_now = cost_new;
                    lambda /= 10.0;
                    if decrease <= params.tolerance * cost_now.max(f64::MIN_POSITIVE) {
                        report.converged = true;
                        break 'outer;
                    }
                    continue 'outer;
                }
            }
            lambda = (lambda * 10.0).max(1e-6);
        }
        // No damping makes the cost drop: a minimum to the precision of the arithmetic — unless
        // the system could never be solved (a part of the graph without a fixed node).
        report.converged = solved;
        break;
    }
    report.final_chi2 = cost_now;
    report
}
