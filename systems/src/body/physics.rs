//! The rapier2d bridge. Robots are dynamic bodies whose velocity is set every step so that,
//! without contacts, they land exactly on the closed-form arc of their drive twist; rapier resolves
//! robot–wall and robot–robot contacts (with CCD, so a fast robot cannot tunnel through a thin
//! wall). Static geometry is one standalone collider per rectangle of a greedy decomposition of
//! each 64-cell tile, so an edit rebuilds only its tile.
//!
//! Collisions are counted as contact STARTS: a robot that touches the wall and slides along it
//! (across several tile colliders) counts once, until it is free of every wall again.
//!
//! Walking people ([`super::people`]) are dynamic discs driven the same way, by the velocity
//! their walker planned; a robot touching a person counts a person collision, while people
//! touching walls or each other count nothing (they are not robots).

use super::footprint::Footprint;
use super::kinematics::{DriveCommand, DriveState, Kinematics, integrate_arc};
use super::people::Walker;
use super::truth::{TruePose, TrueTwist};
use crate::core::{
    JobMemory, KernelPool, Pose2, RobotIndex, SimClock, SimPlugin, SimSet, wrap_angle,
};
use crate::raycast::static_world::{COLLIDER_TILE, StaticWorld};
use crate::world::rects::tile_rects;
use bevy_ecs::prelude::*;
use rapier2d::prelude::*;
use std::sync::Mutex;

#[derive(Component, Clone, Copy, Debug)]
pub struct PhysicsBody(pub RigidBodyHandle);

/// Contact starts of one robot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Collisions {
    pub wall: u32,
    pub robot: u32,
    /// With walking people.
    pub person: u32,
}

impl Collisions {
    pub fn total(&self) -> u32 {
        self.wall + self.robot + self.person
    }
}

#[derive(Default)]
struct EventBuffer(Mutex<Vec<CollisionEvent>>);

impl EventHandler for EventBuffer {
    fn handle_collision_event(
        &self,
        _bodies: &RigidBodySet,
        _colliders: &ColliderSet,
        event: CollisionEvent,
        _contact_pair: Option<&ContactPair>,
    ) {
        if let Ok(mut v) = self.0.lock() {
            v.push(event);
        }
    }

    fn handle_contact_force_event(
        &self,
        _dt: Real,
        _bodies: &RigidBodySet,
        _colliders: &ColliderSet,
        _contact_pair: &ContactPair,
        _total_force_magnitude: Real,
    ) {
    }

    fn handle_soft_body_tear_event(&self, _soft_bodies: &SoftBodySet, _event: &SoftBodyTearEvent) {}
}

/// Robots' colliders carry `robot index + 1` as user data; static colliders carry 0; people
/// carry `PERSON_TAG | person index` (robot indices are u32, so the tag never clashes).
const STATIC_USER_DATA: u128 = 0;
const PERSON_TAG: u128 = 1 << 64;

/// Who a collider belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Owner {
    Static,
    Robot(u32),
    Person,
}

/// Mass of a person (kg): what a robot pushing into one feels.
const PERSON_MASS: f64 = 70.0;

#[derive(Resource)]
pub struct Physics {
    pub world: PhysicsWorld,
    tile_colliders: Vec<Vec<ColliderHandle>>,
    tiles_x: usize,
    events: EventBuffer,
    wall_touching: Vec<u32>,
    collisions: Vec<Collisions>,
}

