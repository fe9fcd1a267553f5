//! The Markov grid on the hospital map with scans ray-cast from a known trajectory.

use super::layout::Span;
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

/// The selective update's sample cells, scored eight at a time, score exactly what the
/// layer kernel gives those cells when it scores every cell.
#[test]
fn sample_cells_score_what_the_whole_layer_scores() {
    let map = hospital();
    let mut grid = MarkovGrid::new(MarkovGridConfig::default(), &map);
    let mut rng = stream_rng(2, "test", "grid-score");
    let scan = scan_at(&map, &Pose2::new(30.0, 24.75, 2.0), &mut rng);
    let pts = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60).returns();
    grid.score(&map, &pts, 20.0, None);
    let full = &grid.scratch.clone();
    let none: Vec<Vec<Span>> = vec![Vec::new(); grid.layout.n_theta];
    let sampled = grid.score(&map, &pts, 20.0, Some(&none));
    let l = &grid.layout;
    let expected: Vec<f32> = grid
        .sample
        .iter()
        .enumerate()
        .flat_map(|(k, cells)| {
            cells
                .iter()
                .map(move |&(i, j)| full[k * l.layer() + j as usize * l.nx + i as usize])
        })
        .collect();
    assert!(grid.sample.iter().any(|c| c.len() % 8 != 0));
    assert_eq!(sampled.len(), expected.len());
    for (a, b) in sampled.iter().zip(&expected) {
        assert_eq!(a.to_bits(), b.to_bits(), "{a} against {b}");
    }
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

/// The belief's mean and variance of x and y (m, m²), cells at their sub-cell positions.
fn spread(grid: &MarkovGrid) -> ([f64; 2], [f64; 2]) {
    let l = &grid.layout;
    let (mut m, mut sq, mut total) = ([0.0; 2], [0.0; 2], 0.0);
    for k in 0..l.n_theta {
        for s in &l.spans {
            for i in s.i0..s.i0 + s.len {
                let w = grid.belief[k * l.layer() + s.j as usize * l.nx + i as usize] as f64;
                let (x, y) = grid.sub_cell.position(l, k, i as usize, s.j as usize);
                total += w;
                for (a, v) in [x, y].into_iter().enumerate() {
                    m[a] += w * v;
                    sq[a] += w * v * v;
                }
            }
        }
    }
    let mean = m.map(|v| v / total);
    (
        [mean[0], mean[1]],
        [0, 1].map(|a| sq[a] / total - mean[a] * mean[a]),
    )
}

