//! The whole tick under generated faults: two robots in a small room, driven by extreme
//! commands into the walls and into each other, their lasers and encoders corrupted by a
//! test-only system that runs after the sensors (Sense) and before the estimators (Estimate),
//! so the real physics, odometry, localizers and SLAM read the faulty data. After every tick
//! every pose, estimate, covariance, weight and map cell must be finite, and a localizer whose
//! scans had no usable beam must say so (degraded).

use super::*;
use crate::body::kinematics::DiffDrive;
use crate::body::{Physics, PhysicsPlugin};
use crate::core::props::{LaserFault, config, extreme_f64, laser_fault};
use crate::core::{KernelPool, SimClock, SimPlugin, SimSet, new_schedule, stream_rng};
use crate::localization::de_filter::{DeFilter, DeFilterConfig};
use crate::localization::mcl::{InitialBelief, MclConfig};
use crate::localization::props::{estimate_fault, room_grid, weights_fault};
use crate::localization::{
    Filter, LocalizationMap, LocalizationPlugin, Localizer, Localizers, MarkovGrid,
    MarkovGridConfig, Mcl, OdometryModel, WheelOdometry,
};
use crate::mapping::{MappingPlugin, ScanToMapConfig, ScanToMapSlam};
use crate::navigation::BehaviourKind;
use crate::navigation::held::apply_held_commands;
use crate::raycast::StaticWorld;
use crate::sensors::{
    Encoder, EncoderReadings, EncoderSpec, Laser, LaserScans, LaserSpec, LaserTruth, SensorsPlugin,
};
use proptest::prelude::*;
use std::f64::consts::PI;

/// What a faulty encoder does in a tick.
#[derive(Clone, Debug)]
enum EncoderFault {
    /// Repeats its last counts.
    Stuck,
    /// Both counters jump by these many ticks (and count on from there).
    Jump(i64, i64),
}

/// One tick's faults and the first robot's command (the second drives into it).
#[derive(Clone, Debug)]
struct TickFault {
    laser: Option<LaserFault>,
    encoder: Option<EncoderFault>,
    command: (f64, f64),
}

/// The faults of the run and what the faulty sensors repeat, per robot.
#[derive(Resource)]
struct Faults {
    ticks: Vec<TickFault>,
    tick: usize,
    last_scan: Vec<Option<Vec<f32>>>,
    last_counts: Vec<Option<(i64, i64)>>,
    offset: Vec<(i64, i64)>,
    /// Whether the robot's scans of this tick had no usable beam.
    unusable: Vec<bool>,
}

/// Script: the first robot gets this tick's command, the second drives at the first.
fn drive(faults: Res<Faults>, mut robots: Query<(&RobotIndex, &mut HeldCommand)>) {
    let Some(t) = faults.ticks.get(faults.tick) else {
        return;
    };
    for (index, mut held) in robots.iter_mut() {
        let (v, w) = if index.0 == 0 { t.command } else { (3.0, 0.0) };
        held.0 = Some(DriveCommand::new(v, w));
    }
}

/// Between Sense and Estimate: this tick's faults overwrite the readings.
fn inject_faults(
    mut faults: ResMut<Faults>,
    mut robots: Query<(&RobotIndex, &mut LaserScans, &mut EncoderReadings)>,
) {
    let f = &mut *faults;
    let Some(t) = f.ticks.get(f.tick).cloned() else {
        return;
    };
    f.tick += 1;
    for (index, mut scans, mut enc) in robots.iter_mut() {
        let i = index.0 as usize;
        f.unusable[i] = false;
        for s in scans.scans.iter_mut() {
            match &t.laser {
                Some(fault) => {
                    fault.apply(&mut s.ranges, s.range_max, f.last_scan[i].as_deref());
                    f.unusable[i] = fault.is_unusable();
                }
                None => f.last_scan[i] = Some(s.ranges.clone()),
            }
        }
        if let Some(EncoderFault::Jump(l, r)) = t.encoder {
            f.offset[i] = (f.offset[i].0.wrapping_add(l), f.offset[i].1.wrapping_add(r));
        }
        for r in enc.readings.iter_mut() {
            let counts = match (&t.encoder, f.last_counts[i]) {
                (Some(EncoderFault::Stuck), Some(last)) => last,
                _ => (
                    r.left_ticks.wrapping_add(f.offset[i].0),
                    r.right_ticks.wrapping_add(f.offset[i].1),
                ),
            };
            (r.left_ticks, r.right_ticks) = counts;
            f.last_counts[i] = Some(counts);
        }
    }
}

fn laser() -> LaserSpec {
    LaserSpec {
        fov: 270f64.to_radians(),
        increment: 3f64.to_radians(),
        min_range: 0.1,
        max_range: 10.0,
        rate: 10.0,
        noise_std: 0.01,
        dropout: 0.0,
        mount: Pose2::IDENTITY,
    }
}

