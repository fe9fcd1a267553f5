//! Walking people: scripted agents that follow a route of world points at human walking speed.
//! Each is a rapier2d dynamic disc (see [`Physics::add_person`](super::physics::Physics)) whose
//! velocity is set every step, like a robot's, so robots and people physically collide and every
//! laser sees them (they are added to [`RobotOutlines`](crate::sensors::others::RobotOutlines)).
//!
//! A person is polite but simple, in the spirit of the "social force" pedestrians of Helbing &
//! Molnár (1995) reduced to three rules: walk straight towards the next route point; slow down
//! and stop when a robot or another person stands in the walking direction (so it never walks
//! into a stopped robot on purpose); meanwhile step aside, keeping to the right (to the left when
//! the right is blocked), and resume once the way is clear. A person held up for
//! [`PATIENCE`] s without getting nearer its next point turns back to the point it came from,
//! since whoever is in its way may be waiting for it in turn. People are part of the world, not
//! robots: they read ground truth (everyone's [`TruePose`]) and carry no
//! [`RobotIndex`], so robot-indexed code (collision counters,
//! summaries) never sees them.

use super::footprint::Footprint;
use super::truth::TruePose;
use crate::core::{Pose2, RobotIndex, SimClock, SimPlugin, SimRng, SimSet};
use crate::raycast::StaticWorld;
use crate::world::OccupancyGrid;
use bevy_ecs::prelude::*;
use rand::RngExt;

/// Default walking speed (m/s): a typical indoor pace (human walking is 0.8–1.5 m/s).
pub const DEFAULT_SPEED: f64 = 1.2;
/// Default body radius (m): shoulders seen from above by a laser at hip height.
pub const DEFAULT_RADIUS: f64 = 0.25;

/// Gap (surface to surface, m) ahead below which a person slows down…
pub const SLOW_GAP: f64 = 1.2;
/// …and below which it stands still until the way clears.
pub const STOP_GAP: f64 = 0.6;
/// Within this surface gap (m) a person does not move any closer to someone.
pub const PERSONAL_SPACE: f64 = 0.2;
/// Someone counts as "in the way" when their centre is within both radii plus this of the
/// walking line (m).
const LANE_MARGIN: f64 = 0.15;
/// How far to the side a person probes before stepping there (m).
const SIDE_PROBE: f64 = 0.3;
/// Sidestep speed as a fraction of the walking speed.
const SIDESTEP: f64 = 0.5;
/// A route point is reached within this distance (m).
pub const ARRIVE_TOL: f64 = 0.1;
/// A person held up by someone in its way that has not come `PROGRESS` m nearer its next
/// route point for this long (s) turns back to the point it came from: a robot may be waiting
/// for it as it waits for the robot.
pub const PATIENCE: f64 = 10.0;
const PROGRESS: f64 = 0.25;
/// Relative spread of each leg's speed (±), drawn from the person's own stream.
const SPEED_JITTER: f64 = 0.05;

/// A walking person's script (what the scenario's `[[people]]` table says).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Person {
    /// World points (m) walked in order; the person starts at the first.
    pub route: Vec<[f64; 2]>,
    /// After the last point, walk back to the first and go round again; otherwise stay there.
    pub looping: bool,
    /// Walking speed (m/s).
    pub speed: f64,
    /// Time spent standing at each route point (s).
    pub pause: f64,
    /// Simulated time at which the person starts walking (s); it stands at the first point
    /// until then.
    pub start_at: f64,
    /// Body radius (m).
    pub radius: f64,
}

impl Person {
    /// A person walking `route` with every default: looping, 1.2 m/s, no pause, from t = 0,
    /// radius 0.25 m.
    pub fn new(route: Vec<[f64; 2]>) -> Self {
        Person {
            route,
            looping: true,
            speed: DEFAULT_SPEED,
            pause: 0.0,
            start_at: 0.0,
            radius: DEFAULT_RADIUS,
        }
    }

    /// The pose at the start: on the first point, facing the second.
    pub fn start_pose(&self) -> Pose2 {
        let p = self.route.first().copied().unwrap_or([0.0, 0.0]);
        let q = self.route.get(1).copied().unwrap_or(p);
        Pose2::new(p[0], p[1], (q[1] - p[1]).atan2(q[0] - p[0]))
    }
}