/// Driving 6 m along the corridor moves the belief with the robot and widens it by the
/// motion noise only: without noise it keeps its shape on the driven pose (the
/// trilinear split it replaced spread it by a sixth of a cell² per axis at every update, to
/// about 0.5 m), with noise its variance grows by the model's per update.
#[test]
fn driving_widens_the_belief_by_the_motion_noise_only() {
    let map = hospital();
    let start = Pose2::new(3.0, 15.8, 5f64.to_radians());
    // one heading only (the start's bin centre), so every cell moves the same way
    let grid_with = |motion: OdometryMotionModel| {
        let mut g = MarkovGrid::new(
            MarkovGridConfig {
                init: InitialBelief::Gaussian {
                    pose: start,
                    sd: [0.05, 0.05, 0.01],
                },
                uniform_mix: 0.0,
                motion,
                ..MarkovGridConfig::default()
            },
            &map,
        );
        let (_, _, k) = g.layout.cell_of(start.x, start.y, start.theta).unwrap();
        let layer = g.layout.layer();
        for (kk, cells) in g.belief.chunks_mut(layer).enumerate() {
            if kk != k {
                cells.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        assert!(g.normalise());
        g
    };
    let steps = 24;
    let drive = |grid: &mut MarkovGrid| {
        let mut odom = Pose2::IDENTITY;
        for _ in 0..steps {
            let next = odom.compose(&Pose2::new(0.25, 0.0, 0.0));
            grid.apply_motion(&odom, &next);
            odom = next;
        }
        start.compose(&odom)
    };
    let mut exact = grid_with(OdometryMotionModel {
        alpha1: 0.0,
        alpha2: 0.0,
        alpha3: 0.0,
        alpha4: 0.0,
    });
    let (_, var0) = spread(&exact);
    let near = |g: &MarkovGrid, p: &Pose2| g.mass_near(p, 0.15, 5f64.to_radians());
    let near0 = near(&exact, &start);
    let want = drive(&mut exact);
    let e = exact.estimate_pose().unwrap().pose;
    assert!(
        near(&exact, &want) > 0.99 * near0 && e.distance(&want) < 0.02,
        "{} of the mass near {want:?}, {near0} at the start; estimate {e:?}",
        near(&exact, &want)
    );
    let (_, var) = spread(&exact);
    assert!(
        var[0] < var0[0] + 1e-4 && var[1] < var0[1] + 1e-4,
        "{var:?} from {var0:?}"
    );
    // α3 only: 0.056 m of translation noise per 0.25 m, about 0.27 m after 24 updates
    let mut noisy = grid_with(OdometryMotionModel {
        alpha1: 0.0,
        alpha2: 0.0,
        alpha3: 0.05,
        alpha4: 0.0,
    });
    drive(&mut noisy);
    let per_update = 0.05 * 0.25f64.powi(2);
    let res2 = noisy.layout.resolution.powi(2);
    let applied = steps as f64 * per_update - noisy.pending_noise[0] * res2;
    let (mean, var) = spread(&noisy);
    for a in 0..2 {
        let grown = var[a] - var0[a];
        assert!(
            (grown - applied).abs() < 0.1 * applied,
            "axis {a}: grew {grown} m², the model applied {applied}"
        );
    }
    let off = (mean[0] - want.x).hypot(mean[1] - want.y);
    assert!(
        off < 0.05,
        "the belief's mean {mean:?} is {off} m from {want:?}"
    );
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
    let mut poses: Vec<(Pose2, Pose2)> = Vec::new();
    drive(&map, &CORRIDOR, 0.0, 3, |truth, odom, scan| {
        let pts = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60).returns();
        if grid.update(&map, &pts, scan.range_max, odom) {
            let e = grid.estimate.unwrap();
            errors.push(error(&e, truth));
            poses.push((e.pose, *truth));
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
    // from one update to the next the estimate moves as the robot did: along the corridor the
    // most probable cell alternated between neighbours, and without the tracked start the
    // estimate jumped by up to 0.48 m more than the robot moved (90 % within 8.4 cm); with the
    // tracked start but no prior, by up to 0.12 m (90 % within 2.1 cm), one scan's noise
    // peaking elsewhere along the corridor
    let mut jumps: Vec<f64> = poses[since..]
        .windows(2)
        .map(|w| {
            let (est, truth) = (w[0].0.between(&w[1].0), w[0].1.between(&w[1].1));
            (est.x - truth.x).hypot(est.y - truth.y)
        })
        .collect();
    jumps.sort_by(f64::total_cmp);
    let (p90, max) = (jumps[jumps.len() * 9 / 10], jumps[jumps.len() - 1]);
    assert!(
        p90 < 0.02 && max < 0.06,
        "jumps: 90 % within {p90} m, max {max} m"
    );
}

/// What the fused passes carry from one to the next is what a pass of its own would find: the
/// peak the selective threshold starts from and the sum the correction normalises by, after the
/// motion and after the weighing, and the most probable cell the estimate starts from, over a
/// global start and a drive; and the correction leaves the belief summing to 1.
#[test]
fn the_carried_peak_and_most_probable_cell_are_the_belief_s() {
    let map = hospital();
    let mut grid = MarkovGrid::new(
        MarkovGridConfig {
            motion: motion(),
            ..MarkovGridConfig::default()
        },
        &map,
    );
    let mut last: Option<Pose2> = None;
    let (mut checked, mut windowed) = (0, 0);
    drive(&map, &CORRIDOR, 0.0, 5, |_, odom, scan| {
        if last.is_some_and(|l| !moved_enough(&l, odom, 0.25, 10f64.to_radians())) {
            return;
        }
        if let Some(l) = last {
            grid.move_belief(&l, odom);
            let carried = grid.carried.unwrap();
            assert_eq!(carried.peak, belief_ops::peak(&grid.belief));
            let sum = belief_ops::sum_plain(&grid.belief) + grid.outside;
            assert!((carried.sum - sum).abs() <= 1e-9 * sum, "{carried:?} {sum}");
        }
        last = Some(*odom);
        let pts = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60).returns();
        let best = grid.weigh(&map, &pts, scan.range_max);
        assert_eq!(best, belief_ops::argmax(&grid.belief).map(|b| b.0));
        let carried = grid.carried.unwrap();
        assert_eq!(carried.peak, belief_ops::peak(&grid.belief));
        let sum = belief_ops::sum_plain(&grid.belief) + grid.outside;
        assert!(
            (carried.sum - sum).abs() <= 1e-9 && (sum - 1.0).abs() < 1e-5,
            "{carried:?} {sum}"
        );
        checked += 1;
        windowed += usize::from(grid.is_windowed());
    });
    assert!(checked > 50, "{checked} updates");
    // the belief gathered, and was then held on a window
    assert!(
        windowed > checked / 2,
        "{windowed} of {checked} updates on a window"
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
            let fast = belief_ops::argmax(&v).map(|(i, x)| (i, x.to_bits()));
            assert_eq!(fast, plain(&v), "{v:?}");
        }
    }
}

/// Endpoints that are not finite or lie farther than the map reaches are dropped before
/// scoring: an infinite endpoint once sized the padded field to the whole address space.
#[test]
fn endpoints_beyond_the_map_or_not_finite_do_not_size_the_field() {
    let map = crate::localization::props::room();
    let mut grid = MarkovGrid::new(MarkovGridConfig::default(), &map);
    let good = [[1.0f32, 0.5], [-2.0, 1.0]];
    let mut with_bad = good.to_vec();
    with_bad.extend([
        [f32::INFINITY, 0.0],
        [f32::NAN, 1.0],
        [1e30, -1e30],
        [1e5, 0.0],
    ]);
    grid.apply_scan(&map, &with_bad, 10.0);
    let reach = grid.field.as_ref().map(|f| f.reach).unwrap_or(0.0);
    assert!(reach < 20.0, "{reach}");
    assert!(grid.belief.iter().all(|p| p.is_finite() && *p >= 0.0));
    // the same as the finite, reachable endpoints alone
    let mut only_good = MarkovGrid::new(MarkovGridConfig::default(), &map);
    only_good.apply_scan(&map, &good, 10.0);
    assert_eq!(grid.belief, only_good.belief);
}

/// A coarse grid (0.5 m, 30°) in the 12 m × 8 m room that updates at every call, started
/// around a pose.
fn small() -> MarkovGridConfig {
    MarkovGridConfig {
        angular_bins: 12,
        resolution: 0.5,
        update_min_d: 0.0,
        update_min_a: 0.0,
        init: InitialBelief::Gaussian {
            pose: Pose2::new(6.0, 4.0, 0.3),
            sd: [0.5, 0.5, 0.2],
        },
        ..MarkovGridConfig::default()
    }
}

/// The motion leaves its normalisation to the correction: after a motion that drops mass off
/// the free space, a correction with no endpoint to weigh by still leaves a distribution.
#[test]
fn a_correction_without_endpoints_normalises_what_the_motion_left() {
    let map = crate::localization::props::room();
    let config = MarkovGridConfig {
        init: InitialBelief::Gaussian {
            pose: Pose2::new(10.0, 4.0, 0.0),
            sd: [0.5, 0.5, 0.1],
        },
        ..small()
    };
    let mut grid = MarkovGrid::new(config, &map);
    assert!(grid.predict(&Pose2::IDENTITY));
    // 1.5 m east, into the room's east wall at x = 12 m
    assert!(grid.predict(&Pose2::new(1.5, 0.0, 0.0)));
    let moved = belief_ops::sum_plain(&grid.belief);
    assert!(moved < 0.9, "the motion kept {moved} of the mass");
    assert!(grid.correct_points(&map, &[], 10.0));
    let sum = belief_ops::sum_plain(&grid.belief);
    assert!((sum - 1.0).abs() < 1e-5, "{sum}");
}

/// Properties under sensor faults: the belief stays a finite distribution and the estimate
/// finite with a covariance, whatever the laser sends and however the odometry jumps.
mod props {
    use super::*;
    use crate::core::props::{config, laser_fault, range_reading};
    use crate::localization::props::{estimate_fault, faulted_drive, odometry_step, room};
    use proptest::prelude::*;

    fn belief_fault(g: &MarkovGrid) -> Option<String> {
        let background = g.background();
        if let Some(bad) = g
            .belief
            .iter()
            .chain([&background])
            .find(|v| !(v.is_finite() && **v >= 0.0))
        {
            return Some(format!("cell {bad}"));
        }
        let sum = g.total_mass();
        ((sum - 1.0).abs() > 1e-3).then(|| format!("belief sums to {sum}"))
    }

    proptest! {
        #![proptest_config(config(48))]

        /// The correction kernel with arbitrary endpoints (NaN, ±∞, huge) and range limits.
        #[test]
        fn any_endpoints_leave_a_finite_distribution(
            points in proptest::collection::vec(
                (range_reading(10.0), range_reading(10.0)), 0..40),
            range_max in prop_oneof![Just(10.0f32), Just(0.0f32), Just(f32::MAX), 0.01f32..30.0],
            selective in prop_oneof![Just(0.0), Just(1e-6)],
        ) {
            let map = room();
            let mut grid = MarkovGrid::new(
                MarkovGridConfig { selective_threshold: selective, ..small() }, &map);
            let points: Vec<[f32; 2]> = points.iter().map(|p| [p.0, p.1]).collect();
            prop_assert!(grid.correct_points(&map, &points, range_max));
            prop_assert_eq!(belief_fault(&grid), None);
            let e = grid.estimate();
            prop_assert!(e.is_some());
            prop_assert_eq!(e.and_then(|e| estimate_fault(&e)), None);
        }

        /// A drive in the room with laser faults and odometry that sticks or jumps.
        #[test]
        fn the_grid_stays_finite_under_laser_faults_and_odometry_jumps(
            steps in proptest::collection::vec(
                (proptest::option::of(laser_fault(10.0, 40)), odometry_step(0.5)),
                1..8),
        ) {
            let map = room();
            let mut grid = MarkovGrid::new(small(), &map);
            for (odom, beams) in faulted_drive(&map, &steps) {
                grid.predict(&odom);
                grid.correct(&map, &beams);
                prop_assert_eq!(belief_fault(&grid), None);
                let e = grid.estimate();
                prop_assert!(e.is_some());
                prop_assert_eq!(e.and_then(|e| estimate_fault(&e)), None);
            }
        }
    }
}

/// An odometry jump of kilometres spreads the belief over the grid: the blur's width is capped
/// at the grid's (it asked for a kernel as long as the jump and the allocation failed).
#[test]
fn an_odometry_jump_blurs_no_wider_than_the_grid() {
    let map = crate::localization::props::room();
    let mut grid = MarkovGrid::new(
        MarkovGridConfig {
            resolution: 0.5,
            angular_bins: 12,
            ..MarkovGridConfig::default()
        },
        &map,
    );
    grid.apply_motion(&Pose2::IDENTITY, &Pose2::new(3e5, -4e5, 2.0));
    let sum: f64 = grid.belief.iter().map(|&v| v as f64).sum();
    assert!(grid.belief.iter().all(|p| p.is_finite() && *p >= 0.0));
    assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    assert!(grid.estimate_pose().is_some());
}
