//! Typed, read-only views of a [`super::Simulation`]'s robots, people and doors between ticks:
//! what a script or a user's program reads instead of querying the ECS world. A view borrows
//! the world; it is taken again after each step.

use super::command::{SimError, names};
use bevy_ecs::prelude::*;
use systems::body::{Collisions, TruePose, TrueTwist};
use systems::core::Pose2;
use systems::eval::localization_metrics::CONVERGENCE_HOLD_S;
use systems::eval::trajectory::convergence_index;
use systems::eval::{LocalizationSamples, RobotMetrics};
use systems::localization::{Filter, Localizers, WheelOdometry};
use systems::matching::ProbGrid;
use systems::navigation::Navigator;
use systems::navigation::navigator::Phase;
use systems::sensors::camera::{CameraFrame, CameraImage};
use systems::sensors::{
    Camera, CameraImages, CompassReading, CompassReadings, EncoderReading, EncoderReadings, GpsFix,
    GpsReadings, LaserScan, LaserScans, LaserTruth, SonarReadings,
};
use systems::world::roads::{RoadSurface, SurfaceRaster};

/// A robot's linear and angular velocity (m/s, rad/s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Twist {
    /// Forward speed (m/s).
    pub v: f64,
    /// Yaw rate (rad/s).
    pub w: f64,
}

/// One robot of a running simulation.
#[derive(Clone, Copy)]
pub struct RobotView<'w> {
    pub(super) world: &'w World,
    pub(super) entity: Entity,
    pub(super) name: &'w str,
    pub(super) index: usize,
}

