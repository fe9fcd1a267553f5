//! The recorded readings of one robot, read from an MCAP file into time-ordered lists: laser
//! scans, encoder readings (from `/joint_states`) or odometry poses (from nav_msgs/Odometry),
//! and the true pose. Our own files carry exact times ([`crate::record::mcap::time_on_grid`]
//! with the periods of `run.json`); a foreign file's header stamps count from its first stamp.

use crate::record::mcap::messages::{
    Header, JointState, LaserScan as ScanMsg, Odometry, Pose, PoseStamped,
};
use crate::record::mcap::{McapRecording, RosMessage, time_on_grid};
use crate::record::topics::RunInfo;
use crate::record::topics::{ACKERMANN_JOINTS, DIFF_DRIVE_JOINTS, ticks_of_angle};
use crate::scenario::RobotConfig;
use anyhow::{anyhow, bail};
use systems::body::Kinematics;
use systems::core::Pose2;
use systems::sensors::{EncoderReading, LaserScan, LaserSpec};

/// Topic names given on the command line (`None`: the default of the file's kind).
#[derive(Clone, Debug, Default)]
pub struct TopicFlags {
    pub scan: Option<String>,
    pub odom: Option<String>,
    pub joint_states: Option<String>,
    pub truth: Option<String>,
}

/// One robot's readings, each list in time order.
#[derive(Clone, Debug, Default)]
pub struct RobotFeed {
    pub scans: Vec<LaserScan>,
    /// Encoder readings (own files: exact ticks).
    pub encoder: Vec<EncoderReading>,
    /// Odometry poses in the robot's odometry frame, which starts at the scenario's start pose
    /// (used instead of `encoder` when an odometry topic is replayed).
    pub odometry: Vec<(f64, Pose2)>,
    /// True poses (own files: at the end of every tick).
    pub truth: Vec<(f64, Pose2)>,
    /// Which topics were read, for the report.
    pub topics: Vec<String>,
    /// What the user should know about these readings (printed before the replay).
    pub notes: Vec<String>,
}

/// How stamps become simulation times.
#[derive(Clone, Copy, Debug)]
pub enum TimeBase<'a> {
    /// Our own file: `time_on_grid` with each topic's period from `run.json`.
    Own(&'a RunInfo),
    /// A foreign file: seconds since this stamp (ns).
    Since(i64),
}

impl TimeBase<'_> {
    fn time(&self, topic: &str, h: &Header) -> f64 {
        let ns = h.stamp.as_nanos();
        match self {
            TimeBase::Own(run) => match run.period(topic) {
                Some(p) => time_on_grid(ns.max(0) as u64, p),
                None => ns as f64 * 1e-9,
            },
            TimeBase::Since(t0) => (ns - t0) as f64 * 1e-9,
        }
    }
}

/// The messages of `topic` as `T`; a missing topic or another type is an error naming the
/// file, the topic and what the file has.
fn read_topic<T: RosMessage>(rec: &McapRecording, topic: &str) -> anyhow::Result<Vec<T>> {
    check_topic(rec, topic, T::NAME)?;
    let msgs: Vec<T> = rec
        .decode_topic::<T>(topic)?
        .into_iter()
        .map(|(_, m)| m)
        .collect();
    if msgs.is_empty() {
        bail!("{}: topic {topic} has no messages", rec.path.display());
    }
    Ok(msgs)
}

/// An error naming the file, the topic, the `expected` message type(s) and what the file has,
/// if the file has no `topic`.
fn check_topic(rec: &McapRecording, topic: &str, expected: &str) -> anyhow::Result<()> {
    if rec.channel(topic).is_none() {
        let mut have: Vec<String> = rec
            .channels
            .iter()
            .map(|c| format!("{} ({})", c.topic, c.schema_name))
            .collect();
        have.sort();
        bail!(
            "{}: no topic {topic} (expected {expected}); the file has: {}",
            rec.path.display(),
            if have.is_empty() {
                "no topics".to_string()
            } else {
                have.join(", ")
            }
        );
    }
    Ok(())
}

/// The schema of `topic`, if the file has it.
fn schema_of<'a>(rec: &'a McapRecording, topic: &str) -> Option<&'a str> {
    rec.channel(topic).map(|c| c.schema_name.as_str())
}