impl Physics {
    /// A physics world with the static colliders of `world` and timestep `dt`.
    pub fn new(world: &mut StaticWorld, dt: f64) -> Self {
        let mut pw = PhysicsWorld::new();
        pw.gravity = Vector::ZERO;
        pw.integration_parameters.dt = dt as Real;
        // a leaf's fat-AABB skin proportional to the body (6 cm for a 0.5 m robot instead of
        // 4 cm): a robot at 0.8 m/s moves 4 cm per 50 ms step, so with the fixed skin its leaf
        // was re-inserted into the broad phase's tree almost every step (about 10 % less
        // physics time with 1000 robots; the same contacts)
        pw.broad_phase.adaptive_change_detection_margin = true;
        widen_broad_phase_skin(&mut pw.integration_parameters);
        let (tx, ty) = world.tile_counts();
        let mut physics = Physics {
            world: pw,
            tile_colliders: vec![Vec::new(); tx * ty],
            tiles_x: tx,
            events: EventBuffer::default(),
            wall_touching: Vec::new(),
            collisions: Vec::new(),
        };
        world.take_dirty_tiles();
        for y in 0..ty {
            for x in 0..tx {
                physics.rebuild_tile(world, x, y);
            }
        }
        physics
    }

    /// Builds the broad phase over every collider (the map's, the robots', the people's) and
    /// finds the first contacts, which the first step would otherwise do inside the run (about
    /// 11 ms for the hospital tiled 4 × 4). Contacts found here count as the first step's would.
    pub fn prepare(&mut self) {
        let events = std::mem::take(&mut self.events);
        self.world.detect_collisions(&(), &events);
        self.events = events;
        self.count_events();
    }

    /// Number of static colliders.
    pub fn static_collider_count(&self) -> usize {
        self.tile_colliders.iter().map(Vec::len).sum()
    }

    fn rebuild_tile(&mut self, world: &StaticWorld, tx: usize, ty: usize) {
        let slot = ty * self.tiles_x + tx;
        for h in std::mem::take(&mut self.tile_colliders[slot]) {
            self.world.remove_collider(h);
        }
        let grid = world.grid();
        for rect in tile_rects(grid, tx, ty, COLLIDER_TILE) {
            let (c, h) = rect.world_box(grid);
            let collider = ColliderBuilder::cuboid(h[0] as Real, h[1] as Real)
                .translation(Vector::new(c[0] as Real, c[1] as Real))
                .friction(0.0)
                .user_data(STATIC_USER_DATA)
                .build();
            let handle = self.world.insert_collider(collider, None);
            self.tile_colliders[slot].push(handle);
        }
    }

    /// Adds robot number `index` (spawn order, dense from 0) as a dynamic body.
    pub fn add_robot(&mut self, index: u32, pose: &Pose2, footprint: &Footprint) -> PhysicsBody {
        let body = RigidBodyBuilder::dynamic()
            .pose(Pose2d::new(
                Vector::new(pose.x as Real, pose.y as Real),
                pose.theta as Real,
            ))
            .ccd_enabled(true)
            .can_sleep(false)
            .build();
        let shape = match footprint {
            Footprint::Circle { radius } => ColliderBuilder::ball(*radius as Real),
            Footprint::Rectangle { length, width } => {
                ColliderBuilder::cuboid((*length / 2.0) as Real, (*width / 2.0) as Real)
            }
        };
        let collider = shape
            .density(200.0)
            .friction(0.0)
            .active_events(ActiveEvents::COLLISION_EVENTS)
            .user_data(index as u128 + 1)
            .build();
        let (handle, _) = self.world.insert(body, collider);
        let n = index as usize + 1;
        if self.collisions.len() < n {
            self.collisions.resize(n, Collisions::default());
            self.wall_touching.resize(n, 0);
        }
        PhysicsBody(handle)
    }

    /// Adds person number `index` (spawn order) as a dynamic disc of `radius` at (x, y). Its
    /// rotation is locked: a person's heading is where it walks, not how contacts spin it.
    pub fn add_person(&mut self, index: u32, x: f64, y: f64, radius: f64) -> PhysicsBody {
        let body = RigidBodyBuilder::dynamic()
            .translation(Vector::new(x as Real, y as Real))
            .lock_rotations()
            .ccd_enabled(true)
            .can_sleep(false)
            .build();
        let area = std::f64::consts::PI * radius * radius;
        let collider = ColliderBuilder::ball(radius as Real)
            .density((PERSON_MASS / area.max(1e-6)) as Real)
            .friction(0.0)
            .user_data(PERSON_TAG | index as u128)
            .build();
        let (handle, _) = self.world.insert(body, collider);
        PhysicsBody(handle)
    }

