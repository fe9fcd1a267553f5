//! `sensor_msgs/msg/*` (ros2/common_interfaces `sensor_msgs/msg/*.msg`, Humble/Jazzy): laser
//! scans, satellite fixes, IMU readings, raw images, single-beam rangers and joint states.

use super::geometry_msgs::{Quaternion, Vector3};
use super::std_msgs::Header;
use serde::{Deserialize, Serialize};

/// `sensor_msgs/msg/LaserScan`: ranges (m) counter-clockwise from `angle_min` in steps of
/// `angle_increment` (rad); values outside `[range_min, range_max]` are to be discarded.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct LaserScan {
    pub header: Header,
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
    pub intensities: Vec<f32>,
}

/// `sensor_msgs/msg/NavSatStatus`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NavSatStatus {
    pub status: i8,
    pub service: u16,
}

impl NavSatStatus {
    pub const STATUS_NO_FIX: i8 = -1;
    pub const STATUS_FIX: i8 = 0;
    pub const STATUS_SBAS_FIX: i8 = 1;
    pub const STATUS_GBAS_FIX: i8 = 2;
    pub const SERVICE_GPS: u16 = 1;
    pub const SERVICE_GLONASS: u16 = 2;
    pub const SERVICE_COMPASS: u16 = 4;
    pub const SERVICE_GALILEO: u16 = 8;
}

/// `sensor_msgs/msg/NavSatFix`: WGS 84 latitude and longitude (degrees), altitude (m) and the
/// ENU position covariance (m², row-major).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct NavSatFix {
    pub header: Header,
    pub status: NavSatStatus,
    pub latitude: f64,
    pub longitude: f64,
    pub altitude: f64,
    pub position_covariance: [f64; 9],
    pub position_covariance_type: u8,
}

impl NavSatFix {
    pub const COVARIANCE_TYPE_UNKNOWN: u8 = 0;
    pub const COVARIANCE_TYPE_APPROXIMATED: u8 = 1;
    pub const COVARIANCE_TYPE_DIAGONAL_KNOWN: u8 = 2;
    pub const COVARIANCE_TYPE_KNOWN: u8 = 3;
}

/// `sensor_msgs/msg/Imu`. A covariance whose first element is -1 means "not provided" (e.g.
/// a compass-only reading gives the orientation and sets the other two to -1).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct Imu {
    pub header: Header,
    pub orientation: Quaternion,
    pub orientation_covariance: [f64; 9],
    pub angular_velocity: Vector3,
    pub angular_velocity_covariance: [f64; 9],
    pub linear_acceleration: Vector3,
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/msg/Image`: an uncompressed image, `height` rows of `step` bytes. `data` goes
/// through `serde_bytes`, so CDR writes it as one block rather than byte by byte.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct Image {
    pub header: Header,
    pub height: u32,
    pub width: u32,
    pub encoding: String,
    pub is_bigendian: u8,
    pub step: u32,
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

impl Image {
    /// An 8-bit RGB image (`rgb8`, 3 bytes a pixel, rows top to bottom).
    pub fn rgb8(header: Header, width: u32, height: u32, data: Vec<u8>) -> Self {
        debug_assert_eq!(data.len(), width as usize * height as usize * 3);
        Image {
            header,
            height,
            width,
            encoding: "rgb8".into(),
            is_bigendian: 0,
            step: width * 3,
            data,
        }
    }
}

/// `sensor_msgs/msg/Range`: one reading of a single-beam ranger (sonar, IR).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct Range {
    pub header: Header,
    pub radiation_type: u8,
    pub field_of_view: f32,
    pub min_range: f32,
    pub max_range: f32,
    pub range: f32,
}

impl Range {
    pub const ULTRASOUND: u8 = 0;
    pub const INFRARED: u8 = 1;
}

/// `sensor_msgs/msg/JointState`: named joints with position (rad or m), velocity and effort;
/// each array is either empty or as long as `name`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct JointState {
    pub header: Header,
    pub name: Vec<String>,
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub effort: Vec<f64>,
}
