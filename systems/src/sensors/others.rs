//! Other robots and walking people as laser obstacles: every robot's footprint and every
//! person's disc in the world at the current tick, bucketed on a coarse grid so a laser only
//! looks at bodies within its range. People take the slots after the robots' (robot count +
//! person index), so `except` (a robot index) never hides a person.

use crate::body::{Footprint, Person, PersonIndex, TruePose};
use crate::core::RobotIndex;
use bevy_ecs::prelude::*;

/// Bucket side (m), unless the bodies are spread so far that a grid of such buckets over them
/// would have many more buckets than bodies.
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
    buckets: Buckets,
    /// The largest bounding radius of a body.
    largest_radius: f64,
    /// Scratch: every body's centre and slot, for bucketing.
    placed: Vec<(f64, f64, u32)>,
}

/// The bodies bucketed on a grid of squares over their bounding box, by a counting sort: the
/// slots in bucket b are `ids[start[b]..start[b + 1]]`, and a row's buckets are contiguous, so
/// a laser's square of buckets is one slice per row (no hashing: a scan looks at ~30 buckets).
#[derive(Default)]
struct Buckets {
    side: f64,
    /// Bucket coordinates of the grid's first bucket, and the grid's size in buckets.
    x0: i64,
    y0: i64,
    w: i64,
    h: i64,
    start: Vec<u32>,
    ids: Vec<u32>,
}

impl Buckets {
    fn coord(&self, v: f64) -> i64 {
        // saturating: a NaN lands on 0, an infinity on the ends (then clamped into the grid)
        (v / self.side).floor() as i64
    }

    /// The bucket of a point inside the grid (points outside are clamped to its edge).
    fn bucket(&self, x: f64, y: f64) -> usize {
        let bx = (self.coord(x) - self.x0).clamp(0, self.w - 1);
        let by = (self.coord(y) - self.y0).clamp(0, self.h - 1);
        (by * self.w + bx) as usize
    }

    fn rebuild(&mut self, placed: &[(f64, f64, u32)]) {
        self.ids.clear();
        self.start.clear();
        if placed.is_empty() {
            (self.w, self.h) = (0, 0);
            return;
        }
        // the box of the finite centres (a body at a non-finite place, which no range test
        // accepts, is clamped to an edge bucket and cannot stretch the grid)
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &(x, y, _) in placed {
            if x.is_finite() && y.is_finite() {
                (lo[0], lo[1]) = (lo[0].min(x), lo[1].min(y));
                (hi[0], hi[1]) = (hi[0].max(x), hi[1].max(y));
            }
        }
        if lo[0] > hi[0] {
            (lo, hi) = ([0.0; 2], [0.0; 2]);
        }
        // the grid is rebuilt every tick: its size follows the number of bodies, so a few robots
        // on a large map do not pay for thousands of empty buckets
        let most = (4 * placed.len()).max(64) as f64;
        self.side = BUCKET;
        while ((hi[0] - lo[0]) / self.side + 2.0) * ((hi[1] - lo[1]) / self.side + 2.0) > most {
            self.side *= 2.0;
        }
        (self.x0, self.y0) = (self.coord(lo[0]), self.coord(lo[1]));
        self.w = self.coord(hi[0]) - self.x0 + 1;
        self.h = self.coord(hi[1]) - self.y0 + 1;
        let cells = (self.w * self.h) as usize;
        self.start.resize(cells + 1, 0);
        for &(x, y, _) in placed {
            let b = self.bucket(x, y);
            self.start[b + 1] += 1;
        }
        for b in 0..cells {
            self.start[b + 1] += self.start[b];
        }
        self.ids.resize(placed.len(), 0);
        // each bucket filled from its start in placing order, `start[b]` moving to its end...
        for &(x, y, id) in placed {
            let b = self.bucket(x, y);
            self.ids[self.start[b] as usize] = id;
            self.start[b] += 1;
        }
        // ...and back: bucket b now ends where b + 1 begins
        for b in (1..=cells).rev() {
            self.start[b] = self.start[b - 1];
        }
        self.start[0] = 0;
    }

