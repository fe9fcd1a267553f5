//! The simulator's readings and poses as ROS 2 messages (pure functions). Values that
//! estimators consume are copied as they are, so a replay can rebuild identical readings: f32
//! ranges, f64 odometry poses (the yaw as a planar quaternion), GPS latitude and longitude, the
//! compass's own quaternion, encoder ticks as wheel angles (`ticks · 2π / ticks_per_rev`, which
//! rounds back to the same integer).

use crate::record::mcap::messages::*;
use crate::record::mcap::stamp_ns;
use std::f64::consts::TAU;
use systems::core::Pose2;
use systems::sensors::{CompassReading, EncoderReading, GpsFix, LaserScan as Scan};

/// The header of data stamped at simulation time `t` (s) in `frame`.
pub fn header(t: f64, frame: &str) -> Header {
    Header::new(Time::from_nanos(stamp_ns(t)), frame)
}

fn transform_of(p: &Pose2) -> Transform {
    Transform {
        translation: Vector3 {
            x: p.x,
            y: p.y,
            z: 0.0,
        },
        rotation: Quaternion::from_yaw(p.theta),
    }
}

/// The transform `frame` → `child` at `t`: the pose of `child` in `frame`.
pub fn transform(t: f64, frame: &str, child: &str, pose: &Pose2) -> TransformStamped {
    TransformStamped {
        header: header(t, frame),
        child_frame_id: child.to_string(),
        transform: transform_of(pose),
    }
}

/// A laser scan (`scan_time`: the laser's period; every beam at once, `time_increment` 0).
pub fn laser_scan(scan: &Scan, frame: &str, scan_time: f32) -> LaserScan {
    let n = scan.ranges.len().max(1);
    LaserScan {
        header: header(scan.stamp, frame),
        angle_min: scan.angle_min,
        angle_max: scan.angle_min + (n - 1) as f32 * scan.angle_increment,
        angle_increment: scan.angle_increment,
        time_increment: 0.0,
        scan_time,
        range_min: scan.range_min,
        range_max: scan.range_max,
        ranges: scan.ranges.clone(),
        intensities: Vec::new(),
    }
}

/// Wheel odometry: `pose` in `frame` (`<robot>/odom`), the velocity over the last step
/// (`previous` pose `dt` seconds earlier) in `child` (`<robot>/base_link`). Covariances are
/// left at zero: the odometry does not estimate them.
pub fn odometry(
    t: f64,
    frame: &str,
    child: &str,
    pose: &Pose2,
    previous: Option<(f64, Pose2)>,
) -> Odometry {
    let mut twist = Twist::default();
    if let Some((t0, p0)) = previous
        && t > t0
    {
        let d = p0.between(pose);
        let dt = t - t0;
        twist.linear.x = d.x / dt;
        twist.linear.y = d.y / dt;
        twist.angular.z = systems::core::wrap_angle(d.theta) / dt;
    }
    Odometry {
        header: header(t, frame),
        child_frame_id: child.to_string(),
        pose: PoseWithCovariance {
            pose: Pose::planar(pose.x, pose.y, pose.theta),
            covariance: [0.0; 36],
        },
        twist: TwistWithCovariance {
            twist,
            covariance: [0.0; 36],
        },
    }
}

/// A pose in `frame` (ground truth in `map`).
pub fn pose_stamped(t: f64, frame: &str, pose: &Pose2) -> PoseStamped {
    PoseStamped {
        header: header(t, frame),
        pose: Pose::planar(pose.x, pose.y, pose.theta),
    }
}

/// Joint names of the encoder message: the two wheels of a differential drive, the drive
/// shaft and the steering of an Ackermann car.
pub const DIFF_DRIVE_JOINTS: [&str; 2] = ["left_wheel_joint", "right_wheel_joint"];
pub const ACKERMANN_JOINTS: [&str; 2] = ["drive_shaft_joint", "steering_joint"];

/// An encoder reading as joint positions: wheel angles `ticks · 2π / ticks_per_rev` (rad); an
/// Ackermann car's shaft angle and measured steering angle (rad).
pub fn joint_state(
    r: &EncoderReading,
    ticks_per_rev: u32,
    ackermann: bool,
    frame: &str,
) -> JointState {
    let k = TAU / ticks_per_rev as f64;
    let (names, position) = if ackermann {
        (ACKERMANN_JOINTS, vec![r.left_ticks as f64 * k, r.steer])
    } else {
        (
            DIFF_DRIVE_JOINTS,
            vec![r.left_ticks as f64 * k, r.right_ticks as f64 * k],
        )
    };
    JointState {
        header: header(r.stamp, frame),
        name: names.iter().map(|n| n.to_string()).collect(),
        position,
        velocity: Vec::new(),
        effort: Vec::new(),
    }
}

/// The tick count of a wheel angle written by `joint_state`.
pub fn ticks_of_angle(angle: f64, ticks_per_rev: u32) -> i64 {
    (angle / (TAU / ticks_per_rev as f64)).round() as i64
}

/// A GPS fix: latitude and longitude as the receiver computed them, its diagonal covariance
/// (east, north, up) as an approximated one.
pub fn nav_sat_fix(fix: &GpsFix, frame: &str) -> NavSatFix {
    let [e, n, u] = fix.covariance;
    NavSatFix {
        header: header(fix.stamp, frame),
        status: NavSatStatus {
            status: NavSatStatus::STATUS_FIX,
            service: NavSatStatus::SERVICE_GPS,
        },
        latitude: fix.position.lat,
        longitude: fix.position.lon,
        altitude: fix.altitude,
        position_covariance: [e, 0.0, 0.0, 0.0, n, 0.0, 0.0, 0.0, u],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_APPROXIMATED,
    }
}

