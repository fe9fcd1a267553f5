//! MCL on the hospital map with scans ray-cast from a known trajectory and noisy odometry.

use super::*;
use crate::core::stream_rng;
use crate::localization::test_drive::{CORRIDOR, drive, error, hospital, scan_at};

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
            errors.push(error(&MapLocalizer::estimate(&mcl).unwrap(), truth));
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

/// AMCL's defaults resample every second update whatever the weights, and still track along
/// the corridor; the default (selective) filter resamples only when the weights degenerate.
#[test]
fn amcl_s_defaults_resample_every_second_update_and_track() {
    let map = hospital();
    let start = Pose2::new(2.2, 16.0, 0.0);
    let init = InitialBelief::Gaussian {
        pose: Pose2::new(2.5, 15.8, 0.1),
        sd: [0.3, 0.3, 0.1],
    };
    let run = |config: MclConfig| {
        let mut mcl = Mcl::new(config, &map, stream_rng(1, "test", "mcl"));
        let mut errors = Vec::new();
        drive(&map, &CORRIDOR, start.theta, 1, |truth, odom, scan| {
            let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, mcl.config.max_beams);
            if mcl.update(&map, &beams, odom) {
                errors.push(error(&MapLocalizer::estimate(&mcl).unwrap(), truth));
            }
        });
        let rms =
            (errors[5..].iter().map(|e| e.0 * e.0).sum::<f64>() / (errors.len() - 5) as f64).sqrt();
        (mcl.updates, mcl.resamplings, rms)
    };
    let (updates, resamplings, rms) = run(MclConfig {
        init,
        ..MclConfig::amcl()
    });
    assert!(updates > 100, "{updates}");
    assert_eq!(resamplings, updates / 2, "{updates} updates");
    assert!(rms < 0.3, "AMCL's defaults: rms {rms} m");
    let (updates, resamplings, _) = run(MclConfig {
        init,
        max_beams: 30,
        ..MclConfig::default()
    });
    assert!(
        resamplings < updates / 2,
        "selective: {resamplings} of {updates}"
    );
}

/// A filter of 100 000 particles started globally (its stream `seed`) driven along the corridor:
/// the update from which it tracks for good (within 0.2 m and 5° to the end), and the updates.
fn global_start_on_the_corridor(seed: u64) -> (Option<usize>, usize) {
    let map = hospital();
    let config = MclConfig {
        max_particles: 100_000,
        ..tuned()
    };
    let mut mcl = Mcl::new(config, &map, stream_rng(seed, "test", "mcl"));
    let (mut tracked_since, mut k) = (None, 0);
    drive(&map, &CORRIDOR, 0.0, 2, |truth, odom, scan| {
        let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
        if mcl.update(&map, &beams, odom) {
            k += 1;
            let (d, a) = error(&MapLocalizer::estimate(&mcl).unwrap(), truth);
            if d < 0.2 && a < 5f64.to_radians() {
                tracked_since.get_or_insert(k);
            } else {
                tracked_since = None;
            }
        }
    });
    (tracked_since, k)
}

#[test]
fn converges_from_global_initialisation() {
    let (since, k) = global_start_on_the_corridor(2);
    let since = since.expect("never converged");
    assert!(
        k > 150 && since < 100,
        "converged only after {since} of {k} updates"
    );
}

/// From a global start the filter draws from the scan at every update until it settles
/// (Mixture MCL's dual proposal): over five seeds it is tracking for good within 15 updates in
/// the median (3 m of travel); drawing only at the challenges of every tenth update took 21.
#[test]
fn the_dual_proposal_finds_a_global_start_within_a_few_updates() {
    let mut found: Vec<usize> = (0..5)
        .map(|seed| global_start_on_the_corridor(seed).0.unwrap_or(usize::MAX))
        .collect();
    found.sort_unstable();
    assert!(found[2] <= 15, "tracking for good from updates {found:?}");
}

