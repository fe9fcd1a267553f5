//! Mapping the simulated hospital with known poses: SICK LMS100
//! scans ray-cast on the true map along the corridors, inserted at their true poses, must give a
//! map whose walls lie on true walls and cover the true walls the robot saw (both > 95 %).

use super::*;
use crate::core::{Pose2, stream_rng};
use crate::raycast::RayMap;
use crate::sensors::{LaserScan, LaserSpec};
use crate::world::{OccupancyGrid, load_map};
use rand::RngExt;
use rand_distr::StandardNormal;

pub(super) fn hospital() -> OccupancyGrid {
    let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
    load_map(&path).expect("the hospital map loads")
}

/// Poses every metre along the corridors of assets/maps/hospital/places.toml, facing both ways:
/// the three long corridors (y = 7.25, 16, 24.75 from x = 3 to 61) and the two cross corridors
/// (x = 21.25, 43.25 between them).
fn corridor_poses() -> Vec<Pose2> {
    let mut poses = Vec::new();
    for y in [7.25, 16.0, 24.75] {
        for x in 3..=61 {
            poses.push(Pose2::new(x as f64, y, 0.0));
            poses.push(Pose2::new(x as f64, y, std::f64::consts::PI));
        }
    }
    for x in [21.25, 43.25] {
        for y in 8..=24 {
            poses.push(Pose2::new(x, y as f64, std::f64::consts::FRAC_PI_2));
            poses.push(Pose2::new(x, y as f64, -std::f64::consts::FRAC_PI_2));
        }
    }
    poses
}

/// SICK LMS100 scans of the true map at `poses` (270°, 0.25°, 1081 beams, 0.5–20 m, 12 mm
/// Gaussian range noise; REP 117: no return +Inf, below the minimum range −Inf).
fn lms100_scans(truth: &OccupancyGrid, poses: &[Pose2]) -> Vec<LaserScan> {
    let spec = LaserSpec::sick_lms100();
    let rays = RayMap::from_grid(truth);
    let mut rng = stream_rng(5, "mapping_test", "laser");
    poses
        .iter()
        .map(|pose| {
            let mut ranges = vec![0f32; spec.beams()];
            let a0 = spec.angle_min() as f32;
            rays.cast_scan(
                [pose.x as f32, pose.y as f32],
                pose.theta as f32 + a0,
                spec.increment as f32,
                spec.max_range as f32,
                &mut ranges,
            );
            for r in ranges.iter_mut().filter(|r| r.is_finite()) {
                let n: f64 = rng.sample(StandardNormal);
                *r += (spec.noise_std * n) as f32;
                if *r < spec.min_range as f32 {
                    *r = f32::NEG_INFINITY;
                }
            }
            LaserScan {
                stamp: 0.0,
                angle_min: a0,
                angle_increment: spec.increment as f32,
                range_min: spec.min_range as f32,
                range_max: spec.max_range as f32,
                ranges,
            }
        })
        .collect()
}

/// The map of the corridor scans, each inserted at its pose expressed in `frame` (a pose in
/// the truth frame).
fn map_in_frame(truth: &OccupancyGrid, frame: &Pose2) -> OccupancyGrid {
    let poses = corridor_poses();
    let scans = lms100_scans(truth, &poses);
    let mut map = LogOddsMap::new(0.05, OccupancyParams::default());
    for (pose, scan) in poses.iter().zip(&scans) {
        map.insert_scan(&frame.between(pose), scan);
    }
    map.to_occupancy()
}

#[test]
fn known_pose_mapping_of_the_hospital_puts_walls_on_true_walls_and_covers_them() {
    let truth = hospital();
    let est = map_in_frame(&truth, &Pose2::IDENTITY);
    let q = map_quality(&est, &truth, &Pose2::IDENTITY);
    eprintln!("hospital, known poses, world frame: {q:?}");
    assert!(q.precision > 0.95 && q.recall > 0.95, "{q:?}");
    // not a trivially small map: the corridors' walls and what the doors show of the rooms
    assert!(
        q.estimated_occupied > 15_000 && q.observable_walls > 25_000,
        "{q:?}"
    );
}

#[test]
fn a_map_in_the_start_pose_frame_is_judged_after_aligning_by_the_start_pose() {
    let truth = hospital();
    // the SLAM convention: the map frame is the robot's start pose, here at an angle to the
    // walls so that the estimated grid is rotated against the true one
    let start = Pose2::new(21.25, 7.25, 0.5);
    let est = map_in_frame(&truth, &start);
    let q = quality_with_start_pose(&est, &truth, &start);
    eprintln!("hospital, known poses, start-pose frame rotated 0.5 rad: {q:?}");
    assert!(q.precision > 0.95 && q.recall > 0.95, "{q:?}");
    let unaligned = map_quality(&est, &truth, &Pose2::IDENTITY);
    assert!(unaligned.precision < 0.3, "{unaligned:?}");
    // a start pose known only roughly is refined back onto the walls
    let rough = Pose2::new(
        start.x + 0.2,
        start.y - 0.15,
        start.theta + 1.5f64.to_radians(),
    );
    let refined = refine_alignment(&est, &truth, &rough, 0.5);
    assert!(refined.distance(&start) < 0.03, "{refined:?}");
    assert!(
        (refined.theta - start.theta).abs() < 0.2f64.to_radians(),
        "{refined:?}"
    );
}

#[test]
fn a_mapped_hospital_one_cell_off_keeps_most_walls_five_cells_off_does_not() {
    let truth = hospital();
    let est = map_in_frame(&truth, &Pose2::IDENTITY);
    let res = est.resolution;
    let moved = |cells: [f64; 2]| {
        let mut g = est.clone();
        g.origin = [g.origin[0] + cells[0] * res, g.origin[1] + cells[1] * res];
        g
    };
    // Mapped walls straddle the true surface (a reading near a cell boundary falls on either
    // side of it, and a hit beats the misses of the same scan), so a one-cell shift carries the
    // cells on one side two cells off: precision drops to 83–93 % here, recall stays.
    for shift in [
        [1.0, 0.0],
        [-1.0, 0.0],
        [0.0, 1.0],
        [0.0, -1.0],
        [1.0, 1.0],
        [-1.0, 1.0],
    ] {
        let q = map_quality(&moved(shift), &truth, &Pose2::IDENTITY);
        assert!(q.precision >= 0.8 && q.recall >= 0.95, "{shift:?}: {q:?}");
    }
    let q = map_quality(&moved([5.0, -5.0]), &truth, &Pose2::IDENTITY);
    assert!(q.precision < 0.3 && q.recall < 0.5, "{q:?}");
    // the same shift undone by the transform
    let back = Pose2::new(-5.0 * res, 5.0 * res, 0.0);
    let q = map_quality(&moved([5.0, -5.0]), &truth, &back);
    assert!(q.precision > 0.95 && q.recall > 0.95, "{q:?}");
}
