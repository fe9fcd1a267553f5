//! Pose-graph optimization tests on synthetic graphs with ground truth.

use super::synthetic::{Noise, SyntheticGraph, manhattan, square_laps};
use super::*;
use crate::core::stream_rng;
use std::f64::consts::PI;

/// ATE as `evo_ape --align_origin`: translation RMSE after moving the estimate so its first
/// pose coincides with the truth's.
fn ate(est: &[Pose2], truth: &[Pose2]) -> f64 {
    let align = truth[0].compose(&est[0].inverse());
    let sum: f64 = est
        .iter()
        .zip(truth)
        .map(|(e, t)| {
            let a = align.compose(e);
            (a.x - t.x).powi(2) + (a.y - t.y).powi(2)
        })
        .sum();
    (sum / est.len() as f64).sqrt()
}

/// The ATE the graph's information allows at its optimum (Cramér-Rao): √(mean over nodes of
/// σ²_x + σ²_y), the position marginals read off H⁻¹ (H at the optimum, node 0 fixed), by one
/// solve per coordinate.
fn expected_ate(graph: &PoseGraph) -> f64 {
    let n = graph.nodes.len();
    let slots: Vec<Option<usize>> = (0..n).map(|k| k.checked_sub(1)).collect();
    let pairs: Vec<(usize, usize)> = graph.edges.iter().map(|e| (e.from, e.to)).collect();
    let mut sys = linear::System::new(&slots, n - 1, &pairs).unwrap();
    linearize(&graph.nodes, &graph.edges, &slots, n - 1, &mut sys);
    let mut sum = 0.0;
    for k in 0..3 * (n - 1) {
        if k % 3 == 2 {
            continue;
        }
        let mut unit = vec![0.0; 3 * (n - 1)];
        unit[k] = 1.0;
        assert!(sys.solve(0.0, &mut unit));
        sum += unit[k];
    }
    // node 0 is exact
    (sum / n as f64).sqrt()
}

fn max_shift(a: &[Pose2], b: &[Pose2]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(q))
        .fold(0.0, f64::max)
}

/// 4 laps of a 10 × 10 m square in 1 m steps: 161 nodes, 160 odometry edges, 120 closures.
fn square() -> SyntheticGraph {
    let mut rng = stream_rng(3, "pose_graph", "square");
    square_laps(4, 10, 1.0, &Noise::default(), &mut rng)
}

#[test]
fn jacobians_match_finite_differences() {
    let xi = Pose2::new(1.0, -2.0, 2.9);
    let xj = Pose2::new(3.5, 0.5, -2.8);
    let z = Pose2::new(0.7, 0.2, 0.4);
    let (a, b) = jacobians(&xi, &xj);
    let h = 1e-6;
    for k in 0..3 {
        let bump = |p: &Pose2, s: f64| {
            let mut v = [p.x, p.y, p.theta];
            v[k] += s;
            Pose2::new(v[0], v[1], v[2])
        };
        for (jac, moved_i) in [(&a, true), (&b, false)] {
            let (p, m) = if moved_i {
                (
                    edge_error(&bump(&xi, h), &xj, &z),
                    edge_error(&bump(&xi, -h), &xj, &z),
                )
            } else {
                (
                    edge_error(&xi, &bump(&xj, h), &z),
                    edge_error(&xi, &bump(&xj, -h), &z),
                )
            };
            for r in 0..3 {
                let fd = (p[r] - m[r]) / (2.0 * h);
                assert!((fd - jac[r][k]).abs() < 1e-6, "row {r} col {k}");
            }
        }
    }
}

#[test]
fn angle_errors_wrap_across_pi() {
    let xi = Pose2::new(0.0, 0.0, PI - 0.05);
    let xj = Pose2::new(0.0, 0.0, -PI + 0.05);
    let e = edge_error(&xi, &xj, &Pose2::new(0.0, 0.0, 0.1));
    assert!(e[2].abs() < 1e-12, "{e:?}");
    let e = edge_error(&xi, &xj, &Pose2::new(0.0, 0.0, -0.1));
    assert!((e[2] - 0.2).abs() < 1e-12, "{e:?}");
}

