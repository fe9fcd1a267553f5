//! Path following by pure pursuit (R. C. Coulter, "Implementation of the Pure Pursuit Path
//! Tracking Algorithm", CMU-RI-TR-92-01, 1992): steer along the circular arc through the robot
//! and the path point one look-ahead distance ahead, curvature κ = 2·y / L² with y the point's
//! lateral offset in the robot frame and L its distance.
//!
//! - Differential drive: ω = κ·v; when the look-ahead point is more than `rotate_threshold` off
//!   the heading the robot first turns on the spot.
//! - Ackermann: |κ| ≤ tan(max_steer) / wheelbase and the car always rolls forward while it
//!   steers (no turning on the spot); a point behind it is reached along the tightest arc.
//! - Speed: the cruise speed, capped so the robot can still stop at the goal
//!   (v ≤ √(2·a·d)), by the yaw-rate limit on tight arcs (v ≤ ω_max / |κ|) and by the caller
//!   (free space ahead); changes at most `max_accel`·dt per step, the yaw rate at most
//!   `max_yaw_accel`·dt.
//!
//! A plain function over the path slice and a small state, so it is tested without the ECS.

use crate::body::kinematics::approach;
use crate::core::{Pose2, wrap_angle};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FollowerParams {
    /// Cruise speed (m/s).
    pub speed: f64,
    /// Speed-up limit, and the comfortable braking the speed profile plans with (m/s²).
    pub max_accel: f64,
    /// Hardest braking allowed when something appears ahead (m/s²).
    pub max_decel: f64,
    /// Yaw-rate limit (rad/s).
    pub max_yaw_rate: f64,
    /// Yaw acceleration limit (rad/s²).
    pub max_yaw_accel: f64,
    /// Look-ahead distance at standstill (m) ...
    pub lookahead: f64,
    /// ... plus this many seconds of travel at the current speed.
    pub lookahead_time: f64,
    /// A differential-drive robot turns on the spot first when the look-ahead point is further
    /// off its heading than this (rad).
    pub rotate_threshold: f64,
    /// The goal is reached within this distance (m).
    pub tolerance: f64,
}

impl Default for FollowerParams {
    fn default() -> Self {
        FollowerParams {
            speed: 0.8,
            max_accel: 0.5,
            max_decel: 1.5,
            max_yaw_rate: 1.5,
            max_yaw_accel: 3.0,
            lookahead: 0.5,
            lookahead_time: 0.4,
            rotate_threshold: 0.6,
            tolerance: 0.25,
        }
    }
}

/// How the robot steers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Steering {
    DiffDrive,
    /// Bicycle model: wheelbase (m) and steering limit (rad).
    Ackermann {
        wheelbase: f64,
        max_steer: f64,
    },
}

impl Steering {
    /// Largest curvature the robot can drive (1/m); infinite for a differential drive.
    pub fn max_curvature(&self) -> f64 {
        match self {
            Steering::DiffDrive => f64::INFINITY,
            Steering::Ackermann {
                wheelbase,
                max_steer,
            } => max_steer.tan() / wheelbase.max(1e-6),
        }
    }
}

/// What the follower remembers between steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FollowerState {
    /// Index of the path segment the robot is on (never decreases for one path).
    pub segment: usize,
    /// Last commanded speed (m/s) and yaw rate (rad/s).
    pub v: f64,
    pub w: f64,
}

/// One step's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FollowOutput {
    pub v: f64,
    pub w: f64,
    /// Path length left from the robot's projection to the goal (m).
    pub remaining: f64,
    /// Distance of the robot from the path (m).
    pub off_path: f64,
    pub arrived: bool,
}

/// Closest point of segment a–b to p: (parameter in [0, 1], distance).
fn project(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (qx, qy) = (a[0] + t * dx, a[1] + t * dy);
    (t, (p[0] - qx).hypot(p[1] - qy))
}