/// A filter sure of a wrong place (a confident Gaussian 6 m along the corridor, where the scans
/// fit but worse) with the weight-average recovery off: the scan-proposal challenges pull it to
/// the truth; without them it stays lost.
#[test]
fn challenges_pull_a_filter_out_of_a_wrong_place() {
    let map = hospital();
    let run = |challenge_every: u64| {
        let config = MclConfig {
            init: InitialBelief::Gaussian {
                pose: Pose2::new(CORRIDOR[0][0] + 6.0, CORRIDOR[0][1], 0.0),
                sd: [0.1, 0.1, 0.03],
            },
            recovery_alpha_slow: 0.0,
            challenge_every,
            ..tuned()
        };
        let mut mcl = Mcl::new(config, &map, stream_rng(3, "test", "mcl"));
        let mut last = (f64::NAN, f64::NAN);
        drive(&map, &CORRIDOR, 0.0, 3, |truth, odom, scan| {
            let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
            if mcl.update(&map, &beams, odom) {
                last = error(&MapLocalizer::estimate(&mcl).unwrap(), truth);
            }
        });
        last
    };
    let (d, a) = run(10);
    assert!(
        d < 0.2 && a < 5f64.to_radians(),
        "with challenges: {d} m, {a} rad"
    );
    let (d, _) = run(0);
    assert!(
        d > 1.0,
        "without challenges the filter should stay lost: {d} m"
    );
}

/// A global filter counts as settled only once its heaviest cluster is tight *and* holds most
/// of the weight: three tight clusters at look-alike places, a third each, keep it searching
/// (the dual proposal at every update, one win enough for a contender); nine tenths at one
/// place settle it.
#[test]
fn a_tight_cluster_with_a_minority_of_the_weight_is_not_settled() {
    let map = hospital();
    let config = MclConfig {
        max_particles: 3000,
        ..tuned()
    };
    let mut mcl = Mcl::new(config, &map, stream_rng(4, "test", "mcl"));
    let n = mcl.len();
    let mut place = |share_first: f64| {
        for i in 0..n {
            let first = (i as f64) < share_first * n as f64;
            let x = if first { 10.0 } else { [30.0, 50.0][i % 2] };
            let jitter = (i % 7) as f64 * 0.01;
            (mcl.xs[i], mcl.ys[i], mcl.ths[i]) = (x + jitter, 16.0 - jitter, 0.0);
            mcl.w[i] = 1.0 / n as f64;
        }
        mcl.trig.clear();
        mcl.estimate = OnceLock::new();
        let e = mcl.estimate().unwrap();
        assert!(e.position_spread() < 0.1, "{e:?}");
        (e.weight, mcl.searching(), mcl.wins_needed())
    };
    let (share, searching, wins) = place(0.34);
    assert!(
        (0.3..0.4).contains(&share) && searching && wins == 1,
        "{share}"
    );
    let (share, searching, wins) = place(0.9);
    assert!(
        share >= 0.9 && !searching && wins == CONTENDER_WINS,
        "{share}"
    );
}

/// A pose that only ties with the filter's best explanation of the scan is not better than it:
/// the likelihood field's scores saturate, so a look-alike place often ties to the bit. The
/// filter's own heaviest particles, offered back to it, are never drawn; the true pose, 0.3 m
/// beside a confident cloud, is.
#[test]
fn poses_that_tie_with_the_filter_are_not_better_than_it() {
    let map = hospital();
    let truth = Pose2::new(CORRIDOR[0][0], CORRIDOR[0][1], 0.0);
    let config = MclConfig {
        init: InitialBelief::Gaussian {
            pose: Pose2::new(truth.x, truth.y + 0.3, 0.0),
            sd: [0.02, 0.02, 0.01],
        },
        ..tuned()
    };
    let mut mcl = Mcl::new(config, &map, stream_rng(5, "test", "mcl"));
    let scan = scan_at(&map, &truth, &mut stream_rng(5, "test", "scan"));
    let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60);
    mcl.weigh_particles(&map, &beams);
    let mut top: Vec<usize> = (0..mcl.len()).collect();
    top.sort_by(|&a, &b| mcl.w[b].total_cmp(&mcl.w[a]).then(a.cmp(&b)));
    let own: Vec<(f64, f64, f64)> = top[..CHALLENGE_TOP]
        .iter()
        .map(|&i| (mcl.xs[i], mcl.ys[i], mcl.ths[i]))
        .collect();
    let table = mcl.field_table(&map, beams.range_max);
    let points = beams.returns();
    assert!(
        mcl.better_than_filter(&map, &table, &points, &own, 1.0)
            .is_empty()
    );
    let at_truth = [(truth.x, truth.y, truth.theta)];
    let better = mcl.better_than_filter(&map, &table, &points, &at_truth, 1.0);
    assert_eq!(better.len(), 1);
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

