//! Checks of the `ros2msg` schemas: every non-primitive field type of every section has its
//! own `MSG:` section, each once, and nothing else is there.

use super::*;
use crate::record::mcap::messages::*;
use std::collections::BTreeSet;

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
    "uint32", "int64", "uint64", "string", "wstring",
];

/// `pkg/msg/Type` or `pkg/Type` → `pkg/Type`.
fn short(name: &str) -> String {
    let parts: Vec<&str> = name.split('/').collect();
    format!("{}/{}", parts[0], parts[parts.len() - 1])
}

/// (section names in order, complex types the fields use) of a definition.
fn analyse(name: &str, def: &str) -> (Vec<String>, BTreeSet<String>) {
    let mut sections = vec![short(name)];
    let mut used = BTreeSet::new();
    let mut lines = def.lines().peekable();
    while let Some(line) = lines.next() {
        if line == SEPARATOR {
            let msg = lines.next().expect("a MSG: line after the separator");
            let dep = msg.strip_prefix("MSG: ").expect("MSG: line");
            assert_eq!(dep, short(dep), "MSG: lines name pkg/Type");
            sections.push(dep.to_string());
            continue;
        }
        assert!(
            !line.starts_with('='),
            "separator of {} characters",
            line.len()
        );
        let line = line.split('#').next().unwrap().trim();
        let mut words = line.split_whitespace();
        let (Some(ty), Some(field)) = (words.next(), words.next()) else {
            assert!(line.is_empty(), "malformed line `{line}`");
            continue;
        };
        if field.contains('=') || line.contains(" =") || line.contains("= ") {
            assert!(PRIMITIVES.contains(&ty), "constant of type {ty}");
            continue;
        }
        let base = ty.split('[').next().unwrap();
        if PRIMITIVES.contains(&base) {
            continue;
        }
        let pkg = sections.last().unwrap().split('/').next().unwrap();
        used.insert(if base.contains('/') {
            short(base)
        } else {
            format!("{pkg}/{base}")
        });
    }
    (sections, used)
}

fn check<T: RosMessage>() {
    let (sections, used) = analyse(T::NAME, T::DEFINITION);
    let deps: BTreeSet<String> = sections[1..].iter().cloned().collect();
    assert_eq!(
        deps.len(),
        sections.len() - 1,
        "{}: a section twice",
        T::NAME
    );
    assert_eq!(deps, used, "{}: sections vs. types used", T::NAME);
    assert!(!used.contains(&sections[0]), "{} uses itself", T::NAME);
}

#[test]
fn every_schema_is_complete() {
    check::<PoseStamped>();
    check::<TransformStamped>();
    check::<TFMessage>();
    check::<Odometry>();
    check::<LaserScan>();
    check::<NavSatFix>();
    check::<Imu>();
    check::<Image>();
    check::<Range>();
    check::<JointState>();
}

#[test]
fn names_and_layout() {
    assert_eq!(SEPARATOR.len(), 80);
    assert!(SEPARATOR.chars().all(|c| c == '='));
    assert_eq!(LaserScan::NAME, "sensor_msgs/msg/LaserScan");
    assert_eq!(TFMessage::NAME, "tf2_msgs/msg/TFMessage");
    assert_eq!(Odometry::NAME, "nav_msgs/msg/Odometry");
    assert_eq!(
        Range::DEFINITION,
        format!(
            "std_msgs/Header header\nuint8 ULTRASOUND=0\nuint8 INFRARED=1\nuint8 radiation_type\n\
             float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\n\
             {SEPARATOR}\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\
             {SEPARATOR}\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
        )
    );
}

#[test]
fn the_checker_catches_a_missing_section() {
    let (_, used) = analyse("sensor_msgs/msg/Range", msg!(Range));
    assert_eq!(used, BTreeSet::from(["std_msgs/Header".to_string()]));
}
