//! Gauss-Newton matcher tests: SICK LMS100 scans (270°, 0.25°, 0.5–20 m) ray-cast on the hospital
//! map (5 cm cells) and on a synthetic featureless corridor.

use super::*;
use crate::core::stream_rng;
use crate::matching::map_pyramid::PyramidOptions;
use crate::matching::tests::{hospital, is_free, scan_at};
use crate::matching::{ProbGrid, scan_to_points};
use crate::raycast::RayMap;
use crate::world::{Cell, OccupancyGrid};
use rand::RngExt;
use std::sync::OnceLock;

/// The hospital map's pyramid, `levels` deep, for the map_server map it is.
fn hospital_pyramid(levels: usize) -> &'static MapPyramid {
    static P: OnceLock<Vec<MapPyramid>> = OnceLock::new();
    &P.get_or_init(|| {
        let grid = ProbGrid::from_occupancy(&hospital().grid);
        (1..=4)
            .map(|n| MapPyramid::with_options(&grid, n, PyramidOptions::static_map()))
            .collect()
    })[levels - 1]
}

/// Poses in rooms (the first three and the last) and in corridors (horizontal, vertical, the
/// long bottom one), each checked free.
const POSES: [(f64, f64, f64); 7] = [
    (15.0, 21.0, 0.3),
    (32.0, 12.0, 1.2),
    (50.0, 20.5, -2.0),
    (30.0, 16.0, 0.0),
    (21.2, 12.0, 1.57),
    (10.0, 7.2, 3.0),
    (4.5, 3.5, 0.5),
];

fn poses() -> impl Iterator<Item = Pose2> {
    POSES.iter().map(|&(x, y, t)| {
        assert!(is_free(x, y), "test pose ({x}, {y}) must be free");
        Pose2::new(x, y, t)
    })
}

/// (position error, heading error) of `found` against `truth`.
fn errors(found: &Pose2, truth: &Pose2) -> (f64, f64) {
    (
        found.distance(truth),
        wrap_angle(found.theta - truth.theta).abs(),
    )
}

fn params(levels: usize) -> GaussNewtonParams {
    GaussNewtonParams {
        levels,
        ..Default::default()
    }
}

#[test]
fn gauss_newton_recovers_hospital_poses_from_the_corners_of_the_error_box() {
    // every corner of ±0.3 m × ±0.3 m × ±0.15 rad (0.42 m off), noise-free scans
    let pyr = hospital_pyramid(3);
    let (mut worst_xy, mut worst_th) = (0f64, 0f64);
    for truth in poses() {
        let pts = scan_at(truth, None);
        for corner in 0..8 {
            let sign = |bit: usize| if corner >> bit & 1 == 1 { 1.0 } else { -1.0 };
            let initial = Pose2::new(
                truth.x + 0.3 * sign(0),
                truth.y + 0.3 * sign(1),
                truth.theta + 0.15 * sign(2),
            );
            let r = match_scan(pyr, &pts, initial, None, &params(3));
            let (e_xy, e_th) = errors(&r.pose, &truth);
            assert!(
                e_xy < 0.02 && e_th < 0.5f64.to_radians() && r.converged,
                "truth {truth:?} from {initial:?}: found {r:?}"
            );
            assert!(r.score > 0.95, "score {} at a correct match", r.score);
            (worst_xy, worst_th) = (worst_xy.max(e_xy), worst_th.max(e_th));
        }
    }
    eprintln!(
        "56 corners: worst error {:.2} mm, {:.4}°",
        worst_xy * 1e3,
        worst_th.to_degrees()
    );
}

