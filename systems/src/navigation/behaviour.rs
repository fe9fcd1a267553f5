//! Simple driving behaviours so robots move meaningfully before planners exist: waypoint
//! following (go-to-point on the belief pose) and wander (a slowly varying random heading),
//! both steering around obstacles seen by the laser ([`super::avoid`]).

use super::avoid::SectorRanges;
use super::collision_guard::{CONTACT_MARGIN, guarded_speed};
use crate::body::{DriveCommand, Kinematics};
use crate::core::{JobMemory, KernelPool, Pose2, SimClock, SimRng, wrap_angle};
use crate::localization::NavBelief;
use crate::sensors::{Laser, LaserScans};
use bevy_ecs::prelude::*;
use rand::RngExt;
use std::f64::consts::PI;

#[derive(Clone, Debug, PartialEq)]
pub enum BehaviourKind {
    /// Stand still.
    Idle,
    /// Visit the points in order; start over after the last one if `looping`.
    Waypoints {
        points: Vec<[f64; 2]>,
        looping: bool,
    },
    /// Drive around, avoiding obstacles.
    Wander,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NavStatus {
    Idle,
    Driving,
    /// Every waypoint reached (non-looping routes).
    Arrived,
}

#[derive(Component, Clone, Debug)]
pub struct Behaviour {
    pub kind: BehaviourKind,
    /// Cruise speed (m/s).
    pub speed: f64,
    /// Yaw-rate limit (rad/s).
    pub max_yaw_rate: f64,
    /// Distance at which a waypoint counts as reached (m).
    pub tolerance: f64,
    /// The radius of the robot's footprint (its bounding circle, m).
    pub radius: f64,
    /// Half the width of the band a heading must have free: the radius plus a margin (m).
    pub half_width: f64,
    pub current: usize,
    pub status: NavStatus,
    /// Waypoints reached so far.
    pub reached: u32,
    sectors: Option<SectorRanges>,
    rng: SimRng,
    wander_offset: f64,
    next_wander_change: f64,
}

impl Behaviour {
    /// A behaviour for a robot whose footprint fits in a circle of `radius` (m).
    pub fn new(kind: BehaviourKind, speed: f64, radius: f64, rng: SimRng) -> Self {
        let status = match kind {
            BehaviourKind::Idle => NavStatus::Idle,
            _ => NavStatus::Driving,
        };
        Behaviour {
            kind,
            speed,
            max_yaw_rate: 1.5,
            tolerance: 0.4,
            radius,
            half_width: radius + BAND_MARGIN,
            current: 0,
            status,
            reached: 0,
            sectors: None,
            rng,
            wander_offset: 0.0,
            next_wander_change: 0.0,
        }
    }

    /// Replaces the route (scenario event): start from its first point.
    pub fn set_waypoints(&mut self, points: Vec<[f64; 2]>, looping: bool) {
        self.kind = BehaviourKind::Waypoints { points, looping };
        self.current = 0;
        self.status = NavStatus::Driving;
    }

    /// Wanted heading relative to the robot (rad) and the distance to the target (+Inf when
    /// wandering), or None when there is nothing to do.
    fn wanted_bearing(&mut self, belief: &Pose2, now: f64) -> Option<(f64, f64)> {
        match &self.kind {
            BehaviourKind::Idle => None,
            BehaviourKind::Waypoints { points, looping } => {
                if points.is_empty() {
                    self.status = NavStatus::Arrived;
                    return None;
                }
                // one pass over the points at most: looping points that all lie within the
                // tolerance of the robot leave nothing to do this tick (not an endless loop)
                for _ in 0..=points.len() {
                    if self.current >= points.len() {
                        if *looping {
                            self.current = 0;
                        } else {
                            self.status = NavStatus::Arrived;
                            return None;
                        }
                    }
                    let p = points[self.current];
                    let d = (p[0] - belief.x).hypot(p[1] - belief.y);
                    if d < self.tolerance {
                        self.current += 1;
                        self.reached += 1;
                        continue;
                    }
                    let bearing =
                        wrap_angle((p[1] - belief.y).atan2(p[0] - belief.x) - belief.theta);
                    return Some((bearing, d));
                }
                None
            }
            BehaviourKind::Wander => {
                if now >= self.next_wander_change {
                    self.wander_offset = self.rng.random_range(-PI / 3.0..PI / 3.0);
                    self.next_wander_change = now + self.rng.random_range(2.0..6.0);
                }
                Some((self.wander_offset * 0.5, f64::INFINITY))
            }
        }
    }

