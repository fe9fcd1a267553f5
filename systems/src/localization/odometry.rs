//! Wheel odometry: integrates encoder tick increments with the geometry the robot BELIEVES it
//! has (nominal wheel radii and wheel base times the calibration errors), along circular arcs.
//! Differential drive: ds = (ds_l + ds_r)/2, dθ = (ds_r − ds_l)/b; Ackermann: ds from the drive
//! shaft, dθ = ds·tan(steer)/L.

use crate::core::Pose2;
use crate::sensors::EncoderReadings;
use bevy_ecs::prelude::*;
use std::f64::consts::TAU;

#[derive(Clone, Debug, PartialEq)]
pub enum OdometryModel {
    DiffDrive {
        left_radius: f64,
        right_radius: f64,
        wheel_base: f64,
    },
    Ackermann {
        wheel_radius: f64,
        wheelbase: f64,
    },
}

/// The odometry estimate (frame `odom`, which coincides with `map` at the start pose).
#[derive(Component, Clone, Debug)]
pub struct WheelOdometry {
    pub model: OdometryModel,
    pub ticks_per_rev: u32,
    pub pose: Pose2,
    pub stamp: f64,
    last: Option<(i64, i64)>,
    /// The poses integrated this tick, after the last one of the previous tick (for
    /// [`WheelOdometry::pose_at`]).
    trail: Vec<(f64, Pose2)>,
}

impl WheelOdometry {
    pub fn new(model: OdometryModel, ticks_per_rev: u32, start: Pose2) -> Self {
        WheelOdometry {
            model,
            ticks_per_rev,
            pose: start,
            stamp: 0.0,
            last: None,
            trail: Vec::new(),
        }
    }

    /// Consumes one reading.
    pub fn update(&mut self, left_ticks: i64, right_ticks: i64, steer: f64, stamp: f64) {
        let Some((l0, r0)) = self.last.replace((left_ticks, right_ticks)) else {
            self.stamp = stamp;
            return;
        };
        let k = TAU / self.ticks_per_rev as f64;
        // counters wrap like the hardware's (a jump across the end of the range overflowed)
        let dl = left_ticks.wrapping_sub(l0) as f64 * k;
        let dr = right_ticks.wrapping_sub(r0) as f64 * k;
        let (ds, dth) = match self.model {
            OdometryModel::DiffDrive {
                left_radius,
                right_radius,
                wheel_base,
            } => {
                let sl = dl * left_radius;
                let sr = dr * right_radius;
                ((sl + sr) / 2.0, (sr - sl) / wheel_base)
            }
            OdometryModel::Ackermann {
                wheel_radius,
                wheelbase,
            } => {
                let s = dl * wheel_radius;
                // a steering reading that is no angle (NaN, ±∞) turns nothing
                let steer = if steer.is_finite() { steer } else { 0.0 };
                (s, s * steer.tan() / wheelbase)
            }
        };
        self.pose = crate::body::kinematics::integrate_arc(&self.pose, ds, dth, 1.0);
        self.stamp = stamp;
        self.trail.push((stamp, self.pose));
    }

    /// The poses integrated in the current tick, after the last one of the previous tick
    /// (`(stamp, pose)` in time order): every odometry update, for recorders.
    pub fn trail(&self) -> &[(f64, Pose2)] {
        &self.trail
    }

    /// Takes a pose measured by another odometry (a replayed nav_msgs/Odometry) instead of
    /// integrating encoder ticks.
    pub fn set_pose(&mut self, pose: Pose2, stamp: f64) {
        self.pose = pose;
        self.stamp = stamp;
        self.trail.push((stamp, pose));
    }

    /// Keeps only the latest pose of the trail (called at the start of each tick).
    pub fn start_tick(&mut self) {
        let keep = self.trail.len().saturating_sub(1);
        self.trail.drain(..keep);
    }

    /// The odometry pose at time `t` of the current tick: interpolated between readings, or
    /// extrapolated from the last two (by at most one reading interval) after the last one.
    pub fn pose_at(&self, t: f64) -> Pose2 {
        let n = self.trail.len();
        if n < 2 {
            return self.pose;
        }
        let i = self.trail.partition_point(|(s, _)| *s < t).clamp(1, n - 1);
        let ((t0, p0), (t1, p1)) = (self.trail[i - 1], self.trail[i]);
        if t1 <= t0 {
            return p1;
        }
        let f = ((t - t0) / (t1 - t0)).clamp(0.0, 2.0);
        p0.lerp(&p1, f)
    }
}

/// The pose a robot believes it has — what controllers and planners use. Written by the estimator
/// selected for navigation (wheel odometry until localization takes over).
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct NavBelief {
    pub pose: Pose2,
    pub stamp: f64,
}

