//! 2-D laser scanner. Fires at its own rate on the simulation clock (several times per tick if
//! needed, at the pose interpolated to each firing time), casts every beam against the static map
//! and the other robots' footprints, then applies the noise model: Gaussian range noise and
//! random dropouts. Readings follow sensor_msgs/LaserScan and REP 117: no return = +Inf, a
//! reading below range_min = -Inf. Scans of all robots are cast in parallel on the kernel pool,
//! each laser drawing only from its own random stream, so results do not depend on threads.

use super::others::{NearbyRobots, RobotOutlines};
use crate::body::TruePose;
use crate::core::clock::RateTimer;
use crate::core::normal::fill_standard_normal;
use crate::core::spatial_order::SpatialOrder;
use crate::core::{JobMemory, KernelPool, Pose2, RobotIndex, SimClock, SimRng};
use crate::raycast::StaticWorld;
use crate::raycast::{overlay_circles, overlay_segments};
use bevy_ecs::prelude::*;
use rand::RngExt;

/// Laser parameters (SI units, angles in radians).
#[derive(Clone, Debug, PartialEq)]
pub struct LaserSpec {
    /// Total field of view, centred on the sensor's x axis.
    pub fov: f64,
    /// Angle between beams.
    pub increment: f64,
    pub min_range: f64,
    pub max_range: f64,
    /// Scans per second.
    pub rate: f64,
    /// Standard deviation of the range noise (m).
    pub noise_std: f64,
    /// Probability that a beam returns nothing.
    pub dropout: f64,
    /// Sensor pose in the robot's base frame.
    pub mount: Pose2,
}

impl LaserSpec {
    /// SICK LMS100: 270°, 0.25° (1081 beams), 0.5–20 m, 50 Hz, 12 mm (1σ) statistical error.
    pub fn sick_lms100() -> Self {
        LaserSpec {
            fov: 270f64.to_radians(),
            increment: 0.25f64.to_radians(),
            min_range: 0.5,
            max_range: 20.0,
            rate: 50.0,
            noise_std: 0.012,
            dropout: 0.0,
            mount: Pose2::IDENTITY,
        }
    }

    /// Hokuyo URG-04LX: 240°, 0.36°, 0.02–5.6 m, 10 Hz, ±30 mm (taken as 3σ).
    pub fn hokuyo_urg04lx() -> Self {
        LaserSpec {
            fov: 240f64.to_radians(),
            increment: 0.36f64.to_radians(),
            min_range: 0.02,
            max_range: 5.6,
            rate: 10.0,
            noise_std: 0.01,
            dropout: 0.0,
            mount: Pose2::IDENTITY,
        }
    }

    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "sick_lms100" => Some(Self::sick_lms100()),
            "hokuyo_urg04lx" => Some(Self::hokuyo_urg04lx()),
            _ => None,
        }
    }

    pub const PRESETS: [&'static str; 2] = ["sick_lms100", "hokuyo_urg04lx"];

    /// The most beams a scan may have (a 360° laser at 0.018°); scenarios and benchmarks
    /// refuse more.
    pub const MAX_BEAMS: usize = 20_000;

    /// Number of beams: fov / increment + 1 (both ends included).
    pub fn beams(&self) -> usize {
        (self.fov / self.increment + 1e-6).floor() as usize + 1
    }

    pub fn angle_min(&self) -> f64 {
        -self.fov / 2.0
    }
}

/// One scan, as sensor_msgs/LaserScan.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserScan {
    /// Simulation time of the scan (s).
    pub stamp: f64,
    pub angle_min: f32,
    pub angle_increment: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
}

impl LaserScan {
    /// Beam endpoints of finite readings in the sensor frame.
    pub fn points(&self) -> impl Iterator<Item = [f32; 2]> + '_ {
        self.ranges.iter().enumerate().filter_map(|(k, &r)| {
            if !r.is_finite() {
                return None;
            }
            let a = self.angle_min + k as f32 * self.angle_increment;
            Some([r * a.cos(), r * a.sin()])
        })
    }
}

#[derive(Component, Clone, Debug)]
pub struct Laser {
    pub spec: LaserSpec,
    pub rng: SimRng,
    pub timer: RateTimer,
    /// False while a scripted fault is active: the sensor produces nothing.
    pub enabled: bool,
}

impl Laser {
    pub fn new(spec: LaserSpec, rng: SimRng) -> Self {
        let timer = RateTimer::new(spec.rate, 0.0);
        Laser {
            spec,
            rng,
            timer,
            enabled: true,
        }
    }
}

/// Readings: the scans of the current tick (estimators consume these) and, through
/// [`LaserScans::latest`], the latest one.
#[derive(Component, Clone, Debug, Default)]
pub struct LaserScans {
    pub scans: Vec<LaserScan>,
    /// The last scan of an earlier tick (kept by moving, not copying, at [`LaserScans::next_tick`]).
    previous: Option<LaserScan>,
    /// Range buffers of dropped scans, for [`LaserScans::buffer`] to hand out again.
    spare: Vec<Vec<f32>>,
}

