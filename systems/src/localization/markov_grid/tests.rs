//! The Markov grid on the hospital map with scans ray-cast from a known trajectory.

use super::*;
use crate::core::stream_rng;
use crate::localization::mcl::BeamSubset;
use crate::localization::test_drive::{CORRIDOR, drive, error, hospital, scan_at};

fn motion() -> OdometryMotionModel {
    OdometryMotionModel {
        alpha1: 0.05,
        alpha2: 0.05,
        alpha3: 0.05,
        alpha4: 0.05,
    }
}

/// The kernel's score of a cell equals the likelihood field evaluated directly at the beam
/// endpoints seen from the cell's centre pose (to within a map cell of rounding).
#[test]
fn layer_score_matches_a_direct_evaluation() {
    let map = hospital();
    let mut grid = MarkovGrid::new(MarkovGridConfig::default(), &map);
    let mut rng = stream_rng(1, "test", "grid-score");
    let truth = Pose2::new(10.0, 16.0, 0.3);
    let scan = scan_at(&map, &truth, &mut rng);
    let pts = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60).returns();
    grid.score(&map, &pts, 20.0, None);
    let l = &grid.layout;
    let (i, j, k) = l.cell_of(truth.x, truth.y, truth.theta).unwrap();
    let (x, y) = l.centre(i, j);
    let th = l.theta(k);
    let p = grid.config.laser;
    let direct: f64 = pts
        .iter()
        .map(|b| {
            let (bx, by) = (b[0] as f64, b[1] as f64);
            let ex = x + th.cos() * bx - th.sin() * by;
            let ey = y + th.sin() * bx + th.cos() * by;
            let d = map.field.distance(ex, ey).min(p.max_dist);
            let r = bx.hypot(by);
            let var = p.sigma_hit.powi(2)
                + l.resolution.powi(2) / 12.0
                + (r * l.theta_step()).powi(2) / 12.0;
            (p.z_hit * (-d * d / (2.0 * var)).exp() + p.z_rand / 20.0).ln()
        })
        .sum();
    let kernel = grid.scratch[k * l.layer() + j * l.nx + i] as f64;
    // rounding the endpoint offset moves it by at most half a map cell per axis
    assert!(
        (kernel - direct).abs() < 0.1 * pts.len() as f64,
        "kernel {kernel}, direct {direct}"
    );
    // and the true cell scores better than cells a metre away or 30° off
    let at = |i: usize, j: usize, k: usize| grid.scratch[k * l.layer() + j * l.nx + i];
    let own = at(i, j, k);
    assert!(own > at(i + 4, j, k) && own > at(i, j, (k + 3) % l.n_theta));
}

/// Prediction keeps the mass (away from walls) and carries a peak along the motion.
#[test]
fn prediction_moves_the_mass_with_the_robot() {
    let map = hospital();
    let start = Pose2::new(10.0, 16.0, 0.0);
    let config = MarkovGridConfig {
        init: InitialBelief::Gaussian {
            pose: start,
            sd: [0.1, 0.1, 0.05],
        },
        motion: motion(),
        ..MarkovGridConfig::default()
    };
    let mut grid = MarkovGrid::new(config, &map);
    let before = grid.estimate.unwrap().pose;
    assert!(before.distance(&start) < 0.15, "{before:?}");
    // 1 m forward, then a quarter turn, in several steps
    let mut odom = Pose2::IDENTITY;
    for _ in 0..4 {
        let next = odom.compose(&Pose2::new(0.25, 0.0, 0.0));
        grid.apply_motion(&odom, &next);
        odom = next;
    }
    let next = odom.compose(&Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
    grid.apply_motion(&odom, &next);
    let total: f64 = grid.belief.iter().map(|&v| v as f64).sum();
    assert!((total - 1.0).abs() < 1e-3, "{total}");
    let e = grid.estimate_pose().unwrap();
    let want = start.compose(&next);
    assert!(
        e.pose.distance(&want) < 0.2 && wrap_angle(e.pose.theta - want.theta).abs() < 0.1,
        "{:?} vs {want:?}",
        e.pose
    );
    // the belief spread: covariance grew
    assert!(e.covariance[0][0] > grid.layout.resolution.powi(2) / 12.0);
}

#[test]
fn converges_from_global_initialisation_and_tracks() {
    let map = hospital();
    let config = MarkovGridConfig {
        motion: motion(),
        ..MarkovGridConfig::default()
    };
    let mut grid = MarkovGrid::new(config, &map);
    assert!(grid.layout.len() > 1_000_000, "{}", grid.layout.len());
    let mut errors = Vec::new();
    drive(&map, &CORRIDOR, 0.0, 3, |truth, odom, scan| {
        let pts = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60).returns();
        if grid.update(&map, &pts, scan.range_max, odom) {
            errors.push(error(&grid.estimate.unwrap(), truth));
        }
    });
    let ok = |e: &(f64, f64)| e.0 < 0.2 && e.1 < 5f64.to_radians();
    // converged: the first update from which five in a row are right
    let since = (0..errors.len().saturating_sub(5))
        .find(|&i| errors[i..i + 5].iter().all(ok))
        .expect("never converged");
    let tail = &errors[since..];
    let tracked = tail.iter().filter(|e| ok(e)).count() as f64 / tail.len() as f64;
    let rms = (tail.iter().map(|e| e.0 * e.0).sum::<f64>() / tail.len() as f64).sqrt();
    assert!(
        errors.len() > 100 && since < 40 && tracked > 0.95 && rms < 0.10,
        "converged after {since} of {} updates, then tracked {tracked}, rms {rms}",
        errors.len()
    );
}

/// The most probable cell is the one `max_by` with `total_cmp`, ties to the first, picks: on
/// ties, zeros of both signs, subnormals, infinities and NaNs.
#[test]
fn argmax_is_total_cmp_s_first_maximum() {
    let plain = |v: &[f32]| {
        v.iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            .map(|(i, &x)| (i, x.to_bits()))
    };
    let specials = [
        0.0,
        -0.0,
        1e-40,
        -1e-40,
        0.25,
        0.25,
        -3.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
    ];
    let mut x = 12345u64;
    for len in [0, 1, 2, 7, 64, 1000] {
        for round in 0..50 {
            let v: Vec<f32> = (0..len)
                .map(|_| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let pick = (x >> 33) as usize;
                    if round % 2 == 0 {
                        specials[pick % specials.len()]
                    } else {
                        (pick % 5) as f32 * 0.125
                    }
                })
                .collect();
            let fast = argmax(&v).map(|(i, x)| (i, x.to_bits()));
            assert_eq!(fast, plain(&v), "{v:?}");
        }
    }
}
