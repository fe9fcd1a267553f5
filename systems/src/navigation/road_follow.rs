//! Road following by the camera ([Park thesis §5.5]: the robot follows the road it recognizes in
//! the image; at a junction it keeps to the left or right road edge when the next road is the
//! leftmost or rightmost). Steering is pure pursuit (R. C. Coulter, CMU-RI-TR-92-01, 1992) towards
//! a point of the recognized road: κ = 2·y / L².
//!
//! 1. Each detected row ([`RoadDetection`]) becomes ground points in the robot frame through
//!    the camera's pinhole model ([`CameraSpec::ground_point`]). A level camera maps an image
//!    row to a ground line across the robot, so the midpoint of a row's edges is the road's
//!    centre on that line.
//! 2. The path point per row depends on [`Keep`]: the midpoint of both edges, or, where only
//!    one edge is in view (near the robot a wide road fills the image), that edge shifted by
//!    half the road width (given, or the median width of rows that see both edges); for
//!    `Left`/`Right`, the left/right edge moved `offset` metres into the road.
//! 3. The target is the mean of the path points whose distance from the robot is within
//!    `lookahead · (1 ± window)`; with fewer than `min_points` of them, the `min_points` points
//!    nearest to the look-ahead distance, if the nearest lies within [L/3, 3L].
//! 4. κ = 2·y / (x² + y²) of the target, limited to ±`max_curvature`; yaw rate = κ·v.

use super::road_recognition::{RoadDetection, RoadRow};
use crate::sensors::camera::CameraSpec;

/// Which part of the road to follow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Keep {
    /// The middle of the road.
    Centre,
    /// The left edge, this many metres inside the road.
    Left(f64),
    /// The right edge, this many metres inside the road.
    Right(f64),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadFollowParams {
    pub keep: Keep,
    /// Look-ahead distance (m).
    pub lookahead: f64,
    /// Half-width of the look-ahead band as a fraction of `lookahead`.
    pub window: f64,
    /// Path points the target is averaged from.
    pub min_points: usize,
    /// Detections with fewer rows are not followed.
    pub min_rows: usize,
    /// The road's width (m), e.g. from the map; `None`: measured in the image.
    pub road_width: Option<f64>,
    /// Curvature limit (1/m), e.g. tan(max steer) / wheelbase of a car.
    pub max_curvature: f64,
}

impl Default for RoadFollowParams {
    fn default() -> Self {
        RoadFollowParams {
            keep: Keep::Centre,
            lookahead: 3.0,
            window: 0.4,
            min_points: 2,
            min_rows: 3,
            road_width: None,
            max_curvature: 1.5,
        }
    }
}

/// The steering command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadCommand {
    /// Curvature of the arc to drive (1/m, left positive).
    pub curvature: f64,
    /// The pursued point (robot frame, m).
    pub target: [f64; 2],
    /// Path points the target was averaged from.
    pub points: usize,
}

impl RoadCommand {
    /// Yaw rate (rad/s, counter-clockwise positive) at speed `v` (m/s).
    pub fn yaw_rate(&self, v: f64) -> f64 {
        self.curvature * v
    }
}

/// A row's edges on the ground (robot frame): (left, right), `None` above the horizon.
fn edges_on_ground(spec: &CameraSpec, row: &RoadRow) -> Option<([f64; 2], [f64; 2])> {
    let v = row.v as f64 + 0.5;
    Some((
        spec.ground_point(row.left, v)?,
        spec.ground_point(row.right, v)?,
    ))
}

/// The median width (m) of the rows whose both edges were found.
pub fn measured_width(spec: &CameraSpec, det: &RoadDetection) -> Option<f64> {
    let mut w: Vec<f64> = det
        .rows
        .iter()
        .filter(|r| r.left_edge && r.right_edge)
        .filter_map(|r| edges_on_ground(spec, r))
        .map(|(l, r)| (l[1] - r[1]).abs())
        .collect();
    if w.is_empty() {
        return None;
    }
    w.sort_by(f64::total_cmp);
    Some(w[w.len() / 2])
}

/// The path to follow as ground points (robot frame, m), nearest first.
pub fn road_path(
    spec: &CameraSpec,
    det: &RoadDetection,
    params: &RoadFollowParams,
) -> Vec<[f64; 2]> {
    let width = params.road_width.or_else(|| measured_width(spec, det));
    det.rows
        .iter()
        .filter_map(|row| {
            let (l, r) = edges_on_ground(spec, row)?;
            match params.keep {
                Keep::Centre => match (row.left_edge, row.right_edge) {
                    (true, true) => Some([0.5 * (l[0] + r[0]), 0.5 * (l[1] + r[1])]),
                    (true, false) => width.map(|w| [l[0], l[1] - 0.5 * w]),
                    (false, true) => width.map(|w| [r[0], r[1] + 0.5 * w]),
                    (false, false) => None,
                },
                Keep::Left(offset) => row.left_edge.then_some([l[0], l[1] - offset]),
                Keep::Right(offset) => row.right_edge.then_some([r[0], r[1] + offset]),
            }
        })
        .collect()
}

/// The steering towards the recognized road; `None` when the detection is too short or shows
/// nothing to follow.
pub fn road_steering(
    spec: &CameraSpec,
    det: &RoadDetection,
    params: &RoadFollowParams,
) -> Option<RoadCommand> {
    if det.rows.len() < params.min_rows {
        return None;
    }
    let mut path = road_path(spec, det, params);
    if path.is_empty() {
        // no usable edge (a bend fills the view): the middle of what is visible, as the
        // thesis steers; it leans towards the side where the road leaves the image
        path = det
            .rows
            .iter()
            .filter_map(|r| edges_on_ground(spec, r))
            .map(|(l, r)| [0.5 * (l[0] + r[0]), 0.5 * (l[1] + r[1])])
            .collect();
    }
    let l = params.lookahead;
    let dist = |p: &[f64; 2]| p[0].hypot(p[1]);
    let band: Vec<[f64; 2]> = path
        .iter()
        .copied()
        .filter(|p| (dist(p) - l).abs() <= params.window * l)
        .collect();
    let chosen = if band.len() >= params.min_points.max(1) {
        band
    } else {
        let mut near = path;
        near.sort_by(|a, b| (dist(a) - l).abs().total_cmp(&(dist(b) - l).abs()));
        near.truncate(params.min_points.max(1));
        let d = dist(near.first()?);
        if !(l / 3.0..=3.0 * l).contains(&d) {
            return None;
        }
        near
    };
    let n = chosen.len() as f64;
    let target = [
        chosen.iter().map(|p| p[0]).sum::<f64>() / n,
        chosen.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    let d2 = target[0] * target[0] + target[1] * target[1];
    if d2 < 1e-9 {
        return None;
    }
    let k = (2.0 * target[1] / d2).clamp(-params.max_curvature, params.max_curvature);
    Some(RoadCommand {
        curvature: k,
        target,
        points: chosen.len(),
    })
}

#[cfg(test)]
mod tests;