/// Estimate: integrate this tick's encoder readings.
pub fn integrate_odometry(
    mut robots: Query<(&EncoderReadings, &mut WheelOdometry, Option<&mut NavBelief>)>,
) {
    for (readings, mut odom, belief) in robots.iter_mut() {
        odom.start_tick();
        for r in &readings.readings {
            odom.update(r.left_ticks, r.right_ticks, r.steer, r.stamp);
        }
        if let Some(mut b) = belief {
            b.pose = odom.pose;
            b.stamp = odom.stamp;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_and_turn_in_place() {
        let model = OdometryModel::DiffDrive {
            left_radius: 0.1,
            right_radius: 0.1,
            wheel_base: 0.5,
        };
        let mut o = WheelOdometry::new(model.clone(), 1000, Pose2::IDENTITY);
        o.update(0, 0, 0.0, 0.0);
        // 1000 ticks = one revolution = 2π·0.1 m
        o.update(1000, 1000, 0.0, 1.0);
        assert!((o.pose.x - TAU * 0.1).abs() < 1e-12 && o.pose.y.abs() < 1e-12);
        let mut o = WheelOdometry::new(model, 1000, Pose2::IDENTITY);
        o.update(0, 0, 0.0, 0.0);
        // wheels opposite by a quarter of the base circle: dθ = (sr - sl)/b
        o.update(-1000, 1000, 0.0, 1.0);
        assert!((o.pose.theta - wrap(2.0 * TAU * 0.1 / 0.5)).abs() < 1e-12);
        assert!(o.pose.x.abs() < 1e-12);
    }

    fn wrap(a: f64) -> f64 {
        crate::core::wrap_angle(a)
    }

    #[test]
    fn unequal_radii_curve() {
        // right wheel believed 1 % larger: equal ticks → odometry turns left
        let model = OdometryModel::DiffDrive {
            left_radius: 0.1,
            right_radius: 0.101,
            wheel_base: 0.5,
        };
        let mut o = WheelOdometry::new(model, 1000, Pose2::IDENTITY);
        for i in 0..=100 {
            o.update(i * 100, i * 100, 0.0, i as f64);
        }
        assert!(o.pose.theta > 0.05 && o.pose.y > 0.1, "{:?}", o.pose);
    }

    #[test]
    fn pose_between_readings_is_interpolated() {
        let model = OdometryModel::DiffDrive {
            left_radius: 0.1,
            right_radius: 0.1,
            wheel_base: 0.5,
        };
        let mut o = WheelOdometry::new(model, 1000, Pose2::IDENTITY);
        o.update(0, 0, 0.0, 0.0);
        o.update(1000, 1000, 0.0, 0.02);
        o.start_tick();
        o.update(2000, 2000, 0.0, 0.04);
        let step = TAU * 0.1;
        assert!((o.pose_at(0.03).x - 1.5 * step).abs() < 1e-9);
        // after the last reading: extrapolated, at most one interval ahead
        assert!((o.pose_at(0.05).x - 2.5 * step).abs() < 1e-9);
        assert!((o.pose_at(9.0).x - 3.0 * step).abs() < 1e-9);
    }

    /// Regression: a counter jumping across the end of its range overflowed the tick
    /// difference (a panic where overflow is checked); a NaN steering reading made the pose NaN.
    #[test]
    fn a_wrapping_counter_and_a_nan_steering_angle_leave_the_pose_finite() {
        let mut o = WheelOdometry::new(
            OdometryModel::DiffDrive {
                left_radius: 0.1,
                right_radius: 0.1,
                wheel_base: 0.5,
            },
            1000,
            Pose2::IDENTITY,
        );
        o.update(i64::MAX - 10, i64::MAX - 10, 0.0, 0.0);
        // eleven ticks on each wheel, past the end of the range: straight ahead
        o.update(i64::MIN, i64::MIN, 0.0, 0.02);
        assert!(
            (o.pose.x - 11.0 * TAU / 1000.0 * 0.1).abs() < 1e-12 && o.pose.theta == 0.0,
            "{:?}",
            o.pose
        );
        let mut car = WheelOdometry::new(
            OdometryModel::Ackermann {
                wheel_radius: 0.05,
                wheelbase: 0.35,
            },
            1000,
            Pose2::IDENTITY,
        );
        car.update(0, 0, 0.0, 0.0);
        car.update(100, 100, f64::NAN, 0.02);
        car.update(200, 200, f64::INFINITY, 0.04);
        assert!(car.pose.x > 0.0 && car.pose.theta == 0.0, "{:?}", car.pose);
    }

    mod props {
        use super::*;
        use crate::core::props::{config, extreme_f64};
        use proptest::prelude::*;

        /// Encoder readings as a faulty encoder sends them: counting normally, stuck, or
        /// jumping anywhere in the counter's range.
        fn ticks() -> impl Strategy<Value = Vec<(i64, i64, f64)>> {
            proptest::collection::vec(
                (
                    prop_oneof![
                        4 => (-200i64..200, -200i64..200),
                        1 => Just((0i64, 0i64)),
                        1 => (-10_000_000i64..10_000_000, -10_000_000i64..10_000_000),
                        1 => (any::<i64>(), any::<i64>()),
                    ],
                    extreme_f64(),
                ),
                1..30,
            )
            .prop_map(|steps| {
                let (mut l, mut r) = (0i64, 0i64);
                steps
                    .into_iter()
                    .map(|((dl, dr), steer)| {
                        (l, r) = (l.wrapping_add(dl), r.wrapping_add(dr));
                        (l, r, steer)
                    })
                    .collect()
            })
        }

        proptest! {
            #![proptest_config(config(256))]

            /// Whatever the counters do and the steering angle reads, the odometry pose and
            /// every pose of its trail stay finite.
            #[test]
            fn odometry_stays_finite_under_encoder_faults(
                car in any::<bool>(),
                readings in ticks(),
            ) {
                let model = if car {
                    OdometryModel::Ackermann { wheel_radius: 0.05, wheelbase: 0.35 }
                } else {
                    OdometryModel::DiffDrive {
                        left_radius: 0.1,
                        right_radius: 0.1,
                        wheel_base: 0.5,
                    }
                };
                let mut o = WheelOdometry::new(model, 4096, Pose2::IDENTITY);
                for (k, (l, r, steer)) in readings.into_iter().enumerate() {
                    o.update(l, r, steer, k as f64 * 0.02);
                    let p = o.pose;
                    prop_assert!(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite(), "{p:?}");
                    let q = o.pose_at(k as f64 * 0.02 + 0.01);
                    prop_assert!(q.x.is_finite() && q.y.is_finite() && q.theta.is_finite(), "{q:?}");
                }
            }
        }
    }
}