impl LaserScans {
    /// The latest scan: this tick's last, else the last of an earlier tick.
    pub fn latest(&self) -> Option<&LaserScan> {
        self.scans.last().or(self.previous.as_ref())
    }

    /// Starts a tick: this tick's scans are dropped, except the last, which stays the latest.
    /// Their range buffers are kept for the next scans.
    pub fn next_tick(&mut self) {
        if let Some(last) = self.scans.pop()
            && let Some(old) = self.previous.replace(last)
        {
            self.spare.push(old.ranges);
        }
        self.spare.extend(self.scans.drain(..).map(|s| s.ranges));
    }

    /// A buffer of `n` zeros for a new scan's ranges: a dropped scan's when there is one (a
    /// swarm's lasers otherwise allocated and freed one per scan, often on different threads).
    pub fn buffer(&mut self, n: usize) -> Vec<f32> {
        let mut b = self.spare.pop().unwrap_or_default();
        b.clear();
        b.resize(n, 0.0);
        b
    }
}

/// The true sensor pose of each scan of this tick (for evaluation and recording only).
#[derive(Component, Clone, Debug, Default)]
pub struct LaserTruth {
    pub poses: Vec<Pose2>,
    pub latest: Option<Pose2>,
}

/// Applies the noise model to exact ranges in place.
pub fn apply_noise(spec: &LaserSpec, rng: &mut SimRng, ranges: &mut [f32]) {
    let max = spec.max_range as f32;
    let min = spec.min_range as f32;
    let (std, dropout) = (spec.noise_std as f32, spec.dropout);
    // draw the same numbers for every beam, whatever it hit, so the stream's use does not
    // depend on the geometry (which draws are made depends only on the laser's parameters):
    // per block of beams, first their deviates, then their dropout draws
    let (draw_drop, draw_noise) = (dropout > 0.0, spec.noise_std > 0.0);
    let mut deviates = [0f32; 64];
    for block in ranges.chunks_mut(deviates.len()) {
        let noise = &mut deviates[..block.len()];
        if draw_noise {
            fill_standard_normal(rng, noise);
        }
        for (r, &n) in block.iter_mut().zip(noise.iter()) {
            let drop: f64 = if draw_drop { rng.random() } else { 1.0 };
            if drop < dropout || !r.is_finite() || *r > max {
                *r = f32::INFINITY;
                continue;
            }
            let noisy = *r + n * std;
            *r = if noisy < min {
                f32::NEG_INFINITY
            } else if noisy > max {
                f32::INFINITY
            } else {
                noisy
            };
        }
    }
}

/// What a worker of [`sample_lasers`] reuses from scan to scan and tick to tick.
#[derive(Default)]
struct Scratch {
    near: NearbyRobots,
    due: Vec<f64>,
}

/// What [`sample_lasers`] keeps from tick to tick: the visiting order, the jobs' memory and
/// the workers' scratch.
#[derive(Default)]
pub struct LaserWork {
    order: SpatialOrder,
    memory: JobMemory,
    scratch: Vec<Scratch>,
}

