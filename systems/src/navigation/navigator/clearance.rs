//! What the robot's sensors leave free ahead: the gap to the nearest seen obstacle in the band
//! the path (and the pursuit arc) sweeps, the look-ahead that keeps the pursuit arc off walls,
//! and the seen points to plan around.

use super::Navigator;
use crate::core::Pose2;
use crate::navigation::costmap::{Costmap, INSCRIBED};
use crate::navigation::follower::{
    FollowerParams, Steering, bearing_to, lookahead_point, pursuit_arc,
};
use crate::navigation::local_map::along_band;

/// Shortest look-ahead (m) [`Navigator::safe_lookahead`] falls back to.
const MIN_LOOKAHEAD: f64 = 0.15;

impl Navigator {
    /// Free distance (m) from the robot's outline to the nearest seen obstacle in the band it will
    /// sweep: along the path ahead when there is one (so walls beside a doorway the path threads
    /// do not count), straight ahead otherwise.
    pub(super) fn gap_ahead(&self, pose: &Pose2, map: &Costmap) -> f64 {
        let r = self.params.radius;
        let hw = r + 0.05;
        let pts = self
            .seen
            .iter()
            .flat_map(|s| s.points())
            .chain(self.extra.iter().copied());
        if self.path.len() < 2 {
            let mut free = f64::INFINITY;
            for (x, y) in pts {
                if x > 0.0 && (y as f64).abs() < hw {
                    free = free.min(x as f64);
                }
            }
            return free - r;
        }
        // the band: the robot's position, then the path from the segment it is on, for as far as
        // stopping needs (plus a metre of look-ahead)
        let v = self.follower.v.max(0.0);
        let reach =
            r + self.params.stop_distance + v * v / (2.0 * self.params.follower.max_accel) + 1.0;
        let mut band = vec![[pose.x, pose.y]];
        let mut len = 0.0;
        for &q in &self.path[(self.follower.segment + 1).min(self.path.len() - 1)..] {
            let last = band[band.len() - 1];
            len += (q[0] - last[0]).hypot(q[1] - last[1]);
            band.push(q);
            if len > reach {
                break;
            }
        }
        // and the arc pure pursuit actually drives to its look-ahead point, which cuts inside
        // the path's corners
        let fp = &self.params.follower;
        let arc = match self.params.steering {
            Steering::DiffDrive => pursuit_arc(&self.path, self.follower.segment, pose, fp, v, 6),
            Steering::Ackermann { .. } => Vec::new(),
        };
        let mut free = f64::INFINITY;
        for (x, y) in pts {
            let w = pose.transform_point([x as f64, y as f64]);
            // a point on a wall the map knows (within the inscribed radius of it) is not an
            // obstacle to stop for: the plan already keeps clear of walls
            let known_wall = map
                .cell_of(w[0], w[1])
                .is_none_or(|(c, r)| map.cost(c, r) >= INSCRIBED);
            if known_wall {
                continue;
            }
            if let Some(along) = along_band(&band, w, hw) {
                free = free.min(along);
            }
            if let Some(along) = along_band(&arc, w, hw) {
                free = free.min(along);
            }
        }
        free - r
    }

    /// `fp` with the look-ahead shortened (halved down to [`MIN_LOOKAHEAD`]) until the arc pure
    /// pursuit would drive to its look-ahead point keeps the robot's centre out of the inscribed
    /// cells of the costmap: near walls (a doorway entered at an angle) the robot tracks the path
    /// closely instead of cutting the corner into the frame. The collision check of the
    /// look-ahead arc of Macenski et al., "Regulated Pure Pursuit for Robot Path Tracking",
    /// Autonomous Robots 47 (2023), §3.3, reduced to choosing the look-ahead.
    pub(super) fn safe_lookahead(
        &self,
        pose: &Pose2,
        map: &Costmap,
        mut fp: FollowerParams,
    ) -> FollowerParams {
        if self.path.len() < 2 {
            return fp;
        }
        let v = self.follower.v;
        let mut lookahead = fp.lookahead + fp.lookahead_time * v.abs();
        let diagonal = (map.width as f64).hypot(map.height as f64) * map.resolution;
        loop {
            let mut trial = fp;
            trial.lookahead = lookahead;
            trial.lookahead_time = 0.0;
            // samples every half cell along the arc; the arc ends on the path, inside the map,
            // so no longer than the map's diagonal is sampled (however long the look-ahead)
            let reach = lookahead.min(diagonal);
            let n = ((reach * 1.6) / (0.5 * map.resolution)).ceil().max(2.0) as usize;
            let arc = pursuit_arc(&self.path, self.follower.segment, pose, &trial, v, n);
            // (the robot's own cell may already be inscribed when squeezed through a doorway)
            let clear = arc.iter().skip(1).all(|q| {
                map.cell_of(q[0], q[1])
                    .is_some_and(|(c, r)| map.cost(c, r) < INSCRIBED)
            });
            if clear || lookahead <= MIN_LOOKAHEAD {
                if lookahead < fp.lookahead + fp.lookahead_time * v.abs() {
                    fp = trial;
                }
                return fp;
            }
            lookahead = (lookahead * 0.5).max(MIN_LOOKAHEAD);
        }
    }

    /// True if the follower steers forward from here (its look-ahead point is within the
    /// rotate threshold, so it is not turning on the spot).
    pub(super) fn wants_forward(&self, pose: &Pose2) -> bool {
        if self.path.len() < 2 {
            return false;
        }
        let fp = &self.params.follower;
        let q = lookahead_point(&self.path, self.follower.segment, pose, fp, self.follower.v);
        bearing_to(pose, q).abs() < fp.rotate_threshold
    }

    /// Seen obstacle points within 4 m, in the world frame of the belief, to plan around: the
    /// laser's when there is one (a sonar echo only says "somewhere in a 55° cone", and marking
    /// the whole arc would close a corridor), else the sonars'.
    pub(super) fn obstacles_world(&self, pose: &Pose2) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        let pts: Box<dyn Iterator<Item = (f32, f32)>> = match &self.seen {
            Some(s) => Box::new(s.points()),
            None => Box::new(self.extra.iter().copied()),
        };
        for (x, y) in pts {
            let (x, y) = (x as f64, y as f64);
            if x * x + y * y <= 16.0 {
                out.push(pose.transform_point([x, y]));
            }
        }
        out
    }
}
