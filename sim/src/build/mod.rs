//! World building: a validated scenario becomes an ECS world (resources, one entity per robot and
//! one per walking person) and the tick schedule composed from the feature plugins of `systems`.

pub mod outdoor;
pub mod script;

use crate::build::script::{EventQueue, ScriptPlugin};
use crate::scenario::{LocalizerKind, PersonConfig, RobotConfig, Scenario};
use bevy_ecs::prelude::*;
use std::time::{Duration, Instant};
use systems::body::{
    Kinematics, PeoplePlugin, PersonId, PersonIndex, Physics, PhysicsPlugin, TruePose, Walker,
};
use systems::core::{KernelPool, MapCache, SimClock, SimPlugin, SimRng, new_schedule, stream_rng};
use systems::eval::{EvalPlugin, LocalizationSamples, NavOutcome};
use systems::localization::de_filter::DeFilter;
use systems::localization::de_mc::DeMc;
use systems::localization::de_odometry::DeOdometry;
use systems::localization::{
    Filter, LocalizationMap, LocalizationPlugin, Localizer, Localizers, MarkovGrid, Mcl, NavSource,
    OdometryModel, ScanEstimator, WheelOdometry,
};
use systems::mapping::{GraphSlam, MappingPlugin, RbpfSlam, ScanToMapSlam};
use systems::navigation::{Behaviour, NavCostmaps, NavigationPlugin, Navigator};
use systems::raycast::{Door, Doors, StaticWorld};
use systems::robot::RobotBundle;
use systems::sensors::{
    Encoder, EncoderReadings, Laser, LaserScans, LaserTruth, SensorsPlugin, SonarReadings,
    SonarTruth, Sonars,
};

/// A world ready to step.
pub struct SimWorld {
    pub world: World,
    pub schedule: Schedule,
    /// Robot entities in spawn (index) order.
    pub robots: Vec<Entity>,
    /// Walking people in spawn (index) order.
    pub people: Vec<Entity>,
    /// What the world was built for: which plugins compose its schedule.
    mode: BuildMode,
}

impl SimWorld {
    /// One tick.
    pub fn step(&mut self) {
        self.schedule.run(&mut self.world);
        self.world.resource_mut::<SimClock>().advance();
    }

    pub fn time(&self) -> f64 {
        self.world.resource::<SimClock>().start()
    }

    /// Composes the schedule again from the plugins, after parts were added to or removed from
    /// the world (a program's estimators or controllers, a replay's odometry): each plugin adds
    /// only the systems that have something to work on. Systems added to the old schedule are
    /// dropped, so this comes before any such addition.
    pub fn compose_schedule(&mut self) {
        self.schedule = compose_schedule(&mut self.world, self.mode);
    }
}

/// The tick schedule for `world`, from the plugins of `mode`.
fn compose_schedule(world: &mut World, mode: BuildMode) -> Schedule {
    let mut schedule = new_schedule();
    let plugins: &[&dyn SimPlugin] = match mode {
        BuildMode::Live => &[
            &ScriptPlugin,
            &NavigationPlugin,
            &PeoplePlugin,
            &PhysicsPlugin,
            &SensorsPlugin,
            &LocalizationPlugin,
            &MappingPlugin,
            &EvalPlugin,
        ],
        BuildMode::Replay => &[
            &ScriptPlugin,
            &LocalizationPlugin,
            &MappingPlugin,
            &EvalPlugin,
        ],
    };
    for p in plugins {
        p.build(world, &mut schedule);
    }
    schedule
}

/// What the world is built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildMode {
    /// A simulation: every plugin.
    Live,
    /// Estimators fed with recorded readings ([`crate::replay`]): the robots with their
    /// sensors' descriptions, odometry, localizers and SLAM systems, the script and the
    /// evaluation; no navigation, people, physics steps, sensor sampling or outdoor parts.
    Replay,
}

/// What a world built from the same scenario hands on to the next one (a restart with another
/// seed): the parts that do not depend on the seed and take long to compute.
#[derive(Default)]
pub struct Reusable {
    /// The localizers' map with its distance field.
    localization_map: Option<LocalizationMap>,
    /// The navigation costmaps.
    costmaps: Option<NavCostmaps>,
    /// The kernel pool (its threads, or a pool the program gave).
    pool: Option<KernelPool>,
}