impl<'w> RobotView<'w> {
    /// The robot's name in the scenario.
    pub fn name(&self) -> &'w str {
        self.name
    }

    /// Its place in the scenario's robot list.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The ECS entity, for programs that add their own components or systems.
    pub fn entity(&self) -> Entity {
        self.entity
    }

    fn get<T: Component>(&self) -> Option<&'w T> {
        self.world.get::<T>(self.entity)
    }

    /// The true pose (ground truth, world frame).
    pub fn pose(&self) -> Pose2 {
        self.get::<TruePose>().map(|t| t.pose).unwrap_or_default()
    }

    /// The true velocity.
    pub fn twist(&self) -> Twist {
        self.get::<TrueTwist>()
            .map(|t| Twist { v: t.v, w: t.w })
            .unwrap_or_default()
    }

    /// The pose integrated from the wheel encoders (None without encoders).
    pub fn odometry(&self) -> Option<Pose2> {
        self.get::<WheelOdometry>().map(|o| o.pose)
    }

    /// The latest laser scan, of this tick or an earlier one (None before the first scan or
    /// without a laser).
    pub fn scan(&self) -> Option<ScanView<'w>> {
        let scan = self.get::<LaserScans>()?.latest()?;
        let sensor = self.get::<LaserTruth>().and_then(|t| t.latest);
        Some(ScanView { scan, sensor })
    }

    /// The encoder readings of the last tick.
    pub fn encoder_readings(&self) -> &'w [EncoderReading] {
        self.get::<EncoderReadings>()
            .map_or(&[], |r| r.readings.as_slice())
    }

    /// The GPS fixes of the last tick.
    pub fn gps_fixes(&self) -> &'w [GpsFix] {
        self.get::<GpsReadings>()
            .map_or(&[], |r| r.fixes.as_slice())
    }

    /// The compass readings of the last tick.
    pub fn compass_readings(&self) -> &'w [CompassReading] {
        self.get::<CompassReadings>()
            .map_or(&[], |r| r.readings.as_slice())
    }

    /// The latest sonar ranges, one per mount (None without sonars).
    pub fn sonar(&self) -> Option<&'w SonarReadings> {
        self.get::<SonarReadings>()
    }

    /// The latest camera frame (None without a camera, or before its first frame).
    pub fn camera(&self) -> Option<&'w CameraFrame> {
        self.get::<CameraImages>()?.frame.as_ref()
    }

    /// The latest camera frame's pixels (None without a camera, or before its first frame):
    /// rendered when asked, as the recording renders it, from the frame's pose and draws.
    pub fn camera_image(&self) -> Option<CameraImage> {
        let frame = self.camera()?;
        let camera = self.get::<Camera>()?;
        let image = match self.world.get_resource::<RoadSurface>() {
            Some(surface) => camera.render(frame, &surface.0),
            None => camera.render(frame, &SurfaceRaster::empty()),
        };
        Some(CameraImage {
            stamp: frame.stamp,
            ..image
        })
    }

    /// Every localizer and SLAM system of the robot, in the scenario's order.
    pub fn localizers(&self) -> Vec<LocalizerView<'w>> {
        let samples = self.get::<LocalizationSamples>();
        self.get::<Localizers>().map_or(Vec::new(), |l| {
            l.items
                .iter()
                .map(|l| LocalizerView {
                    name: &l.name,
                    kind: l.filter.kind(),
                    estimate: l.latest.as_ref().map(|e| Estimate {
                        stamp: e.stamp,
                        pose: e.estimate.pose,
                        covariance: e.estimate.covariance,
                    }),
                    degraded: l.degraded,
                    converged_after: samples
                        .and_then(|s| s.per_localizer.iter().find(|(n, _)| *n == l.name))
                        .and_then(|(_, s)| {
                            // converged once the tracking has held for the hold time
                            let last = s.last()?.t;
                            convergence_index(s, CONVERGENCE_HOLD_S)
                                .map(|i| s[i].t)
                                .filter(|t| last - t >= CONVERGENCE_HOLD_S)
                        }),
                    filter: &l.filter,
                })
                .collect()
        })
    }

    /// The localizer or SLAM system called `name`.
    pub fn localizer(&self, name: &str) -> Result<LocalizerView<'w>, SimError> {
        let mut all = self.localizers();
        match all.iter().position(|l| l.name == name) {
            Some(i) => Ok(all.swap_remove(i)),
            None => Err(SimError::UnknownLocalizer {
                robot: self.name.to_string(),
                name: name.to_string(),
                known: names(all.iter().map(|l| l.name)),
            }),
        }
    }

    /// The navigator's tasks and state (None for a robot driven by a behaviour).
    pub fn navigation(&self) -> Option<NavigationView<'w>> {
        self.get::<Navigator>()
            .map(|n| NavigationView { navigator: n })
    }

    /// Collisions so far, with walls, other robots and people.
    pub fn collisions(&self) -> Collisions {
        self.get::<RobotMetrics>()
            .map(|m| m.collisions)
            .unwrap_or_default()
    }

    /// Distance driven so far (m).
    pub fn distance(&self) -> f64 {
        self.get::<RobotMetrics>().map_or(0.0, |m| m.distance_m)
    }
}

/// A laser scan and the true sensor pose it was taken from.
#[derive(Clone, Copy)]
pub struct ScanView<'w> {
    scan: &'w LaserScan,
    sensor: Option<Pose2>,
}

impl<'w> ScanView<'w> {
    /// The scan as the sensor reported it (stamp, angles, ranges; +Inf for no return).
    pub fn scan(&self) -> &'w LaserScan {
        self.scan
    }

    /// The ranges (m), beam by beam from the first angle; +Inf for no return.
    pub fn ranges(&self) -> &'w [f32] {
        &self.scan.ranges
    }

    /// The beam angles in the sensor frame (rad), one per range.
    pub fn angles(&self) -> impl Iterator<Item = f32> + 'w {
        let s = self.scan;
        (0..s.ranges.len()).map(move |i| s.angle_min + i as f32 * s.angle_increment)
    }

    /// The true sensor pose of the scan (world frame).
    pub fn sensor_pose(&self) -> Option<Pose2> {
        self.sensor
    }

    /// The returns as points in the world frame, from the true sensor pose (beams without a
    /// return, or below the minimum range, left out).
    pub fn world_points(&self) -> Vec<[f64; 2]> {
        let Some(p) = self.sensor else {
            return Vec::new();
        };
        let (min, max) = (self.scan.range_min, self.scan.range_max);
        self.angles()
            .zip(&self.scan.ranges)
            .filter(|(_, r)| r.is_finite() && **r >= min && **r <= max)
            .map(|(a, &r)| {
                let t = p.theta + a as f64;
                [p.x + r as f64 * t.cos(), p.y + r as f64 * t.sin()]
            })
            .collect()
    }
}

