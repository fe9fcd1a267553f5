//! One robot's topics: which it gets (one per sensor it carries), their channels, frames and
//! periods, its static transforms, and what the recorder remembers between ticks.

use super::convert::transform;
use crate::record::mcap::messages::*;
use crate::record::mcap::{Channel, McapRecorder, RosMessage};
use bevy_ecs::prelude::*;
use serde::{Deserialize, Serialize};
use systems::core::{Pose2, RobotId, RobotIndex};
use systems::localization::{OdometryModel, WheelOdometry};
use systems::sensors::{Camera, Compass, Encoder, Gps, Laser, Sonars};

/// A topic as `run.json` lists it.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct TopicInfo {
    pub topic: String,
    #[serde(rename = "type")]
    pub r#type: String,
    pub robot: String,
    /// The period of the stamps' time grid (s): stamps are `k · period_s`.
    pub period_s: f64,
}

/// A sonar ring's constant message fields.
pub(super) struct SonarTopics {
    pub channels: Vec<Channel<Range>>,
    pub frames: Vec<String>,
    pub field_of_view: f32,
    pub min_range: f32,
    pub max_range: f32,
}

/// A robot's channels and recording state.
pub(super) struct RobotTopics {
    pub index: u32,
    pub base: String,
    pub odom_frame: String,
    pub laser_frame: String,
    pub camera_frame: String,
    pub truth: Channel<PoseStamped>,
    /// (channel, scan time = laser period)
    pub scan: Option<(Channel<LaserScan>, f32)>,
    /// (channel, ticks per revolution, Ackermann)
    pub joints: Option<(Channel<JointState>, u32, bool)>,
    pub odom: Option<Channel<Odometry>>,
    pub gps: Option<Channel<NavSatFix>>,
    pub compass: Option<Channel<Imu>>,
    pub camera: Option<Channel<Image>>,
    pub sonars: Option<SonarTopics>,
    /// The odometry's pose before the first encoder reading.
    pub odom_start: Pose2,
    /// The last odometry pose written (stamp, pose).
    pub last_odom: Option<(f64, Pose2)>,
    /// map → odom from the latest estimate of the localizer the robot navigates by (else its
    /// first), and that estimate's stamp.
    pub correction: Pose2,
    pub correction_stamp: f64,
}

/// Registers `topic` and notes it for `run.json`.
fn channel<T: RosMessage>(
    rec: &mut McapRecorder,
    topics: &mut Vec<TopicInfo>,
    robot: &str,
    topic: String,
    period_s: f64,
) -> anyhow::Result<Channel<T>> {
    let ch = rec.channel::<T>(&topic)?;
    topics.push(TopicInfo {
        topic,
        r#type: T::NAME.to_string(),
        robot: robot.to_string(),
        period_s,
    });
    Ok(ch)
}

/// The topics of every robot of `world` (in index order), registered on `rec`; their static
/// transforms (base → sensor mounts) are added to `statics`.
pub(super) fn robot_topics(
    world: &mut World,
    rec: &mut McapRecorder,
    dt: f64,
    topics: &mut Vec<TopicInfo>,
    statics: &mut Vec<TransformStamped>,
) -> anyhow::Result<Vec<RobotTopics>> {
    let mut q = world.query::<(Entity, &RobotIndex, &RobotId)>();
    let mut robots: Vec<(Entity, u32, String)> = q
        .iter(world)
        .map(|(e, i, id)| (e, i.0, id.0.clone()))
        .collect();
    robots.sort_by_key(|r| r.1);
    let mut out = Vec::with_capacity(robots.len());
    for (e, index, name) in robots {
        let e = world.entity(e);
        let base = format!("{name}/base_link");
        let laser_frame = format!("{name}/laser");
        let camera_frame = format!("{name}/camera");
        let t = &mut *topics;
        let truth = channel(rec, t, &name, format!("/{name}/ground_truth"), dt)?;
        let scan = match e.get::<Laser>() {
            Some(l) => {
                statics.push(transform(0.0, &base, &laser_frame, &l.spec.mount));
                let p = l.timer.period();
                Some((
                    channel(rec, t, &name, format!("/{name}/scan"), p)?,
                    p as f32,
                ))
            }
            None => None,
        };
        let odom_start = e.get::<WheelOdometry>().map(|o| o.pose);
        let (joints, odom) = match (e.get::<Encoder>(), e.get::<WheelOdometry>()) {
            (Some(enc), odo) => {
                let p = enc.timer.period();
                let ackermann =
                    odo.is_some_and(|o| matches!(o.model, OdometryModel::Ackermann { .. }));
                let joints = channel(rec, t, &name, format!("/{name}/joint_states"), p)?;
                let odom = match odo {
                    Some(_) => Some(channel(rec, t, &name, format!("/{name}/odom"), p)?),
                    None => None,
                };
                (Some((joints, enc.spec.ticks_per_rev, ackermann)), odom)
            }
            (None, _) => (None, None),
        };
        let gps = match e.get::<Gps>() {
            Some(g) => Some(channel(
                rec,
                t,
                &name,
                format!("/{name}/gps/fix"),
                g.timer.period(),
            )?),
            None => None,
        };
        let compass = match e.get::<Compass>() {
            Some(c) => Some(channel(
                rec,
                t,
                &name,
                format!("/{name}/compass"),
                c.timer.period(),
            )?),
            None => None,
        };
        let camera = match e.get::<Camera>() {
            Some(c) => {
                let s = &c.spec;
                statics.push(TransformStamped {
                    header: super::convert::header(0.0, &base),
                    child_frame_id: camera_frame.clone(),
                    transform: Transform {
                        translation: Vector3 {
                            x: s.mount_x,
                            y: 0.0,
                            z: s.mount_height,
                        },
                        // pitched down: a positive rotation about y (REP 103)
                        rotation: Quaternion {
                            x: 0.0,
                            y: (s.pitch / 2.0).sin(),
                            z: 0.0,
                            w: (s.pitch / 2.0).cos(),
                        },
                    },
                });
                let topic = format!("/{name}/camera/image_raw");
                Some(channel(rec, t, &name, topic, c.timer.period())?)
            }
            None => None,
        };
        let sonars = match e.get::<Sonars>() {
            Some(s) => {
                let mut channels = Vec::new();
                let mut frames = Vec::new();
                for (k, mount) in s.mounts.iter().enumerate() {
                    let frame = format!("{name}/sonar_{k}");
                    statics.push(transform(0.0, &base, &frame, mount));
                    let topic = format!("/{name}/sonar/{k}");
                    channels.push(channel(rec, t, &name, topic, s.timer.period())?);
                    frames.push(frame);
                }
                Some(SonarTopics {
                    channels,
                    frames,
                    field_of_view: s.spec.cone as f32,
                    min_range: s.spec.min_range as f32,
                    max_range: s.spec.max_range as f32,
                })
            }
            None => None,
        };
        out.push(RobotTopics {
            index,
            odom_frame: format!("{name}/odom"),
            base,
            laser_frame,
            camera_frame,
            truth,
            scan,
            joints,
            odom,
            gps,
            compass,
            camera,
            sonars,
            odom_start: odom_start.unwrap_or(Pose2::IDENTITY),
            last_odom: None,
            correction: Pose2::IDENTITY,
            correction_stamp: f64::NEG_INFINITY,
        });
    }
    Ok(out)
}
