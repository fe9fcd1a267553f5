//! Tilt-compensated compass ([Park thesis §4.1.2]: CMPS09; [Park thesis §5.3.1]: off by
//! under 1° in the open, by 8–20° near electromagnetic interference). A reading is the true
//! heading as a compass azimuth (clockwise from north; magnetic north is taken as true north)
//! plus a constant bias, Gaussian noise and the deflection of the interference zone the robot is
//! in ([`crate::world::Zones`]). Recorded like the orientation of a sensor_msgs/Imu: a reading
//! carries that quaternion and its azimuth is computed from it, so a replay that rebuilds the
//! reading from a recorded message ([`CompassReading::from_orientation`]) gets the same azimuth
//! bit for bit (systems/ARCHITECTURE.md, "File formats": estimators consume readings shaped
//! like their ROS messages).

use crate::body::TruePose;
use crate::core::clock::RateTimer;
use crate::core::{SimClock, SimRng};
use crate::world::roads::geo::azimuth_of;
use crate::world::zones::Zones;
use bevy_ecs::prelude::*;
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::{FRAC_PI_2, TAU};

#[derive(Clone, Debug, PartialEq)]
pub struct CompassSpec {
    pub rate: f64,
    /// Standard deviation of the noise (degrees).
    pub noise_std_deg: f64,
    /// Constant error (degrees, clockwise positive): residual calibration.
    pub bias_deg: f64,
}

