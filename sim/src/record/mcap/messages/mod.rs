//! Rust mirrors of the ROS 2 messages the simulator records, one module per ROS package, with
//! serde derives whose field order is the order of the `.msg` files (CDR has no field names:
//! the order is the format).
//! The definitions are those of ROS 2 Humble and Jazzy (ros2/common_interfaces,
//! ros2/rcl_interfaces, ros2/geometry2 for `tf2_msgs`); Kilted's `sensor_msgs/Range` adds a
//! `variance` field that is not here.
//!
//! Mapping of `.msg` types: `float64` → `f64`, `float32` → `f32`, `int8` → `i8`, `uint8` →
//! `u8`, `uint16` → `u16`, `int32` → `i32`, `uint32` → `u32`, `string` → `String`, `T[]` →
//! `Vec<T>` (`uint8[]` as bytes, see [`sensor_msgs::Image`]), `T[N]` → `[T; N]`.

pub mod geometry_msgs;
pub mod nav_msgs;
pub mod sensor_msgs;
pub mod std_msgs;
pub mod tf2_msgs;

pub use geometry_msgs::{
    Point, Pose, PoseStamped, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist,
    TwistWithCovariance, Vector3,
};
pub use nav_msgs::Odometry;
pub use sensor_msgs::{Image, Imu, JointState, LaserScan, NavSatFix, NavSatStatus, Range};
pub use std_msgs::{Header, Time};
pub use tf2_msgs::TFMessage;

/// Serde for fixed arrays longer than serde's built-in 32 (the 6×6 covariances): written as a
/// tuple, i.e. the N elements with no length prefix, as CDR wants for `float64[36]`. Use with
/// `#[serde(with = "fixed_array")]`.
pub mod fixed_array {
    use ::std::fmt;
    use ::std::marker::PhantomData;
    use serde::de::{self, Deserialize, Deserializer, SeqAccess, Visitor};
    use serde::ser::{Serialize, SerializeTuple, Serializer};

    pub fn serialize<S, T, const N: usize>(a: &[T; N], s: S) -> Result<S::Ok, S::Error>
    where
        S: Serializer,
        T: Serialize,
    {
        let mut t = s.serialize_tuple(N)?;
        for v in a {
            t.serialize_element(v)?;
        }
        t.end()
    }

    pub fn deserialize<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de> + Copy + Default,
    {
        struct ArrayVisitor<T, const N: usize>(PhantomData<T>);
        impl<'de, T, const N: usize> Visitor<'de> for ArrayVisitor<T, N>
        where
            T: Deserialize<'de> + Copy + Default,
        {
            type Value = [T; N];
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} elements")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[T; N], A::Error> {
                let mut out = [T::default(); N];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                Ok(out)
            }
        }
        d.deserialize_tuple(N, ArrayVisitor::<T, N>(PhantomData))
    }
}
