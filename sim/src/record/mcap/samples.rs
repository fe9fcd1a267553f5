//! Sample messages of every type, with every field set to something non-default, for the
//! tests here, and the cross-check of a file of them with Foxglove's Python readers
//! (`tests/check_mcap.py`).

use super::messages::*;
use super::{McapRecorder, McapRecording, ROS2_PROFILE};

pub const SEC: u64 = 1_000_000_000;
pub const SCENARIO: &str = "[world]\nmap = \"maps/office.yaml\"\n";

pub fn header(t: f64, frame: &str) -> Header {
    Header::new(Time::from_secs_f64(t), frame)
}

/// Row-major 6×6 with distinct entries.
fn cov36(scale: f64) -> [f64; 36] {
    std::array::from_fn(|i| scale * (i as f64 + 1.0))
}

pub fn pose_stamped(t: f64) -> PoseStamped {
    PoseStamped {
        header: header(t, "map"),
        pose: Pose::planar(1.25 + t, -2.5, 0.75),
    }
}

pub fn transform_stamped(t: f64) -> TransformStamped {
    TransformStamped {
        header: header(t, "odom"),
        child_frame_id: "base_link".into(),
        transform: Transform {
            translation: Vector3 {
                x: 0.5 * t,
                y: -0.25,
                z: 0.0,
            },
            rotation: Quaternion::from_yaw(-1.0),
        },
    }
}

pub fn tf(t: f64) -> TFMessage {
    let mut second = transform_stamped(t);
    second.header.frame_id = "map".into();
    second.child_frame_id = "odom".into();
    TFMessage {
        transforms: vec![transform_stamped(t), second],
    }
}

pub fn odometry(t: f64) -> Odometry {
    Odometry {
        header: header(t, "odom"),
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose::planar(t, 2.0, -0.5),
            covariance: cov36(0.01),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: Vector3 {
                    x: 0.4,
                    y: 0.0,
                    z: 0.0,
                },
                angular: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: -0.2,
                },
            },
            covariance: cov36(0.001),
        },
    }
}

pub fn laser_scan(t: f64, beams: usize) -> LaserScan {
    LaserScan {
        header: header(t, "laser"),
        angle_min: -1.5,
        angle_max: 1.5,
        angle_increment: 3.0 / (beams.max(2) - 1) as f32,
        time_increment: 0.0001,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 30.0,
        ranges: (0..beams).map(|i| 1.0 + 0.125 * i as f32).collect(),
        intensities: (0..beams).map(|i| (i % 7) as f32).collect(),
    }
}

pub fn nav_sat_fix(t: f64) -> NavSatFix {
    NavSatFix {
        header: header(t, "gps"),
        status: NavSatStatus {
            status: NavSatStatus::STATUS_SBAS_FIX,
            service: NavSatStatus::SERVICE_GPS | NavSatStatus::SERVICE_GALILEO,
        },
        latitude: 48.137154,
        longitude: 11.576124 + 1e-6 * t,
        altitude: 519.5,
        position_covariance: [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 9.0],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_DIAGONAL_KNOWN,
    }
}

pub fn imu(t: f64) -> Imu {
    Imu {
        header: header(t, "imu"),
        orientation: Quaternion::from_yaw(0.3 + t),
        orientation_covariance: [0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.02],
        angular_velocity: Vector3 {
            x: 0.0,
            y: 0.0,
            z: 0.1,
        },
        angular_velocity_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        linear_acceleration: Vector3 {
            x: 0.2,
            y: 0.0,
            z: 9.81,
        },
        linear_acceleration_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    }
}

pub fn image(t: f64, width: u32, height: u32) -> Image {
    let data = (0..width * height * 3)
        .map(|i| (i * 7 % 251) as u8)
        .collect();
    Image::rgb8(header(t, "camera"), width, height, data)
}

pub fn range(t: f64) -> Range {
    Range {
        header: header(t, "sonar_0"),
        radiation_type: Range::ULTRASOUND,
        field_of_view: 0.26,
        min_range: 0.02,
        max_range: 4.0,
        range: 1.5 + t as f32,
    }
}

pub fn joint_state(t: f64) -> JointState {
    JointState {
        header: header(t, "base_link"),
        name: vec!["left_wheel_joint".into(), "right_wheel_joint".into()],
        position: vec![12.5 + t, -3.25],
        velocity: vec![0.5, 0.25],
        effort: Vec::new(),
    }
}

