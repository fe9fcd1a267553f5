//! Driven paths as the .rrd and the HTML report draw them: line strips sent as new segments
//! only ([`PathTrace::take_new`]), each continuing from where the last one ended, so a
//! recording grows linearly with the run (the blueprint draws a path's rows from the start to
//! the time cursor). Points are kept only where the path bends: a point is dropped while every
//! point since the last kept one stays within [`TOLERANCE`] of the straight line from that kept
//! point to the newest one (a streaming form of the Reumann–Witkam / Douglas–Peucker
//! simplification). A 190 m park route keeps a few hundred points instead of thousands;
//! nothing drawn moves by more than a centimetre.
//!
//! A path breaks where it jumps: a point farther from the previous one than [`JUMP_BASE`] plus
//! [`JUMP_SPEED`] times the time between them (a localizer's estimate snapping to another
//! place, a teleported robot) starts a new strip, so no line is drawn across the building.

use systems::core::Pose2;

/// Largest distance (m) of a dropped point from the recorded polyline.
pub const TOLERANCE: f32 = 0.01;
/// Points closer than this (m) to the previous one are not considered (a robot standing still).
const SPACING: f32 = 0.05;
/// At most this many points wait for the next bend (bounds the work per point).
const MAX_PENDING: usize = 256;
/// A step longer than this (m) plus [`JUMP_SPEED`] times its duration breaks the path.
pub const JUMP_BASE: f32 = 1.0;
/// Faster than any robot drives (m/s): a step beyond it is a jump, not a drive.
pub const JUMP_SPEED: f32 = 5.0;

