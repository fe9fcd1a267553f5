//! `builtin_interfaces/msg/Time` and `std_msgs/msg/Header`, field for field as in the ROS 2
//! definitions (ros2/rcl_interfaces `builtin_interfaces/msg/Time.msg`, ros2/common_interfaces
//! `std_msgs/msg/Header.msg`).

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`: seconds and nanoseconds (`nanosec` in `[0, 1e9)`, added to
/// `sec`, so -1.7 s is `{sec: -2, nanosec: 3e8}`).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds since the epoch (of the simulation: sim time 0 is `{0, 0}`). Times past
    /// `i32::MAX` seconds (year 2038 as Unix time) saturate.
    pub fn from_nanos(ns: u64) -> Self {
        let sec = (ns / 1_000_000_000).min(i32::MAX as u64) as i32;
        Time {
            sec,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    /// From seconds, rounded to the nearest nanosecond; negative times keep `nanosec` in range.
    pub fn from_secs_f64(t: f64) -> Self {
        let total = (t * 1e9).round();
        let sec = (total / 1e9).floor();
        let nanosec = (total - sec * 1e9).clamp(0.0, 999_999_999.0);
        Time {
            sec: sec.clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            nanosec: nanosec as u32,
        }
    }

    /// Nanoseconds since the epoch (negative before it).
    pub fn as_nanos(&self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// Seconds as a float.
    pub fn as_secs_f64(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

/// `std_msgs/msg/Header`: the stamp and the coordinate frame of the data.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

impl Header {
    pub fn new(stamp: Time, frame_id: impl Into<String>) -> Self {
        Header {
            stamp,
            frame_id: frame_id.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_conversions() {
        assert_eq!(
            Time::from_secs_f64(1.5),
            Time {
                sec: 1,
                nanosec: 500_000_000
            }
        );
        assert_eq!(
            Time::from_secs_f64(-1.7),
            Time {
                sec: -2,
                nanosec: 300_000_000
            }
        );
        assert_eq!(Time::from_nanos(2_000_000_001), Time { sec: 2, nanosec: 1 });
        assert_eq!(
            Time::from_secs_f64(0.9999999999),
            Time { sec: 1, nanosec: 0 }
        );
        assert_eq!(Time::from_nanos(1_500_000_000).as_nanos(), 1_500_000_000);
        assert!((Time::from_secs_f64(12.25).as_secs_f64() - 12.25).abs() < 1e-12);
    }
}
