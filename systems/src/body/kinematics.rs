//! Drive kinematics. Commands are body velocities (v, ω); each model turns them into actuator
//! states under its limits and back into the body twist actually driven, and poses advance along
//! exact circular arcs (the closed form of constant (v, ω) over a step).

use crate::core::Pose2;
use bevy_ecs::prelude::Component;

/// Differential drive: two wheels on a common axle.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffDrive {
    /// Distance between the wheel contact points (m).
    pub wheel_base: f64,
    pub wheel_radius: f64,
    /// Wheel speed limit (rad/s).
    pub max_wheel_speed: f64,
    /// Wheel acceleration limit (rad/s²).
    pub max_wheel_accel: f64,
}

/// Ackermann (car-like) steering: bicycle model, no turning on the spot.
#[derive(Clone, Debug, PartialEq)]
pub struct Ackermann {
    /// Front-to-rear axle distance (m).
    pub wheelbase: f64,
    /// Steering angle limit (rad).
    pub max_steer: f64,
    /// Steering rate limit (rad/s).
    pub max_steer_rate: f64,
    pub max_speed: f64,
    pub max_accel: f64,
    /// Drive wheel radius (for the drive-shaft encoder).
    pub wheel_radius: f64,
}

#[derive(Component, Clone, Debug, PartialEq)]
pub enum Kinematics {
    DiffDrive(DiffDrive),
    Ackermann(Ackermann),
}

/// Desired body velocities, written by controllers.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveCommand {
    /// Forward speed (m/s).
    pub v: f64,
    /// Yaw rate (rad/s).
    pub w: f64,
    /// A car's steering angle (rad) given directly (the speed/steer form): an Ackermann drive
    /// steers to it instead of to the angle `w` asks for, also at a standstill. Differential
    /// drives ignore it.
    pub steer: Option<f64>,
}

impl DriveCommand {
    /// The (v, ω) form.
    pub const fn new(v: f64, w: f64) -> DriveCommand {
        DriveCommand { v, w, steer: None }
    }

    /// Whether a drive can act on it: no NaN in it (infinite speeds are fine: the drive's
    /// limits make them its fastest).
    pub fn is_usable(&self) -> bool {
        !(self.v.is_nan() || self.w.is_nan() || self.steer.is_some_and(f64::is_nan))
    }
}

/// Actuator state, advanced by the physics step.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveState {
    /// Wheel speeds (rad/s) of a differential drive.
    pub left: f64,
    pub right: f64,
    /// Forward speed (m/s) and steering angle (rad) of an Ackermann drive.
    pub speed: f64,
    pub steer: f64,
}

/// `current` moved towards `target` by at most `max_delta` (rate limits).
pub(crate) fn approach(current: f64, target: f64, max_delta: f64) -> f64 {
    current + (target - current).clamp(-max_delta, max_delta)
}

impl DiffDrive {
    /// Wheel speeds for (v, ω), scaled down together if one exceeds the limit (keeps curvature).
    pub fn wheel_targets(&self, cmd: &DriveCommand) -> (f64, f64) {
        let half = self.wheel_base / 2.0;
        let l = (cmd.v - cmd.w * half) / self.wheel_radius;
        let r = (cmd.v + cmd.w * half) / self.wheel_radius;
        if !(l.is_finite() && r.is_finite()) {
            return self.saturated_targets(cmd);
        }
        let m = l.abs().max(r.abs());
        if m > self.max_wheel_speed && m > 0.0 {
            let s = self.max_wheel_speed / m;
            (l * s, r * s)
        } else {
            (l, r)
        }
    }

    /// [`DiffDrive::wheel_targets`] of a command whose wheel speeds overflow (huge or infinite
    /// v or ω): the command's curvature at the speed limit, computed on the command scaled
    /// into range first (inf · 0 made them NaN); a NaN command stops the wheels.
    fn saturated_targets(&self, cmd: &DriveCommand) -> (f64, f64) {
        let (v, w) = (
            cmd.v.clamp(-f64::MAX, f64::MAX),
            cmd.w.clamp(-f64::MAX, f64::MAX),
        );
        let scale = v.abs().max(w.abs());
        if scale.is_nan() || scale == 0.0 {
            return (0.0, 0.0);
        }
        let half = self.wheel_base / 2.0;
        let l = (v / scale - w / scale * half) / self.wheel_radius;
        let r = (v / scale + w / scale * half) / self.wheel_radius;
        let m = l.abs().max(r.abs());
        if m > 0.0 && m.is_finite() {
            (l / m * self.max_wheel_speed, r / m * self.max_wheel_speed)
        } else {
            (0.0, 0.0)
        }
    }