fn localizers(map: &LocalizationMap, start: Pose2, full: bool) -> Localizers {
    let init = InitialBelief::Gaussian {
        pose: start,
        sd: [0.2, 0.2, 0.1],
    };
    let mcl = MclConfig {
        min_particles: 50,
        max_particles: 300,
        injection_candidates: 200,
        challenge_every: 3,
        update_min_d: 0.0,
        update_min_a: 0.0,
        init,
        ..MclConfig::default()
    };
    let rng = |name: &str| stream_rng(7, "props", name);
    let mut items = vec![Localizer::new(
        "mcl",
        Filter::Map(Box::new(Mcl::new(mcl, map, rng("mcl")))),
    )];
    if full {
        let grid = MarkovGridConfig {
            resolution: 0.5,
            angular_bins: 12,
            update_min_d: 0.0,
            update_min_a: 0.0,
            init,
            ..MarkovGridConfig::default()
        };
        let de = DeFilterConfig {
            population: 60,
            min_population: 20,
            generations: 2,
            tracking_generations: 1,
            refine_rounds: 1,
            refine_samples: 8,
            update_min_d: 0.0,
            update_min_a: 0.0,
            init,
            ..DeFilterConfig::default()
        };
        let slam = ScanToMapSlam::new(ScanToMapConfig::default()).with_rng(rng("slam"));
        items.extend([
            Localizer::new("grid", Filter::Map(Box::new(MarkovGrid::new(grid, map)))),
            Localizer::new(
                "de",
                Filter::Map(Box::new(DeFilter::new(de, map, rng("de")))),
            ),
            Localizer::new("slam", Filter::Scan(Box::new(slam))),
        ]);
    }
    Localizers { items }
}

/// The room with two robots facing each other across it and the tick schedule, faults
/// injected; `dt` is the clock's step.
fn world(ticks: Vec<TickFault>, dt: f64) -> (World, Schedule, [Entity; 2]) {
    let mut world = World::new();
    world.insert_resource(SimClock::new(dt));
    world.insert_resource(KernelPool::new(1).unwrap());
    let grid = room_grid();
    let map = LocalizationMap::new(grid.clone(), 2.0);
    let mut ground = StaticWorld::new(grid);
    let mut physics = Physics::new(&mut ground, dt);
    let drive_kin = DiffDrive {
        wheel_base: 0.4,
        wheel_radius: 0.1,
        max_wheel_speed: 30.0,
        max_wheel_accel: 60.0,
    };
    let starts = [Pose2::new(6.0, 4.0, 0.0), Pose2::new(9.0, 4.2, PI)];
    let footprint = Footprint::Circle { radius: 0.25 };
    let robots = [0, 1].map(|i| {
        let start = starts[i];
        let body = physics.add_robot(i as u32, &start, &footprint);
        let idle = Behaviour::new(BehaviourKind::Idle, 0.5, 0.25, stream_rng(1, "r", "b"));
        let bundle = RobotBundle::new(
            format!("r{i}"),
            i as u32,
            start,
            footprint.clone(),
            Kinematics::DiffDrive(drive_kin.clone()),
            body,
            idle,
        );
        let odometry = OdometryModel::DiffDrive {
            left_radius: 0.1,
            right_radius: 0.1,
            wheel_base: 0.4,
        };
        world
            .spawn((
                bundle,
                Laser::new(laser(), stream_rng(1, &format!("r{i}"), "laser")),
                LaserScans::default(),
                LaserTruth::default(),
                Encoder::new(EncoderSpec::default(), stream_rng(1, "r", "encoder")),
                EncoderReadings::default(),
                WheelOdometry::new(odometry, 4096, start),
                localizers(&map, start, i == 0),
            ))
            .id()
    });
    world.insert_resource(ground);
    world.insert_resource(physics);
    world.insert_resource(map);
    world.insert_resource(Faults {
        ticks,
        tick: 0,
        last_scan: vec![None; 2],
        last_counts: vec![None; 2],
        offset: vec![(0, 0); 2],
        unusable: vec![false; 2],
    });
    let mut schedule = new_schedule();
    schedule.add_systems(drive.in_set(SimSet::Script));
    schedule.add_systems(apply_held_commands.in_set(SimSet::Control));
    PhysicsPlugin.build(&mut world, &mut schedule);
    SensorsPlugin.build(&mut world, &mut schedule);
    LocalizationPlugin.build(&mut world, &mut schedule);
    MappingPlugin.build(&mut world, &mut schedule);
    schedule.add_systems(inject_faults.after(SimSet::Sense).before(SimSet::Estimate));
    (world, schedule, robots)
}