impl Reusable {
    /// Takes the seed-independent parts out of a built world, unless a door has moved (door
    /// events edit them; the next world starts with every door open).
    pub fn take(world: &mut World) -> Self {
        let pool = world.remove_resource::<KernelPool>();
        if world.resource::<StaticWorld>().version != 0 {
            return Reusable::with_pool(pool);
        }
        Reusable {
            localization_map: world.remove_resource::<LocalizationMap>(),
            costmaps: world.remove_resource::<NavCostmaps>(),
            pool,
        }
    }

    /// Nothing to reuse but the kernel pool (none: the build starts its own).
    pub fn with_pool(pool: Option<KernelPool>) -> Self {
        Reusable {
            pool,
            ..Reusable::default()
        }
    }
}

/// How long each part of building the world took, in order (`sim bench startup` reports them).
#[derive(Resource, Default, Clone, Debug)]
pub struct BuildTimes {
    pub phases: Vec<(&'static str, Duration)>,
    last: Option<Instant>,
}

impl BuildTimes {
    fn start() -> Self {
        BuildTimes {
            phases: Vec::new(),
            last: Some(Instant::now()),
        }
    }

    /// Ends the phase called `name` (it began where the last one ended).
    fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        let began = self.last.replace(now).unwrap_or(now);
        self.phases.push((name, now - began));
    }
}

/// Builds the world for `scenario` with a kernel pool of `threads` workers (0 = all cores), with
/// the process's cache of map-derived structures ([`crate::cache::process_cache`]).
pub fn build_world(scenario: &Scenario, threads: usize) -> anyhow::Result<SimWorld> {
    build_world_with(
        scenario,
        threads,
        BuildMode::Live,
        Reusable::default(),
        &crate::cache::process_cache(),
    )
}

/// [`build_world`] for a live run or a replay, with what an earlier world of the same scenario
/// left ([`Reusable::take`]; `Reusable::default()` for none), reading and writing the structures
/// that depend on the map alone (ray caster, costmaps, likelihood field, road raster) through
/// `cache`.
pub fn build_world_with(
    scenario: &Scenario,
    threads: usize,
    mode: BuildMode,
    reuse: Reusable,
    cache: &MapCache,
) -> anyhow::Result<SimWorld> {
    // every way of setting a length (file, --duration, a replay's stamps) ends here
    if let Some(why) = crate::scenario::model::too_many_ticks(scenario.duration, scenario.dt) {
        anyhow::bail!("{}: duration: {why}", scenario.name);
    }
    let live = mode == BuildMode::Live;
    let mut times = BuildTimes::start();
    let mut world = World::new();
    let pool = match reuse.pool.clone() {
        Some(pool) => pool,
        None => KernelPool::new(threads)
            .map_err(|e| anyhow::anyhow!("cannot start {threads} kernel threads: {e}"))?,
    };
    world.insert_resource(pool);
    world.insert_resource(SimClock::new(scenario.dt));
    times.lap("kernel pool");
    let mut static_world = StaticWorld::new_cached(scenario.grid.clone(), cache);
    times.lap("ray caster");
    let mut physics = Physics::new(&mut static_world, scenario.dt);
    times.lap("wall colliders");
    // one shared costmap per distinct inflation setting of the robots with tasks
    let nav_params: Vec<_> = scenario
        .robots
        .iter()
        .filter(|_| live)
        .filter_map(|r| r.navigation.as_ref().map(|n| n.costmap))
        .collect();
    let costmaps = (!nav_params.is_empty()).then(|| {
        reuse
            .costmaps
            .unwrap_or_else(|| NavCostmaps::new_cached(&static_world, &nav_params, cache))
    });
    times.lap("navigation costmaps");
    // the map the localizers believe in is the floor plan as it is at the start: the static
    // world's ray caster, not yet edited, serves both
    let any_localizer = scenario.robots.iter().any(|r| !r.localizers.is_empty());
    let localizer_rays =
        (any_localizer && reuse.localization_map.is_none()).then(|| static_world.rays().clone());
    world.insert_resource(static_world);
    world.insert_resource(Doors {
        doors: scenario
            .doors
            .iter()
            .map(|d| Door::new(d.name.clone(), d.from, d.to, d.thickness))
            .collect(),
    });
    let field_max_dist = scenario
        .robots
        .iter()
        .flat_map(|r| r.localizers.iter().filter_map(|l| l.field_max_dist()))
        .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))));
    if any_localizer {
        // DE localizers ray-cast only; the field is then small and unused
        let max_dist = field_max_dist.unwrap_or(scenario.grid.resolution);
        let map = match (reuse.localization_map, localizer_rays) {
            (Some(map), _) => map,
            (None, Some(rays)) => {
                LocalizationMap::with_rays_cached(scenario.grid.clone(), max_dist, rays, cache)
            }
            (None, None) => LocalizationMap::new(scenario.grid.clone(), max_dist),
        };
        world.insert_resource(map);
    }

    times.lap("localization map");
    if live {
        crate::build::outdoor::insert_outdoor_world(&mut world, scenario, cache);
    }
    times.lap("outdoor world");
    let mut localizers = build_localizers(&world, scenario)?.into_iter();
    let mut robots = Vec::with_capacity(scenario.robots.len());
    for (i, r) in scenario.robots.iter().enumerate() {
        let body = physics.add_robot(i as u32, &r.start, &r.footprint);
        let items = localizers.next().unwrap_or_default();
        let e = spawn_robot(&mut world, scenario.seed, i as u32, r, body, items)?;
        if live {
            crate::build::outdoor::insert_outdoor_parts(&mut world, scenario.seed, e, r);
        }
        if let (Some(nav), Some(maps)) = (&r.navigation, &costmaps) {
            let mut params = nav.params.clone();
            params.costmap = maps.index_of(&nav.costmap).unwrap_or(0);
            let mut ent = world.entity_mut(e);
            ent.remove::<Behaviour>();
            ent.insert((
                Navigator::new(params, nav.tasks.clone()),
                NavOutcome::default(),
            ));
            if let Some(l) = nav.localizer {
                ent.insert(NavSource::new(l));
            }
        }
        if let (None, Some(l)) = (&r.navigation, r.behaviour_localizer) {
            world.entity_mut(e).insert(NavSource::new(l));
        }
        robots.push(e);
    }
    times.lap("robots and their localizers");
    let people = scenario
        .people
        .iter()
        .enumerate()
        .map(|(k, p)| spawn_person(&mut world, &mut physics, scenario.seed, k as u32, p))
        .collect();
    if let Some(maps) = costmaps {
        world.insert_resource(maps);
    }
    times.lap("people");
    physics.prepare();
    times.lap("first contacts");
    world.insert_resource(physics);
    world.insert_resource(EventQueue::new(
        scenario.events.clone(),
        &scenario.robots,
        &robots,
    ));

    let schedule = compose_schedule(&mut world, mode);
    times.lap("plugins");
    world.insert_resource(times);
    Ok(SimWorld {
        world,
        schedule,
        robots,
        people,
        mode,
    })
}