/// Sense: every laser takes the scans due in this tick.
#[allow(clippy::type_complexity)]
pub fn sample_lasers(
    clock: Res<SimClock>,
    world: Res<StaticWorld>,
    outlines: Res<RobotOutlines>,
    pool: Res<KernelPool>,
    mut kept: Local<LaserWork>,
    mut lasers: Query<(
        Entity,
        &RobotIndex,
        &TruePose,
        &mut Laser,
        &mut LaserScans,
        &mut LaserTruth,
    )>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    // neighbours' scans one after the other on a worker read the same map tiles (measured on
    // 1000 robots with 180 beams: about 12 % less time in the sweep)
    let LaserWork {
        order,
        memory,
        scratch,
    } = &mut *kept;
    let mut jobs = memory.take();
    jobs.extend(lasers.iter_mut());
    let mut jobs = order.arrange(jobs, |job| job.0, |job| (job.2.pose.x, job.2.pose.y));
    let rays = world.rays();
    let outlines = &*outlines;
    pool.for_each_with(
        &mut jobs,
        scratch,
        |s, (_, index, truth, laser, scans, laser_truth)| {
            scans.next_tick();
            laser_truth.poses.clear();
            let laser = &mut **laser;
            laser.timer.due(start, end, &mut s.due);
            if !laser.enabled {
                return;
            }
            let spec = &laser.spec;
            let n = spec.beams();
            for &t in &s.due {
                let f = ((t - start) / dt).clamp(0.0, 1.0);
                let sensor = truth.interpolate(f).compose(&spec.mount);
                let p = [sensor.x as f32, sensor.y as f32];
                let a0 = (sensor.theta + spec.angle_min()) as f32;
                let inc = spec.increment as f32;
                let mut ranges = scans.buffer(n);
                rays.cast_scan(p, a0, inc, spec.max_range as f32, &mut ranges);
                outlines.near(
                    sensor.x,
                    sensor.y,
                    spec.max_range + 1.0,
                    index.0,
                    &mut s.near,
                );
                overlay_circles(p, a0, inc, &mut ranges, &s.near.circles);
                overlay_segments(p, a0, inc, &mut ranges, &s.near.segments);
                apply_noise(spec, &mut laser.rng, &mut ranges);
                scans.scans.push(LaserScan {
                    stamp: t,
                    angle_min: spec.angle_min() as f32,
                    angle_increment: inc,
                    range_min: spec.min_range as f32,
                    range_max: spec.max_range as f32,
                    ranges,
                });
                laser_truth.poses.push(sensor);
            }
            if !scans.scans.is_empty() {
                laser_truth.latest = laser_truth.poses.last().copied();
            }
        },
    );
    memory.keep(jobs);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;

    #[test]
    fn the_latest_scan_outlives_its_tick_until_a_newer_one() {
        let scan = |stamp: f64| LaserScan {
            stamp,
            angle_min: 0.0,
            angle_increment: 0.1,
            range_min: 0.1,
            range_max: 10.0,
            ranges: vec![1.0; 3],
        };
        let mut s = LaserScans::default();
        assert!(s.latest().is_none());
        s.scans.extend([scan(0.1), scan(0.2)]);
        assert_eq!(s.latest().map(|l| l.stamp), Some(0.2));
        s.next_tick();
        assert!(s.scans.is_empty(), "a new tick starts without scans");
        assert_eq!(s.latest().map(|l| l.stamp), Some(0.2));
        s.next_tick();
        assert_eq!(s.latest().map(|l| l.stamp), Some(0.2));
        s.scans.push(scan(0.5));
        assert_eq!(s.latest().map(|l| l.stamp), Some(0.5));
    }

    /// Dropped scans' buffers come back zeroed and at the asked length, the latest scan stays
    /// readable, and the spare buffers do not pile up.
    #[test]
    fn scan_buffers_are_reused_zeroed() {
        let mut s = LaserScans::default();
        let fire = |s: &mut LaserScans, stamp: f64, n: usize| {
            let mut ranges = s.buffer(n);
            assert_eq!(ranges, vec![0.0; n], "a fresh buffer is zeros");
            ranges.iter_mut().for_each(|r| *r = 7.0);
            let ptr = ranges.as_ptr();
            s.scans.push(LaserScan {
                stamp,
                angle_min: 0.0,
                angle_increment: 0.1,
                range_min: 0.1,
                range_max: 10.0,
                ranges,
            });
            ptr
        };
        let mut seen = Vec::new();
        for tick in 0..20 {
            s.next_tick();
            // two scans on even ticks, none on odd ones
            if tick % 2 == 0 {
                seen.push(fire(&mut s, tick as f64, 5));
                seen.push(fire(&mut s, tick as f64 + 0.5, 3 + tick % 4));
            }
            let latest = s.latest().map(|l| l.stamp).unwrap_or(-1.0);
            let want = if tick % 2 == 0 {
                tick as f64 + 0.5
            } else {
                tick as f64 - 0.5
            };
            assert_eq!(latest, want, "tick {tick}");
            assert!(
                s.spare.len() <= 2,
                "spare buffers pile up: {}",
                s.spare.len()
            );
        }
        seen.sort();
        seen.dedup();
        assert!(
            seen.len() <= 3,
            "{} distinct buffers for 20 scans",
            seen.len()
        );
    }

    #[test]
    fn presets_have_the_datasheet_beam_counts() {
        assert_eq!(LaserSpec::sick_lms100().beams(), 1081);
        assert_eq!(LaserSpec::hokuyo_urg04lx().beams(), 667);
    }

    #[test]
    fn noise_has_the_configured_spread_and_dropout() {
        let mut spec = LaserSpec::sick_lms100();
        spec.noise_std = 0.05;
        spec.dropout = 0.1;
        let mut rng = stream_rng(1, "r", "laser");
        let mut ranges = vec![5.0f32; 100_000];
        apply_noise(&spec, &mut rng, &mut ranges);
        let finite: Vec<f64> = ranges
            .iter()
            .filter(|r| r.is_finite())
            .map(|&r| r as f64)
            .collect();
        let drop = 1.0 - finite.len() as f64 / ranges.len() as f64;
        assert!((drop - 0.1).abs() < 0.01, "dropout {drop}");
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        let var = finite.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / finite.len() as f64;
        assert!((mean - 5.0).abs() < 0.002, "mean {mean}");
        assert!((var.sqrt() - 0.05).abs() < 0.002, "std {}", var.sqrt());
    }

    #[test]
    fn out_of_range_readings_follow_rep_117() {
        let spec = LaserSpec::sick_lms100();
        let mut rng = stream_rng(1, "r", "laser");
        let mut ranges = vec![f32::INFINITY, 25.0, 0.1, 3.0];
        apply_noise(&spec, &mut rng, &mut ranges);
        assert_eq!(ranges[0], f32::INFINITY);
        assert_eq!(ranges[1], f32::INFINITY);
        assert_eq!(ranges[2], f32::NEG_INFINITY);
        assert!((ranges[3] - 3.0).abs() < 0.1);
    }
}