#[derive(Clone, Debug, Default)]
pub struct PathTrace {
    kept: Vec<[f32; 2]>,
    /// Points since the last kept one, the newest last (all within TOLERANCE of the line from
    /// the last kept point to the newest).
    pending: Vec<[f32; 2]>,
    /// Indices into `kept` where a strip starts after a jump.
    breaks: Vec<usize>,
    /// Time of the newest point.
    last_t: f64,
    /// Kept points already handed out by [`PathTrace::take_new`].
    taken: usize,
    /// The last point handed out, where the next new segment starts (None after a jump).
    taken_end: Option<[f32; 2]>,
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
    /// Adds the robot's position at simulated time `t` (s).
    pub fn push(&mut self, pose: &Pose2, t: f64) {
        let q = [pose.x as f32, pose.y as f32];
        let Some(&anchor) = self.kept.last() else {
            self.kept.push(q);
            self.last_t = t;
            return;
        };
        let last = self.pending.last().copied().unwrap_or(anchor);
        let step = (q[0] - last[0]).hypot(q[1] - last[1]);
        let dt = (t - self.last_t).max(0.0) as f32;
        self.last_t = t;
        if step > JUMP_BASE + JUMP_SPEED * dt {
            // the newest point before the jump ends its strip; the new one starts the next
            if let Some(end) = self.pending.pop() {
                self.kept.push(end);
                self.pending.clear();
            }
            self.breaks.push(self.kept.len());
            self.kept.push(q);
            return;
        }
        if step < SPACING {
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

    /// The path drawn since the last call, as strips continuing from where that one ended (the
    /// union of all calls' strips is [`PathTrace::strips`], the newest points of earlier calls
    /// included); empty when it has not moved.
    pub fn take_new(&mut self) -> Vec<Vec<[f32; 3]>> {
        let mut out = Vec::new();
        let mut strip: Vec<[f32; 2]> = self.taken_end.into_iter().collect();
        let mut breaks = self
            .breaks
            .iter()
            .skip_while(|&&b| b < self.taken)
            .peekable();
        for i in self.taken..self.kept.len() {
            if breaks.next_if(|&&b| b == i).is_some() {
                if strip.len() >= 2 {
                    out.push(std::mem::take(&mut strip));
                }
                strip.clear();
            }
            if strip.last() != Some(&self.kept[i]) {
                strip.push(self.kept[i]);
            }
        }
        if let Some(&newest) = self.pending.last()
            && strip.last() != Some(&newest)
        {
            strip.push(newest);
        }
        self.taken = self.kept.len();
        self.taken_end = strip.last().copied().or(self.taken_end);
        if strip.len() >= 2 {
            out.push(strip);
        }
        out.into_iter()
            .map(|s| s.into_iter().map(|p| [p[0], p[1], 0.0]).collect())
            .collect()
    }

    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// The polylines to draw, one per stretch between jumps: the kept points and the newest
    /// one.
    pub fn strips(&self) -> Vec<Vec<[f32; 3]>> {
        let mut out: Vec<Vec<[f32; 3]>> = Vec::with_capacity(self.breaks.len() + 1);
        let mut from = 0;
        for &b in self.breaks.iter().chain([&self.kept.len()]) {
            out.push(
                self.kept[from..b]
                    .iter()
                    .map(|p| [p[0], p[1], 0.0])
                    .collect(),
            );
            from = b;
        }
        if let (Some(newest), Some(last)) = (self.pending.last(), out.last_mut()) {
            last.push([newest[0], newest[1], 0.0]);
        }
        out.retain(|s| !s.is_empty());
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trace of `points` pushed 0.1 s apart.
    fn trace(points: &[[f64; 2]]) -> PathTrace {
        let mut t = PathTrace::default();
        for (k, p) in points.iter().enumerate() {
            t.push(&Pose2::new(p[0], p[1], 0.0), k as f64 * 0.1);
        }
        t
    }

    /// The one strip of a trace without jumps.
    fn strip(t: &PathTrace) -> Vec<[f32; 3]> {
        let mut s = t.strips();
        assert!(s.len() <= 1, "{s:?}");
        s.pop().unwrap_or_default()
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
        let s = strip(&trace(&pts));
        assert_eq!(s.len(), 2);
        assert_eq!(s[0], [0.0, 2.0, 0.0]);
        assert!((s[1][0] - 19.9).abs() < 1e-4);
        // a long one gets a vertex every MAX_PENDING points (bounded work per point)
        let pts: Vec<[f64; 2]> = (0..1000).map(|k| [k as f64 * 0.1, 2.0]).collect();
        let s = strip(&trace(&pts));
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
        let s = strip(&trace(&pts));
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
        let s = strip(&trace(&pts));
        assert_eq!(s.len(), 3, "{s:?}");
        assert!((s[1][0] - 2.0).abs() < 1e-6 && s[1][1].abs() < 1e-6);
        assert!(deviation(&pts, &s) <= TOLERANCE);
    }

    #[test]
    fn an_empty_trace_draws_nothing_and_one_point_draws_itself() {
        assert!(PathTrace::default().strips().is_empty());
        let t = trace(&[[1.0, 2.0]]);
        assert_eq!(t.strips(), vec![vec![[1.0, 2.0, 0.0]]]);
    }

    /// A localizer snapping 12 m away (global localization converging, or a kidnapping)
    /// starts a new strip: no segment is drawn across the jump, and each side keeps its own
    /// simplified line.
    #[test]
    fn a_jump_breaks_the_path_and_no_segment_crosses_it() {
        let mut pts: Vec<[f64; 2]> = (0..30).map(|k| [k as f64 * 0.05, 0.0]).collect();
        pts.extend((0..30).map(|k| [k as f64 * 0.05, 12.0]));
        let t = trace(&pts);
        let s = t.strips();
        assert_eq!(s.len(), 2, "{s:?}");
        assert!(s[0].iter().all(|p| p[1] == 0.0) && s[1].iter().all(|p| p[1] == 12.0));
        assert!(deviation(&pts[..30], &s[0]) <= TOLERANCE);
        assert!(deviation(&pts[30..], &s[1]) <= TOLERANCE);
        // a single point between two jumps is a strip of one point (drawn as nothing)
        let t = trace(&[[0.0, 0.0], [0.05, 0.0], [9.0, 9.0], [0.1, 0.0], [0.15, 0.0]]);
        let s = t.strips();
        assert_eq!(s.len(), 3, "{s:?}");
        assert_eq!(s[1], vec![[9.0, 9.0, 0.0]]);
    }

    /// Points of `strips` as segments (pairs of end points).
    fn segments(strips: &[Vec<[f32; 3]>]) -> Vec<[[f32; 3]; 2]> {
        strips
            .iter()
            .flat_map(|s| s.windows(2).map(|w| [w[0], w[1]]))
            .collect()
    }

    /// Taking the new segments every few points draws the same path as the whole trace: every
    /// segment of the whole lies on a taken one (the taken ones also hold each call's newest
    /// point, which the whole may have dropped since), none crosses a jump, and a call
    /// without movement hands out nothing.
    #[test]
    fn new_segments_draw_the_whole_path_and_no_jump() {
        let mut pts: Vec<[f64; 2]> = (0..200)
            .map(|k| {
                let a = k as f64 * 0.02;
                [3.0 * a.cos(), 3.0 * a.sin()]
            })
            .collect();
        pts.extend((0..100).map(|k| [20.0 + k as f64 * 0.05, 5.0]));
        let mut t = PathTrace::default();
        let mut taken = Vec::new();
        for (k, p) in pts.iter().enumerate() {
            t.push(&Pose2::new(p[0], p[1], 0.0), k as f64 * 0.1);
            if k % 7 == 3 {
                taken.extend(t.take_new());
            }
        }
        taken.extend(t.take_new());
        assert!(t.take_new().is_empty());
        let taken_segments = segments(&taken);
        // every input point lies on the taken segments
        let on = |p: [f32; 2]| {
            taken_segments.iter().any(|s| {
                segment_distance(p, [s[0][0], s[0][1]], [s[1][0], s[1][1]]) <= TOLERANCE + 1e-4
            })
        };
        for p in &pts {
            assert!(on([p[0] as f32, p[1] as f32]), "{p:?} not drawn");
        }
        // no segment spans the jump from the circle to the line
        for s in &taken_segments {
            let len = (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1]);
            assert!(len < 2.0, "{s:?} crosses the jump");
        }
        // the last strip ends at the newest point
        let whole = t.strips();
        assert_eq!(taken.last().unwrap().last(), whole.last().unwrap().last());
    }

    /// A robot driving fast but recorded rarely (3 m/s, a point a second) is one path; the same
    /// distance in a tenth of a second is a jump.
    #[test]
    fn a_fast_drive_recorded_rarely_is_not_a_jump() {
        let mut t = PathTrace::default();
        for k in 0..20 {
            t.push(&Pose2::new(k as f64 * 3.0, 0.0, 0.0), k as f64);
        }
        assert_eq!(t.strips().len(), 1);
        let mut t = PathTrace::default();
        t.push(&Pose2::new(0.0, 0.0, 0.0), 0.0);
        t.push(&Pose2::new(3.0, 0.0, 0.0), 0.1);
        assert_eq!(t.strips().len(), 2);
    }
}
