//! Driven paths as the .rrd draws them: a line strip re-logged at the path rate, so its size is
//! what a long run pays for again and again. Points are kept only where the path bends: a point
//! is dropped while every point since the last kept one stays within [`TOLERANCE`] of the
//! straight line from that kept point to the newest one (a streaming form of the
//! Reumann–Witkam / Douglas–Peucker simplification). A 190 m park route keeps a few hundred
//! points instead of thousands; nothing drawn moves by more than a centimetre.

use systems::core::Pose2;

/// Largest distance (m) of a dropped point from the recorded polyline.
pub const TOLERANCE: f32 = 0.01;
/// Points closer than this (m) to the previous one are not considered (a robot standing still).
const SPACING: f32 = 0.05;
/// At most this many points wait for the next bend (bounds the work per point).
const MAX_PENDING: usize = 256;

#[derive(Clone, Debug, Default)]
pub struct PathTrace {
    kept: Vec<[f32; 2]>,
    /// Points since the last kept one, the newest last (all within TOLERANCE of the line from
    /// the last kept point to the newest).
    pending: Vec<[f32; 2]>,
}

/// Distance of `p` from the segment a–b.
fn segment_distance(p: [f32; 2], a: [f32; 2], b: [f32; 2]) -> f32 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let (px, py) = (p[0] - a[0], p[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (px - t * dx).hypot(py - t * dy)
}

impl PathTrace {
    /// Adds the robot's position.
    pub fn push(&mut self, pose: &Pose2) {
        let q = [pose.x as f32, pose.y as f32];
        let Some(&anchor) = self.kept.last() else {
            self.kept.push(q);
            return;
        };
        let last = self.pending.last().copied().unwrap_or(anchor);
        if (q[0] - last[0]).hypot(q[1] - last[1]) < SPACING {
            return;
        }
        let straight = self.pending.len() < MAX_PENDING
            && self
                .pending
                .iter()
                .all(|&p| segment_distance(p, anchor, q) <= TOLERANCE);
        if !straight && let Some(bend) = self.pending.pop() {
            // the newest point bends away: the previous one is a vertex
            self.kept.push(bend);
            self.pending.clear();
        }
        self.pending.push(q);
    }

    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// The polyline to draw: the kept points and the newest one.
    pub fn strip(&self) -> Vec<[f32; 3]> {
        self.kept
            .iter()
            .chain(self.pending.last())
            .map(|p| [p[0], p[1], 0.0])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(points: &[[f64; 2]]) -> PathTrace {
        let mut t = PathTrace::default();
        for p in points {
            t.push(&Pose2::new(p[0], p[1], 0.0));
        }
        t
    }

    /// Largest distance of any input point from the drawn polyline.
    fn deviation(points: &[[f64; 2]], strip: &[[f32; 3]]) -> f32 {
        points
            .iter()
            .map(|p| {
                let p = [p[0] as f32, p[1] as f32];
                strip
                    .windows(2)
                    .map(|w| segment_distance(p, [w[0][0], w[0][1]], [w[1][0], w[1][1]]))
                    .fold(f32::INFINITY, f32::min)
            })
            .fold(0.0, f32::max)
    }

    #[test]
    fn a_straight_drive_is_two_points() {
        let pts: Vec<[f64; 2]> = (0..200).map(|k| [k as f64 * 0.1, 2.0]).collect();
        let s = trace(&pts).strip();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0], [0.0, 2.0, 0.0]);
        assert!((s[1][0] - 19.9).abs() < 1e-4);
        // a long one gets a vertex every MAX_PENDING points (bounded work per point)
        let pts: Vec<[f64; 2]> = (0..1000).map(|k| [k as f64 * 0.1, 2.0]).collect();
        let s = trace(&pts).strip();
        assert_eq!(s.len(), 2 + 999 / MAX_PENDING);
        assert!(deviation(&pts, &s) < 1e-4);
    }

    #[test]
    fn a_circle_keeps_few_points_and_stays_within_the_tolerance() {
        // radius 5 m, a point every 5 cm
        let n = 628;
        let pts: Vec<[f64; 2]> = (0..=n)
            .map(|k| {
                let a = k as f64 / n as f64 * std::f64::consts::TAU;
                [5.0 * a.cos(), 5.0 * a.sin()]
            })
            .collect();
        let s = trace(&pts).strip();
        // chords with a 1 cm sagitta on a 5 m radius are about 0.63 m long: ~50 of them
        assert!(s.len() < 80, "{} points", s.len());
        assert!(s.len() > 30, "{} points", s.len());
        let d = deviation(&pts, &s);
        assert!(d <= TOLERANCE + 1e-5, "deviation {d}");
    }

    #[test]
    fn corners_are_kept_and_a_robot_standing_still_adds_nothing() {
        let mut pts = Vec::new();
        for k in 0..=20 {
            pts.push([k as f64 * 0.1, 0.0]);
        }
        for _ in 0..50 {
            pts.push([2.0, 0.0]);
        }
        for k in 1..=20 {
            pts.push([2.0, k as f64 * 0.1]);
        }
        let s = trace(&pts).strip();
        assert_eq!(s.len(), 3, "{s:?}");
        assert!((s[1][0] - 2.0).abs() < 1e-6 && s[1][1].abs() < 1e-6);
        assert!(deviation(&pts, &s) <= TOLERANCE);
    }

    #[test]
    fn an_empty_trace_draws_nothing_and_one_point_draws_itself() {
        assert!(PathTrace::default().strip().is_empty());
        let t = trace(&[[1.0, 2.0]]);
        assert_eq!(t.strip(), vec![[1.0, 2.0, 0.0]]);
    }
}