/// The estimate is computed when first asked for, yet always stands for the set as it was built
/// or last corrected: the same as computing it at once, before or after particles move.
#[test]
fn the_first_estimate_is_the_built_cloud_s_whenever_it_is_asked_for() {
    let map = hospital();
    let config = MclConfig {
        max_particles: 20_000,
        init: InitialBelief::Global,
        ..tuned()
    };
    let built = Mcl::new(config.clone(), &map, stream_rng(3, "test", "mcl"));
    let at_once =
        cluster::dominant_cluster(&built.xs, &built.ys, &built.ths, &built.w, &config.bins);
    assert!(at_once.is_some());
    assert_eq!(built.estimate(), at_once);
    // asked for only after the particles moved: still the built cloud's
    let mut moved = Mcl::new(config.clone(), &map, stream_rng(3, "test", "mcl"));
    moved.apply_motion(&Pose2::new(0.0, 0.0, 0.0), &Pose2::new(3.0, 1.0, 0.5));
    assert_eq!(moved.estimate(), at_once);
    let now = cluster::dominant_cluster(&moved.xs, &moved.ys, &moved.ths, &moved.w, &config.bins);
    assert_ne!(now, at_once);
    // a correction replaces it
    let scan = scan_at(
        &map,
        &Pose2::new(2.2, 16.0, 0.0),
        &mut stream_rng(3, "test", "scan"),
    );
    let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60);
    assert!(MapLocalizer::correct(&mut moved, &map, &beams));
    let corrected =
        cluster::dominant_cluster(&moved.xs, &moved.ys, &moved.ths, &moved.w, &config.bins);
    assert_eq!(moved.estimate(), corrected);
}

/// Properties under sensor faults: whatever the laser sends and however the odometry jumps, the
/// beams a filter reads are finite, the weights stay normalised and every estimate is finite
/// with a covariance.
mod props {
    use super::*;
    use crate::core::props::{config, extreme_f64, laser_fault, range_reading};
    use crate::localization::props::{
        estimate_fault, faulted_drive, odometry_step, room, weights_fault,
    };
    use crate::sensors::LaserScan;
    use proptest::prelude::*;

    /// A scan of the room's geometry with arbitrary readings.
    fn garbage_scan(ranges: Vec<f32>) -> LaserScan {
        let n = ranges.len().max(2);
        LaserScan {
            stamp: 0.0,
            angle_min: -2.0,
            angle_increment: 4.0 / (n - 1) as f32,
            range_min: 0.1,
            range_max: 10.0,
            ranges,
        }
    }

    /// A small filter that still does everything the full one does (KLD, injection, challenge).
    fn small(model: LaserModel) -> MclConfig {
        MclConfig {
            min_particles: 50,
            max_particles: 300,
            model,
            injection_candidates: 300,
            challenge_every: 2,
            update_min_d: 0.0,
            update_min_a: 0.0,
            init: InitialBelief::Gaussian {
                pose: Pose2::new(6.0, 4.0, 0.3),
                sd: [0.3, 0.3, 0.1],
            },
            ..MclConfig::default()
        }
    }

    fn model() -> impl Strategy<Value = LaserModel> {
        prop_oneof![Just(LaserModel::LikelihoodField), Just(LaserModel::Beam)]
    }