#[test]
fn gauss_newton_with_range_noise_stays_within_3_cm() {
    // 12 mm Gaussian range noise, starts uniform in ±0.3 m, ±0.15 rad; the full scan and every
    // fourth beam (270 points)
    let mut rng = stream_rng(5, "gauss-newton", "noise");
    for max_points in [usize::MAX, 271] {
        let p = GaussNewtonParams {
            max_points,
            ..params(3)
        };
        let (mut worst_xy, mut worst_th) = (0f64, 0f64);
        // Σ of squared errors over predicted variances, per axis (≈ the count if consistent)
        let mut nees = [0f64; 3];
        let mut evals = 0;
        for truth in poses() {
            for _ in 0..6 {
                let pts = scan_at(truth, Some(&mut rng));
                let initial = Pose2::new(
                    truth.x + rng.random_range(-0.3..0.3),
                    truth.y + rng.random_range(-0.3..0.3),
                    truth.theta + rng.random_range(-0.15..0.15),
                );
                let r = match_scan(hospital_pyramid(3), &pts, initial, None, &p);
                evals += r.evaluations;
                let (e_xy, e_th) = errors(&r.pose, &truth);
                assert!(
                    e_xy < 0.03 && e_th < 0.5f64.to_radians(),
                    "max_points {max_points}, truth {truth:?} from {initial:?}: found {r:?}"
                );
                (worst_xy, worst_th) = (worst_xy.max(e_xy), worst_th.max(e_th));
                let e = [
                    r.pose.x - truth.x,
                    r.pose.y - truth.y,
                    wrap_angle(r.pose.theta - truth.theta),
                ];
                for (k, n) in nees.iter_mut().enumerate() {
                    *n += e[k] * e[k] / r.covariance[k][k];
                }
            }
        }
        eprintln!(
            "noise, max_points {max_points}: worst {:.2} mm, {:.4}°; RMS error / predicted σ \
             per axis {:?}",
            worst_xy * 1e3,
            worst_th.to_degrees(),
            nees.map(|v| (v / 42.0).sqrt())
        );
        eprintln!("mean evaluations {}", evals as f64 / 42.0);
    }
}

#[test]
fn gauss_newton_pyramid_widens_the_basin() {
    // 0.5 m off in eight directions and 0.1 rad turned: three levels bring every start back,
    // level 0 alone (a basin of about one 5 cm cell) almost none
    let (mut three, mut one, mut n) = (0, 0, 0);
    for truth in poses() {
        let pts = scan_at(truth, None);
        for k in 0..8 {
            let a = k as f64 * std::f64::consts::FRAC_PI_4 + 0.2;
            let turn = if k % 2 == 0 { 0.1 } else { -0.1 };
            let initial = Pose2::new(
                truth.x + 0.5 * a.cos(),
                truth.y + 0.5 * a.sin(),
                truth.theta + turn,
            );
            let ok = |levels| {
                let r = match_scan(
                    hospital_pyramid(levels),
                    &pts,
                    initial,
                    None,
                    &params(levels),
                );
                let (e_xy, e_th) = errors(&r.pose, &truth);
                e_xy < 0.02 && e_th < 0.5f64.to_radians()
            };
            n += 1;
            three += ok(3) as usize;
            one += ok(1) as usize;
        }
    }
    eprintln!("0.5 m starts: 3 levels {three}/{n}, 1 level {one}/{n}");
    assert_eq!(three, n, "3 levels must recover every 0.5 m start");
    assert!(
        one * 10 <= n,
        "1 level recovered {one}/{n}: the basin test is void"
    );
}

/// A straight corridor along x: 2.4 m wide, 100 m long (its ends beyond the 20 m range of a
/// sensor near the middle), walls 2 cells thick, 5 cm cells.
fn corridor() -> (OccupancyGrid, MapPyramid) {
    let (w, h) = (2000, 60);
    let mut g = OccupancyGrid::new(w, h, 0.05, [0.0, 0.0], Cell::Unknown);
    for c in 0..w {
        for r in 4..56 {
            let wall = !(6..54).contains(&r);
            g.set(c, r, if wall { Cell::Occupied } else { Cell::Free });
        }
    }
    let pyr = MapPyramid::with_options(
        &ProbGrid::from_occupancy(&g),
        3,
        PyramidOptions::static_map(),
    );
    (g, pyr)
}

fn corridor_scan(map: &RayMap, pose: Pose2) -> Vec<[f32; 2]> {
    let (start, inc) = (-135f32.to_radians(), 0.25f32.to_radians());
    let mut ranges = vec![0f32; 1081];
    map.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + start,
        inc,
        20.0,
        &mut ranges,
    );
    scan_to_points(start, inc, &ranges, 0.5, 20.0)
}