/// A person's scenario name (unique among people): its Rerun path `people/<name>` and the key
/// of its random stream.
#[derive(Component, Clone, Debug, PartialEq, Eq, Hash)]
pub struct PersonId(pub String);

/// A person's spawn index: the stable order people are iterated in wherever order matters.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PersonIndex(pub u32);

/// A person's walking state.
#[derive(Component, Clone, Debug)]
pub struct Walker {
    /// Index in the route of the point walked to.
    pub next: usize,
    /// Standing at a route point until this time (s).
    pub wait_until: f64,
    /// Speed of the current leg (m/s): the person's speed with a small per-leg variation.
    pub leg_speed: f64,
    /// World-frame velocity for this step (m/s), applied by the physics step.
    pub velocity: [f64; 2],
    /// Facing direction (rad): the walking direction, kept while standing.
    pub heading: f64,
    /// Route points reached so far.
    pub reached: u32,
    /// A non-looping route is done: the person stays at its last point.
    pub finished: bool,
    /// The nearest the person has come to its next route point on this leg (m), and when.
    pub nearest: (f64, f64),
    rng: SimRng,
}

impl Walker {
    /// The walking state at the start; `rng` is the person's own stream (`walk`).
    pub fn new(person: &Person, mut rng: SimRng) -> Self {
        let leg_speed = leg_speed(person.speed, &mut rng);
        Walker {
            next: 1.min(person.route.len().saturating_sub(1)),
            wait_until: person.start_at,
            leg_speed,
            velocity: [0.0, 0.0],
            heading: person.start_pose().theta,
            reached: 0,
            finished: person.route.len() < 2,
            nearest: (f64::INFINITY, 0.0),
            rng,
        }
    }
}

fn leg_speed(speed: f64, rng: &mut SimRng) -> f64 {
    let u: f64 = rng.random();
    speed * (1.0 + SPEED_JITTER * (2.0 * u - 1.0))
}

/// Someone a person may meet: centre and radius (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agent {
    pub x: f64,
    pub y: f64,
    pub radius: f64,
}

/// The nearest surface gap (m) to an agent in the way along unit direction `d` from `p`
/// (radius `r`), if any.
fn gap_ahead(p: [f64; 2], r: f64, d: [f64; 2], others: &[Agent]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for o in others {
        let (rx, ry) = (o.x - p[0], o.y - p[1]);
        let along = rx * d[0] + ry * d[1];
        let lateral = (rx * d[1] - ry * d[0]).abs();
        if along <= 0.0 || lateral >= r + o.radius + LANE_MARGIN {
            continue;
        }
        let gap = (rx.hypot(ry) - r - o.radius).max(0.0);
        best = Some(best.map_or(gap, |b: f64| b.min(gap)));
    }
    best
}

/// True when a person of radius `r` at `q` overlaps neither the static map nor anyone.
fn spot_is_free(q: [f64; 2], r: f64, others: &[Agent], grid: &OccupancyGrid) -> bool {
    grid.disc_is_clear(q[0], q[1], r)
        && others
            .iter()
            .all(|o| (o.x - q[0]).hypot(o.y - q[1]) >= r + o.radius + 0.05)
}