fn seg_len(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Distance of `p` from the polyline (m), +Inf for an empty one.
pub fn distance_to_polyline(path: &[[f64; 2]], p: [f64; 2]) -> f64 {
    match path.len() {
        0 => f64::INFINITY,
        1 => seg_len(path[0], p),
        _ => path
            .windows(2)
            .map(|w| project(w[0], w[1], p).1)
            .fold(f64::INFINITY, f64::min),
    }
}

/// The point `dist` metres along the path from parameter `t` of segment `seg`.
fn point_along(path: &[[f64; 2]], seg: usize, t: f64, dist: f64) -> [f64; 2] {
    let mut left = dist;
    let mut i = seg;
    let mut from = lerp(path[seg], path[seg + 1], t);
    while i + 1 < path.len() {
        let to = path[i + 1];
        let l = seg_len(from, to);
        if l >= left && l > 0.0 {
            let f = left / l;
            return lerp(from, to, f);
        }
        left -= l;
        from = to;
        i += 1;
    }
    *path.last().unwrap_or(&from)
}

fn lerp(a: [f64; 2], b: [f64; 2], f: f64) -> [f64; 2] {
    [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f]
}

/// Speed change limited by the acceleration when speeding up and the braking limit when slowing.
fn ramp(current: f64, target: f64, p: &FollowerParams, dt: f64) -> f64 {
    if target.abs() < current.abs() {
        approach(current, target, p.max_decel.max(p.max_accel) * dt)
    } else {
        approach(current, target, p.max_accel * dt)
    }
}

/// One control step along `path` (≥ 1 point; the last one is the goal) from `pose`.
/// `speed_cap` limits the speed from outside (free space ahead); `dt` is the step (s).
pub fn follow(
    path: &[[f64; 2]],
    pose: &Pose2,
    state: &mut FollowerState,
    p: &FollowerParams,
    steering: &Steering,
    speed_cap: f64,
    dt: f64,
) -> FollowOutput {
    let here = [pose.x, pose.y];
    let goal = *path.last().unwrap_or(&here);
    let to_goal = seg_len(here, goal);
    if path.len() < 2 {
        let arrived = to_goal <= p.tolerance;
        return brake(state, p, dt, to_goal, 0.0, arrived);
    }
    // advance along the path: the nearest segment among the current one and a few ahead (a
    // window, so a path that comes back near itself does not make the robot skip ahead)
    let last_seg = path.len() - 2;
    state.segment = state.segment.min(last_seg);
    let mut best = (state.segment, 0.0, f64::INFINITY);
    // (`walked`: length of the whole segments between the current one and segment i)
    let mut walked = 0.0;
    for i in state.segment..=last_seg {
        if i > state.segment + 1 {
            walked += seg_len(path[i - 1], path[i]);
            if walked > 3.0 + p.lookahead {
                break;
            }
        }
        let (t, d) = project(path[i], path[i + 1], here);
        if d < best.2 - 1e-9 {
            best = (i, t, d);
        }
    }
    let (seg, t, off_path) = best;
    state.segment = seg;
    let mut remaining = seg_len(lerp(path[seg], path[seg + 1], t), path[seg + 1]);
    for i in seg + 1..=last_seg {
        remaining += seg_len(path[i], path[i + 1]);
    }
    if to_goal <= p.tolerance {
        return brake(state, p, dt, remaining, off_path, true);
    }

    let lookahead = p.lookahead + p.lookahead_time * state.v.abs();
    let target = if remaining <= lookahead {
        goal
    } else {
        point_along(path, seg, t, lookahead)
    };
    // the look-ahead point in the robot frame
    let (s, c) = pose.theta.sin_cos();
    let (dx, dy) = (target[0] - pose.x, target[1] - pose.y);
    let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
    let l2 = (lx * lx + ly * ly).max(1e-9);
    let bearing = ly.atan2(lx);
    let mut kappa = 2.0 * ly / l2;

    // speed: cruise, stop at the goal, the caller's cap
    let stop_at_goal = (2.0 * p.max_accel * (to_goal - 0.5 * p.tolerance).max(0.0)).sqrt();
    let mut v_target = p.speed.min(stop_at_goal).min(speed_cap.max(0.0));
    let (v_new, w_new) = match steering {
        Steering::DiffDrive => {
            if bearing.abs() > p.rotate_threshold {
                // turn on the spot towards the point first
                let w = (2.0 * bearing).clamp(-p.max_yaw_rate, p.max_yaw_rate);
                (0.0, w)
            } else {
                if kappa.abs() > 1e-9 {
                    v_target = v_target.min(p.max_yaw_rate / kappa.abs());
                }
                // slow down while the heading error is large, so the arc stays tight
                v_target *= bearing.cos().max(0.0);
                let v = ramp(state.v, v_target, p, dt);
                (v, kappa * v)
            }
        }
        Steering::Ackermann { .. } => {
            let kmax = steering.max_curvature();
            if lx <= 0.0 {
                // behind: the tightest arc towards it
                kappa = kmax * if ly >= 0.0 { 1.0 } else { -1.0 };
            }
            kappa = kappa.clamp(-kmax, kmax);
            if kappa.abs() > 1e-9 {
                v_target = v_target.min(p.max_yaw_rate / kappa.abs());
            }
            // a car has to roll to turn: keep a crawl unless told to stop
            if speed_cap > 0.05 {
                v_target = v_target.max(0.2 * p.speed.min(speed_cap));
            }
            let v = ramp(state.v, v_target, p, dt);
            (v, kappa * v)
        }
    };
    let w = approach(state.w, w_new, p.max_yaw_accel * dt).clamp(-p.max_yaw_rate, p.max_yaw_rate);
    // keep the commanded arc's curvature when the yaw rate was limited
    let v = if w_new.abs() > 1e-9 && w.abs() < w_new.abs() && v_new > 0.0 {
        (v_new * w / w_new).clamp(0.0, v_new)
    } else {
        v_new
    };
    state.v = v;
    state.w = w;
    FollowOutput {
        v,
        w,
        remaining,
        off_path,
        arrived: false,
    }
}

/// Braking step (at the goal or with nothing to follow).
fn brake(
    state: &mut FollowerState,
    p: &FollowerParams,
    dt: f64,
    remaining: f64,
    off_path: f64,
    arrived: bool,
) -> FollowOutput {
    state.v = ramp(state.v, 0.0, p, dt);
    state.w = approach(state.w, 0.0, p.max_yaw_accel * dt);
    FollowOutput {
        v: state.v,
        w: state.w,
        remaining,
        off_path,
        arrived,
    }
}

/// The point pure pursuit steers for: the look-ahead distance at speed `v` along `path` (≥ 2
/// points) from the robot's projection on segment `seg`.
pub fn lookahead_point(
    path: &[[f64; 2]],
    seg: usize,
    pose: &Pose2,
    p: &FollowerParams,
    v: f64,
) -> [f64; 2] {
    let seg = seg.min(path.len() - 2);
    let (t, _) = project(path[seg], path[seg + 1], [pose.x, pose.y]);
    point_along(path, seg, t, p.lookahead + p.lookahead_time * v.abs())
}

/// The arc pure pursuit drives from `pose` towards the look-ahead point on `path` (≥ 2 points,
/// from segment `seg` on, at speed `v`): `n` + 1 points from the robot to the look-ahead point
/// along the circle tangent to the heading (Coulter 1992, eq. of the curvature 2·y / L²). Empty
/// when the point lies too far to the side to be driven to directly (a diff-drive robot turns
/// on the spot first).
pub fn pursuit_arc(
    path: &[[f64; 2]],
    seg: usize,
    pose: &Pose2,
    p: &FollowerParams,
    v: f64,
    n: usize,
) -> Vec<[f64; 2]> {
    if path.len() < 2 || n == 0 {
        return Vec::new();
    }
    let target = lookahead_point(path, seg, pose, p, v);
    let (s, c) = pose.theta.sin_cos();
    let (dx, dy) = (target[0] - pose.x, target[1] - pose.y);
    let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
    let bearing = ly.atan2(lx);
    if bearing.abs() > p.rotate_threshold.min(std::f64::consts::FRAC_PI_2) {
        return Vec::new();
    }
    let l2 = lx * lx + ly * ly;
    let kappa = 2.0 * ly / l2.max(1e-9);
    // arc length to the point: the swept angle is twice the bearing
    let len = if kappa.abs() < 1e-6 {
        l2.sqrt()
    } else {
        2.0 * bearing / kappa
    };
    (0..=n)
        .map(|i| {
            let a = len * i as f64 / n as f64;
            let (x, y) = if kappa.abs() < 1e-6 {
                (a, 0.0)
            } else {
                ((kappa * a).sin() / kappa, (1.0 - (kappa * a).cos()) / kappa)
            };
            [pose.x + c * x - s * y, pose.y + s * x + c * y]
        })
        .collect()
}

/// Angle between the robot's heading and the direction to `p` (rad).
pub fn bearing_to(pose: &Pose2, p: [f64; 2]) -> f64 {
    wrap_angle((p[1] - pose.y).atan2(p[0] - pose.x) - pose.theta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::kinematics::integrate_arc;
    use std::f64::consts::PI;

    /// Drives a unicycle along `path` with the follower; returns (final pose, steps, max |v|,
    /// max |Δv|/dt, max distance from the path).
    fn drive(path: &[[f64; 2]], start: Pose2, steering: Steering) -> (Pose2, usize, f64, f64, f64) {
        let p = FollowerParams::default();
        let mut s = FollowerState::default();
        let mut pose = start;
        let dt = 0.05;
        let (mut vmax, mut amax, mut offmax) = (0.0f64, 0.0f64, 0.0f64);
        let mut prev_v = 0.0;
        for k in 0..4000 {
            let out = follow(path, &pose, &mut s, &p, &steering, f64::INFINITY, dt);
            if out.arrived && out.v.abs() < 1e-6 {
                return (pose, k, vmax, amax, offmax);
            }
            vmax = vmax.max(out.v.abs());
            amax = amax.max((out.v - prev_v).abs() / dt);
            offmax = offmax.max(out.off_path);
            prev_v = out.v;
            pose = integrate_arc(&pose, out.v, out.w, dt);
        }
        (pose, usize::MAX, vmax, amax, offmax)
    }

    #[test]
    fn diff_drive_follows_an_l_shaped_path_within_limits() {
        let path = [[0.0, 0.0], [5.0, 0.0], [5.0, 4.0]];
        let (end, steps, vmax, amax, offmax) =
            drive(&path, Pose2::new(0.0, 0.0, 0.0), Steering::DiffDrive);
        assert!(steps < 4000, "never arrived: {end:?}");
        assert!(end.x.hypot(0.0) > 0.0 && (end.x - 5.0).hypot(end.y - 4.0) <= 0.25);
        assert!(vmax <= 0.8 + 1e-9, "speed {vmax}");
        assert!(amax <= 1.5 + 1e-6, "accel {amax}");
        // pure pursuit cuts the corner by less than the look-ahead distance
        assert!(offmax < 0.6, "off path {offmax}");
    }

    #[test]
    fn diff_drive_turns_on_the_spot_when_the_path_is_behind() {
        let path = [[0.0, 0.0], [-4.0, 0.0]];
        let p = FollowerParams::default();
        let mut s = FollowerState::default();
        let out = follow(
            &path,
            &Pose2::new(0.0, 0.0, 0.0),
            &mut s,
            &p,
            &Steering::DiffDrive,
            f64::INFINITY,
            0.05,
        );
        assert_eq!(out.v, 0.0);
        assert!(out.w.abs() > 0.0);
        let (end, steps, ..) = drive(&path, Pose2::new(0.0, 0.0, 0.0), Steering::DiffDrive);
        assert!(steps < 4000 && (end.x + 4.0).abs() <= 0.25, "{end:?}");
    }

    #[test]
    fn ackermann_never_turns_on_the_spot_and_reaches_the_goal() {
        let steering = Steering::Ackermann {
            wheelbase: 0.5,
            max_steer: 0.5,
        };
        let path = [[0.0, 0.0], [6.0, 0.0], [6.0, 6.0]];
        let p = FollowerParams::default();
        let mut s = FollowerState::default();
        let mut pose = Pose2::new(0.0, 0.0, 0.0);
        let kmax = steering.max_curvature();
        let mut arrived = false;
        for _ in 0..4000 {
            let out = follow(&path, &pose, &mut s, &p, &steering, f64::INFINITY, 0.05);
            if out.arrived {
                arrived = true;
                break;
            }
            assert!(out.v >= 0.0);
            if out.v > 1e-9 {
                assert!((out.w / out.v).abs() <= kmax + 1e-6, "curvature");
            } else {
                assert!(out.w.abs() < 1e-9, "turned on the spot");
            }
            pose = integrate_arc(&pose, out.v, out.w, 0.05);
        }
        assert!(arrived, "{pose:?}");
    }

    #[test]
    fn long_first_segments_do_not_hide_the_next_ones() {
        // a 14 m leg, then a turn into a doorway: the follower must move on to the later segments
        let path = [
            [61.8, 16.0],
            [47.8, 16.5],
            [47.7, 16.8],
            [47.7, 18.2],
            [47.8, 18.6],
        ];
        let (end, steps, ..) = drive(&path, Pose2::new(61.8, 16.0, PI), Steering::DiffDrive);
        assert!(steps < 4000, "never arrived: {end:?}");
        assert!((end.x - 47.8).hypot(end.y - 18.6) <= 0.25, "{end:?}");
    }

    #[test]
    fn a_speed_cap_stops_the_robot() {
        let path = [[0.0, 0.0], [5.0, 0.0]];
        let p = FollowerParams::default();
        let mut s = FollowerState {
            v: 0.8,
            ..Default::default()
        };
        let pose = Pose2::new(1.0, 0.0, 0.0);
        let mut v = 1.0;
        for _ in 0..100 {
            v = follow(&path, &pose, &mut s, &p, &Steering::DiffDrive, 0.0, 0.05).v;
        }
        assert_eq!(v, 0.0);
    }

    #[test]
    fn distance_to_a_polyline() {
        let path = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]];
        assert!((distance_to_polyline(&path, [1.0, 1.0]) - 1.0).abs() < 1e-12);
        assert!((distance_to_polyline(&path, [3.0, 3.0]) - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(distance_to_polyline(&[], [0.0, 0.0]), f64::INFINITY);
    }
}