    /// The drive command for this tick.
    pub fn command(&mut self, belief: &Pose2, now: f64, kin: &Kinematics) -> DriveCommand {
        let Some((wanted, goal_distance)) = self.wanted_bearing(belief, now) else {
            return DriveCommand::default();
        };
        let lookahead = 1.0 + self.speed;
        // near a goal, only the way to the goal needs to be free (a waypoint just inside a
        // furnished room must not send the robot looking for 1.8 m of open floor)
        let needed = lookahead.min(goal_distance + 0.2);
        // between two scans the sectors do not change, so a wanted heading that stays put (a
        // wandering robot's) gets its answers from memory
        let (heading, free, ahead) = match &mut self.sectors {
            Some(s) => {
                let (h, f) = s.choose_heading_remembered(wanted, self.half_width, needed, PI * 0.8);
                (h, f, s.free_distance_remembered(0.0, self.half_width))
            }
            None => (wanted, f64::INFINITY, f64::INFINITY),
        };
        if matches!(self.kind, BehaviourKind::Wander) && free < needed {
            // remember the way out so wander does not oscillate
            self.wander_offset = heading;
        }
        let car = matches!(kin, Kinematics::Ackermann(_));
        // the robot moves along its CURRENT heading while it turns towards `heading`, so the
        // speed is limited by the room straight ahead
        let slow = ((ahead.min(free) - 0.35) / needed.max(0.5)).clamp(0.0, 1.0);
        let mut v = self.speed * slow * heading.cos().max(0.0);
        if !car && heading.abs() > PI / 3.0 {
            v = 0.0; // turn in place first
        }
        if car && v < 0.1 * self.speed && ahead > 0.6 {
            v = 0.1 * self.speed; // a car must roll to turn
        }
        let w = (2.0 * heading).clamp(-self.max_yaw_rate, self.max_yaw_rate);
        if !car && let Some(s) = &self.sectors {
            v = guarded_speed(s, v, w, self.radius + CONTACT_MARGIN);
        }
        DriveCommand::new(v, w)
    }
}

/// What the heading band adds to each side of the footprint (m).
const BAND_MARGIN: f64 = 0.1;
/// Robots from which behaviours run on the kernel pool: about a microsecond each (the laser's
/// sectors and a heading), so a few do not pay for the hand-over.
const PARALLEL_ROBOTS: usize = 32;

/// Control: every robot's behaviour produces its drive command, in parallel on the kernel pool
/// (each behaviour draws only from its own random stream, so threads do not change results).
#[allow(clippy::type_complexity)]
pub fn drive_behaviours(
    clock: Res<SimClock>,
    pool: Res<KernelPool>,
    mut memory: Local<JobMemory>,
    mut robots: Query<(
        &mut Behaviour,
        &NavBelief,
        &Kinematics,
        &mut DriveCommand,
        Option<(&Laser, &LaserScans)>,
    )>,
) {
    let now = clock.start();
    let mut jobs = memory.take();
    jobs.extend(robots.iter_mut());
    pool.for_each_from(
        PARALLEL_ROBOTS,
        &mut jobs,
        |(b, belief, kin, cmd, laser)| {
            if let Some((laser, scans)) = laser {
                if let Some(scan) = scans.scans.last() {
                    b.sectors
                        .get_or_insert_with(SectorRanges::default)
                        .update(scan, &laser.spec.mount);
                } else if !laser.enabled {
                    // a failed laser leaves the behaviour blind (it has no map): a protective
                    // stop until it works again, as a safety scanner's fault causes
                    b.sectors = None;
                    **cmd = DriveCommand::default();
                    return;
                }
            }
            **cmd = b.command(&belief.pose, now, kin);
        },
    );
    memory.keep(jobs);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looping_points_all_within_reach_leave_nothing_to_do_and_return() {
        // every point within the tolerance of the robot: the search for the next point to
        // drive to went round the loop for ever
        let rng = crate::core::stream_rng(1, "r1", "behaviour");
        let points = vec![[2.0, 2.0], [2.1, 2.0]];
        let mut b = Behaviour::new(
            BehaviourKind::Waypoints {
                points: points.clone(),
                looping: true,
            },
            0.5,
            0.3,
            rng.clone(),
        );
        b.tolerance = 0.5;
        let here = Pose2::new(2.0, 2.0, 0.0);
        assert_eq!(b.wanted_bearing(&here, 0.0), None);
        assert_eq!(b.status, NavStatus::Driving);
        // once away from them, it drives to the next one again
        let away = Pose2::new(4.0, 2.0, 0.0);
        let (bearing, d) = b.wanted_bearing(&away, 0.1).expect("a point to drive to");
        assert!(
            (bearing.abs() - PI).abs() < 1e-9 && d > 1.8,
            "{bearing} {d}"
        );
        // not looping: arrived
        let mut once = Behaviour::new(
            BehaviourKind::Waypoints {
                points,
                looping: false,
            },
            0.5,
            0.3,
            rng,
        );
        once.tolerance = 0.5;
        assert_eq!(once.wanted_bearing(&here, 0.0), None);
        assert_eq!(once.status, NavStatus::Arrived);
    }
}
