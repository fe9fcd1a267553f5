//! Other robots and walking people as laser obstacles: every robot's footprint and every
//! person's disc in the world at the current tick, bucketed on a coarse grid so a laser only
//! looks at bodies within its range. People take the slots after the robots' (robot count +
//! person index), so `except` (a robot index) never hides a person.

use crate::body::{Footprint, Person, PersonIndex, TruePose};
use crate::core::RobotIndex;
use bevy_ecs::prelude::*;

/// Bucket side (m).
const BUCKET: f64 = 4.0;

/// Reusable output of [`RobotOutlines::near`].
#[derive(Default)]
pub struct NearbyRobots {
    pub circles: Vec<[f32; 3]>,
    pub segments: Vec<[f32; 4]>,
    ids: Vec<u32>,
}

#[derive(Resource, Default)]
pub struct RobotOutlines {
    /// Per robot (by index), then per person: circle (cx, cy, r) or polygon edges.
    circles: Vec<Option<[f32; 3]>>,
    polygons: Vec<Vec<[f32; 4]>>,
    centres: Vec<[f64; 3]>,
    /// Bucket → robots in it (a fast non-cryptographic hash: a scan looks up ~100 buckets).
    buckets: rustc_hash::FxHashMap<(i32, i32), Vec<u32>>,
}

impl RobotOutlines {
    /// Robots (other than `except`) whose bounding discs come within `range` of (x, y), in index
    /// order, as circles and segments.
    pub fn near(&self, x: f64, y: f64, range: f64, except: u32, out: &mut NearbyRobots) {
        let NearbyRobots {
            circles,
            segments,
            ids: scratch,
        } = out;
        circles.clear();
        segments.clear();
        scratch.clear();
        let b0 = (
            ((x - range) / BUCKET).floor() as i32,
            ((y - range) / BUCKET).floor() as i32,
        );
        let b1 = (
            ((x + range) / BUCKET).floor() as i32,
            ((y + range) / BUCKET).floor() as i32,
        );
        let nb = ((b1.0 - b0.0 + 1) as i64) * ((b1.1 - b0.1 + 1) as i64);
        if nb as usize > self.buckets.len() {
            // huge range relative to the world: scan the occupied buckets instead
            for (k, v) in &self.buckets {
                if k.0 >= b0.0 && k.0 <= b1.0 && k.1 >= b0.1 && k.1 <= b1.1 {
                    scratch.extend_from_slice(v);
                }
            }
        } else {
            for bx in b0.0..=b1.0 {
                for by in b0.1..=b1.1 {
                    if let Some(v) = self.buckets.get(&(bx, by)) {
                        scratch.extend_from_slice(v);
                    }
                }
            }
        }
        scratch.sort_unstable();
        for &i in scratch.iter() {
            if i == except {
                continue;
            }
            let c = self.centres[i as usize];
            let (dx, dy, reach) = (c[0] - x, c[1] - y, range + c[2]);
            if dx * dx + dy * dy > reach * reach {
                continue;
            }
            if let Some(circle) = self.circles[i as usize] {
                circles.push(circle);
            } else {
                segments.extend_from_slice(&self.polygons[i as usize]);
            }
        }
    }
}

