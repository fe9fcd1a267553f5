use super::tile_map::TileMap;
use super::*;
use crate::core::stream_rng;
use crate::localization::fixtures::{CORRIDOR, DriveStep, hospital, recorded_drive, scan_at};
use crate::mapping::LogOddsMap;
use crate::mapping::insert::LogOddsModel;

fn insert_into_tiles(map: &mut TileMap, sensor: &Pose2, scan: &LaserScan) {
    let params = OccupancyParams::slam();
    map.insert(
        sensor,
        scan,
        &params,
        &LogOddsModel::new(&params),
        &mut Vec::new(),
    );
}

#[test]
fn tile_map_holds_the_same_cells_as_the_contiguous_map() {
    let world = hospital();
    let mut rng = stream_rng(1, "rbpf", "scans");
    let mut tiles = TileMap::new(0.05);
    let mut flat = LogOddsMap::new(0.05, OccupancyParams::slam());
    // across tile borders, into negative lattice coordinates and back (the map grows both ways)
    for pose in [
        Pose2::new(5.0, 16.0, 0.3),
        Pose2::new(21.25, 20.0, 1.6),
        Pose2::new(3.2, 7.25, -2.8),
        Pose2::new(21.25, 16.0, 0.0),
    ] {
        let scan = scan_at(&world, &pose, &mut rng);
        insert_into_tiles(&mut tiles, &pose, &scan);
        flat.insert_scan(&pose, &scan);
    }
    let g = tiles.to_prob_grid();
    let f = flat.to_prob_grid();
    let (mut compared, mut occupied) = (0, 0);
    for r in 0..f.height {
        for c in 0..f.width {
            let x = f.origin[0] + (c as f64 + 0.5) * f.resolution;
            let y = f.origin[1] + (r as f64 + 0.5) * f.resolution;
            let (gc, gr) = g.cell_of(x, y).expect("the tile map covers the flat map");
            assert_eq!(g.get(gc, gr), f.get(c, r), "cell at ({x}, {y})");
            let l = tiles.get(tiles.cell(x, y));
            assert_eq!(super::super::inverse_model::probability(l), f.get(c, r));
            compared += 1;
            occupied += (f.get(c, r) > 0.5) as usize;
        }
    }
    assert!(
        compared > 400_000 && occupied > 2_000,
        "{compared} {occupied}"
    );
}

#[test]
fn a_copied_map_shares_tiles_until_it_writes_them() {
    let world = hospital();
    let mut rng = stream_rng(2, "rbpf", "scans");
    let mut a = TileMap::new(0.05);
    let here = Pose2::new(10.0, 16.0, 0.0);
    insert_into_tiles(&mut a, &here, &scan_at(&world, &here, &mut rng));
    let before = a.to_prob_grid();
    let mut b = a.clone();
    assert!(b.shares_all_tiles_with(&a));
    // b maps a room far down the corridor: a is unchanged, b copied only what it wrote
    let there = Pose2::new(50.0, 16.0, 0.0);
    insert_into_tiles(&mut b, &there, &scan_at(&world, &there, &mut rng));
    assert!(!b.shares_all_tiles_with(&a));
    let after = a.to_prob_grid();
    assert_eq!(before.p, after.p);
    assert!(b.tiles() > a.tiles());
}

fn run(steps: &[DriveStep], config: RbpfConfig, seed: u64) -> RbpfSlam {
    let mut slam = RbpfSlam::new(config, stream_rng(seed, "rbpf", "filter"));
    for s in steps {
        slam.step(&s.scan, &Pose2::default(), &s.odom);
    }
    slam
}

fn corridor_config(steps: &[DriveStep]) -> RbpfConfig {
    RbpfConfig {
        // the map frame is the world frame: the robot's pose at the first scan is known
        init_pose: steps[0].truth,
        ..RbpfConfig::default()
    }
}

fn rmse(traj: &[(f64, Pose2)], steps: &[DriveStep]) -> f64 {
    let s: f64 = traj
        .iter()
        .zip(steps)
        .map(|((_, p), s)| p.distance(&s.truth).powi(2))
        .sum();
    (s / steps.len() as f64).sqrt()
}

#[test]
fn rbpf_follows_the_corridor_where_odometry_drifts() {
    let world = hospital();
    let steps = recorded_drive(&world, &CORRIDOR, 0.0, 3);
    let slam = run(&steps, corridor_config(&steps), 7);
    let traj = slam.trajectory();
    assert_eq!(traj.len(), steps.len());
    let odom: Vec<(f64, Pose2)> = steps
        .iter()
        .map(|s| (0.0, steps[0].truth.compose(&steps[0].odom.between(&s.odom))))
        .collect();
    let (ate, ate_odom) = (rmse(&traj, &steps), rmse(&odom, &steps));
    let last = steps.last().unwrap();
    let end = slam.estimate().unwrap().pose;
    eprintln!(
        "rbpf corridor: ATE {ate:.3} m (odometry {ate_odom:.3} m), end error {:.3} m, {:?}",
        end.distance(&last.truth),
        slam.stats
    );
    assert!(ate_odom > 0.2, "the drive's odometry drifts: {ate_odom}");
    assert!(ate < 0.06 && ate < ate_odom / 4.0, "{ate}");
    assert!(end.distance(&last.truth) < 0.08);
    // GMapping's linearUpdate 1 m along 40 m of corridors and turns
    assert!(slam.stats.updates > 40 && slam.stats.resamples > 0);
    // the map is the corridor's: its walls lie on the true walls
    let map = slam.map().unwrap().to_occupancy();
    let q = crate::mapping::map_quality(&map, &world.grid, &Pose2::IDENTITY);
    assert!(q.precision > 0.9, "{q:?}");
}

#[test]
fn rbpf_is_deterministic_for_a_seed_whatever_the_threads() {
    let world = hospital();
    let steps = recorded_drive(&world, &CORRIDOR[..2], 0.0, 4);
    let steps = &steps[..120];
    let mut config = corridor_config(steps);
    config.particles = 8;
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let a = pool(1).install(|| run(steps, config.clone(), 11));
    let b = pool(2).install(|| run(steps, config.clone(), 11));
    assert_eq!(a.trajectory(), b.trajectory());
    assert_eq!(a.poses(), b.poses());
    let c = run(steps, config, 12);
    assert_ne!(a.poses(), c.poses());
}