    proptest! {
        #![proptest_config(config(256))]

        #[test]
        fn beam_subsets_of_any_scan_are_finite_returns_within_the_range(
            ranges in proptest::collection::vec(range_reading(10.0), 0..120),
            max_beams in 0usize..80,
            mount in (-0.5f64..0.5, -0.5f64..0.5, -3.2f64..3.2),
        ) {
            let scan = garbage_scan(ranges);
            let mount = Pose2::new(mount.0, mount.1, mount.2);
            let b = BeamSubset::from_scan(&scan, &mount, max_beams);
            prop_assert!(b.len() <= max_beams);
            prop_assert_eq!(b.max_reading.len(), b.len());
            prop_assert_eq!(b.points.len(), b.len());
            for k in 0..b.len() {
                let r = b.ranges[k];
                prop_assert!(r.is_finite() && r >= scan.range_min && r <= scan.range_max, "{r}");
                prop_assert!(b.angles[k].is_finite());
                prop_assert!(b.points[k].iter().all(|v| v.is_finite()));
            }
        }

        /// The check every scan gets tells what the subset it spares would have told.
        #[test]
        fn a_scan_has_returns_exactly_when_its_beam_subset_has(
            ranges in proptest::collection::vec(range_reading(10.0), 0..120),
            max_beams in 0usize..80,
        ) {
            let scan = garbage_scan(ranges);
            prop_assert_eq!(
                BeamSubset::scan_has_returns(&scan, max_beams),
                BeamSubset::from_scan(&scan, &Pose2::IDENTITY, max_beams).has_returns()
            );
        }
    }

    proptest! {
        #![proptest_config(config(48))]

        /// The likelihood-field kernel on arbitrary endpoints and particle poses (NaN, ±∞,
        /// huge): every factor finite and at least 1.
        #[test]
        fn the_field_kernel_scores_any_endpoint_finite(
            points in proptest::collection::vec(
                (range_reading(10.0), range_reading(10.0)), 0..40),
            poses in proptest::collection::vec(
                (extreme_f64(), extreme_f64(), extreme_f64()), 1..40),
        ) {
            let map = room();
            let table = sensor_model::likelihood_table(
                &map.field, &LaserModelParams::default(), 10.0);
            let points: Vec<[f32; 2]> = points.iter().map(|p| [p.0, p.1]).collect();
            let xs: Vec<f64> = poses.iter().map(|p| p.0).collect();
            let ys: Vec<f64> = poses.iter().map(|p| p.1).collect();
            let ths: Vec<f64> = poses.iter().map(|p| p.2).collect();
            let mut w = vec![1.0; xs.len()];
            sensor_model::weigh_likelihood_field(&map.field, &table, &points, &xs, &ys, &ths, &mut w);
            prop_assert!(w.iter().all(|v| v.is_finite() && *v >= 1.0), "{w:?}");
        }

        /// Weighing by any scan, with either model, leaves the weights normalised.
        #[test]
        fn weighing_any_scan_keeps_the_weights_normalised(
            model in model(),
            ranges in proptest::collection::vec(range_reading(10.0), 1..80),
        ) {
            let map = room();
            let mut mcl = Mcl::new(small(model), &map, stream_rng(1, "props", "mcl"));
            let beams = BeamSubset::from_scan(&garbage_scan(ranges), &Pose2::IDENTITY, 60);
            let factor = mcl.weigh(&map, &beams);
            prop_assert!(factor.is_finite() && factor >= 0.0, "{factor}");
            prop_assert_eq!(weights_fault(&mcl.w), None);
        }

        /// A drive in the room with laser faults and odometry that sticks or jumps: after every
        /// update the particles are finite, the weights normalised, the estimate finite with a
        /// covariance.
        #[test]
        fn mcl_stays_finite_under_laser_faults_and_odometry_jumps(
            model in model(),
            steps in proptest::collection::vec(
                (proptest::option::of(laser_fault(10.0, 40)), odometry_step(0.3)),
                1..12),
        ) {
            let map = room();
            let mut mcl = Mcl::new(small(model), &map, stream_rng(2, "props", "mcl"));
            for (odom, beams) in faulted_drive(&map, &steps) {
                mcl.update(&map, &beams, &odom);
                prop_assert_eq!(weights_fault(&mcl.w), None);
                prop_assert!(mcl.xs.iter().chain(&mcl.ys).chain(&mcl.ths).all(|v| v.is_finite()));
                let e = MapLocalizer::estimate(&mcl);
                prop_assert!(e.is_some());
                prop_assert_eq!(e.and_then(|e| estimate_fault(&e)), None);
            }
        }
    }
}