    /// Moves a body instantly (kidnapping), stopping it.
    pub fn teleport(&mut self, body: PhysicsBody, pose: &Pose2) {
        if let Some(b) = self.world.bodies.get_mut(body.0) {
            b.set_position(
                Pose2d::new(
                    Vector::new(pose.x as Real, pose.y as Real),
                    pose.theta as Real,
                ),
                true,
            );
            b.set_linvel(Vector::ZERO, true);
            b.set_angvel(0.0, true);
        }
    }

    pub fn collisions(&self, index: u32) -> Collisions {
        self.collisions
            .get(index as usize)
            .copied()
            .unwrap_or_default()
    }

    fn owner(&self, h: ColliderHandle) -> Owner {
        match self.world.colliders.get(h).map(|c| c.user_data) {
            None | Some(STATIC_USER_DATA) => Owner::Static,
            Some(d) if d & PERSON_TAG != 0 => Owner::Person,
            Some(d) => Owner::Robot((d - 1) as u32),
        }
    }

    /// Turns this step's collision events into contact-start counts.
    fn count_events(&mut self) {
        let events = match self.events.0.lock() {
            Ok(mut v) => std::mem::take(&mut *v),
            Err(_) => return,
        };
        for e in events {
            let (h1, h2, started) = match e {
                CollisionEvent::Started(a, b, _) => (a, b, true),
                CollisionEvent::Stopped(a, b, _) => (a, b, false),
            };
            match (self.owner(h1), self.owner(h2)) {
                (Owner::Robot(a), Owner::Robot(b)) if started => {
                    self.collisions[a as usize].robot += 1;
                    self.collisions[b as usize].robot += 1;
                }
                (Owner::Robot(r), Owner::Person) | (Owner::Person, Owner::Robot(r)) if started => {
                    self.collisions[r as usize].person += 1;
                }
                (Owner::Robot(r), Owner::Static) | (Owner::Static, Owner::Robot(r)) => {
                    let t = &mut self.wall_touching[r as usize];
                    if started {
                        if *t == 0 {
                            self.collisions[r as usize].wall += 1;
                        }
                        *t += 1;
                    } else {
                        *t = t.saturating_sub(1);
                    }
                }
                // contact ends between bodies, people against walls or people: nothing to count
                _ => {}
            }
        }
    }
}

/// How many times rapier's length unit (1 m) the broad phase's fat-AABB skin is scaled by.
/// Measured with 1000 robots (180 beams, hospital 4 × 4): 4 took the physics step from about
/// 1.6 to 1.4 ms; 8 and 16 were slower again (fatter static boxes pair with more robots).
const SKIN_SCALE: Real = 4.0;

/// Scales rapier's length unit by [`SKIN_SCALE`] and every length it multiplies back down, so
/// the solver's tolerances, prediction distance and velocity caps stay what they were, to the
/// bit (a power of two divides and multiplies exactly), while the broad phase's change-detection
/// skin, which has no setting of its own, grows: a 0.5 m robot's leaf gets 16 cm instead of
/// 6 cm, so at 0.8 m/s it leaves its fat box and is re-inserted into the broad phase's tree
/// every fourth step instead of almost every step. Bodies never sleep here, so the length
/// unit's one other use (sleep thresholds) does not matter.
fn widen_broad_phase_skin(p: &mut IntegrationParameters) {
    p.length_unit *= SKIN_SCALE;
    p.normalized_allowed_linear_error /= SKIN_SCALE;
    p.normalized_max_corrective_velocity /= SKIN_SCALE;
    p.normalized_prediction_distance /= SKIN_SCALE;
    p.normalized_max_linear_velocity /= SKIN_SCALE;
    p.normalized_contact_recycle_distance /= SKIN_SCALE;
}

