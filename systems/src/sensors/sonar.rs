//! Ultrasonic range sensors (sonars), modelled on the Devantech SRF02 of the outdoor robot of
//! the [Park thesis] (§4.1.2, §5.5: 4 × SRF02: one straight ahead, two at ±45°, one at the back;
//! they guard against collisions). All of a robot's sonars fire together at the spec's rate.
//!
//! A sonar reports the range of the nearest echo inside its beam. The beam is modelled as a fan of
//! rays spread evenly across the cone (at most [`MAX_RAY_SPACING`] apart, both edges included),
//! each cast against the static map and the other robots' footprints exactly like the laser's
//! beams (so anything added to [`RobotOutlines`] is seen too); the reading is the shortest ray.
//! Then the noise model: Gaussian range noise, quantisation to the sensor's resolution (the SRF02
//! reports whole centimetres) and REP 117 limits (below `min_range` = -Inf, no echo within
//! `max_range` = +Inf), as sensor_msgs/Range consumers expect.
//!
//! Not modelled: specular reflection (a 40 kHz sonar loses a flat wall hit at a steep angle),
//! the beam's gain falling off towards the cone edge, cross-talk between sonars.

use super::others::{NearbyRobots, RobotOutlines};
use crate::body::{Footprint, TruePose};
use crate::core::clock::RateTimer;
use crate::core::{KernelPool, Pose2, RobotIndex, SimClock, SimRng};
use crate::raycast::StaticWorld;
use crate::raycast::{RayMap, overlay_circles, overlay_segments};
use bevy_ecs::prelude::*;
use rand::RngExt;
use rand_distr::StandardNormal;

/// Largest angle between neighbouring rays of a sonar's fan (4°: 15 rays across the SRF02's 55°;
/// an obstacle narrower than the gap, ~0.4 m at 6 m, can slip between rays).
pub const MAX_RAY_SPACING: f64 = 4.0 * std::f64::consts::PI / 180.0;

/// Sonar parameters (SI units, angles in radians).
#[derive(Clone, Debug, PartialEq)]
pub struct SonarSpec {
    /// Full width of the beam cone, centred on the sensor's x axis.
    pub cone: f64,
    pub min_range: f64,
    pub max_range: f64,
    /// Reading sets per second (every mount fires at each).
    pub rate: f64,
    /// Standard deviation of the range noise (m).
    pub noise_std: f64,
    /// Readings are rounded to a multiple of this (m); 0 = no rounding.
    pub resolution: f64,
}

impl SonarSpec {
    /// Devantech SRF02 (robot-electronics.co.uk, "SRF02 Ultrasonic range finder, Technical
    /// Specification"): range 15 cm – 6 m; results in whole centimetres (srf02techI2C.htm: range
    /// registers in inches, cm or µs) → 1 cm resolution; "the ranging lasts up to 65 mS" → at most
    /// ~15 readings per second. Beam: Devantech's 40 kHz beam pattern is ~55° wide (its SRF04
    /// pattern, which the SRF235 page quotes as "the 55° typical pattern"; the [Park thesis]
    /// (§4.1.2, fig. 5b) reproduces the SRF02 plot and notes the beam is not wide, hence three
    /// front sensors). The datasheet gives no noise figure: 1 cm (1σ), the "accuracy of mm to
    /// cm" of [Park thesis §2.4].
    pub fn srf02() -> Self {
        SonarSpec {
            cone: 55f64.to_radians(),
            min_range: 0.15,
            max_range: 6.0,
            rate: 15.0,
            noise_std: 0.01,
            resolution: 0.01,
        }
    }

    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "srf02" => Some(Self::srf02()),
            _ => None,
        }
    }

    pub const PRESETS: [&'static str; 1] = ["srf02"];

    /// Rays in each sonar's fan: both cone edges plus enough between them that neighbours are at
    /// most [`MAX_RAY_SPACING`] apart.
    pub fn fan_rays(&self) -> usize {
        (self.cone / MAX_RAY_SPACING - 1e-9).ceil().max(1.0) as usize + 1
    }
}

