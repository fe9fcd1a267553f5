//! MCL on the hospital map with scans ray-cast from a known trajectory and noisy odometry.

use super::*;
use crate::core::stream_rng;
use crate::sensors::LaserScan;
use crate::world::load_map;

fn hospital() -> LocalizationMap {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/maps/hospital/hospital.yaml"
    );
    LocalizationMap::new(load_map(std::path::Path::new(path)).unwrap(), 2.0)
}

/// A SICK LMS100-like scan (270°, 0.25°, 20 m) from `pose` with 1 cm noise.
fn scan_at(map: &LocalizationMap, pose: &Pose2, rng: &mut SimRng) -> LaserScan {
    let n = 1081;
    let inc = 0.25f32.to_radians();
    let start = -135f32.to_radians();
    let mut ranges = vec![0.0f32; n];
    map.rays.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + start,
        inc,
        20.0,
        &mut ranges,
    );
    for r in ranges.iter_mut() {
        if r.is_finite() {
            let e: f64 = StandardNormal.sample(rng);
            *r += 0.01 * e as f32;
        }
    }
    LaserScan {
        stamp: 0.0,
        angle_min: start,
        angle_increment: inc,
        range_min: 0.5,
        range_max: 20.0,
        ranges,
    }
}

/// Drives along `route` in 0.1 m steps; odometry has 1 % translation and 2 % rotation error
/// plus jitter. Calls `f(truth, odom, scan)` every step.
fn drive(
    map: &LocalizationMap,
    route: &[[f64; 2]],
    start_heading: f64,
    seed: u64,
    mut f: impl FnMut(&Pose2, &Pose2, &LaserScan),
) {
    let mut rng = stream_rng(seed, "test", "drive");
    let mut truth = Pose2::new(route[0][0], route[0][1], start_heading);
    let mut odom = Pose2::new(0.0, 0.0, 0.0);
    for goal in &route[1..] {
        loop {
            let (dx, dy) = (goal[0] - truth.x, goal[1] - truth.y);
            let dist = dx.hypot(dy);
            if dist < 0.05 {
                break;
            }
            let turn = wrap_angle(dy.atan2(dx) - truth.theta);
            let step = if turn.abs() > 0.3 {
                Pose2::new(0.0, 0.0, turn.clamp(-0.3, 0.3))
            } else {
                Pose2::new(dist.min(0.1), 0.0, turn)
            };
            truth = truth.compose(&step);
            let g = |r: &mut SimRng| -> f64 { StandardNormal.sample(r) };
            let noisy = Pose2::new(
                step.x * 1.01 + 0.002 * g(&mut rng),
                0.002 * g(&mut rng),
                step.theta * 1.02 + 0.003 * g(&mut rng),
            );
            odom = odom.compose(&noisy);
            let scan = scan_at(map, &truth, &mut rng);
            f(&truth, &odom, &scan);
        }
    }
}

fn error(e: &PoseEstimate, truth: &Pose2) -> (f64, f64) {
    (
        e.pose.distance(truth),
        wrap_angle(e.pose.theta - truth.theta).abs(),
    )
}

/// Defaults with motion noise and σ_hit for a well-calibrated robot and a precise laser.
fn tuned() -> MclConfig {
    MclConfig {
        motion: crate::localization::OdometryMotionModel {
            alpha1: 0.05,
            alpha2: 0.05,
            alpha3: 0.05,
            alpha4: 0.05,
        },
        laser: LaserModelParams {
            sigma_hit: 0.1,
            ..LaserModelParams::default()
        },
        ..MclConfig::default()
    }
}

const CORRIDOR: [[f64; 2]; 4] = [[2.2, 16.0], [20.0, 16.0], [20.0, 24.75], [40.0, 24.75]];

#[test]
fn tracks_from_a_gaussian_around_the_start() {
    let map = hospital();
    let start = Pose2::new(2.2, 16.0, 0.0);
    let config = MclConfig {
        init: InitialBelief::Gaussian {
            pose: Pose2::new(2.5, 15.8, 0.1),
            sd: [0.3, 0.3, 0.1],
        },
        ..tuned()
    };
    let mut mcl = Mcl::new(config, &map, stream_rng(1, "test", "mcl"));
    let mut errors = Vec::new();
    drive(&map, &CORRIDOR, start.theta, 1, |truth, odom, scan| {
        let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
        if mcl.update(&map, &beams, odom) {
            errors.push(error(&mcl.estimate.unwrap(), truth));
        }
    });
    assert!(errors.len() > 100, "{}", errors.len());
    let rms =
        (errors[5..].iter().map(|e| e.0 * e.0).sum::<f64>() / (errors.len() - 5) as f64).sqrt();
    let worst_th = errors[5..].iter().map(|e| e.1).fold(0.0, f64::max);
    assert!(
        rms < 0.10 && worst_th < 5f64.to_radians(),
        "rms {rms} worst θ {worst_th}"
    );
    // KLD shrinks the set once it is concentrated
    assert!(mcl.len() < 3500, "{}", mcl.len());
}

