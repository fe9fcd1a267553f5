//! Branch-and-bound tests on the hospital map with SICK LMS100 scans (270°, 0.25°, 20 m).

use super::*;
use crate::core::{stream_rng, wrap_angle};
use crate::matching::tests::{hospital, is_free, scan_at};
use crate::matching::{ProbGrid, likelihood_grid};
use rand::RngExt;
use std::f64::consts::FRAC_PI_2;
use std::sync::OnceLock;

/// The hospital map blurred by σ = 0.1 m (two cells, see [`crate::matching::likelihood`]),
/// depth 7 as in Hess et al.
fn hospital_grids() -> &'static PrecomputedGrids {
    static G: OnceLock<PrecomputedGrids> = OnceLock::new();
    G.get_or_init(|| PrecomputedGrids::new(&likelihood_grid(&hospital().grid, 0.1), 7))
}

/// The scan's own angular step (eq. 7 with its farthest point).
fn step_of(points: &[[f32; 2]]) -> f64 {
    let d_max = points
        .iter()
        .map(|p| (p[0] as f64).hypot(p[1] as f64))
        .fold(0.0, f64::max);
    angular_step(0.05, d_max)
}

/// Every `n`-th point: small scans keep the exhaustive reference fast.
fn every(points: &[[f32; 2]], n: usize) -> Vec<[f32; 2]> {
    points.iter().step_by(n).copied().collect()
}

fn random_free_pose(rng: &mut crate::core::SimRng) -> Pose2 {
    let b = hospital().grid.bounds();
    loop {
        let (x, y) = (rng.random_range(b[0]..b[2]), rng.random_range(b[1]..b[3]));
        if is_free(x, y) {
            return Pose2::new(x, y, rng.random_range(-PI..PI));
        }
    }
}

#[test]
fn angular_step_is_hess_eq_7() {
    // r = 5 cm, d_max = 20 m: 0.05 / 20 rad to first order
    let s = angular_step(0.05, 20.0);
    assert!((s - 0.0025).abs() < 1e-6, "{s}");
    // a point at d_max moves by exactly one cell (chord 2 d sin(δθ/2) = r)
    assert!((2.0 * 20.0 * (s / 2.0).sin() - 0.05).abs() < 1e-9);
    assert_eq!(angular_step(0.05, 0.0), PI);
}

#[test]
fn equals_the_exhaustive_search() {
    let grids: Vec<PrecomputedGrids> = [1, 3, 5]
        .iter()
        .map(|&d| PrecomputedGrids::new(&ProbGrid::from_occupancy(&hospital().grid), d))
        .collect();
    let mut rng = stream_rng(11, "bnb", "exhaustive");
    let window = BnbWindow {
        x: 0.4,
        y: 0.3,
        theta: 0.08,
    };
    for _ in 0..4 {
        let truth = random_free_pose(&mut rng);
        let points = every(&scan_at(truth, None), 12);
        let initial = Pose2::new(
            truth.x + rng.random_range(-0.3..0.3),
            truth.y + rng.random_range(-0.3..0.3),
            truth.theta + rng.random_range(-0.06..0.06),
        );
        for min_score in [0.0, 0.3, 0.95] {
            let reference = match_exhaustive(&grids[0], &points, initial, &window, min_score);
            for g in &grids {
                let bnb = match_bnb(g, &points, initial, &window, min_score);
                assert_eq!(bnb, reference, "depth {} min {min_score}", g.depth());
            }
        }
    }
}

#[test]
fn breaks_ties_like_the_exhaustive_search() {
    // An unknown (0.5) map: every candidate ties, the initial guess itself must win.
    let flat = ProbGrid::new(80, 60, 0.05, [0.0, 0.0], 0.5);
    // Two walls: ties along the walls' direction.
    let mut walls = ProbGrid::new(80, 60, 0.05, [0.0, 0.0], 0.0);
    for r in 0..60 {
        walls.p[r * 80 + 20] = 1.0;
        walls.p[r * 80 + 21] = 1.0;
    }
    let points: Vec<[f32; 2]> = (0..20).map(|k| [0.0, -0.5 + 0.05 * k as f32]).collect();
    let initial = Pose2::new(0.9, 1.5, 0.0);
    let window = BnbWindow {
        x: 0.6,
        y: 0.6,
        theta: 0.05,
    };
    for map in [&flat, &walls] {
        let reference = match_exhaustive(
            &PrecomputedGrids::new(map, 1),
            &points,
            initial,
            &window,
            0.0,
        );
        for depth in [1, 2, 4] {
            let bnb = match_bnb(
                &PrecomputedGrids::new(map, depth),
                &points,
                initial,
                &window,
                0.0,
            );
            assert_eq!(bnb, reference, "depth {depth}");
        }
    }
    let m = match_bnb(
        &PrecomputedGrids::new(&flat, 3),
        &points,
        initial,
        &window,
        0.0,
    )
    .unwrap();
    assert_eq!(m.pose, initial);
    assert!((m.score - 128.0 / 255.0).abs() < 1e-12);
}