/// One control step of one person at `p` at time `now`: advances its route and sets
/// `walker.velocity` (and heading). `others` are everyone else (robots and people).
pub fn plan_walk(
    person: &Person,
    walker: &mut Walker,
    p: [f64; 2],
    now: f64,
    dt: f64,
    others: &[Agent],
    grid: &OccupancyGrid,
) {
    walker.velocity = [0.0, 0.0];
    let n = person.route.len();
    if walker.finished || n < 2 || now + 1e-9 < walker.wait_until {
        return;
    }
    let r = person.radius;
    let mut target = person.route[walker.next];
    let (mut dx, mut dy) = (target[0] - p[0], target[1] - p[1]);
    let mut dist = dx.hypot(dy);
    // a point someone else stands on counts as reached once the person is close to it, rather
    // than circling it forever
    let taken = dist < SLOW_GAP + 2.0 * r
        && others
            .iter()
            .any(|o| (o.x - target[0]).hypot(o.y - target[1]) < r + o.radius + LANE_MARGIN);
    if dist <= ARRIVE_TOL || taken {
        walker.reached += 1;
        walker.nearest = (f64::INFINITY, now);
        walker.leg_speed = leg_speed(person.speed, &mut walker.rng);
        if walker.next + 1 < n {
            walker.next += 1;
        } else if person.looping {
            walker.next = 0;
        } else {
            walker.finished = true;
            return;
        }
        if person.pause > 0.0 {
            walker.wait_until = now + person.pause;
            return;
        }
        target = person.route[walker.next];
        (dx, dy) = (target[0] - p[0], target[1] - p[1]);
        dist = dx.hypot(dy);
        if dist < 1e-9 {
            return;
        }
    }
    let d = [dx / dist, dy / dist];
    walker.heading = dy.atan2(dx);
    // land on the point rather than overshoot it
    let speed = walker.leg_speed.min(dist / dt);
    if dist < walker.nearest.0 - PROGRESS {
        walker.nearest = (dist, now);
    }
    let Some(gap) = gap_ahead(p, r, d, others).filter(|g| *g < SLOW_GAP) else {
        walker.velocity = keep_clear(p, r, [d[0] * speed, d[1] * speed], others);
        return;
    };
    // someone is in the way: slow down (to a stop at STOP_GAP) and step aside meanwhile
    let f = ((gap - STOP_GAP) / (SLOW_GAP - STOP_GAP)).clamp(0.0, 1.0);
    if now - walker.nearest.1 >= PATIENCE {
        // held up too long: the one in the way may be waiting for us (a robot at a door we
        // stepped into, or two robots we cannot pass between): walk back the way we came
        let back = if walker.next > 0 {
            Some(walker.next - 1)
        } else {
            person.looping.then_some(n - 1)
        };
        if let Some(back) = back {
            walker.next = back;
            walker.nearest = (f64::INFINITY, now);
            walker.leg_speed = leg_speed(person.speed, &mut walker.rng);
            return;
        }
    }
    let right = [d[1], -d[0]];
    let left = [-d[1], d[0]];
    let side = [right, left].into_iter().find(|s| {
        let q = [p[0] + s[0] * SIDE_PROBE, p[1] + s[1] * SIDE_PROBE];
        spot_is_free(q, r, others, grid)
    });
    let side_speed = SIDESTEP * walker.leg_speed;
    let (sx, sy) = side.map_or((0.0, 0.0), |s| (s[0] * side_speed, s[1] * side_speed));
    walker.velocity = keep_clear(p, r, [d[0] * speed * f + sx, d[1] * speed * f + sy], others);
}

/// `v` without the part that would take a person at `p` (radius `r`) closer to anyone already
/// within [`PERSONAL_SPACE`] of it: nobody walks into someone beside them, whatever their route
/// says (the repulsive term of the social force model, reduced to a hard constraint).
fn keep_clear(p: [f64; 2], r: f64, mut v: [f64; 2], others: &[Agent]) -> [f64; 2] {
    for o in others {
        let (rx, ry) = (o.x - p[0], o.y - p[1]);
        let d = rx.hypot(ry);
        if d < 1e-9 || d - r - o.radius >= PERSONAL_SPACE {
            continue;
        }
        let u = [rx / d, ry / d];
        let towards = v[0] * u[0] + v[1] * u[1];
        if towards > 0.0 {
            v = [v[0] - towards * u[0], v[1] - towards * u[1]];
        }
    }
    v
}