/// Robots from which the per-robot arithmetic around rapier's step runs on the kernel pool: a
/// fraction of a microsecond per robot, so fewer do not pay for the hand-over.
const PARALLEL_ROBOTS: usize = 256;

/// rapier's 2-D pose type.
type Pose2d = rapier2d::math::Pose;

/// Physics: drive every robot along its commanded arc and every person at its planned velocity,
/// resolve contacts, read back ground truth. The per-robot arithmetic before and after the
/// (serial) rapier step runs on the kernel pool: only the hand-over of velocities to rapier is
/// serial. Each robot's values come from its own state only, so threads do not change results.
#[allow(clippy::type_complexity)]
pub fn physics_step(
    mut physics: ResMut<Physics>,
    mut world: ResMut<StaticWorld>,
    clock: Res<SimClock>,
    pool: Res<KernelPool>,
    mut memory: Local<JobMemory>,
    mut robots: Query<(
        &PhysicsBody,
        &Kinematics,
        &DriveCommand,
        &mut DriveState,
        &mut TruePose,
        &mut TrueTwist,
    )>,
    mut people: Query<(&PhysicsBody, &Walker, &mut TruePose), Without<Kinematics>>,
) {
    let dt = clock.dt;
    if dt.is_nan() || dt <= 0.0 {
        // a step of no length moves nothing (and the velocities below divide by it)
        return;
    }
    let dirty = world.take_dirty_tiles();
    for (tx, ty) in dirty {
        physics.rebuild_tile(&world, tx, ty);
    }
    let mut jobs = memory.take();
    jobs.extend(
        robots
            .iter_mut()
            .map(|(body, kin, cmd, state, truth, twist)| {
                (*body, kin, cmd, state, truth, twist, None)
            }),
    );
    {
        let bodies = &physics.world.bodies;
        pool.for_each_from(
            PARALLEL_ROBOTS,
            &mut jobs,
            |(body, kin, cmd, state, truth, _, vel)| {
                let (v, w) = kin.step(cmd, state, dt);
                let current = match bodies.get(body.0) {
                    Some(b) => {
                        let t = b.translation();
                        Pose2::new(t.x as f64, t.y as f64, b.rotation().angle() as f64)
                    }
                    None => truth.pose,
                };
                truth.prev = current;
                let target = integrate_arc(&current, v, w, dt);
                *vel = Some((
                    Vector::new(
                        ((target.x - current.x) / dt) as Real,
                        ((target.y - current.y) / dt) as Real,
                    ),
                    w as Real,
                ));
            },
        );
    }
    for (body, .., vel) in &jobs {
        if let (Some(b), Some((linvel, angvel))) = (physics.world.bodies.get_mut(body.0), vel) {
            b.set_linvel(*linvel, true);
            b.set_angvel(*angvel, true);
        }
    }
    for (body, walker, mut truth) in people.iter_mut() {
        if let Some(b) = physics.world.bodies.get_mut(body.0) {
            let t = b.translation();
            truth.prev = Pose2::new(t.x as f64, t.y as f64, truth.pose.theta);
            let v = walker.velocity;
            b.set_linvel(Vector::new(v[0] as Real, v[1] as Real), true);
        }
    }
    let events = std::mem::take(&mut physics.events);
    physics.world.step_with_events(&(), &events);
    physics.events = events;
    physics.count_events();
    for (body, walker, mut truth) in people.iter_mut() {
        if let Some(b) = physics.world.bodies.get(body.0) {
            let t = b.translation();
            truth.pose = Pose2::new(t.x as f64, t.y as f64, walker.heading);
        }
    }
    let bodies = &physics.world.bodies;
    pool.for_each_from(
        PARALLEL_ROBOTS,
        &mut jobs,
        |(body, _, _, _, truth, twist, _)| {
            if let Some(b) = bodies.get(body.0) {
                let t = b.translation();
                let pose = Pose2::new(t.x as f64, t.y as f64, b.rotation().angle() as f64);
                let d = truth.prev.between(&pose);
                twist.v = d.x / dt;
                twist.w = wrap_angle(pose.theta - truth.prev.theta) / dt;
                truth.pose = pose;
            }
        },
    );
    memory.keep(jobs);
}