/// A scan as the estimators take it. Ranges follow REP 117: NaN and readings beyond
/// `range_max` become +∞ (no return), readings under `range_min` −∞ (too close); our own scans
/// already are so and stay bit for bit as recorded.
fn scan_of(m: ScanMsg, stamp: f64) -> LaserScan {
    let (lo, hi) = (m.range_min, m.range_max);
    let ranges = m
        .ranges
        .into_iter()
        .map(|r| {
            if r.is_nan() || r > hi {
                f32::INFINITY
            } else if r < lo {
                f32::NEG_INFINITY
            } else {
                r
            }
        })
        .collect();
    LaserScan {
        stamp,
        angle_min: m.angle_min,
        angle_increment: m.angle_increment,
        range_min: lo,
        range_max: hi,
        ranges,
    }
}

/// A scan's geometry: beams, first angle, increment, range limits.
fn geometry(s: &LaserScan) -> (usize, f32, f32, f32, f32) {
    let (a, i) = (s.angle_min, s.angle_increment);
    (s.ranges.len(), a, i, s.range_min, s.range_max)
}

/// Says so when the scans of `topic` do not have the beams of the scenario's laser (count,
/// angles or range limits), or change geometry within the file: the localizers and maps use
/// each message's own angles and limits, and the scenario's laser gives only its mount.
pub fn laser_mismatch(
    robot: &str,
    topic: &str,
    laser: &LaserSpec,
    scans: &[LaserScan],
) -> Option<String> {
    let first = scans.first()?;
    let got = geometry(first);
    let want = (
        laser.beams(),
        laser.angle_min() as f32,
        laser.increment as f32,
        laser.min_range as f32,
        laser.max_range as f32,
    );
    let describe = |(n, a, i, lo, hi): (usize, f32, f32, f32, f32)| {
        format!(
            "{n} beams from {:.2}° every {:.3}°, {lo}–{hi} m",
            a.to_degrees(),
            i.to_degrees()
        )
    };
    let near = |a: f32, b: f32| (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1.0);
    let same = got.0 == want.0
        && near(got.1, want.1)
        && near(got.2, want.2)
        && near(got.3, want.3)
        && near(got.4, want.4);
    let changes = scans.iter().filter(|s| geometry(s) != got).count();
    let mut note = String::new();
    if !same {
        note = format!(
            "robot `{robot}`: the scans on {topic} have {}; the scenario's laser has {}. The \
             messages' angles and limits are used; the scenario's laser gives only the mount",
            describe(got),
            describe(want)
        );
    }
    if changes > 0 {
        if !note.is_empty() {
            note.push_str(". ");
        }
        note.push_str(&format!(
            "robot `{robot}`: {changes} of the {} scans on {topic} have another geometry than \
             the first ({}); each is used with its own",
            scans.len(),
            describe(got)
        ));
    }
    (!note.is_empty()).then_some(note)
}

fn planar(p: &Pose) -> Pose2 {
    Pose2::new(p.position.x, p.position.y, p.orientation.yaw())
}