#[test]
fn converges_from_global_initialisation() {
    let map = hospital();
    let config = MclConfig {
        max_particles: 100_000,
        ..tuned()
    };
    let mut mcl = Mcl::new(config, &map, stream_rng(2, "test", "mcl"));
    let mut tracked_since = None;
    let mut k = 0;
    drive(&map, &CORRIDOR, 0.0, 2, |truth, odom, scan| {
        let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
        if mcl.update(&map, &beams, odom) {
            k += 1;
            let (d, a) = error(&mcl.estimate.unwrap(), truth);
            if d < 0.2 && a < 5f64.to_radians() {
                tracked_since.get_or_insert(k);
            } else {
                tracked_since = None;
            }
        }
    });
    let since = tracked_since.expect("never converged");
    assert!(
        k > 150 && since < 100,
        "converged only after {since} of {k} updates"
    );
}

/// Weighing a grid of poses around the truth: the best is within a cell of it (no bias
/// towards the walls the beams end on).
#[test]
fn likelihood_peaks_at_the_true_pose() {
    let map = hospital();
    let mut rng = stream_rng(5, "test", "peak");
    let table = sensor_model::likelihood_table(
        &map.field,
        &LaserModelParams {
            sigma_hit: 0.05,
            ..LaserModelParams::default()
        },
        20.0,
    );
    for truth in [
        Pose2::new(10.0, 16.0, 0.3),
        Pose2::new(30.1, 24.75, 2.0),
        Pose2::new(35.25, 7.25, -1.0),
    ] {
        let scan = scan_at(&map, &truth, &mut rng);
        let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 180);
        let pts = beams.returns();
        let mut best = (f64::MIN, 0.0, 0.0);
        let (mut xs, mut ys, mut ths) = (vec![], vec![], vec![]);
        for i in -10..=10 {
            for j in -10..=10 {
                xs.push(truth.x + i as f64 * 0.01);
                ys.push(truth.y + j as f64 * 0.01);
                ths.push(truth.theta);
            }
        }
        let mut w = vec![1.0; xs.len()];
        sensor_model::weigh_likelihood_field(&map.field, &table, &pts, &xs, &ys, &ths, &mut w);
        for k in 0..w.len() {
            if w[k] > best.0 {
                best = (w[k], xs[k] - truth.x, ys[k] - truth.y);
            }
        }
        // the field is exact to a cell (5 cm): the peak is within a cell of the truth
        assert!(
            best.1.abs() <= 0.05 && best.2.abs() <= 0.05,
            "{truth:?}: {best:?}"
        );
    }
}

/// The beam model (ray-cast expected ranges) prefers the true pose to poses 0.2 m or 3° off.
#[test]
fn beam_model_prefers_the_true_pose() {
    let map = hospital();
    let mut rng = stream_rng(6, "test", "beam");
    let params = LaserModelParams::default();
    for truth in [Pose2::new(10.0, 16.0, 0.3), Pose2::new(30.1, 24.75, 2.0)] {
        let scan = scan_at(&map, &truth, &mut rng);
        let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60);
        let offsets = [
            (0.0, 0.0, 0.0),
            (0.2, 0.0, 0.0),
            (0.0, -0.2, 0.0),
            (0.0, 0.0, 3f64.to_radians()),
        ];
        let xs: Vec<f64> = offsets.iter().map(|o| truth.x + o.0).collect();
        let ys: Vec<f64> = offsets.iter().map(|o| truth.y + o.1).collect();
        let ths: Vec<f64> = offsets.iter().map(|o| truth.theta + o.2).collect();
        let mut w = vec![1.0; offsets.len()];
        sensor_model::weigh_beam_model(&map.rays, &params, &beams, &xs, &ys, &ths, &mut w);
        assert!(w[1..].iter().all(|&o| o < w[0]), "{truth:?}: {w:?}");
    }
}