pub struct PhysicsPlugin;

impl SimPlugin for PhysicsPlugin {
    fn build(&self, _world: &mut World, schedule: &mut Schedule) {
        schedule.add_systems(physics_step.in_set(SimSet::Physics));
    }
}

/// A robot's index, for looking up its collision counters.
pub fn collisions_of(physics: &Physics, index: &RobotIndex) -> Collisions {
    physics.collisions(index.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A room of 10 × 10 m walls with a robot starting against the east wall and one in the
    /// middle, both driven east for three seconds; each body's path and the collision counts.
    fn drive_east(prepared: bool) -> (Vec<[u32; 3]>, Vec<Collisions>) {
        use crate::world::{Cell, OccupancyGrid};
        let mut grid = OccupancyGrid::new(100, 100, 0.1, [0.0, 0.0], Cell::Free);
        for i in 0..100 {
            for (c, r) in [(i, 0), (i, 99), (0, i), (99, i)] {
                grid.set(c, r, Cell::Occupied);
            }
        }
        let mut ground = StaticWorld::new(grid);
        let mut physics = Physics::new(&mut ground, 0.05);
        let circle = Footprint::Circle { radius: 0.25 };
        // the wall's face is at x = 9.9: the first robot overlaps it by a centimetre
        let bodies = [
            physics.add_robot(0, &Pose2::new(9.66, 5.0, 0.0), &circle),
            physics.add_robot(1, &Pose2::new(6.0, 3.0, 0.3), &circle),
        ];
        if prepared {
            physics.prepare();
        }
        let mut path = Vec::new();
        for _ in 0..60 {
            for b in &bodies {
                let body = physics.world.bodies.get_mut(b.0).unwrap();
                body.set_linvel(Vector::new(2.0, 0.1), true);
                body.set_angvel(0.2, true);
            }
            let events = std::mem::take(&mut physics.events);
            physics.world.step_with_events(&(), &events);
            physics.events = events;
            physics.count_events();
            for b in &bodies {
                let body = &physics.world.bodies[b.0];
                let t = body.translation();
                path.push([
                    t.x.to_bits(),
                    t.y.to_bits(),
                    body.rotation().angle().to_bits(),
                ]);
            }
        }
        (path, vec![physics.collisions(0), physics.collisions(1)])
    }

    /// Building the broad phase and the first contacts before the first step changes nothing
    /// that follows, to the bit, contacts at the start included.
    #[test]
    fn a_prepared_world_steps_exactly_as_an_unprepared_one() {
        let (plain, plain_hits) = drive_east(false);
        let (prepared, prepared_hits) = drive_east(true);
        assert_eq!(plain_hits, prepared_hits);
        // both robots reached the east wall
        assert_eq!(plain_hits[0].wall, 1, "{plain_hits:?}");
        assert_eq!(plain_hits[1].wall, 1, "{plain_hits:?}");
        assert_eq!(plain, prepared);
    }

    /// Widening the skin leaves every length the solver derives from the length unit as it was,
    /// to the bit (so contacts, tolerances and velocity caps do not change with it).
    #[test]
    fn a_wider_skin_leaves_the_solver_lengths_exact() {
        let default = IntegrationParameters::default();
        let mut widened = default;
        widen_broad_phase_skin(&mut widened);
        assert_eq!(widened.length_unit, default.length_unit * SKIN_SCALE);
        let lengths = |p: &IntegrationParameters| {
            [
                p.allowed_linear_error(),
                p.max_corrective_velocity(),
                p.prediction_distance(),
                p.max_linear_velocity(),
                p.contact_recycle_distance(),
            ]
            .map(f32::to_bits)
        };
        assert_eq!(lengths(&widened), lengths(&default));
    }
}