/// A walking person: a physics disc at its first route point, its script and walking state
/// (random draws from its own `walk` stream).
fn spawn_person(
    world: &mut World,
    physics: &mut Physics,
    seed: u64,
    index: u32,
    p: &PersonConfig,
) -> Entity {
    let start = p.person.start_pose();
    let body = physics.add_person(index, start.x, start.y, p.person.radius);
    let walker = Walker::new(&p.person, stream_rng(seed, &p.name, "walk"));
    world
        .spawn((
            PersonId(p.name.clone()),
            PersonIndex(index),
            p.person.clone(),
            walker,
            TruePose::at(start),
            body,
        ))
        .id()
}

fn odometry_model(kin: &Kinematics, enc: &systems::sensors::EncoderSpec) -> OdometryModel {
    match kin {
        Kinematics::DiffDrive(d) => OdometryModel::DiffDrive {
            left_radius: d.wheel_radius * (1.0 + enc.left_radius_error),
            right_radius: d.wheel_radius * (1.0 + enc.right_radius_error),
            wheel_base: d.wheel_base * (1.0 + enc.wheel_base_error),
        },
        Kinematics::Ackermann(a) => OdometryModel::Ackermann {
            wheel_radius: a.wheel_radius * (1.0 + enc.left_radius_error),
            wheelbase: a.wheelbase * (1.0 + enc.wheel_base_error),
        },
    }
}

/// Every robot's localizers, in robot order. They are built on the kernel threads, one job per
/// localizer: each draws only from its own stream (`stream_rng(seed, robot,
/// "localizer/<name>")`), so they are the same whatever the number of threads; the first error
/// in scenario order is the one reported.
fn build_localizers(world: &World, scenario: &Scenario) -> anyhow::Result<Vec<Vec<Localizer>>> {
    type Job<'a> = (&'a RobotConfig, usize, Option<anyhow::Result<Localizer>>);
    let mut jobs: Vec<Job> = scenario
        .robots
        .iter()
        .flat_map(|r| (0..r.localizers.len()).map(move |k| (r, k, None)))
        .collect();
    let map = world.get_resource::<LocalizationMap>();
    let seed = scenario.seed;
    world
        .resource::<KernelPool>()
        .for_each(&mut jobs, |(r, k, out)| {
            let l = &r.localizers[*k];
            let rng = stream_rng(seed, &r.name, &format!("localizer/{}", l.name));
            *out = Some(new_filter(&l.kind, map, rng).map(|f| Localizer::new(l.name.clone(), f)));
        });
    let mut built = jobs.into_iter();
    scenario
        .robots
        .iter()
        .map(|r| {
            (0..r.localizers.len())
                .map(|_| match built.next() {
                    Some((_, _, Some(l))) => l,
                    _ => Err(anyhow::anyhow!("a localizer of {} was not built", r.name)),
                })
                .collect()
        })
        .collect()
}