impl Default for CompassSpec {
    fn default() -> Self {
        CompassSpec {
            rate: 10.0,
            noise_std_deg: 0.5,
            bias_deg: 0.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompassReading {
    pub stamp: f64,
    /// Compass azimuth (radians clockwise from north, [0, 2π)), computed from `orientation`.
    pub azimuth: f64,
    /// Variance the sensor states (rad²): its noise only; it cannot know about interference.
    pub variance: f64,
    /// The heading as the orientation quaternion `[x, y, z, w]` of a sensor_msgs/Imu in the
    /// ENU world frame (REP 103/145: yaw counter-clockwise from east, π/2 − azimuth).
    pub orientation: [f64; 4],
}

impl CompassReading {
    /// The reading whose orientation quaternion is `orientation` (only its yaw is used).
    pub fn from_orientation(stamp: f64, orientation: [f64; 4], variance: f64) -> Self {
        let yaw = 2.0 * orientation[2].atan2(orientation[3]);
        let azimuth = (FRAC_PI_2 - yaw).rem_euclid(TAU);
        CompassReading {
            stamp,
            // rem_euclid of a tiny negative angle rounds up to 2π itself
            azimuth: if azimuth >= TAU { 0.0 } else { azimuth },
            variance,
            orientation,
        }
    }
}

/// The ENU orientation quaternion `[x, y, z, w]` of a compass azimuth (radians clockwise from
/// north): a rotation about z by the heading π/2 − azimuth.
pub fn orientation_of_azimuth(azimuth: f64) -> [f64; 4] {
    let yaw = crate::core::wrap_angle(FRAC_PI_2 - azimuth);
    let (s, c) = (yaw / 2.0).sin_cos();
    [0.0, 0.0, s, c]
}

#[derive(Component, Clone, Debug)]
pub struct Compass {
    pub spec: CompassSpec,
    pub rng: SimRng,
    pub timer: RateTimer,
    pub enabled: bool,
}

impl Compass {
    pub fn new(spec: CompassSpec, rng: SimRng) -> Self {
        Compass {
            timer: RateTimer::new(spec.rate, 0.0),
            spec,
            rng,
            enabled: true,
        }
    }

    /// The reading for true world heading `theta` (counter-clockwise from east) with the
    /// interference deflection `deflection` (radians, clockwise positive).
    pub fn read(&mut self, stamp: f64, theta: f64, deflection: f64) -> CompassReading {
        let n: f64 = self.rng.sample(StandardNormal);
        let truth = azimuth_of([theta.cos(), theta.sin()]);
        let err = (self.spec.bias_deg + self.spec.noise_std_deg * n).to_radians() + deflection;
        let azimuth = (truth + err).rem_euclid(TAU);
        CompassReading::from_orientation(
            stamp,
            orientation_of_azimuth(azimuth),
            self.spec.noise_std_deg.to_radians().powi(2),
        )
    }
}

#[derive(Component, Clone, Debug, Default)]
pub struct CompassReadings {
    pub readings: Vec<CompassReading>,
}

/// Sense: the readings due in this tick.
pub fn sample_compasses(
    clock: Res<SimClock>,
    zones: Option<Res<Zones>>,
    mut compasses: Query<(&TruePose, &mut Compass, &mut CompassReadings)>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    let mut due = Vec::new();
    for (truth, mut compass, mut out) in compasses.iter_mut() {
        out.readings.clear();
        compass.timer.due(start, end, &mut due);
        if !compass.enabled {
            continue;
        }
        for &t in &due {
            let f = ((t - start) / dt).clamp(0.0, 1.0);
            let pose = truth.interpolate(f);
            let at = [pose.x, pose.y];
            let deflection = zones.as_ref().map_or(0.0, |z| z.compass_deflection_at(at));
            let r = compass.read(t, pose.theta, deflection);
            out.readings.push(r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::world::zones::{Zone, ZoneKind, ZoneShape};

    fn angle_diff_deg(a: f64, b: f64) -> f64 {
        crate::core::wrap_angle(a - b).to_degrees()
    }

    #[test]
    fn a_reading_rebuilt_from_its_quaternion_is_identical() {
        let mut c = Compass::new(CompassSpec::default(), stream_rng(2, "c", "compass"));
        for k in 0..5000 {
            let theta = -3.2 + k as f64 * 0.00128;
            let r = c.read(k as f64, theta, 0.0);
            assert!((0.0..TAU).contains(&r.azimuth), "{}", r.azimuth);
            let raw = azimuth_of([theta.cos(), theta.sin()]);
            assert!(angle_diff_deg(r.azimuth, raw).abs() < 3.0, "{theta}");
            let again = CompassReading::from_orientation(r.stamp, r.orientation, r.variance);
            assert_eq!(again, r);
            assert_eq!(again.azimuth.to_bits(), r.azimuth.to_bits());
        }
        // the quaternion is the ENU heading: azimuth 90° (east) is yaw 0
        let east = orientation_of_azimuth(FRAC_PI_2);
        assert!(east[2].abs() < 1e-15 && (east[3] - 1.0).abs() < 1e-15);
        let r = CompassReading::from_orientation(0.0, orientation_of_azimuth(0.0), 0.0);
        assert!(r.azimuth.abs() < 1e-12 || (TAU - r.azimuth) < 1e-12);
    }

    #[test]
    fn in_the_open_the_compass_is_within_a_degree() {
        let mut c = Compass::new(CompassSpec::default(), stream_rng(1, "c", "compass"));
        let mut worst: f64 = 0.0;
        for k in 0..2000 {
            let theta = -3.0 + 0.003 * k as f64;
            let r = c.read(0.0, theta, 0.0);
            let truth = azimuth_of([theta.cos(), theta.sin()]);
            worst = worst.max(angle_diff_deg(r.azimuth, truth).abs());
        }
        // 0.5° noise: the largest of 2000 readings is about 3.5σ
        assert!(worst < 2.5, "{worst}");
        // heading east reads 90°, north 0°
        let mut quiet = Compass::new(
            CompassSpec {
                noise_std_deg: 0.0,
                ..CompassSpec::default()
            },
            stream_rng(1, "c", "compass"),
        );
        assert!((quiet.read(0.0, 0.0, 0.0).azimuth.to_degrees() - 90.0).abs() < 1e-9);
        assert!(
            quiet
                .read(0.0, std::f64::consts::FRAC_PI_2, 0.0)
                .azimuth
                .to_degrees()
                .abs()
                < 1e-9
        );
    }

    #[test]
    fn interference_turns_it_by_8_to_20_degrees() {
        let zones = Zones {
            zones: vec![Zone::new(
                "transformer",
                ZoneKind::EmInterference,
                ZoneShape::Circle {
                    centre: [0.0, 0.0],
                    radius: 12.0,
                },
            )],
        };
        let mut c = Compass::new(CompassSpec::default(), stream_rng(2, "c", "compass"));
        for x in [0.0, 3.0, 6.0, 9.0, 11.9] {
            let d = zones.compass_deflection_at([x, 0.0]);
            let r = c.read(0.0, 0.0, d);
            let err = angle_diff_deg(r.azimuth, std::f64::consts::FRAC_PI_2);
            assert!((6.5..=21.5).contains(&err), "{x} m from the centre: {err}°");
        }
        assert_eq!(zones.compass_deflection_at([20.0, 0.0]), 0.0);
    }
}