    /// Body twist (v, ω) of wheel speeds.
    pub fn twist(&self, left: f64, right: f64) -> (f64, f64) {
        let v = self.wheel_radius * (left + right) / 2.0;
        let w = self.wheel_radius * (right - left) / self.wheel_base;
        (v, w)
    }
}

impl Ackermann {
    /// Steering angle giving yaw rate ω at speed v; none at standstill (no turning on the spot).
    pub fn steer_for(&self, v: f64, w: f64) -> Option<f64> {
        if v.abs() < 1e-6 {
            return None;
        }
        // ∞/∞ (both infinite) has no angle: the wheels stay where they are
        let steer = (w * self.wheelbase / v).atan();
        (!steer.is_nan()).then(|| steer.clamp(-self.max_steer, self.max_steer))
    }

    pub fn yaw_rate(&self, speed: f64, steer: f64) -> f64 {
        speed * steer.tan() / self.wheelbase
    }

    /// The speed/steer command: forward `speed` (m/s) with the wheels at `steer` (rad); its
    /// `w` is the yaw rate that steering gives at that speed (what recordings show).
    pub fn command(&self, speed: f64, steer: f64) -> DriveCommand {
        DriveCommand {
            v: speed,
            w: self.yaw_rate(speed, steer),
            steer: Some(steer),
        }
    }
}

impl Kinematics {
    /// Advances the actuator state towards the command over `dt` under the limits and returns the
    /// body twist (v, ω) driven during the step. A command with a NaN in it (a broken driver)
    /// counts as a stop: it never reaches the actuators.
    pub fn step(&self, cmd: &DriveCommand, state: &mut DriveState, dt: f64) -> (f64, f64) {
        const STOP: DriveCommand = DriveCommand::new(0.0, 0.0);
        let cmd = if cmd.is_usable() { cmd } else { &STOP };
        match self {
            Kinematics::DiffDrive(d) => {
                let (tl, tr) = d.wheel_targets(cmd);
                let dmax = d.max_wheel_accel * dt;
                state.left = approach(state.left, tl, dmax);
                state.right = approach(state.right, tr, dmax);
                d.twist(state.left, state.right)
            }
            Kinematics::Ackermann(a) => {
                let target_v = cmd.v.clamp(-a.max_speed, a.max_speed);
                state.speed = approach(state.speed, target_v, a.max_accel * dt);
                let target = match cmd.steer {
                    Some(steer) => Some(steer.clamp(-a.max_steer, a.max_steer)),
                    None => a.steer_for(cmd.v, cmd.w),
                };
                if let Some(target_steer) = target {
                    state.steer = approach(state.steer, target_steer, a.max_steer_rate * dt);
                }
                (state.speed, a.yaw_rate(state.speed, state.steer))
            }
        }
    }

    /// Fastest forward speed the drive can reach (m/s).
    pub fn max_speed(&self) -> f64 {
        match self {
            Kinematics::DiffDrive(d) => d.max_wheel_speed * d.wheel_radius,
            Kinematics::Ackermann(a) => a.max_speed,
        }
    }
}