/// Mount poses on the edge of a footprint, one per yaw (radians, base frame), each facing
/// outwards along its yaw: on the circle of a round robot, on the rectangle's side that the
/// direction crosses for a rectangular one.
pub fn edge_mounts(footprint: &Footprint, yaws: &[f64]) -> Vec<Pose2> {
    yaws.iter()
        .map(|&yaw| {
            let (s, c) = yaw.sin_cos();
            let d = match footprint {
                Footprint::Circle { radius } => *radius,
                Footprint::Rectangle { length, width } => {
                    let tx = if c.abs() > 1e-12 {
                        length / 2.0 / c.abs()
                    } else {
                        f64::INFINITY
                    };
                    let ty = if s.abs() > 1e-12 {
                        width / 2.0 / s.abs()
                    } else {
                        f64::INFINITY
                    };
                    tx.min(ty)
                }
            };
            Pose2::new(d * c, d * s, yaw)
        })
        .collect()
}

/// A robot's sonars: one spec for all, their mounts, one random stream and one timer.
#[derive(Component, Clone, Debug)]
pub struct Sonars {
    pub spec: SonarSpec,
    /// Sensor poses in the robot's base frame (x along the beam axis).
    pub mounts: Vec<Pose2>,
    pub rng: SimRng,
    pub timer: RateTimer,
    /// False while a scripted fault is active: no new readings.
    pub enabled: bool,
}

impl Sonars {
    pub fn new(spec: SonarSpec, mounts: Vec<Pose2>, rng: SimRng) -> Self {
        let timer = RateTimer::new(spec.rate, 0.0);
        Sonars {
            spec,
            mounts,
            rng,
            timer,
            enabled: true,
        }
    }
}

/// The latest reading set (sensor_msgs/Range ranges, REP 117): empty until the first firing.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct SonarReadings {
    /// One range per mount, in mount order (m; +Inf = no echo, -Inf = closer than min_range).
    pub latest: Vec<f32>,
    /// Simulation time of `latest` (s).
    pub stamp: f64,
    /// True if `latest` was measured in this tick.
    pub fired: bool,
}

/// The true base pose at the latest reading set (for recording and evaluation only).
#[derive(Component, Clone, Debug, Default)]
pub struct SonarTruth {
    pub latest: Option<Pose2>,
}

/// The nearest echo of a fan: the shortest exact ray range (+Inf if every ray is clear).
pub fn nearest_echo(ranges: &[f32]) -> f32 {
    ranges.iter().copied().fold(f32::INFINITY, f32::min)
}

/// The noise model for one exact echo range: `n` is a standard normal draw. Adds noise, rounds
/// to the resolution, then REP 117: no echo within max_range = +Inf, below min_range = -Inf.
pub fn measure(spec: &SonarSpec, exact: f32, n: f64) -> f32 {
    if !exact.is_finite() || exact as f64 > spec.max_range {
        return f32::INFINITY;
    }
    let mut r = exact as f64 + n * spec.noise_std;
    if spec.resolution > 0.0 {
        r = (r / spec.resolution).round() * spec.resolution;
    }
    if r < spec.min_range {
        f32::NEG_INFINITY
    } else if r > spec.max_range {
        f32::INFINITY
    } else {
        r as f32
    }
}

/// Exact nearest echo of one sonar at world pose `sensor`: its fan of rays cast against the map
/// and the nearby robots (`fan` is scratch, resized to the fan's ray count).
pub fn cast_cone(
    rays: &RayMap,
    near: &NearbyRobots,
    spec: &SonarSpec,
    sensor: &Pose2,
    fan: &mut Vec<f32>,
) -> f32 {
    let n = spec.fan_rays();
    fan.clear();
    fan.resize(n, 0.0);
    let p = [sensor.x as f32, sensor.y as f32];
    let start = (sensor.theta - spec.cone / 2.0) as f32;
    let inc = (spec.cone / (n - 1) as f64) as f32;
    let max = spec.max_range as f32;
    // a handful of rays: walk each through the distance field (the face sweep pays off only
    // for whole scans)
    rays.cast_scan_rays(p, start, inc, max, fan);
    overlay_circles(p, start, inc, fan, &near.circles);
    overlay_segments(p, start, inc, fan, &near.segments);
    nearest_echo(fan)
}

