//! Property-test support for the estimators: a small room to localize in (quick to build, so
//! every case can start afresh), scans of it, and the checks every estimate and weight set must
//! pass whatever the sensors sent.

use super::map::LocalizationMap;
use super::mcl::{BeamSubset, PoseEstimate};
use crate::core::Pose2;
use crate::core::props::{LaserFault, all_finite, is_covariance};
use crate::sensors::LaserScan;
use crate::world::{Cell, OccupancyGrid};
use proptest::prelude::*;

/// A 12 m × 8 m room at 5 cm with a pillar and a wall stub (so a pose is well defined).
pub fn room_grid() -> OccupancyGrid {
    let (w, h) = (240, 160);
    let mut g = OccupancyGrid::new(w, h, 0.05, [0.0, 0.0], Cell::Free);
    let mut wall = |c0: usize, r0: usize, c1: usize, r1: usize| {
        for r in r0..r1 {
            for c in c0..c1 {
                g.set(c, r, Cell::Occupied);
            }
        }
    };
    wall(0, 0, w, 2);
    wall(0, h - 2, w, h);
    wall(0, 0, 2, h);
    wall(w - 2, 0, w, h);
    // a pillar at (3..4, 2..4) m and a stub from the north wall at x = 8 m
    wall(60, 40, 80, 80);
    wall(160, 100, 163, h);
    g
}

/// The localizers' map of [`room_grid`].
pub fn room() -> LocalizationMap {
    LocalizationMap::new(room_grid(), 2.0)
}

/// A noise-free scan of `beams` beams over 270° with a 10 m range, taken at `pose` in `map`.
pub fn room_scan(map: &LocalizationMap, pose: &Pose2, beams: usize) -> LaserScan {
    let fov = 270f32.to_radians();
    let inc = fov / (beams.max(2) - 1) as f32;
    let start = -fov / 2.0;
    let mut ranges = vec![0.0f32; beams];
    map.rays.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + start,
        inc,
        10.0,
        &mut ranges,
    );
    for r in ranges.iter_mut() {
        if *r >= 10.0 {
            *r = f32::INFINITY;
        }
    }
    LaserScan {
        stamp: 0.0,
        angle_min: start,
        angle_increment: inc,
        range_min: 0.1,
        range_max: 10.0,
        ranges,
    }
}

/// An odometry step of a drive in the room: mostly a move of at most `small` (m, and rad), now
/// and then none (stuck encoders) or a jump of up to a thousand kilometres.
pub fn odometry_step(small: f64) -> impl Strategy<Value = Pose2> {
    prop_oneof![
        4 => (-small..small, -0.1f64..0.1, -small..small),
        1 => Just((0.0, 0.0, 0.0)),
        1 => (-1e6f64..1e6, -1e6f64..1e6, -1e3f64..1e3),
    ]
    .prop_map(|(x, y, theta)| Pose2::new(x, y, theta))
}

/// A drive through the room from (6, 4, 0.3): per step, the odometry pose and 30 beams of the
/// 90-beam scan taken at the true pose with the step's laser fault, if any (a stuck laser
/// repeats the scan before). A step of a metre or more is an odometry jump: the robot itself
/// stays.
pub fn faulted_drive(
    map: &LocalizationMap,
    steps: &[(Option<LaserFault>, Pose2)],
) -> Vec<(Pose2, BeamSubset)> {
    let mut truth = Pose2::new(6.0, 4.0, 0.3);
    let mut odom = Pose2::IDENTITY;
    let mut last: Option<Vec<f32>> = None;
    let mut out = Vec::with_capacity(steps.len());
    for (fault, step) in steps {
        odom = odom.compose(step);
        if step.x.abs() < 1.0 {
            truth = truth.compose(step);
        }
        let mut scan = room_scan(map, &truth, 90);
        if let Some(f) = fault {
            f.apply(&mut scan.ranges, 10.0, last.as_deref());
        }
        last = Some(scan.ranges.clone());
        out.push((odom, BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 30)));
    }
    out
}

/// Why an estimate is unfit to publish (a pose or covariance not finite, a covariance not
/// symmetric positive semi-definite, a weight not finite), if it is.
pub fn estimate_fault(e: &PoseEstimate) -> Option<String> {
    let p = &e.pose;
    if !all_finite(&[p.x, p.y, p.theta]) {
        return Some(format!("pose not finite: {p:?}"));
    }
    if !is_covariance(&e.covariance) {
        return Some(format!("not a covariance: {:?}", e.covariance));
    }
    if !e.weight.is_finite() {
        return Some(format!("weight {}", e.weight));
    }
    None
}

/// Why normalised weights are not (a weight negative or not finite, a sum off 1), if they are
/// not.
pub fn weights_fault(w: &[f64]) -> Option<String> {
    if let Some(bad) = w.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Some(format!("weight {bad}"));
    }
    let sum: f64 = w.iter().sum();
    if !w.is_empty() && (sum - 1.0).abs() > 1e-6 {
        return Some(format!("weights sum to {sum}"));
    }
    None
}