/// Control: every person plans this step's velocity from last step's ground truth.
#[allow(clippy::type_complexity)]
pub fn walk_people(
    clock: Res<SimClock>,
    world: Res<StaticWorld>,
    robots: Query<(&TruePose, &Footprint), With<RobotIndex>>,
    mut people: Query<(&PersonIndex, &Person, &TruePose, &mut Walker)>,
) {
    let mut agents: Vec<(Option<u32>, Agent)> = robots
        .iter()
        .map(|(t, f)| {
            let a = Agent {
                x: t.pose.x,
                y: t.pose.y,
                radius: f.bounding_radius(),
            };
            (None, a)
        })
        .collect();
    agents.extend(people.iter().map(|(i, p, t, _)| {
        let a = Agent {
            x: t.pose.x,
            y: t.pose.y,
            radius: p.radius,
        };
        (Some(i.0), a)
    }));
    let grid = world.grid();
    let mut others = Vec::with_capacity(agents.len());
    for (idx, person, truth, mut walker) in people.iter_mut() {
        others.clear();
        others.extend(
            agents
                .iter()
                .filter(|(i, _)| *i != Some(idx.0))
                .map(|(_, a)| *a),
        );
        let p = [truth.pose.x, truth.pose.y];
        plan_walk(
            person,
            &mut walker,
            p,
            clock.start(),
            clock.dt,
            &others,
            grid,
        );
    }
}

pub struct PeoplePlugin;

impl SimPlugin for PeoplePlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        if crate::core::any_with::<Walker>(world) {
            schedule.add_systems(walk_people.in_set(SimSet::Control));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::world::Cell;

    fn open_floor() -> OccupancyGrid {
        OccupancyGrid::new(200, 200, 0.1, [-10.0, -10.0], Cell::Free)
    }

    /// Integrates `plan_walk` without physics (kinematic point) for `ticks` steps.
    fn walk(
        person: &Person,
        others: &[Agent],
        grid: &OccupancyGrid,
        ticks: usize,
    ) -> Vec<[f64; 2]> {
        let mut w = Walker::new(person, stream_rng(1, "p", "walk"));
        let mut p = person.route[0];
        let dt = 0.05;
        let mut out = vec![p];
        for k in 0..ticks {
            plan_walk(person, &mut w, p, k as f64 * dt, dt, others, grid);
            p = [p[0] + w.velocity[0] * dt, p[1] + w.velocity[1] * dt];
            out.push(p);
        }
        out
    }

    #[test]
    fn walks_its_route_at_its_speed_and_loops() {
        let person = Person::new(vec![[0.0, 0.0], [6.0, 0.0], [6.0, 3.0]]);
        let grid = open_floor();
        // 6 m at 1.2 m/s (±5 %) takes 5 s = 100 ticks
        let path = walk(&person, &[], &grid, 100);
        let p = path[95];
        assert!(p[0] > 5.2 && p[0] < 6.0 && p[1].abs() < 1e-9, "{p:?}");
        // the loop: 6 + 3 + 6.7 m ≈ 13 s, then it is back on the first leg
        let path = walk(&person, &[], &grid, 300);
        let last = path[300];
        assert!(last[1].abs() < ARRIVE_TOL && last[0] > 0.5, "{last:?}");
    }

    #[test]
    fn never_walks_into_someone_beside_it() {
        // a robot just beside the route (surface gap 0.1 m): the person may pass it but never
        // closes the gap, while walking on at full speed along the route
        let person = Person {
            looping: false,
            ..Person::new(vec![[-3.0, 0.0], [3.0, 0.0]])
        };
        let me = [0.0, 0.0];
        let robot = Agent {
            x: 0.1,
            y: 0.65,
            radius: 0.3,
        };
        // heading straight at it: nothing of the velocity is left towards it
        let v = keep_clear(me, 0.25, [0.3, 1.0], &[robot]);
        let towards = v[0] * 0.1 + v[1] * 0.65;
        assert!(towards.abs() < 1e-9, "{v:?}");
        // heading away or past it: untouched
        assert_eq!(keep_clear(me, 0.25, [0.0, -1.0], &[robot]), [0.0, -1.0]);
        let beside = Agent { x: 0.0, ..robot };
        assert_eq!(keep_clear(me, 0.25, [1.2, 0.0], &[beside]), [1.2, 0.0]);
        // over a whole walk past it: no contact, and the person gets by
        let path = walk(&person, &[robot], &open_floor(), 200);
        let min_gap = path
            .iter()
            .map(|q| (robot.x - q[0]).hypot(robot.y - q[1]) - 0.55)
            .fold(f64::INFINITY, f64::min);
        assert!(min_gap > 0.05, "{min_gap}");
        assert!(path[200][0] > 2.0, "{:?}", path[200]);
    }