/// Poses of a topic carrying geometry_msgs/PoseStamped or nav_msgs/Odometry.
fn read_poses(
    rec: &McapRecording,
    topic: &str,
    time: &TimeBase<'_>,
) -> anyhow::Result<Vec<(f64, Pose2)>> {
    check_topic(
        rec,
        topic,
        &format!("{} or {}", Odometry::NAME, PoseStamped::NAME),
    )?;
    let mut out: Vec<(f64, Pose2)> = if schema_of(rec, topic) == Some(Odometry::NAME) {
        read_topic::<Odometry>(rec, topic)?
            .iter()
            .map(|m| (time.time(topic, &m.header), planar(&m.pose.pose)))
            .collect()
    } else {
        read_topic::<PoseStamped>(rec, topic)?
            .iter()
            .map(|m| (time.time(topic, &m.header), planar(&m.pose)))
            .collect()
    };
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

/// Encoder readings from joint positions: wheel angles back to ticks (exact for our files).
fn read_joints(
    rec: &McapRecording,
    topic: &str,
    time: &TimeBase<'_>,
    robot: &RobotConfig,
) -> anyhow::Result<Vec<EncoderReading>> {
    let Some(enc) = &robot.encoder else {
        bail!(
            "{}: robot `{}` has no encoder in the scenario, so {topic} cannot be turned into \
             odometry",
            rec.path.display(),
            robot.name
        );
    };
    let ackermann = matches!(robot.kinematics, Kinematics::Ackermann(_));
    let names = if ackermann {
        ACKERMANN_JOINTS
    } else {
        DIFF_DRIVE_JOINTS
    };
    let tpr = enc.ticks_per_rev;
    let mut out = Vec::new();
    for m in read_topic::<JointState>(rec, topic)? {
        let t = time.time(topic, &m.header);
        let pos = |name: &str| -> anyhow::Result<f64> {
            let i = m.name.iter().position(|n| n == name).ok_or_else(|| {
                anyhow!(
                    "{}: {topic} at {t:.3} s has no joint `{name}` (joints: {}; robot `{}` \
                     expects {})",
                    rec.path.display(),
                    m.name.join(", "),
                    robot.name,
                    names.join(", ")
                )
            })?;
            m.position.get(i).copied().ok_or_else(|| {
                anyhow!(
                    "{}: {topic} at {t:.3} s: no position for joint `{name}`",
                    rec.path.display()
                )
            })
        };
        let (a, b) = (pos(names[0])?, pos(names[1])?);
        out.push(if ackermann {
            let ticks = ticks_of_angle(a, tpr);
            EncoderReading {
                stamp: t,
                left_ticks: ticks,
                right_ticks: ticks,
                steer: b,
            }
        } else {
            EncoderReading {
                stamp: t,
                left_ticks: ticks_of_angle(a, tpr),
                right_ticks: ticks_of_angle(b, tpr),
                steer: 0.0,
            }
        });
    }
    out.sort_by(|a, b| a.stamp.total_cmp(&b.stamp));
    Ok(out)
}

/// The earliest header stamp (ns) on the given topics of a foreign file.
pub fn first_stamp(rec: &McapRecording, topics: &[&str]) -> anyhow::Result<i64> {
    let mut first: Option<i64> = None;
    for topic in topics {
        let Some(index) = rec.channels.iter().position(|c| c.topic == *topic) else {
            continue;
        };
        for m in rec.messages.iter().filter(|m| m.channel == index) {
            // every message starts with its std_msgs/Header
            let h: Header = crate::record::mcap::decode_prefix(&m.data).map_err(|e| {
                anyhow!(
                    "{}: message {} on {topic}: no header: {e}",
                    rec.path.display(),
                    m.sequence
                )
            })?;
            let ns = h.stamp.as_nanos();
            first = Some(first.map_or(ns, |f| f.min(ns)));
        }
    }
    first.ok_or_else(|| {
        anyhow!(
            "{}: no messages on {}",
            rec.path.display(),
            topics.join(", ")
        )
    })
}

/// The readings of `robot`. Our own files default to the robot's topics (`/<r>/scan`,
/// `/<r>/joint_states`, `/<r>/ground_truth`); foreign files to `/scan` and `/odom`, with
/// ground truth only from `--truth-topic`.
pub fn robot_feed(
    rec: &McapRecording,
    robot: &RobotConfig,
    flags: &TopicFlags,
    time: &TimeBase<'_>,
) -> anyhow::Result<RobotFeed> {
    let own = matches!(time, TimeBase::Own(_));
    let r = &robot.name;
    let mut feed = RobotFeed::default();
    if robot.laser.is_some() {
        let topic = flags.scan.clone().unwrap_or_else(|| {
            if own {
                format!("/{r}/scan")
            } else {
                "/scan".into()
            }
        });
        feed.scans = read_topic::<ScanMsg>(rec, &topic)?
            .into_iter()
            .map(|m| {
                let t = time.time(&topic, &m.header);
                scan_of(m, t)
            })
            .collect();
        feed.scans.sort_by(|a, b| a.stamp.total_cmp(&b.stamp));
        if let Some(laser) = &robot.laser {
            feed.notes
                .extend(laser_mismatch(r, &topic, laser, &feed.scans));
        }
        feed.topics.push(topic);
    } else if let Some(t) = &flags.scan {
        bail!(
            "--scan-topic {t}: robot `{r}` has no laser in the scenario (its mount and limits \
             come from there)"
        );
    }
    let odom_topic = flags.odom.clone().or((!own).then(|| "/odom".to_string()));
    if let Some(topic) = odom_topic {
        let poses = read_poses(rec, &topic, time)?;
        // the recorded odometry frame is moved to start at the scenario's start pose
        if let Some((_, first)) = poses.first().copied() {
            feed.odometry = poses
                .into_iter()
                .map(|(t, p)| (t, robot.start.compose(&first.between(&p))))
                .collect();
        }
        feed.topics.push(topic);
    } else if robot.encoder.is_some() {
        let topic = flags
            .joint_states
            .clone()
            .unwrap_or_else(|| format!("/{r}/joint_states"));
        feed.encoder = read_joints(rec, &topic, time, robot)?;
        feed.topics.push(topic);
    }
    let truth_topic = flags
        .truth
        .clone()
        .or(own.then(|| format!("/{r}/ground_truth")));
    if let Some(topic) = truth_topic {
        feed.truth = read_poses(rec, &topic, time)?;
        feed.topics.push(topic);
    }
    Ok(feed)
}