#[test]
fn gauss_newton_corridor_holds_the_prior_along_its_axis() {
    let (g, pyr) = corridor();
    let map = RayMap::from_grid(&g);
    // the walls' faces are at y = 0.3 and 2.7; the robot is 0.4 m further along than odometry says
    let truth = Pose2::new(50.4, 1.3, 0.05);
    let pts = corridor_scan(&map, truth);
    let odom = Pose2::new(50.0, 1.45, 0.12);
    let prior = OdometryPrior::from_std(odom, [0.1, 0.1, 0.05]);
    for initial in [odom, Pose2::new(50.25, 1.2, 0.0)] {
        let r = match_scan(&pyr, &pts, initial, Some(prior), &params(3));
        let c = r.covariance;
        assert!(c.iter().flatten().all(|v| v.is_finite()), "{r:?}");
        // across the corridor and in heading the scan wins, along it the prior
        assert!((r.pose.y - truth.y).abs() < 0.02, "{r:?}");
        assert!(
            wrap_angle(r.pose.theta - truth.theta).abs() < 0.5f64.to_radians(),
            "{r:?}"
        );
        assert!((r.pose.x - odom.x).abs() < 0.02, "from {initial:?}: {r:?}");
        // σx is the prior's 0.1 m, σy far smaller
        assert!((c[0][0].sqrt() - 0.1).abs() < 0.01, "{c:?}");
        assert!(c[0][0] > 100.0 * c[1][1], "{c:?}");
        eprintln!(
            "corridor with prior from {initial:?}: {:?}, σ = {:?}",
            r.pose,
            [0, 1, 2].map(|i| c[i][i].sqrt())
        );
    }
    // without the prior: no step along the axis (nothing there to step on), no NaN, and the
    // covariance says the axis is unknown
    let initial = Pose2::new(50.0, 1.45, 0.12);
    let r = match_scan(&pyr, &pts, initial, None, &params(3));
    let c = r.covariance;
    assert!(c.iter().flatten().all(|v| v.is_finite()), "{r:?}");
    assert!(
        (r.pose.x - initial.x).abs() < 0.05,
        "jumped along the corridor: {r:?}"
    );
    assert!((r.pose.y - truth.y).abs() < 0.02, "{r:?}");
    assert!(c[0][0] > 1e4 * c[1][1], "{c:?}");
    eprintln!(
        "corridor without prior: {:?}, σ = {:?}",
        r.pose,
        [0, 1, 2].map(|i| c[i][i].sqrt())
    );
}

#[test]
fn gauss_newton_covariance_is_small_and_symmetric_in_a_room() {
    let truth = Pose2::new(15.0, 21.0, 0.3);
    let pts = scan_at(truth, None);
    let r = match_scan(
        hospital_pyramid(3),
        &pts,
        Pose2::new(15.1, 20.9, 0.25),
        None,
        &params(3),
    );
    let c = r.covariance;
    for (i, row) in c.iter().enumerate() {
        assert!(row[i] > 0.0 && row[i] < 1e-4, "{c:?}");
        assert!(row.iter().enumerate().all(|(j, &v)| v == c[j][i]), "{c:?}");
    }
}

#[test]
fn gauss_newton_degenerate_input_returns_the_guess() {
    let pyr = hospital_pyramid(3);
    let initial = Pose2::new(15.0, 21.0, 0.3);
    let far = [[1e6f32, 1e6]; 10];
    let nan = [[f32::NAN, 1.0]; 10];
    for pts in [&[][..], &far[..], &nan[..]] {
        let r = match_scan(pyr, pts, initial, None, &params(3));
        assert_eq!(r.pose, initial);
        assert!(!r.converged && r.score == 0.0);
        assert!(r.covariance.iter().flatten().all(|v| v.is_finite()));
    }
    // a non-finite guess is handed back, never iterated on
    let bad = Pose2 {
        x: f64::NAN,
        ..initial
    };
    let r = match_scan(pyr, &scan_at(initial, None), bad, None, &params(3));
    assert!(r.pose.x.is_nan() && !r.converged && r.evaluations == 0);
}