#[test]
fn square_laps_ate_drops_more_than_5x() {
    let SyntheticGraph { mut graph, truth } = square();
    assert_eq!(graph.nodes.len(), 161);
    let before = ate(&graph.nodes, &truth);
    let report = optimize(&mut graph, &OptimizeParams::default());
    let after = ate(&graph.nodes, &truth);
    eprintln!("square: ATE {before:.3} m → {after:.4} m, {report:?}");
    assert!(report.converged && report.final_chi2 < report.initial_chi2);
    assert!(after * 5.0 <= before, "{before} → {after}");
    // The bound: the closures tie the laps together and back to the start, but the shape of
    // the loop itself is only known from the (4 laps of) odometry, so even the exact optimum
    // keeps an error; its expected size is the Cramér-Rao figure from H⁻¹ (0.086 m here).
    // ATE² is dominated by a few loop-shape modes, so one draw can reach 2× its expectation
    // (see the seed sweep below): allow 2.5×.
    let expected = expected_ate(&graph);
    eprintln!("square: expected ATE at the optimum {expected:.4} m");
    assert!(after < 2.5 * expected, "{after} vs expected {expected}");
    // the optimum's χ² is about its degrees of freedom (3 per edge − 3 per free node)
    let dof = 3.0 * (graph.edges.len() as f64 - (graph.nodes.len() - 1) as f64);
    assert!(
        report.final_chi2 < 2.0 * dof,
        "{} vs {dof}",
        report.final_chi2
    );
}

#[test]
fn huber_shrugs_off_a_loop_closure_5_m_off() {
    let SyntheticGraph { mut graph, truth } = square();
    for e in graph.edges.iter_mut() {
        if e.kind == EdgeKind::LoopClosure {
            e.huber = Some(1.0);
        }
    }
    // the reference: the same graph and kernel without the outlier
    let mut clean = graph.clone();
    optimize(&mut clean, &OptimizeParams::default());
    let mut bad = graph.clone();
    // a closure between nodes of laps 2 and 3 whose measurement is 5 m off
    let (i, j) = (50, 100);
    let mut z = truth[i].between(&truth[j]);
    z.x += 5.0;
    bad.edges.push(Edge {
        from: i,
        to: j,
        measurement: z,
        information: information_from_sigmas(0.01, 0.01, 0.005),
        kind: EdgeKind::LoopClosure,
        huber: Some(1.0),
    });
    let mut plain = bad.clone();
    plain.edges.iter_mut().for_each(|e| e.huber = None);
    let r_plain = optimize(&mut plain, &OptimizeParams::default());
    let mut robust = bad;
    let r_robust = optimize(&mut robust, &OptimizeParams::default());
    let (d_plain, d_robust) = (
        max_shift(&plain.nodes, &clean.nodes),
        max_shift(&robust.nodes, &clean.nodes),
    );
    let (a_clean, a_plain, a_robust) = (
        ate(&clean.nodes, &truth),
        ate(&plain.nodes, &truth),
        ate(&robust.nodes, &truth),
    );
    eprintln!(
        "outlier: max shift from the clean optimum {d_plain:.3} m without Huber, {d_robust:.4} m \
         with; ATE clean {a_clean:.4}, plain {a_plain:.3}, Huber {a_robust:.4}; {r_plain:?} {r_robust:?}"
    );
    assert!(r_plain.converged && r_robust.converged);
    // Huber bounds the outlier's pull to that of a closure 1σ off (δ = 1), which still bends
    // this loosely held loop a little (its poses are known to ~0.1 m, see the ATE test), but
    // 20× less than the plain squares do, and the ATE stays at the clean one's.
    assert!(
        d_plain > 2.0 && d_robust < d_plain / 20.0,
        "{d_plain} {d_robust}"
    );
    assert!(a_plain > 5.0 * a_clean, "{a_plain} vs {a_clean}");
    assert!(a_robust < a_clean + 0.02, "{a_robust} vs {a_clean}");
}