    /// Appends the slots of the buckets that meet the square [x0, x1] × [y0, y1].
    fn extend_near(&self, x0: f64, y0: f64, x1: f64, y1: f64, out: &mut Vec<u32>) {
        if self.w == 0 {
            return;
        }
        let bx0 = (self.coord(x0) - self.x0).max(0);
        let bx1 = (self.coord(x1) - self.x0).min(self.w - 1);
        let by0 = (self.coord(y0) - self.y0).max(0);
        let by1 = (self.coord(y1) - self.y0).min(self.h - 1);
        if bx0 > bx1 || by0 > by1 {
            return;
        }
        for by in by0..=by1 {
            let row = by * self.w;
            let (a, b) = (
                self.start[(row + bx0) as usize] as usize,
                self.start[(row + bx1 + 1) as usize] as usize,
            );
            out.extend_from_slice(&self.ids[a..b]);
        }
    }
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
        // a body counts by its bounding disc: its centre may lie up to the largest radius
        // beyond the range
        let reach = range + self.largest_radius;
        self.buckets
            .extend_near(x - reach, y - reach, x + reach, y + reach, scratch);
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
    o.placed.clear();
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
        o.placed.push((p.x, p.y, idx.0));
    }
    for (idx, truth, person) in people.iter() {
        let i = n_robots + idx.0 as usize;
        let p = truth.pose;
        o.centres[i] = [p.x, p.y, person.radius];
        o.circles[i] = Some([p.x as f32, p.y as f32, person.radius as f32]);
        o.placed.push((p.x, p.y, i as u32));
    }
    o.buckets.rebuild(&o.placed);
    o.largest_radius = o
        .centres
        .iter()
        .map(|c| c[2])
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{KernelPool, Pose2, SimClock, stream_rng};
    use crate::raycast::StaticWorld;
    use crate::sensors::laser::{Laser, LaserScans, LaserSpec, LaserTruth, sample_lasers};
    use crate::world::{Cell, OccupancyGrid};

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

    /// The bodies a laser is shown are exactly those whose bounding disc comes within its
    /// range, in index order, however the bodies are spread (a crowd, a few far apart, one
    /// alone), and wherever the laser is (inside, at the edge of or far outside the crowd).
    #[test]
    fn nearby_bodies_are_those_in_range_however_spread() {
        let mut rng = stream_rng(7, "outlines", "placing");
        let mut next = || rand::RngExt::random::<f64>(&mut rng);
        for (count, spread) in [(1, 10.0), (300, 60.0), (50, 20_000.0), (200, 3.0)] {
            let mut world = World::new();
            world.init_resource::<RobotOutlines>();
            let mut centres = Vec::new();
            for i in 0..count {
                let (x, y) = ((next() - 0.5) * spread, (next() - 0.3) * spread);
                let footprint = if i % 3 == 0 {
                    Footprint::Rectangle {
                        length: 0.8,
                        width: 0.5,
                    }
                } else {
                    Footprint::Circle { radius: 0.3 }
                };
                centres.push((x, y, footprint.bounding_radius()));
                world.spawn((
                    RobotIndex(i),
                    TruePose::at(Pose2::new(x, y, next())),
                    footprint,
                ));
            }
            let mut schedule = Schedule::default();
            schedule.add_systems(update_robot_outlines);
            schedule.run(&mut world);
            let outlines = world.resource::<RobotOutlines>();
            let mut near = NearbyRobots::default();
            for q in 0..50 {
                let (x, y) = ((next() - 0.5) * spread * 1.5, (next() - 0.5) * spread * 1.5);
                let range = [9.0, 0.5, 30.0][q % 3];
                outlines.near(x, y, range, 0, &mut near);
                let want: Vec<u32> = (1..count)
                    .filter(|&i| {
                        let (cx, cy, r) = centres[i as usize];
                        (cx - x).hypot(cy - y) <= range + r
                    })
                    .collect();
                let seen = near.circles.len() + near.segments.len() / 4;
                let want_shapes: usize =
                    want.iter().map(|&i| 1 + 3 * ((i % 3 == 0) as usize)).sum();
                assert_eq!(
                    near.circles.len() + near.segments.len(),
                    want_shapes,
                    "{count} bodies over {spread} m, query {q}: {seen} seen, {want:?} in range"
                );
                let circles: Vec<[f32; 3]> = want
                    .iter()
                    .filter(|&&i| i % 3 != 0)
                    .map(|&i| {
                        let (cx, cy, _) = centres[i as usize];
                        [cx as f32, cy as f32, 0.3]
                    })
                    .collect();
                assert_eq!(near.circles, circles, "{count} over {spread} m, query {q}");
            }
        }
    }

    /// A body thrown to infinity (a numerical blow-up) is never near, and does not stretch the
    /// bucket grid so that the others are lost.
    #[test]
    fn a_body_at_infinity_hides_no_other() {
        let mut world = World::new();
        world.init_resource::<RobotOutlines>();
        for (i, x) in [(0, 0.0), (1, 3.0), (2, 250.0), (3, f64::INFINITY)] {
            world.spawn((
                RobotIndex(i),
                TruePose::at(Pose2::new(x, 1.0, 0.0)),
                Footprint::Circle { radius: 0.3 },
            ));
        }
        let mut schedule = Schedule::default();
        schedule.add_systems(update_robot_outlines);
        schedule.run(&mut world);
        let outlines = world.resource::<RobotOutlines>();
        let mut near = NearbyRobots::default();
        outlines.near(0.0, 0.0, 9.0, 0, &mut near);
        assert_eq!(near.circles, vec![[3.0, 1.0, 0.3]]);
        outlines.near(250.0, 0.0, 9.0, 0, &mut near);
        assert_eq!(near.circles, vec![[250.0, 1.0, 0.3]]);
    }
}