/// Writes every message type on its own topic (`/scan` twice as often, times interleaved);
/// returns the topic → count table.
pub fn write_all_types(rec: &mut McapRecorder, seconds: u64) -> Vec<(&'static str, usize)> {
    let truth = rec.channel::<PoseStamped>("/truth").unwrap();
    let scan = rec.channel::<LaserScan>("/scan").unwrap();
    let odom = rec.channel::<Odometry>("/odom").unwrap();
    let tf = rec.channel::<TFMessage>("/tf").unwrap();
    let ts = rec.channel::<TransformStamped>("/transform").unwrap();
    let gps = rec.channel::<NavSatFix>("/gps/fix").unwrap();
    let imu = rec.channel::<Imu>("/imu").unwrap();
    let cam = rec.channel::<Image>("/camera/image_raw").unwrap();
    let sonar = rec.channel::<Range>("/sonar/0").unwrap();
    let joints = rec.channel::<JointState>("/joint_states").unwrap();
    for s in 0..seconds {
        let t = s as f64;
        let ns = s * SEC;
        // Out of time order on purpose: the reader sorts.
        rec.write(odom, ns + SEC / 2, &odometry(t + 0.5)).unwrap();
        rec.write(scan, ns, &laser_scan(t, 360)).unwrap();
        rec.write(scan, ns + SEC / 2, &laser_scan(t + 0.5, 360))
            .unwrap();
        rec.write(truth, ns, &pose_stamped(t)).unwrap();
        rec.write(tf, ns, &self::tf(t)).unwrap();
        rec.write(ts, ns, &transform_stamped(t)).unwrap();
        rec.write(gps, ns, &nav_sat_fix(t)).unwrap();
        rec.write(imu, ns, &self::imu(t)).unwrap();
        rec.write(cam, ns, &image(t, 320, 240)).unwrap();
        rec.write(sonar, ns, &range(t)).unwrap();
        rec.write(joints, ns, &joint_state(t)).unwrap();
    }
    let n = seconds as usize;
    vec![
        ("/truth", n),
        ("/scan", 2 * n),
        ("/odom", n),
        ("/tf", n),
        ("/transform", n),
        ("/gps/fix", n),
        ("/imu", n),
        ("/camera/image_raw", n),
        ("/sonar/0", n),
        ("/joint_states", n),
    ]
}

/// Foxglove's Python readers (mcap 1.6.0, mcap-ros2-support 0.6.0, installed by tests/run.sh in
/// `$SIM_RERUN_VENV`) decode every message of a file with every message type, with the counts
/// and field values we wrote: `tests/check_mcap.py` on the sample of [`write_sample`]. Skipped
/// without the readers, unless `SIM_REQUIRE_TOOLS=1` ([`systems::core::test_tools`]).
#[test]
fn python_ros2_readers_decode_every_message() {
    use systems::core::test_tools::{TestTool, test_tool};
    let Some(venv) = test_tool(TestTool::McapReaders) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sample.mcap");
    write_sample(&path);
    let script = systems::core::source::source_path("tests/check_mcap.py");
    let out = std::process::Command::new(venv.join("bin/python"))
        .arg(script)
        .arg(&path)
        .arg(path.with_extension("counts.json"))
        .arg("--values")
        .arg(path.with_extension("values.json"))
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.contains(" passed, 0 failed"), "{text}");
}

/// Writes the sample file of the Python cross-check (`tests/check_mcap.py`) to `path`, with
/// `.counts.json` (topic → count) and `.values.json` (topic → the messages as JSON, in
/// log-time order) beside it.
fn write_sample(path: &std::path::Path) {
    let mut rec = McapRecorder::create(path, ROS2_PROFILE).unwrap();
    let counts = write_all_types(&mut rec, 4);
    rec.attach("scenario.toml", "application/toml", SCENARIO.as_bytes())
        .unwrap();
    rec.finish().unwrap();
    let r = McapRecording::open(path).unwrap();
    // Built as text: serde_json::to_string keeps the struct's field order, a Value would sort.
    let mut topics = Vec::new();
    for (index, ch) in r.channels.iter().enumerate() {
        let msgs = r.messages.iter().filter(|m| m.channel == index);
        let json: Vec<String> = msgs
            .map(|m| match ch.schema_name.as_str() {
                "geometry_msgs/msg/PoseStamped" => json(r.decode::<PoseStamped>(m)),
                "geometry_msgs/msg/TransformStamped" => json(r.decode::<TransformStamped>(m)),
                "tf2_msgs/msg/TFMessage" => json(r.decode::<TFMessage>(m)),
                "nav_msgs/msg/Odometry" => json(r.decode::<Odometry>(m)),
                "sensor_msgs/msg/LaserScan" => json(r.decode::<LaserScan>(m)),
                "sensor_msgs/msg/NavSatFix" => json(r.decode::<NavSatFix>(m)),
                "sensor_msgs/msg/Imu" => json(r.decode::<Imu>(m)),
                "sensor_msgs/msg/Image" => json(r.decode::<Image>(m)),
                "sensor_msgs/msg/Range" => json(r.decode::<Range>(m)),
                "sensor_msgs/msg/JointState" => json(r.decode::<JointState>(m)),
                other => panic!("no sample of {other}"),
            })
            .collect();
        let topic = serde_json::to_string(&ch.topic).unwrap();
        topics.push(format!("{topic}: [{}]", json.join(", ")));
    }
    let values = format!("{{{}}}", topics.join(",\n"));
    let counts: serde_json::Map<_, _> = counts
        .iter()
        .map(|(t, n)| (t.to_string(), (*n).into()))
        .collect();
    let side = |ext: &str| path.with_extension(ext);
    std::fs::write(side("counts.json"), serde_json::to_string(&counts).unwrap()).unwrap();
    std::fs::write(side("values.json"), values).unwrap();
}

fn json<T: serde::Serialize>(m: anyhow::Result<T>) -> String {
    serde_json::to_string(&m.unwrap()).unwrap()
}