/// A pose estimate with its covariance (x, y, θ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The time of the data it comes from (s).
    pub stamp: f64,
    /// The estimated pose (map frame).
    pub pose: Pose2,
    /// Its covariance over (x, y, θ) (m², rad²).
    pub covariance: [[f64; 3]; 3],
}

/// One localizer or SLAM system of a robot.
#[derive(Clone, Copy, Debug)]
pub struct LocalizerView<'w> {
    /// The name given in the scenario.
    pub name: &'w str,
    /// Its type as written in scenario files (`mcl`, `markov_grid`, ...).
    pub kind: &'static str,
    /// The latest estimate (None before its first).
    pub estimate: Option<Estimate>,
    /// The robot's laser is faulted, or its scans have no usable beam: the estimate is the last
    /// one carried forward by the odometry, its covariance growing with the path, until a scan
    /// with returns comes.
    pub degraded: bool,
    /// When its estimates came and stayed close to the truth (the summary's convergence,
    /// judged on the estimates so far: known once they have stayed close for the summary's
    /// hold time; s), None if not (yet).
    pub converged_after: Option<f64>,
    filter: &'w Filter,
}

impl LocalizerView<'_> {
    /// A SLAM system's map so far (P(occupied) per cell, map frame), None for localizers.
    pub fn map(&self) -> Option<ProbGrid> {
        match self.filter {
            Filter::Scan(e) => e.map(),
            _ => None,
        }
    }

    /// A SLAM system's best trajectory so far (stamp, pose), empty for localizers.
    pub fn trajectory(&self) -> Vec<(f64, Pose2)> {
        match self.filter {
            Filter::Scan(e) => e.trajectory(),
            _ => Vec::new(),
        }
    }

    /// The algorithm itself, for programs that know its type ([`Filter`]).
    pub fn filter(&self) -> &Filter {
        self.filter
    }
}

/// A walking person.
#[derive(Clone, Copy, Debug)]
pub struct PersonView<'w> {
    /// The name given in the scenario.
    pub name: &'w str,
    /// Where the person is (ground truth).
    pub pose: Pose2,
    /// The route point the person walks to next.
    pub next_point: usize,
}

/// A robot's navigator.
#[derive(Clone, Copy)]
pub struct NavigationView<'w> {
    navigator: &'w Navigator,
}

impl<'w> NavigationView<'w> {
    /// Tasks done so far.
    pub fn tasks_done(&self) -> usize {
        self.navigator.task.min(self.navigator.tasks.len())
    }

    /// Tasks given in all.
    pub fn tasks(&self) -> usize {
        self.navigator.tasks.len()
    }

    /// Every task is done and the robot is idle.
    pub fn finished(&self) -> bool {
        self.navigator.finished()
    }

    /// What it is doing now.
    pub fn phase(&self) -> &'w Phase {
        &self.navigator.phase
    }

    /// The current task, as the recording describes it.
    pub fn status(&self) -> String {
        self.navigator.status_text()
    }
}

/// A door of the world.
#[derive(Clone, Debug, PartialEq)]
pub struct DoorView {
    /// Its name in the map's places file.
    pub name: String,
    /// Open (passable) or closed.
    pub open: bool,
}
