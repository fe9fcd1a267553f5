//! Wheel encoders. The true wheel rotation follows the drive state (wheels turn as commanded, so
//! a robot pushing against a wall spins its wheels and odometry keeps counting, as in reality),
//! perturbed by slip noise; readings are cumulative quadrature tick counts at the encoder's own
//! rate. Calibration errors (relative errors of the left/right wheel radius and of the wheel base
//! that odometry assumes) make odometry curve away from the truth, like the robot of
//! [SLAM thesis §4.3.4] that drifted right; the [Park thesis] (§5.3.3) measured distance errors
//! of 0.31–1.06 % after calibration. An Ackermann robot has one drive-shaft encoder (both counts
//! equal) and reports its steering angle.

use crate::body::{DriveState, Kinematics};
use crate::core::clock::RateTimer;
use crate::core::{SimClock, SimRng};
use bevy_ecs::prelude::*;
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::TAU;

#[derive(Clone, Debug, PartialEq)]
pub struct EncoderSpec {
    pub ticks_per_rev: u32,
    /// Relative error of the left wheel radius odometry assumes (0.01 = 1 % too large).
    pub left_radius_error: f64,
    pub right_radius_error: f64,
    /// Relative error of the wheel base odometry assumes.
    pub wheel_base_error: f64,
    /// Standard deviation of the relative slip per tick of rotation.
    pub slip_std: f64,
    pub rate: f64,
}

impl Default for EncoderSpec {
    fn default() -> Self {
        EncoderSpec {
            ticks_per_rev: 4096,
            left_radius_error: 0.0,
            right_radius_error: 0.0,
            wheel_base_error: 0.0,
            slip_std: 0.0,
            rate: 50.0,
        }
    }
}

/// One reading, cumulative since start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncoderReading {
    pub stamp: f64,
    pub left_ticks: i64,
    pub right_ticks: i64,
    /// Measured steering angle (Ackermann), 0 for differential drives.
    pub steer: f64,
}

#[derive(Component, Clone, Debug)]
pub struct Encoder {
    pub spec: EncoderSpec,
    pub rng: SimRng,
    pub timer: RateTimer,
    pub enabled: bool,
    /// True wheel (or shaft) angles (rad), ground truth.
    left_angle: f64,
    right_angle: f64,
}

impl Encoder {
    pub fn new(spec: EncoderSpec, rng: SimRng) -> Self {
        let timer = RateTimer::new(spec.rate, 0.0);
        Encoder {
            spec,
            rng,
            timer,
            enabled: true,
            left_angle: 0.0,
            right_angle: 0.0,
        }
    }

    fn ticks(&self, angle: f64) -> i64 {
        (angle / TAU * self.spec.ticks_per_rev as f64).floor() as i64
    }
}

#[derive(Component, Clone, Debug, Default)]
pub struct EncoderReadings {
    pub readings: Vec<EncoderReading>,
}

/// Sense: advance the wheel angles over the tick and emit the readings due.
pub fn sample_encoders(
    clock: Res<SimClock>,
    mut encoders: Query<(&Kinematics, &DriveState, &mut Encoder, &mut EncoderReadings)>,
) {
    let (start, end, dt) = (clock.start(), clock.now(), clock.dt);
    let mut due = Vec::new();
    for (kin, state, mut enc, mut out) in encoders.iter_mut() {
        out.readings.clear();
        let (wl, wr) = match kin {
            Kinematics::DiffDrive(_) => (state.left, state.right),
            Kinematics::Ackermann(a) => {
                let w = state.speed / a.wheel_radius;
                (w, w)
            }
        };
        let slip = enc.spec.slip_std;
        let nl: f64 = enc.rng.sample(StandardNormal);
        let nr: f64 = enc.rng.sample(StandardNormal);
        let dl = wl * dt * (1.0 + slip * nl);
        let dr = if matches!(kin, Kinematics::Ackermann(_)) {
            dl
        } else {
            wr * dt * (1.0 + slip * nr)
        };
        let (l0, r0) = (enc.left_angle, enc.right_angle);
        enc.left_angle += dl;
        enc.right_angle += dr;
        enc.timer.due(start, end, &mut due);
        if !enc.enabled {
            continue;
        }
        for &t in &due {
            let f = ((t - start) / dt).clamp(0.0, 1.0);
            out.readings.push(EncoderReading {
                stamp: t,
                left_ticks: enc.ticks(l0 + dl * f),
                right_ticks: enc.ticks(r0 + dr * f),
                steer: state.steer,
            });
        }
    }
}