/// The pose after moving with constant (v, ω) for `dt` from `pose`: an exact circular arc
/// (a straight line when ω = 0).
pub fn integrate_arc(pose: &Pose2, v: f64, w: f64, dt: f64) -> Pose2 {
    let dth = w * dt;
    let (dx, dy) = if dth.abs() < 1e-9 {
        // second-order expansion avoids 0/0
        (v * dt * (1.0 - dth * dth / 6.0), v * dt * dth / 2.0)
    } else {
        (v / w * dth.sin(), v / w * (1.0 - dth.cos()))
    };
    pose.compose(&Pose2::new(dx, dy, dth))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn arc_closes_a_circle() {
        // v = 1 m/s, ω = 0.5 rad/s → radius 2 m, full circle in 4π s
        let mut p = Pose2::new(1.0, 2.0, 0.3);
        let n = 1000;
        let dt = 4.0 * PI / n as f64;
        let mut max_dev: f64 = 0.0;
        let centre = p.transform_point([0.0, 2.0]);
        for _ in 0..n {
            p = integrate_arc(&p, 1.0, 0.5, dt);
            max_dev = max_dev.max(((p.x - centre[0]).hypot(p.y - centre[1]) - 2.0).abs());
        }
        assert!(max_dev < 1e-9, "{max_dev}");
        assert!((p.x - 1.0).abs() < 1e-9 && (p.y - 2.0).abs() < 1e-9);
        // quarter circle: from heading 0 at origin, ends at (2, 2) heading π/2
        let q = integrate_arc(&Pose2::IDENTITY, 1.0, 0.5, PI);
        assert!((q.x - 2.0).abs() < 1e-12 && (q.y - 2.0).abs() < 1e-12);
        assert!((q.theta - PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn diff_drive_limits_keep_curvature() {
        let d = DiffDrive {
            wheel_base: 0.5,
            wheel_radius: 0.1,
            max_wheel_speed: 10.0,
            max_wheel_accel: 1000.0,
        };
        let cmd = DriveCommand::new(2.0, 2.0);
        let (l, r) = d.wheel_targets(&cmd);
        assert!(r <= 10.0 + 1e-12 && l > 0.0);
        let (v, w) = d.twist(l, r);
        assert!((w / v - 1.0).abs() < 1e-12, "curvature kept");
        // spin in place is allowed
        let (v, w) = d.twist(-5.0, 5.0);
        assert_eq!(v, 0.0);
        assert!((w - 2.0).abs() < 1e-12);
    }

    #[test]
    fn acceleration_is_limited() {
        let k = Kinematics::DiffDrive(DiffDrive {
            wheel_base: 0.5,
            wheel_radius: 0.1,
            max_wheel_speed: 20.0,
            max_wheel_accel: 10.0,
        });
        let mut s = DriveState::default();
        let cmd = DriveCommand::new(1.0, 0.0);
        let (v, _) = k.step(&cmd, &mut s, 0.1);
        assert!((v - 0.1).abs() < 1e-12); // 10 rad/s² · 0.1 s · 0.1 m
        for _ in 0..20 {
            k.step(&cmd, &mut s, 0.1);
        }
        let (v, _) = k.step(&cmd, &mut s, 0.1);
        assert!((v - 1.0).abs() < 1e-12);
    }

    /// A 0.35 m car steering at most 0.5 rad at 1 rad/s, up to 2 m/s.
    fn small_car() -> Ackermann {
        Ackermann {
            wheelbase: 0.35,
            max_steer: 0.5,
            max_steer_rate: 1.0,
            max_speed: 2.0,
            max_accel: 100.0,
            wheel_radius: 0.05,
        }
    }

    #[test]
    fn ackermann_cannot_turn_on_the_spot() {
        let k = Kinematics::Ackermann(small_car());
        let mut s = DriveState::default();
        let (v, w) = k.step(&DriveCommand::new(0.0, 1.0), &mut s, 0.1);
        assert_eq!((v, w), (0.0, 0.0));
        // steering is rate limited and clamped
        let mut s = DriveState::default();
        k.step(&DriveCommand::new(1.0, 10.0), &mut s, 0.1);
        assert!((s.steer - 0.1).abs() < 1e-12);
        for _ in 0..20 {
            k.step(&DriveCommand::new(1.0, 10.0), &mut s, 0.1);
        }
        assert!((s.steer - 0.5).abs() < 1e-12);
        let (v, w) = k.step(&DriveCommand::new(1.0, 10.0), &mut s, 0.1);
        assert!((w - v * 0.5f64.tan() / 0.35).abs() < 1e-12);
    }

    #[test]
    fn a_speed_steer_command_steers_at_a_standstill_and_holds_its_angle() {
        let car = small_car();
        let k = Kinematics::Ackermann(car.clone());
        let mut s = DriveState::default();
        // standing: the wheels turn (at the steering rate), the car does not
        let (v, w) = k.step(&car.command(0.0, -0.3), &mut s, 0.1);
        assert_eq!((v, w), (0.0, 0.0));
        assert!((s.steer + 0.1).abs() < 1e-12, "{s:?}");
        for _ in 0..5 {
            k.step(&car.command(0.0, -0.3), &mut s, 0.1);
        }
        assert!((s.steer + 0.3).abs() < 1e-12, "{s:?}");
        // rolling: the angle stays where it was sent; the yaw rate is the bicycle model's
        let cmd = car.command(1.0, -0.3);
        assert!((cmd.w - car.yaw_rate(1.0, -0.3)).abs() < 1e-12);
        let (v, w) = k.step(&cmd, &mut s, 0.1);
        assert!((s.steer + 0.3).abs() < 1e-12, "{s:?}");
        assert!((w - v * (-0.3f64).tan() / 0.35).abs() < 1e-12);
        // a differential drive goes by (v, ω) alone
        let d = Kinematics::DiffDrive(DiffDrive {
            wheel_base: 0.5,
            wheel_radius: 0.1,
            max_wheel_speed: 20.0,
            max_wheel_accel: 1000.0,
        });
        let mut a = DriveState::default();
        let mut b = DriveState::default();
        let with_steer = DriveCommand {
            steer: Some(0.4),
            ..DriveCommand::new(0.5, 0.2)
        };
        assert_eq!(
            d.step(&with_steer, &mut a, 0.1),
            d.step(&DriveCommand::new(0.5, 0.2), &mut b, 0.1)
        );
    }

    fn diff() -> DiffDrive {
        DiffDrive {
            wheel_base: 0.5,
            wheel_radius: 0.1,
            max_wheel_speed: 20.0,
            max_wheel_accel: 40.0,
        }
    }

    fn car() -> Ackermann {
        Ackermann {
            wheelbase: 0.35,
            max_steer: 0.5,
            max_steer_rate: 2.0,
            max_speed: 3.0,
            max_accel: 2.0,
            wheel_radius: 0.05,
        }
    }

    /// Regression: an infinite or overflowing speed made the wheel targets inf · 0 = NaN; they
    /// are the fastest the wheels turn, in the command's direction.
    #[test]
    fn an_infinite_command_is_the_fastest_the_wheels_turn() {
        let d = diff();
        assert_eq!(
            d.wheel_targets(&DriveCommand::new(f64::INFINITY, 0.0)),
            (20.0, 20.0)
        );
        assert_eq!(
            d.wheel_targets(&DriveCommand::new(-1e308, 0.0)),
            (-20.0, -20.0)
        );
        let (l, r) = d.wheel_targets(&DriveCommand::new(0.0, f64::NEG_INFINITY));
        assert_eq!((l, r), (20.0, -20.0));
        // ordinary commands are computed as before
        assert_eq!(d.wheel_targets(&DriveCommand::new(1.0, 0.0)), (10.0, 10.0));
    }

    /// Regression: a NaN command (v, ω or a car's steering angle) reached the wheel speeds and
    /// from there the pose; it counts as a stop.
    #[test]
    fn a_nan_command_stops_the_robot() {
        for kin in [Kinematics::DiffDrive(diff()), Kinematics::Ackermann(car())] {
            let mut state = DriveState::default();
            kin.step(&DriveCommand::new(1.0, 0.5), &mut state, 0.1);
            for cmd in [
                DriveCommand::new(f64::NAN, 0.0),
                DriveCommand::new(0.0, f64::NAN),
                DriveCommand {
                    steer: Some(f64::NAN),
                    ..DriveCommand::new(1.0, 0.0)
                },
            ] {
                let (v, w) = kin.step(&cmd, &mut state, 0.1);
                assert!(v.is_finite() && w.is_finite(), "{kin:?} {cmd:?}");
            }
            for _ in 0..100 {
                kin.step(&DriveCommand::new(f64::NAN, f64::NAN), &mut state, 0.1);
            }
            let (v, _) = kin.step(&DriveCommand::new(f64::NAN, 0.0), &mut state, 0.1);
            assert_eq!(v, 0.0, "{kin:?}");
        }
        // a car told to go infinitely fast while turning infinitely fast keeps its wheels
        assert_eq!(car().steer_for(f64::INFINITY, f64::INFINITY), None);
    }

    mod props {
        use super::*;
        use crate::core::props::{config, extreme_f64};
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(config(512))]

            /// Any sequence of commands (NaN, ±∞, huge) and steps (dt 0 included) leaves the
            /// actuator state, the twist and the pose finite, within the drive's limits.
            #[test]
            fn any_command_drives_finite_within_the_limits(
                ackermann in any::<bool>(),
                cmds in proptest::collection::vec(
                    (extreme_f64(), extreme_f64(), proptest::option::of(extreme_f64()),
                     prop_oneof![Just(0.0f64), Just(0.05), 0.0f64..1.0]),
                    1..20),
            ) {
                let kin = if ackermann {
                    Kinematics::Ackermann(car())
                } else {
                    Kinematics::DiffDrive(diff())
                };
                let mut state = DriveState::default();
                let mut pose = Pose2::new(1.0, 2.0, 0.3);
                for (v, w, steer, dt) in cmds {
                    let cmd = DriveCommand { v, w, steer };
                    let (tv, tw) = kin.step(&cmd, &mut state, dt);
                    prop_assert!(tv.is_finite() && tw.is_finite(), "{cmd:?}: ({tv}, {tw})");
                    prop_assert!(tv.abs() <= kin.max_speed() + 1e-9);
                    let s = [state.left, state.right, state.speed, state.steer];
                    prop_assert!(s.iter().all(|x| x.is_finite()), "{state:?}");
                    let before = pose;
                    pose = integrate_arc(&pose, tv, tw, dt);
                    prop_assert!(pose.x.is_finite() && pose.y.is_finite() && pose.theta.is_finite());
                    if dt == 0.0 {
                        prop_assert_eq!(pose, before);
                    }
                }
            }
        }
    }
}