#[test]
fn finds_a_pose_1_5_m_and_0_4_rad_off_the_guess() {
    // Wards, offices and a corridor junction of the hospital (places.toml), the guess 1.5 m
    // away along whole cells (so the true translation is a candidate) and 0.4 rad off (so the
    // true angle is not: it lies between two candidate angles).
    let places = [
        (13.5, 27.3, FRAC_PI_2),
        (36.5, 13.45, -FRAC_PI_2),
        (3.5, 4.7, -FRAC_PI_2),
        (47.45, 13.45, -FRAC_PI_2),
        (32.0, 18.7, FRAC_PI_2),
        (43.25, 16.0, 0.0),
    ];
    let offsets = [
        (1.2, 0.9),
        (-0.9, 1.2),
        (-1.5, 0.0),
        (0.0, -1.5),
        (1.2, -0.9),
        (0.9, 1.2),
    ];
    let window = BnbWindow {
        x: 2.0,
        y: 2.0,
        theta: 0.5,
    };
    for (&(x, y, t), &(ox, oy)) in places.iter().zip(&offsets) {
        let truth = Pose2::new(x + 0.13, y - 0.07, t + 0.3);
        let points = scan_at(truth, None);
        let initial = Pose2::new(truth.x - ox, truth.y - oy, truth.theta - 0.4);
        let m = match_bnb(hospital_grids(), &points, initial, &window, 0.5).expect("a match");
        let (dx, dy) = (m.pose.x - truth.x, m.pose.y - truth.y);
        let dt = wrap_angle(m.pose.theta - truth.theta) / step_of(&points);
        eprintln!(
            "({x}, {y}): error ({dx:+.3} m, {dy:+.3} m, {dt:+.2} steps), score {:.3}",
            m.score
        );
        assert!(
            dx.abs() <= 0.05 + 1e-9 && dy.abs() <= 0.05 + 1e-9,
            "({dx}, {dy})"
        );
        assert!(dt.abs() <= 1.0, "{dt} steps");
        assert!(m.score > 0.9, "{}", m.score);
    }
}

#[test]
fn finds_random_poses_to_a_cell() {
    // Any direction: neither the true translation nor the true angle is a candidate, and the
    // best candidate is not always the nearest one: δθ (eq. 7) moves the FARTHEST point by a
    // cell, so where most points are near (clutter, a far point through a door) a few steps
    // trade against a sub-cell shift. Bound: translation within two cells, and the angle error
    // moves the scan's median-range point by at most one cell. (Cartographer refines the
    // branch-and-bound result by a continuous match.)
    let grids = hospital_grids();
    let mut rng = stream_rng(5, "bnb", "offset");
    let window = BnbWindow {
        x: 2.0,
        y: 2.0,
        theta: 0.5,
    };
    for _ in 0..12 {
        let truth = random_free_pose(&mut rng);
        let points = scan_at(truth, None);
        let dir = rng.random_range(-PI..PI);
        let initial = Pose2::new(
            truth.x - 1.5 * dir.cos(),
            truth.y - 1.5 * dir.sin(),
            truth.theta - 0.4,
        );
        let m = match_bnb(grids, &points, initial, &window, 0.5).expect("a match");
        let (dx, dy) = (m.pose.x - truth.x, m.pose.y - truth.y);
        let dt = wrap_angle(m.pose.theta - truth.theta) / step_of(&points);
        let mut r: Vec<f64> = points
            .iter()
            .map(|p| (p[0] as f64).hypot(p[1] as f64))
            .collect();
        r.sort_by(f64::total_cmp);
        eprintln!(
            "error ({dx:+.3} m, {dy:+.3} m, {dt:+.2} steps), score {:.3}, median range {:.1} m",
            m.score,
            r[r.len() / 2],
        );
        let median = r[r.len() / 2];
        assert!(dx.abs() <= 0.1 && dy.abs() <= 0.1, "({dx}, {dy})");
        assert!(dt.abs() * step_of(&points) * median <= 0.05, "{dt} steps");
        assert!(m.score > 0.9, "{}", m.score);
    }
}

#[test]
fn a_scan_from_another_room_does_not_reach_the_threshold() {
    let grids = hospital_grids();
    // the top-left ward (ward_9) and the central room with the two large blocks (elevator
    // lobby), 30 m apart
    let truth = Pose2::new(3.8, 27.3, 1.3);
    let guess = Pose2::new(32.0, 18.7, 1.3);
    assert!(is_free(truth.x, truth.y) && is_free(guess.x, guess.y));
    let points = scan_at(truth, None);
    let window = BnbWindow {
        x: 3.0,
        y: 3.0,
        theta: PI / 6.0,
    };
    assert_eq!(match_bnb(grids, &points, guess, &window, 0.6), None);
    // what the best wrong pose scores, and what the right one scores
    let wrong = match_bnb(grids, &points, guess, &window, 0.0).unwrap();
    let right = match_bnb(grids, &points, truth, &window, 0.0).unwrap();
    eprintln!(
        "wrong room best {:.3}, right room {:.3}",
        wrong.score, right.score
    );
    assert!(wrong.score < 0.6 && right.score > 0.9);
}
