//! The Sense-set system of a replay: in each tick it hands every robot exactly the recorded
//! readings the live sensors produced in that tick, the readings stamped in `(start, end]`
//! (and those at 0 in the first tick), as [`systems::core::RateTimer`] fires them. The
//! estimators then run unchanged. Ground truth is set for evaluation and recording only.

use super::source::RobotFeed;
use bevy_ecs::prelude::*;
use std::cell::Cell;
use systems::body::TruePose;
use systems::core::{Pose2, SimClock, SimPlugin, SimSet};
use systems::localization::WheelOdometry;
use systems::sensors::{EncoderReadings, Laser, LaserScans, LaserTruth};

/// Slack of the tick boundaries, as the sensors' timers have it.
const EPS: f64 = 1e-9;

/// A robot's readings and how far the replay has got in each list.
pub struct FedRobot {
    pub entity: Entity,
    pub feed: RobotFeed,
    /// Next scan, encoder reading and odometry pose.
    next: [usize; 3],
}

impl FedRobot {
    pub fn new(entity: Entity, feed: RobotFeed) -> Self {
        FedRobot {
            entity,
            feed,
            next: [0; 3],
        }
    }
}

/// The recorded readings of every replayed robot (a resource while the replay runs).
#[derive(Resource)]
pub struct ReplayFeed {
    pub robots: Vec<FedRobot>,
}

/// The recorded readings and [`feed_recorded`] in the Sense set.
pub struct ReplayFeedPlugin {
    feed: Cell<Option<ReplayFeed>>,
}

impl ReplayFeedPlugin {
    pub fn new(feed: ReplayFeed) -> Self {
        ReplayFeedPlugin {
            feed: Cell::new(Some(feed)),
        }
    }
}

impl SimPlugin for ReplayFeedPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        world.insert_resource(self.feed.take().expect("ReplayFeedPlugin is built once"));
        schedule.add_systems(feed_recorded.in_set(SimSet::Sense));
    }
}

/// The items of `list` from `*next` on with a time up to `end`; advances `*next` past them.
fn due<'a, T>(list: &'a [T], next: &mut usize, end: f64, time: impl Fn(&T) -> f64) -> &'a [T] {
    let from = *next;
    while *next < list.len() && time(&list[*next]) <= end + EPS {
        *next += 1;
    }
    &list[from..*next]
}

/// The true pose at `t` from time-ordered samples: the sample stamped `t` if there is one
/// (our files: one per tick end), else interpolated between its neighbours (held before the
/// first and after the last).
fn truth_at(samples: &[(f64, Pose2)], t: f64) -> Option<Pose2> {
    let i = samples.partition_point(|(s, _)| *s < t - EPS);
    match (i.checked_sub(1).map(|j| samples[j]), samples.get(i)) {
        (_, Some(&(s, p))) if (s - t).abs() <= EPS => Some(p),
        (Some((t0, p0)), Some(&(t1, p1))) => Some(p0.lerp(&p1, (t - t0) / (t1 - t0))),
        (None, Some(&(_, p))) | (Some((_, p)), None) => Some(p),
        (None, None) => None,
    }
}

type Fed<'a> = (
    &'a mut TruePose,
    Option<(&'a Laser, &'a mut LaserScans, &'a mut LaserTruth)>,
    Option<&'a mut EncoderReadings>,
    Option<&'a mut WheelOdometry>,
);

/// Sense: this tick's recorded readings for every replayed robot.
pub fn feed_recorded(clock: Res<SimClock>, feed: ResMut<ReplayFeed>, mut robots: Query<Fed<'_>>) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    for r in feed.into_inner().robots.iter_mut() {
        let Ok((mut truth, laser, encoder, odom)) = robots.get_mut(r.entity) else {
            continue;
        };
        let [scan_i, enc_i, odom_i] = &mut r.next;
        let f = &r.feed;
        // the truth first: the true sensor poses of this tick's scans interpolate it
        let now = truth_at(&f.truth, end).unwrap_or(truth.pose);
        truth.prev = truth.pose;
        truth.pose = now;
        if let Some((laser, mut scans, mut laser_truth)) = laser {
            scans.next_tick();
            laser_truth.poses.clear();
            for s in due(&f.scans, scan_i, end, |s| s.stamp) {
                let at = ((s.stamp - start) / dt).clamp(0.0, 1.0);
                laser_truth
                    .poses
                    .push(truth.interpolate(at).compose(&laser.spec.mount));
                scans.scans.push(s.clone());
            }
            if !scans.scans.is_empty() {
                laser_truth.latest = laser_truth.poses.last().copied();
            }
        }
        if let Some(mut readings) = encoder {
            readings.readings.clear();
            readings
                .readings
                .extend_from_slice(due(&f.encoder, enc_i, end, |e| e.stamp));
        }
        // odometry poses replace the encoder (the entity then has no EncoderReadings)
        if let Some(mut odom) = odom
            && !f.odometry.is_empty()
        {
            odom.start_tick();
            for &(t, p) in due(&f.odometry, odom_i, end, |o| o.0) {
                odom.set_pose(p, t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_go_to_the_tick_whose_end_they_do_not_pass() {
        let list = [0.0, 0.05, 0.1, 0.1 + 1e-12, 0.15];
        let mut next = 0;
        assert_eq!(
            due(&list, &mut next, 0.1, |t| *t),
            &[0.0, 0.05, 0.1, 0.1 + 1e-12]
        );
        assert_eq!(due(&list, &mut next, 0.2, |t| *t), &[0.15]);
        assert!(due(&list, &mut next, 0.3, |t| *t).is_empty());
    }

    #[test]
    fn truth_is_the_sample_at_the_tick_end_or_interpolated() {
        let s = [
            (0.1, Pose2::new(1.0, 0.0, 0.0)),
            (0.3, Pose2::new(3.0, 0.0, 0.0)),
        ];
        assert_eq!(truth_at(&s, 0.1), Some(s[0].1));
        assert_eq!(truth_at(&s, 0.0), Some(s[0].1));
        assert_eq!(truth_at(&s, 0.5), Some(s[1].1));
        assert!((truth_at(&s, 0.2).unwrap().x - 2.0).abs() < 1e-12);
        assert_eq!(truth_at(&[], 0.2), None);
    }
}