/// Roll and pitch variance of a compass reading (rad²): not measured.
pub const UNMEASURED_VARIANCE: f64 = 1e6;

/// A compass reading as an orientation-only IMU message (REP 145): the reading's own ENU
/// quaternion, its variance about z, roll and pitch marked unmeasured, angular velocity and
/// linear acceleration "not provided" (covariance element 0 = -1).
pub fn compass_imu(r: &CompassReading, frame: &str) -> Imu {
    let [x, y, z, w] = r.orientation;
    let mut none = [0.0; 9];
    none[0] = -1.0;
    let v = UNMEASURED_VARIANCE;
    Imu {
        header: header(r.stamp, frame),
        orientation: Quaternion { x, y, z, w },
        orientation_covariance: [v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, r.variance],
        angular_velocity: Vector3::default(),
        angular_velocity_covariance: none,
        linear_acceleration: Vector3::default(),
        linear_acceleration_covariance: none,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use systems::world::roads::GeoPoint;

    #[test]
    fn headers_carry_integer_nanoseconds() {
        let h = header(0.15000000000000002, "map");
        assert_eq!(
            (h.stamp.sec, h.stamp.nanosec, h.frame_id.as_str()),
            (0, 150_000_000, "map")
        );
        assert_eq!(header(12.34, "x").stamp.as_nanos(), 12_340_000_000);
    }

    #[test]
    fn scans_keep_their_f32_values() {
        let scan = Scan {
            stamp: 0.5,
            angle_min: -1.0,
            angle_increment: 0.5,
            range_min: 0.1,
            range_max: 8.0,
            ranges: vec![1.5, f32::INFINITY, f32::NEG_INFINITY, 2.25, 7.0],
        };
        let m = laser_scan(&scan, "r/laser", 0.1);
        assert_eq!(m.angle_max, 1.0);
        assert_eq!(m.ranges, scan.ranges);
        assert_eq!((m.range_min, m.range_max, m.scan_time), (0.1, 8.0, 0.1));
        assert_eq!(m.header.stamp.nanosec, 500_000_000);
    }

    #[test]
    fn odometry_pose_and_velocity() {
        let p0 = Pose2::new(1.0, 2.0, 0.5);
        let p1 = p0.compose(&Pose2::new(0.1, 0.0, 0.02));
        let m = odometry(1.02, "r/odom", "r/base_link", &p1, Some((1.0, p0)));
        assert_eq!(m.pose.pose.position.x, p1.x);
        assert_eq!(m.pose.pose.position.y, p1.y);
        assert!((m.pose.pose.orientation.yaw() - p1.theta).abs() < 1e-15);
        assert!((m.twist.twist.linear.x - 5.0).abs() < 1e-9);
        assert!((m.twist.twist.angular.z - 1.0).abs() < 1e-9);
        assert_eq!(
            (m.header.frame_id.as_str(), m.child_frame_id.as_str()),
            ("r/odom", "r/base_link")
        );
        let first = odometry(0.0, "o", "b", &p0, None);
        assert_eq!(first.twist.twist, Twist::default());
    }

    #[test]
    fn encoder_ticks_round_trip_through_wheel_angles() {
        for tpr in [512, 4096, 1000] {
            for ticks in [0i64, 1, -1, 4095, 123_456_789, -987_654_321, 1 << 40] {
                let r = EncoderReading {
                    stamp: 0.02,
                    left_ticks: ticks,
                    right_ticks: -ticks / 3,
                    steer: 0.0,
                };
                let m = joint_state(&r, tpr, false, "b");
                assert_eq!(ticks_of_angle(m.position[0], tpr), ticks);
                assert_eq!(ticks_of_angle(m.position[1], tpr), -ticks / 3);
                assert_eq!(m.name, DIFF_DRIVE_JOINTS);
            }
        }
        let car = EncoderReading {
            stamp: 1.0,
            left_ticks: 700,
            right_ticks: 700,
            steer: -0.25,
        };
        let m = joint_state(&car, 512, true, "b");
        assert_eq!(m.name, ACKERMANN_JOINTS);
        assert_eq!(m.position[1], -0.25);
        assert_eq!(ticks_of_angle(m.position[0], 512), 700);
    }

    #[test]
    fn gps_and_compass_messages() {
        let fix = GpsFix {
            stamp: 3.2,
            position: GeoPoint::new(50.0645123, 14.4181234),
            altitude: 0.0,
            covariance: [4.0, 4.0, 16.0],
        };
        let m = nav_sat_fix(&fix, "car/base_link");
        assert_eq!((m.latitude, m.longitude), (50.0645123, 14.4181234));
        assert_eq!(m.position_covariance[0], 4.0);
        assert_eq!(m.position_covariance[4], 4.0);
        assert_eq!(m.position_covariance[8], 16.0);
        assert_eq!(m.status.status, NavSatStatus::STATUS_FIX);
        let r = CompassReading::from_orientation(1.0, [0.0, 0.0, 0.3, 0.91f64.sqrt()], 1e-4);
        let imu = compass_imu(&r, "car/base_link");
        assert_eq!(imu.orientation.z, 0.3);
        assert_eq!(imu.orientation_covariance[8], 1e-4);
        assert_eq!(imu.angular_velocity_covariance[0], -1.0);
        assert_eq!(imu.linear_acceleration_covariance[0], -1.0);
        let back = CompassReading::from_orientation(
            1.0,
            [
                imu.orientation.x,
                imu.orientation.y,
                imu.orientation.z,
                imu.orientation.w,
            ],
            imu.orientation_covariance[8],
        );
        assert_eq!(back, r);
    }
}