#[derive(Default)]
struct Scratch {
    near: NearbyRobots,
    due: Vec<f64>,
    fan: Vec<f32>,
}

/// Sense: every robot's sonars take the reading set due in this tick (the last one if several
/// are due: only the latest is kept), at the true pose interpolated to its firing time.
#[allow(clippy::type_complexity)]
pub fn sample_sonars(
    clock: Res<SimClock>,
    world: Res<StaticWorld>,
    outlines: Res<RobotOutlines>,
    pool: Res<KernelPool>,
    mut sonars: Query<(
        &RobotIndex,
        &TruePose,
        &mut Sonars,
        &mut SonarReadings,
        &mut SonarTruth,
    )>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    let mut jobs: Vec<_> = sonars.iter_mut().collect();
    let rays = world.rays();
    let outlines = &*outlines;
    pool.for_each_init(
        &mut jobs,
        Scratch::default,
        |s, (index, truth, sonars, readings, sonar_truth)| {
            readings.fired = false;
            let sonars = &mut **sonars;
            sonars.timer.due(start, end, &mut s.due);
            let Some(&t) = s.due.last() else {
                return;
            };
            if !sonars.enabled {
                return;
            }
            let f = ((t - start) / dt).clamp(0.0, 1.0);
            let base = truth.interpolate(f);
            let reach = sonars
                .mounts
                .iter()
                .map(|m| m.x.hypot(m.y))
                .fold(0.0, f64::max);
            outlines.near(
                base.x,
                base.y,
                sonars.spec.max_range + reach + 1.0,
                index.0,
                &mut s.near,
            );
            let spec = &sonars.spec;
            readings.latest.clear();
            for m in &sonars.mounts {
                let exact = cast_cone(rays, &s.near, spec, &base.compose(m), &mut s.fan);
                // one draw per mount whatever it saw, so the stream's use depends only on
                // the parameters, never on the geometry
                let n: f64 = if spec.noise_std > 0.0 {
                    sonars.rng.sample(StandardNormal)
                } else {
                    0.0
                };
                readings.latest.push(measure(spec, exact, n));
            }
            readings.stamp = t;
            readings.fired = true;
            sonar_truth.latest = Some(base);
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::sensors::others::update_robot_outlines;
    use crate::world::{Cell, OccupancyGrid};

    /// A 20 × 20 m free map at 5 cm with the given cells occupied.
    fn map(occupied: impl Fn(f64, f64) -> bool) -> StaticWorld {
        let mut g = OccupancyGrid::new(400, 400, 0.05, [-10.0, -10.0], Cell::Free);
        for row in 0..400 {
            for col in 0..400 {
                let c = g.cell_center(col, row);
                if occupied(c[0], c[1]) {
                    g.set(col, row, Cell::Occupied);
                }
            }
        }
        StaticWorld::new(g)
    }

    fn exact(world: &StaticWorld, near: &NearbyRobots, sensor: Pose2) -> f32 {
        cast_cone(
            world.rays(),
            near,
            &SonarSpec::srf02(),
            &sensor,
            &mut Vec::new(),
        )
    }

    #[test]
    fn srf02_fan_has_15_rays_at_most_4_degrees_apart() {
        let s = SonarSpec::srf02();
        assert_eq!(s.fan_rays(), 15);
        assert!(s.cone / (s.fan_rays() - 1) as f64 <= MAX_RAY_SPACING + 1e-12);
        let narrow = SonarSpec {
            cone: 1f64.to_radians(),
            ..s
        };
        assert_eq!(narrow.fan_rays(), 2);
    }

    #[test]
    fn wall_straight_ahead_is_measured_within_noise() {
        // wall face at x = 3.0 (cells from 3.0 on)
        let w = map(|x, _| x > 3.0);
        let near = NearbyRobots::default();
        let e = exact(&w, &near, Pose2::new(1.0, 0.3, 0.0));
        assert!((e - 2.0).abs() < 0.01, "exact {e}");
        let spec = SonarSpec::srf02();
        let mut rng = stream_rng(3, "r", "sonar");
        let readings: Vec<f32> = (0..2000)
            .map(|_| measure(&spec, e, rng.sample(StandardNormal)))
            .collect();
        let mean = readings.iter().map(|&r| r as f64).sum::<f64>() / readings.len() as f64;
        assert!((mean - 2.0).abs() < 0.005, "mean {mean}");
        for r in &readings {
            assert!((r - 2.0).abs() < 0.06, "reading {r}");
            // whole centimetres
            assert!((r * 100.0 - (r * 100.0).round()).abs() < 1e-3, "{r}");
        }
    }

    #[test]
    fn obstacle_at_the_cone_edge_is_seen_one_outside_is_not() {
        let half = SonarSpec::srf02().cone / 2.0;
        let near = NearbyRobots::default();
        let sensor = Pose2::new(0.0, 0.0, 0.0);
        // a 0.3 m post centred on the cone's edge, 2 m away
        let at = |a: f64| (2.0 * a.cos(), 2.0 * a.sin());
        let (ex, ey) = at(half);
        let edge = map(|x, y| (x - ex).hypot(y - ey) < 0.15);
        let e = exact(&edge, &near, sensor);
        assert!((e - 1.85).abs() < 0.06, "edge post {e}");
        // the same post 10° outside the cone
        let (ox, oy) = at(half + 10f64.to_radians());
        let outside = map(|x, y| (x - ox).hypot(y - oy) < 0.15);
        assert_eq!(exact(&outside, &near, sensor), f32::INFINITY);
        // and on the other side
        let (mx, my) = at(-half + 0.5f64.to_radians());
        let mirrored = map(|x, y| (x - mx).hypot(y - my) < 0.15);
        assert!(exact(&mirrored, &near, sensor) < 2.0);
    }

    #[test]
    fn below_min_and_no_echo_follow_rep_117() {
        let spec = SonarSpec::srf02();
        assert_eq!(measure(&spec, f32::INFINITY, 0.0), f32::INFINITY);
        assert_eq!(measure(&spec, 6.5, 0.0), f32::INFINITY);
        assert_eq!(measure(&spec, 0.10, 0.0), f32::NEG_INFINITY);
        assert_eq!(measure(&spec, 0.0, 0.0), f32::NEG_INFINITY);
        assert!((measure(&spec, 0.154, 0.0) - 0.15).abs() < 1e-6);
        // noise pushing a reading past max_range is no echo as well
        assert_eq!(measure(&spec, 5.99, 3.0), f32::INFINITY);
        // nothing within 6 m: +Inf; a wall 7 m ahead is beyond range
        let w = map(|x, _| x > 7.0);
        assert_eq!(
            exact(&w, &NearbyRobots::default(), Pose2::IDENTITY),
            f32::INFINITY
        );
        // inside a wall: 0 → -Inf
        let inside = exact(&w, &NearbyRobots::default(), Pose2::new(8.0, 0.0, 0.0));
        assert_eq!(measure(&spec, inside, 0.0), f32::NEG_INFINITY);
    }

    #[test]
    fn edge_mounts_lie_on_the_footprint() {
        let yaws = [
            0.0,
            45f64.to_radians(),
            -45f64.to_radians(),
            std::f64::consts::PI,
        ];
        let c = edge_mounts(&Footprint::Circle { radius: 0.3 }, &yaws);
        for (m, yaw) in c.iter().zip(yaws) {
            assert!((m.x.hypot(m.y) - 0.3).abs() < 1e-12);
            assert!((m.theta - yaw).abs() < 1e-12);
        }
        // the [Park thesis] car's 520 × 400 mm chassis
        let r = edge_mounts(
            &Footprint::Rectangle {
                length: 0.52,
                width: 0.4,
            },
            &yaws,
        );
        assert!((r[0].x - 0.26).abs() < 1e-12 && r[0].y.abs() < 1e-12);
        assert!((r[1].x - 0.2).abs() < 1e-12 && (r[1].y - 0.2).abs() < 1e-12);
        assert!((r[2].y + 0.2).abs() < 1e-12);
        assert!((r[3].x + 0.26).abs() < 1e-12);
    }

    /// Robot 0 at the origin facing +x with the four sonars of the [Park thesis] car; robot 1 a
    /// disc ahead.
    fn run_world(threads: usize, seed: u64, ticks: usize) -> Vec<(f64, Vec<f32>)> {
        let mut world = World::new();
        world.insert_resource(KernelPool::new(threads).unwrap());
        world.insert_resource(SimClock::new(0.05));
        world.insert_resource(map(|x, y| x.abs() > 5.0 || y.abs() > 5.0));
        world.init_resource::<RobotOutlines>();
        let fp = Footprint::Circle { radius: 0.25 };
        let yaws = [
            0.0,
            45f64.to_radians(),
            -45f64.to_radians(),
            std::f64::consts::PI,
        ];
        let mut robots = Vec::new();
        for (i, (name, x)) in [("a", 0.0), ("b", 2.0), ("c", -3.0)].iter().enumerate() {
            let e = world.spawn((
                RobotIndex(i as u32),
                TruePose::at(Pose2::new(*x, 0.0, 0.0)),
                fp.clone(),
                Sonars::new(
                    SonarSpec::srf02(),
                    edge_mounts(&fp, &yaws),
                    stream_rng(seed, name, "sonar"),
                ),
                SonarReadings::default(),
                SonarTruth::default(),
            ));
            robots.push(e.id());
        }
        let mut schedule = Schedule::default();
        schedule.add_systems((update_robot_outlines, sample_sonars).chain());
        let mut out = Vec::new();
        for _ in 0..ticks {
            schedule.run(&mut world);
            for &e in &robots {
                let r = world.get::<SonarReadings>(e).unwrap();
                if r.fired {
                    out.push((r.stamp, r.latest.clone()));
                }
            }
            world.resource_mut::<SimClock>().advance();
        }
        out
    }

    #[test]
    fn other_robots_are_seen() {
        let out = run_world(1, 7, 1);
        // robot a: front sonar at x = 0.25; robot b's disc front face at 1.75 → 1.5 m
        let a = &out[0].1;
        assert_eq!(a.len(), 4);
        assert!((a[0] - 1.5).abs() < 0.05, "front {a:?}");
        // rear sonar at x = -0.25; robot c's disc at -3 + 0.25 → 2.5 m
        assert!((a[3] - 2.5).abs() < 0.05, "rear {a:?}");
        // the ±45° sonars' cones (17.5°..72.5°) miss b (within ±7.2° of the axis) and see the
        // room's walls instead (5 m away along y)
        assert!(a[1] > 4.0 && a[2] > 4.0, "{a:?}");
    }

    #[test]
    fn same_seed_same_readings_whatever_the_threads() {
        let one = run_world(1, 11, 20);
        let three = run_world(3, 11, 20);
        assert_eq!(one, three);
        // 20 ticks of 50 ms end at t = 1 s; at 15 Hz: t = 0, 1/15, ..., 15/15 → 16 sets per robot
        assert_eq!(one.len(), 3 * 16);
        let other = run_world(1, 12, 20);
        assert_ne!(one, other, "the noise comes from the seed");
    }
}