    #[test]
    fn stops_before_someone_in_a_narrow_way_then_turns_back() {
        // a 1 m corridor along x: no room to step aside
        let mut grid = open_floor();
        for col in 0..200 {
            for row in 0..200 {
                let y = -10.0 + (row as f64 + 0.5) * 0.1;
                if y.abs() > 0.5 {
                    grid.set(col, row, Cell::Occupied);
                }
            }
        }
        let person = Person::new(vec![[-5.0, 0.0], [5.0, 0.0]]);
        let robot = Agent {
            x: 0.0,
            y: 0.0,
            radius: 0.3,
        };
        let path = walk(&person, &[robot], &grid, 600);
        // 4.45 m to the stop at about 1.2 m/s, slowing down over the last 0.6 m: standing by
        // 6 s, and still standing at 12 s
        let stand = path[120];
        let gap = (stand[0] - robot.x).hypot(stand[1] - robot.y) - 0.3 - person.radius;
        assert!(gap > STOP_GAP - 0.05 && gap < STOP_GAP + 0.1, "gap {gap}");
        assert!((path[240][0] - stand[0]).abs() < 1e-3, "stood still");
        // held up without progress for PATIENCE s: it walks back to where it came from, and
        // then tries again
        let back = 120
            + path[120..]
                .iter()
                .position(|p| p[0] < stand[0] - 1.0)
                .expect("turned back");
        let t = back as f64 * 0.05;
        assert!(t > PATIENCE && t < PATIENCE + 6.0, "turned back at {t} s");
        assert!(path[600][0] < stand[0], "{:?}", path[600]);
    }

    #[test]
    fn steps_aside_in_the_open_and_passes() {
        let mut person = Person::new(vec![[-5.0, 0.0], [5.0, 0.0]]);
        person.looping = false;
        let robot = Agent {
            x: 0.0,
            y: 0.0,
            radius: 0.3,
        };
        let path = walk(&person, &[robot], &open_floor(), 300);
        let min_gap = path
            .iter()
            .map(|p| (p[0] - robot.x).hypot(p[1] - robot.y) - 0.3 - person.radius)
            .fold(f64::INFINITY, f64::min);
        assert!(min_gap > 0.1, "{min_gap}");
        let end = path[300];
        assert!((end[0] - 5.0).abs() < 0.2, "passed on the right: {end:?}");
        // kept to the right (negative y when walking along +x)
        let y_at_robot = path
            .iter()
            .find(|p| p[0] > 0.0)
            .map(|p| p[1])
            .unwrap_or(0.0);
        assert!(y_at_robot < -0.5, "{y_at_robot}");
    }

    #[test]
    fn waits_at_points_and_starts_late() {
        let mut person = Person::new(vec![[0.0, 0.0], [1.2, 0.0]]);
        person.looping = false;
        person.start_at = 1.0;
        person.pause = 2.0;
        let path = walk(&person, &[], &open_floor(), 100);
        assert_eq!(path[20], [0.0, 0.0], "stands until start_at");
        let end = path[100];
        assert!(
            (end[0] - 1.2).abs() < ARRIVE_TOL,
            "at its last point: {end:?}"
        );
        assert_eq!(path[99], end, "and stays there");
        // 1.2 m at 1.2 m/s from t = 1 s: arrived by 2.1 s; the pause is not spent at the last
        // point of a route that does not loop, and the first point does not pause it either
        assert!((path[42][0] - 1.2).abs() < ARRIVE_TOL, "{:?}", path[42]);
        let mut looping = person.clone();
        looping.looping = true;
        let path = walk(&looping, &[], &open_floor(), 100);
        // at the second point by ~2.0 s, standing there for 2 s, then walking back
        assert!(
            (path[70][0] - 1.2).abs() < ARRIVE_TOL,
            "pausing: {:?}",
            path[70]
        );
        assert!(path[95][0] < 0.6, "walking back: {:?}", path[95]);
    }
}