fn spawn_robot(
    world: &mut World,
    seed: u64,
    index: u32,
    r: &RobotConfig,
    body: systems::body::PhysicsBody,
    localizers: Vec<Localizer>,
) -> anyhow::Result<Entity> {
    let mut behaviour = Behaviour::new(
        r.behaviour.clone(),
        r.speed,
        r.footprint.bounding_radius(),
        stream_rng(seed, &r.name, "behaviour"),
    );
    behaviour.tolerance = r.tolerance;
    let mut e = world.spawn(RobotBundle::new(
        r.name.clone(),
        index,
        r.start,
        r.footprint.clone(),
        r.kinematics.clone(),
        body,
        behaviour,
    ));
    if let Some(spec) = &r.laser {
        e.insert((
            Laser::new(spec.clone(), stream_rng(seed, &r.name, "laser")),
            LaserScans::default(),
            LaserTruth::default(),
        ));
    }
    if let Some(spec) = &r.encoder {
        e.insert((
            Encoder::new(spec.clone(), stream_rng(seed, &r.name, "encoder")),
            EncoderReadings::default(),
            WheelOdometry::new(
                odometry_model(&r.kinematics, spec),
                spec.ticks_per_rev,
                r.start,
            ),
        ));
    }
    if let Some(s) = &r.sonar {
        e.insert((
            Sonars::new(
                s.spec.clone(),
                s.mounts.clone(),
                stream_rng(seed, &r.name, "sonar"),
            ),
            SonarReadings::default(),
            SonarTruth::default(),
        ));
    }
    let id = e.id();
    if !localizers.is_empty() {
        world.entity_mut(id).insert((
            Localizers { items: localizers },
            LocalizationSamples::default(),
        ));
    }
    Ok(id)
}

/// The localizer or SLAM system a resolved scenario entry describes, with its random stream
/// (`stream_rng(seed, robot, "localizer/<name>")`). Map-based localizers need the map they
/// localize in; SLAM systems ([`Filter::Scan`]) take none.
pub fn new_filter(
    kind: &LocalizerKind,
    map: Option<&LocalizationMap>,
    rng: SimRng,
) -> anyhow::Result<Filter> {
    let need_map =
        || map.ok_or_else(|| anyhow::anyhow!("a localizer of this type needs the scenario's map"));
    Ok(match kind {
        LocalizerKind::Mcl(c) => Filter::Map(Box::new(Mcl::new(c.clone(), need_map()?, rng))),
        LocalizerKind::MarkovGrid(c) => {
            Filter::Map(Box::new(MarkovGrid::new(c.clone(), need_map()?)))
        }
        LocalizerKind::DeFilter(c) => {
            Filter::Map(Box::new(DeFilter::new(c.clone(), need_map()?, rng)))
        }
        LocalizerKind::DeMc(c) => Filter::Map(Box::new(DeMc::new(c.clone(), need_map()?, rng))),
        LocalizerKind::DeOdometry(c) => Filter::Map(Box::new(DeOdometry::new(c.clone(), rng))),
        LocalizerKind::ScanToMap(c) => {
            Filter::Scan(Box::new(ScanToMapSlam::new((**c).clone()).with_rng(rng)))
        }
        LocalizerKind::Graph(c) => Filter::Scan(Box::new(GraphSlam::new((**c).clone()))),
        LocalizerKind::Rbpf(c) => Filter::Scan(Box::new(RbpfSlam::new((**c).clone(), rng))),
    })
}

/// The SLAM system a resolved `slam` entry describes (an error for other localizer kinds).
pub fn new_scan_estimator(
    kind: &LocalizerKind,
    rng: SimRng,
) -> anyhow::Result<Box<dyn ScanEstimator>> {
    match new_filter(kind, None, rng) {
        Ok(Filter::Scan(e)) => Ok(e),
        Ok(f) => anyhow::bail!("`{}` is a localizer, not a SLAM system", f.kind()),
        Err(e) => Err(e),
    }
}