#[test]
fn fixed_nodes_do_not_move() {
    let SyntheticGraph { mut graph, .. } = square();
    let before = graph.nodes.clone();
    optimize(&mut graph, &OptimizeParams::default());
    assert_eq!(graph.nodes[0], before[0]);
    assert!(max_shift(&graph.nodes, &before) > 0.1);
    // a chosen set
    let SyntheticGraph { mut graph, .. } = square();
    graph.fixed = vec![0, 77];
    let before = graph.nodes.clone();
    optimize(&mut graph, &OptimizeParams::default());
    assert_eq!(graph.nodes[0], before[0]);
    assert_eq!(graph.nodes[77], before[77]);
    assert_ne!(graph.nodes[76], before[76]);
}

#[test]
fn gauss_newton_and_levenberg_marquardt_agree() {
    let SyntheticGraph { graph, .. } = square();
    let mut gn = graph.clone();
    let params = OptimizeParams {
        lm_lambda: 0.0,
        ..OptimizeParams::default()
    };
    let r_gn = optimize(&mut gn, &params);
    let mut lm = graph;
    let r_lm = optimize(&mut lm, &OptimizeParams::default());
    assert!(r_gn.converged && r_lm.converged);
    assert!(max_shift(&gn.nodes, &lm.nodes) < 1e-3);
    assert!((r_gn.final_chi2 - r_lm.final_chi2).abs() < 1e-3 * r_lm.final_chi2);
}

#[test]
fn manhattan_3500_converges_in_a_few_iterations() {
    let mut rng = stream_rng(3, "pose_graph", "manhattan");
    let SyntheticGraph { mut graph, truth } = manhattan(3500, &Noise::default(), &mut rng);
    let before = ate(&graph.nodes, &truth);
    let report = optimize(&mut graph, &OptimizeParams::default());
    let after = ate(&graph.nodes, &truth);
    eprintln!(
        "manhattan: {} nodes, {} edges, ATE {before:.2} m → {after:.4} m, {report:?}",
        graph.nodes.len(),
        graph.edges.len()
    );
    assert!(report.converged && report.iterations <= 10, "{report:?}");
    assert!(after * 5.0 < before && after < 0.1, "{before} → {after}");
}

#[test]
fn deterministic() {
    let a = {
        let mut g = square().graph;
        optimize(&mut g, &OptimizeParams::default());
        g.nodes
    };
    let b = {
        let mut g = square().graph;
        optimize(&mut g, &OptimizeParams::default());
        g.nodes
    };
    assert_eq!(a, b);
}

#[test]
fn ate_over_seeds_is_the_cramer_rao_figure() {
    // The optimizer is efficient: over 40 noise draws the RMS ATE at the optimum is what H⁻¹
    // predicts (measured: 0.085 m vs 0.086 m; single draws reach 2× it).
    let (mut got, mut predicted) = (0.0, 0.0);
    for seed in 0..40 {
        let mut rng = stream_rng(seed, "pose_graph", "square");
        let SyntheticGraph {
            mut graph, truth, ..
        } = square_laps(4, 10, 1.0, &Noise::default(), &mut rng);
        optimize(&mut graph, &OptimizeParams::default());
        got += ate(&graph.nodes, &truth).powi(2);
        predicted += expected_ate(&graph).powi(2);
    }
    let ratio = (got / predicted).sqrt();
    eprintln!("RMS ATE / Cramér-Rao over 40 draws: {ratio:.3}");
    assert!((0.8..1.2).contains(&ratio), "{ratio}");
}
