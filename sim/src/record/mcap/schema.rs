//! Message definitions as MCAP schemas in the `ros2msg` encoding, the way rosbag2 writes them
//! (rosbag2 `docs/message_definition_encoding.md`; MCAP spec, "Well-known schema encodings"
//! and the `ros2` profile): the top-level `.msg` text first, then every type it depends on,
//! recursively, each once, after a line of exactly 80 `=` and a `MSG: pkg/Type` line.
//!
//! The `.msg` texts are the ROS 2 Humble/Jazzy definitions (see [`super::messages`]) with
//! their comments left out; field types, names, array sizes, constants and defaults are as in
//! the `.msg` files. Type names inside a definition are written as there: bare (`Point`) for a
//! type of the same package, `pkg/Type` otherwise.

/// A top-level ROS 2 message the recorder can write: its schema name (`pkg/msg/Type`) and its
/// complete `ros2msg` definition.
pub trait RosMessage: serde::Serialize + serde::de::DeserializeOwned {
    /// Schema name, e.g. `sensor_msgs/msg/LaserScan`.
    const NAME: &'static str;
    /// The `.msg` text followed by every dependent definition.
    const DEFINITION: &'static str;
}

/// The schema encoding of [`RosMessage::DEFINITION`].
pub const SCHEMA_ENCODING: &str = "ros2msg";

/// The line between definitions, exactly 80 `=`, as a literal for `concat!`.
macro_rules! separator {
    () => {
        "================================================================================"
    };
}

/// The line between definitions: exactly 80 `=`.
pub const SEPARATOR: &str = separator!();

/// `.msg` texts, as literals so `concat!` can join them at compile time.
macro_rules! msg {
    (Time) => {
        "int32 sec\nuint32 nanosec"
    };
    (Header) => {
        "builtin_interfaces/Time stamp\nstring frame_id"
    };
    (Point) => {
        "float64 x\nfloat64 y\nfloat64 z"
    };
    (Quaternion) => {
        "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1"
    };
    (Pose) => {
        "Point position\nQuaternion orientation"
    };
    (PoseWithCovariance) => {
        "Pose pose\nfloat64[36] covariance"
    };
    (Vector3) => {
        "float64 x\nfloat64 y\nfloat64 z"
    };
    (Twist) => {
        "Vector3  linear\nVector3  angular"
    };
    (TwistWithCovariance) => {
        "Twist twist\nfloat64[36] covariance"
    };
    (Transform) => {
        "Vector3 translation\nQuaternion rotation"
    };
    (TransformStamped) => {
        "std_msgs/Header header\nstring child_frame_id\nTransform transform"
    };
    (PoseStamped) => {
        "std_msgs/Header header\nPose pose"
    };
    (Odometry) => {
        "std_msgs/Header header\nstring child_frame_id\n\
         geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist"
    };
    (LaserScan) => {
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n\
         float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n\
         float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities"
    };
    (NavSatStatus) => {
        "int8 STATUS_NO_FIX =  -1\nint8 STATUS_FIX =      0\nint8 STATUS_SBAS_FIX = 1\n\
         int8 STATUS_GBAS_FIX = 2\nint8 status\nuint16 SERVICE_GPS =     1\n\
         uint16 SERVICE_GLONASS = 2\nuint16 SERVICE_COMPASS = 4\nuint16 SERVICE_GALILEO = 8\n\
         uint16 service"
    };
    (NavSatFix) => {
        "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\n\
         float64 altitude\nfloat64[9] position_covariance\n\
         uint8 COVARIANCE_TYPE_UNKNOWN = 0\nuint8 COVARIANCE_TYPE_APPROXIMATED = 1\n\
         uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\nuint8 COVARIANCE_TYPE_KNOWN = 3\n\
         uint8 position_covariance_type"
    };
    (Imu) => {
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n\
         float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n\
         float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n\
         float64[9] linear_acceleration_covariance"
    };
    (Image) => {
        "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n\
         uint8 is_bigendian\nuint32 step\nuint8[] data"
    };
    (Range) => {
        "std_msgs/Header header\nuint8 ULTRASOUND=0\nuint8 INFRARED=1\nuint8 radiation_type\n\
         float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range"
    };
    (JointState) => {
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n\
         float64[] effort"
    };
    (TFMessage) => {
        "geometry_msgs/TransformStamped[] transforms"
    };
}

/// `impl RosMessage` with the top-level text and, after it, each dependency as
/// `pkg/Type` (its separator, `MSG:` line and text).
macro_rules! ros_message {
    ($ty:ident, $pkg:literal $(, $dep_pkg:literal $dep:ident)*) => {
        impl RosMessage for super::messages::$ty {
            const NAME: &'static str = concat!($pkg, "/msg/", stringify!($ty));
            const DEFINITION: &'static str = concat!(
                msg!($ty),
                $(
                    "\n", separator!(), "\nMSG: ", $dep_pkg, "/", stringify!($dep), "\n",
                    msg!($dep),
                )*
                "\n"
            );
        }
    };
}

ros_message!(PoseStamped, "geometry_msgs",
    "std_msgs" Header, "builtin_interfaces" Time,
    "geometry_msgs" Pose, "geometry_msgs" Point, "geometry_msgs" Quaternion);
ros_message!(TransformStamped, "geometry_msgs",
    "std_msgs" Header, "builtin_interfaces" Time,
    "geometry_msgs" Transform, "geometry_msgs" Vector3, "geometry_msgs" Quaternion);
ros_message!(TFMessage, "tf2_msgs",
    "geometry_msgs" TransformStamped, "std_msgs" Header, "builtin_interfaces" Time,
    "geometry_msgs" Transform, "geometry_msgs" Vector3, "geometry_msgs" Quaternion);
ros_message!(Odometry, "nav_msgs",
    "std_msgs" Header, "builtin_interfaces" Time,
    "geometry_msgs" PoseWithCovariance, "geometry_msgs" Pose, "geometry_msgs" Point,
    "geometry_msgs" Quaternion, "geometry_msgs" TwistWithCovariance, "geometry_msgs" Twist,
    "geometry_msgs" Vector3);
ros_message!(LaserScan, "sensor_msgs", "std_msgs" Header, "builtin_interfaces" Time);
ros_message!(NavSatFix, "sensor_msgs",
    "std_msgs" Header, "builtin_interfaces" Time, "sensor_msgs" NavSatStatus);
ros_message!(Imu, "sensor_msgs",
    "std_msgs" Header, "builtin_interfaces" Time,
    "geometry_msgs" Quaternion, "geometry_msgs" Vector3);
ros_message!(Image, "sensor_msgs", "std_msgs" Header, "builtin_interfaces" Time);
ros_message!(Range, "sensor_msgs", "std_msgs" Header, "builtin_interfaces" Time);
ros_message!(JointState, "sensor_msgs", "std_msgs" Header, "builtin_interfaces" Time);

#[cfg(test)]
mod tests;