/// Sense (first): refresh every robot's outline and every person's disc.
pub fn update_robot_outlines(
    mut outlines: ResMut<RobotOutlines>,
    robots: Query<(&RobotIndex, &TruePose, &Footprint)>,
    people: Query<(&PersonIndex, &TruePose, &Person), Without<RobotIndex>>,
) {
    let n_robots = robots
        .iter()
        .map(|(i, _, _)| i.0 as usize + 1)
        .max()
        .unwrap_or(0);
    let n = n_robots
        + people
            .iter()
            .map(|(i, _, _)| i.0 as usize + 1)
            .max()
            .unwrap_or(0);
    let o = &mut *outlines;
    o.circles.clear();
    o.circles.resize(n, None);
    o.polygons.resize_with(n, Vec::new);
    o.centres.clear();
    o.centres.resize(n, [f64::NAN; 3]);
    for v in o.buckets.values_mut() {
        v.clear();
    }
    for (idx, truth, footprint) in robots.iter() {
        let i = idx.0 as usize;
        let p = truth.pose;
        o.centres[i] = [p.x, p.y, footprint.bounding_radius()];
        match footprint {
            Footprint::Circle { radius } => {
                o.circles[i] = Some([p.x as f32, p.y as f32, *radius as f32]);
            }
            Footprint::Rectangle { .. } => {
                let pts = footprint.outline(&p);
                let poly = &mut o.polygons[i];
                poly.clear();
                for k in 0..pts.len() {
                    let a = pts[k];
                    let b = pts[(k + 1) % pts.len()];
                    poly.push([a[0] as f32, a[1] as f32, b[0] as f32, b[1] as f32]);
                }
            }
        }
        let key = ((p.x / BUCKET).floor() as i32, (p.y / BUCKET).floor() as i32);
        o.buckets.entry(key).or_default().push(idx.0);
    }
    for (idx, truth, person) in people.iter() {
        let i = n_robots + idx.0 as usize;
        let p = truth.pose;
        o.centres[i] = [p.x, p.y, person.radius];
        o.circles[i] = Some([p.x as f32, p.y as f32, person.radius as f32]);
        let key = ((p.x / BUCKET).floor() as i32, (p.y / BUCKET).floor() as i32);
        o.buckets.entry(key).or_default().push(i as u32);
    }
    o.buckets.retain(|_, v| !v.is_empty());
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{KernelPool, Pose2, SimClock, stream_rng};
    use crate::sensors::laser::{Laser, LaserScans, LaserSpec, LaserTruth, sample_lasers};
    use crate::world::{Cell, OccupancyGrid, StaticWorld};

    /// A noiseless laser on robot 0 looking along +x at a person standing 3 m ahead (centre),
    /// radius 0.25: the middle beam measures 2.75 m; a second robot behind the person is hidden.
    #[test]
    fn a_laser_in_front_of_a_person_measures_the_person() {
        let mut world = World::new();
        let grid = OccupancyGrid::new(300, 300, 0.1, [-15.0, -15.0], Cell::Free);
        world.insert_resource(StaticWorld::new(grid));
        world.insert_resource(KernelPool::new(1).expect("pool"));
        world.insert_resource(SimClock::new(0.1));
        world.init_resource::<RobotOutlines>();
        let mut spec = LaserSpec::sick_lms100();
        spec.noise_std = 0.0;
        spec.rate = 10.0;
        let robot = world
            .spawn((
                RobotIndex(0),
                TruePose::at(Pose2::new(0.0, 0.0, 0.0)),
                Footprint::Circle { radius: 0.3 },
                Laser::new(spec.clone(), stream_rng(1, "r", "laser")),
                LaserScans::default(),
                LaserTruth::default(),
            ))
            .id();
        world.spawn((
            RobotIndex(1),
            TruePose::at(Pose2::new(6.0, 0.0, 0.0)),
            Footprint::Circle { radius: 0.3 },
        ));
        world.spawn((
            PersonIndex(0),
            TruePose::at(Pose2::new(3.0, 0.0, 0.0)),
            Person::new(vec![[3.0, 0.0], [3.0, 5.0]]),
        ));
        let mut schedule = Schedule::default();
        schedule.add_systems((update_robot_outlines, sample_lasers).chain());
        schedule.run(&mut world);
        let scans = world.get::<LaserScans>(robot).expect("scans");
        let scan = scans.latest().expect("a scan");
        let mid = spec.beams() / 2;
        assert!(
            (scan.ranges[mid] - 2.75).abs() < 1e-3,
            "{}",
            scan.ranges[mid]
        );
        // the person covers ±asin(0.25 / 3) ≈ ±4.8° around the axis
        let k = (4.0f64.to_radians() / spec.increment) as usize;
        assert!(scan.ranges[mid + k] < 3.0 && scan.ranges[mid - k] < 3.0);
        assert!(scan.ranges[mid + 40].is_infinite(), "nothing else at 10°");
        // a robot's `except` never hides a person
        let outlines = world.resource::<RobotOutlines>();
        let mut near = NearbyRobots::default();
        outlines.near(0.0, 0.0, 10.0, 0, &mut near);
        assert_eq!(near.circles.len(), 2, "the person and robot 1");
        assert_eq!(near.circles[1], [3.0, 0.0, 0.25], "people after robots");
    }
}