/// Why the state of `robot` after a tick breaks a property, if it does.
fn fault_of(world: &World, robot: Entity, unusable: bool) -> Option<String> {
    let finite = |p: &Pose2| p.x.is_finite() && p.y.is_finite() && p.theta.is_finite();
    let truth = world.get::<TruePose>(robot)?.pose;
    if !finite(&truth) {
        return Some(format!("true pose {truth:?}"));
    }
    let twist = world.get::<TrueTwist>(robot)?;
    if !(twist.v.is_finite() && twist.w.is_finite()) {
        return Some(format!("true twist {twist:?}"));
    }
    let odom = world.get::<WheelOdometry>(robot)?.pose;
    if !finite(&odom) {
        return Some(format!("odometry {odom:?}"));
    }
    for l in &world.get::<Localizers>(robot)?.items {
        if let Some(why) = l.latest.and_then(|e| estimate_fault(&e.estimate)) {
            return Some(format!("{}: {why}", l.name));
        }
        if unusable && !l.filter.is_scan() && !l.degraded {
            return Some(format!("{}: no usable beam, yet not degraded", l.name));
        }
        if let Some(why) = l
            .filter
            .downcast_ref::<Mcl>()
            .and_then(|m| weights_fault(&m.w))
        {
            return Some(format!("{}: {why}", l.name));
        }
        if let Some(g) = l.filter.downcast_ref::<MarkovGrid>() {
            let sum = g.total_mass();
            if g.belief.iter().any(|v| !(v.is_finite() && *v >= 0.0)) || (sum - 1.0).abs() > 1e-3 {
                return Some(format!("{}: belief sums to {sum}", l.name));
            }
        }
    }
    None
}

/// Why a SLAM map of `robot` has a cell that is not a finite probability, if one has.
fn map_fault(world: &World, robot: Entity) -> Option<String> {
    for l in &world.get::<Localizers>(robot)?.items {
        if let Filter::Scan(e) = &l.filter
            && let Some(map) = e.map()
            && let Some(bad) = map
                .p
                .iter()
                .find(|p| !(p.is_finite() && (0.0..=1.0).contains(*p)))
        {
            return Some(format!("{}: cell {bad}", l.name));
        }
    }
    None
}

fn tick_fault() -> impl Strategy<Value = TickFault> {
    (
        proptest::option::weighted(0.5, laser_fault(10.0, 30)),
        proptest::option::weighted(
            0.3,
            prop_oneof![
                Just(EncoderFault::Stuck),
                (-100_000i64..100_000, -100_000i64..100_000)
                    .prop_map(|(l, r)| EncoderFault::Jump(l, r)),
            ],
        ),
        (extreme_f64(), extreme_f64()),
    )
        .prop_map(|(laser, encoder, command)| TickFault {
            laser,
            encoder,
            command,
        })
}

proptest! {
    #![proptest_config(config(16))]

    /// Two seconds of faults, extreme commands and collisions: after every tick every pose,
    /// estimate, covariance and weight is finite (and the SLAM map at the end), and a localizer
    /// fed scans without a usable beam is degraded.
    #[test]
    fn the_pipeline_stays_finite_under_sensor_faults_and_collisions(
        ticks in proptest::collection::vec(tick_fault(), 40),
    ) {
        let (mut world, mut schedule, robots) = world(ticks.clone(), 0.05);
        for k in 0..ticks.len() {
            schedule.run(&mut world);
            world.resource_mut::<SimClock>().advance();
            for (i, &r) in robots.iter().enumerate() {
                let unusable = world.resource::<Faults>().unusable[i];
                if let Some(why) = fault_of(&world, r, unusable) {
                    return Err(TestCaseError::fail(format!("tick {k}, r{i}: {why}")));
                }
            }
        }
        prop_assert_eq!(map_fault(&world, robots[0]), None);
    }
}

/// A clock whose step is 0 moves nothing and divides by nothing: the physics step refuses a
/// zero-length (or negative, or NaN) step instead of dividing the motion by it.
#[test]
fn a_zero_length_tick_moves_nothing_and_divides_by_nothing() {
    let drive_hard = TickFault {
        laser: None,
        encoder: None,
        command: (2.0, 1.0),
    };
    for dt in [0.0, -0.05, f64::NAN] {
        let (mut world, mut schedule, robots) = world(vec![drive_hard.clone(); 10], dt);
        let before: Vec<Pose2> = robots
            .iter()
            .map(|&r| world.get::<TruePose>(r).unwrap().pose)
            .collect();
        for _ in 0..10 {
            schedule.run(&mut world);
            world.resource_mut::<SimClock>().advance();
        }
        for (i, &r) in robots.iter().enumerate() {
            assert_eq!(world.get::<TruePose>(r).unwrap().pose, before[i], "{dt}");
            assert_eq!(fault_of(&world, r, false), None, "{dt}");
        }
    }
}
