//! A robot's table resolved: its start, footprint, kinematics, sensors and behaviour, with the
//! points it names read from the map and its places.

use super::world::World;
use crate::scenario::check::{Checker, OdometrySource, R, check_name};
use crate::scenario::error::KeyPath;
use crate::scenario::file::*;
use crate::scenario::model::RobotConfig;
use crate::scenario::outdoor::RoadsConfig;
use crate::scenario::outdoor_robot;
use crate::scenario::outdoor_robot::RouteConfig;
use crate::scenario::sensors::{resolve_encoder, resolve_laser};
use crate::scenario::sonar::SonarConfig;
use systems::body::{Ackermann, DiffDrive, Footprint, Kinematics};
use systems::core::Pose2;
use systems::navigation::BehaviourKind;
use systems::sensors::{CameraSpec, CompassSpec, EncoderSpec, GpsSpec, LaserSpec};

/// One `[[robots]]` table (`others`: the robots before it).
pub(super) fn resolve_robot(
    w: &World,
    p: &KeyPath,
    i: usize,
    r: &RobotFile,
    roads: Option<&RoadsConfig>,
    others: &[RobotConfig],
) -> R<RobotConfig> {
    let c = w.c;
    if !check_name(&r.name) {
        return c.err(
            &p.key("name"),
            format!("expected letters, digits, `_` or `-`, got `{}`", r.name),
        );
    }
    if others.iter().any(|o| o.name == r.name) {
        return c.err(&p.key("name"), format!("duplicate robot name `{}`", r.name));
    }
    let preset = match &r.preset {
        Some(name) => Some(outdoor_robot::preset(name).map_or_else(
            || {
                c.err(
                    &p.key("preset"),
                    format!(
                        "unknown robot preset `{name}`; known: {}",
                        outdoor_robot::PRESETS.join(", ")
                    ),
                )
            },
            Ok,
        )?),
        None => None,
    };
    let footprint = match (&r.footprint, &preset) {
        (None, Some(pr)) => pr.footprint.clone(),
        (f, _) => resolve_footprint(c, &p.key("footprint"), f.as_ref())?,
    };
    let (start, route) = resolve_start(w, p, r, roads, &footprint)?;
    let kinematics = match (&r.kinematics, &preset) {
        (None, Some(pr)) => pr.kinematics.clone(),
        (k, _) => resolve_kinematics(c, &p.key("kinematics"), k.as_ref())?,
    };
    let bp = p.key("behaviour");
    let (behaviour, speed, tolerance) =
        resolve_behaviour(w, &bp, r.behaviour.as_ref(), &kinematics)?;
    let RobotSensors {
        laser,
        encoder,
        sonar,
        gps,
        compass,
        camera,
    } = resolve_sensors(c, p, r, preset.as_ref(), &footprint, route.as_ref())?;
    let lp = p.key("localization");
    let mut localizers = crate::scenario::localizers::resolve_localizers(
        c,
        &lp,
        &r.localization,
        &start,
        &|path, v| w.point_inside(path, v),
    )?;
    let slam = crate::scenario::slam::resolve_slam(
        c,
        &p.key("slam"),
        r.slam.as_ref(),
        &start,
        &localizers,
    )?;
    // odometry recorded on a topic (a replay) stands in for the encoders
    let recorded = c.odometry == OdometrySource::Recorded;
    let needs = if recorded {
        "the laser and recorded odometry: give the robot `[robots.sensors.laser]`"
    } else {
        "the laser and the wheel odometry: give the robot `[robots.sensors.laser]` and \
         `[robots.sensors.encoder]`"
    };
    let lacking = laser.is_none() || (encoder.is_none() && !recorded);
    if !slam.is_empty() && lacking {
        return c.err(&p.key("slam"), format!("SLAM reads {needs}"));
    }
    localizers.extend(slam);
    if !localizers.is_empty() && lacking {
        return c.err(&lp, format!("localizers read {needs}"));
    }
    let navigation = crate::scenario::navigation::resolve_navigation(
        c,
        p,
        r.navigation.as_ref(),
        &r.tasks,
        crate::scenario::navigation::RobotParts {
            kinematics: &kinematics,
            footprint: &footprint,
            localizers: &localizers,
            index: i,
        },
        &|path, v| {
            let pose = w.point_inside(path, v)?;
            crate::scenario::navigation::goal_clear(
                c,
                path,
                w.grid,
                &pose,
                footprint.bounding_radius(),
            )?;
            Ok(pose)
        },
    )?;
    if navigation.is_some() {
        if r.behaviour.is_some() {
            return c.err(
                &bp,
                "a robot with tasks is driven by its navigator: remove `behaviour`",
            );
        }
        if encoder.is_none() && !recorded {
            return c.err(
                &p.key("tasks"),
                "a robot with tasks navigates by its odometry and localization: give it `[robots.sensors.encoder]`",
            );
        }
    }
    let behaviour_localizer = match r.behaviour.as_ref().and_then(|b| b.localizer.as_deref()) {
        None => None,
        Some(_) if matches!(behaviour, BehaviourKind::Idle) => {
            return c.err(
                &bp.key("localizer"),
                "an `idle` robot does not move: only `waypoints` and `wander` drive by a localizer",
            );
        }
        Some(name) => Some(crate::scenario::localizers::localizer_index(
            c,
            &bp.key("localizer"),
            name,
            &localizers,
        )?),
    };
    if matches!(behaviour, BehaviourKind::Waypoints { .. }) && encoder.is_none() && !recorded {
        return c.err(
            &bp.key("type"),
            "a `waypoints` robot navigates by its odometry: give it `[robots.sensors.encoder]`",
        );
    }
    Ok(RobotConfig {
        name: r.name.clone(),
        start,
        footprint,
        kinematics,
        behaviour,
        behaviour_localizer,
        speed,
        tolerance,
        laser,
        encoder,
        sonar,
        localizers,
        navigation,
        gps,
        compass,
        camera,
        route,
    })
}

/// A robot's sensors.
struct RobotSensors {
    laser: Option<LaserSpec>,
    encoder: Option<EncoderSpec>,
    sonar: Option<SonarConfig>,
    gps: Option<GpsSpec>,
    compass: Option<CompassSpec>,
    camera: Option<CameraSpec>,
}

/// `[robots.sensors]`: each sensor's table over its preset (the robot preset's sensors without
/// a table).
fn resolve_sensors(
    c: &Checker,
    p: &KeyPath,
    r: &RobotFile,
    preset: Option<&outdoor_robot::Preset>,
    footprint: &Footprint,
    route: Option<&RouteConfig>,
) -> R<RobotSensors> {
    let sensors = r.sensors.as_ref();
    let sp = p.key("sensors");
    let laser = match sensors.and_then(|s| s.laser.as_ref()) {
        Some(l) => Some(resolve_laser(c, &sp.key("laser"), l)?),
        None => None,
    };
    let encoder = match sensors.and_then(|s| s.encoder.as_ref()) {
        Some(e) => Some(resolve_encoder(c, &sp.key("encoder"), e)?),
        None => preset.map(|pr| pr.encoder.clone()),
    };
    let default_sonar = crate::scenario::sonar::SonarFile::default();
    let sonar = match sensors.and_then(|s| s.sonar.as_ref()) {
        Some(s) => Some(s),
        None if preset.is_some_and(|pr| pr.sonars) => Some(&default_sonar),
        None => None,
    };
    let sonar = match sonar {
        Some(s) => Some(crate::scenario::sonar::resolve_sonar(
            c,
            &sp.key("sonar"),
            &r.name,
            footprint,
            s,
        )?),
        None => None,
    };
    let tables = outdoor_robot::OutdoorTables {
        gps: sensors.and_then(|s| s.gps.as_ref()),
        compass: sensors.and_then(|s| s.compass.as_ref()),
        camera: sensors.and_then(|s| s.camera.as_ref()),
        has_encoder: encoder.is_some(),
        driven_otherwise: r.behaviour.is_some() || !r.tasks.is_empty(),
    };
    let (gps, compass, camera) =
        outdoor_robot::resolve_outdoor_sensors(c, p, &tables, preset, route)?;
    Ok(RobotSensors {
        laser,
        encoder,
        sonar,
        gps,
        compass,
        camera,
    })
}

/// A robot's start pose (`start`, or the start of its `route`), clear of obstacles.
fn resolve_start(
    w: &World,
    p: &KeyPath,
    r: &RobotFile,
    roads: Option<&RoadsConfig>,
    footprint: &Footprint,
) -> R<(Pose2, Option<RouteConfig>)> {
    let c = w.c;
    let (start, route) = match (&r.start, &r.route) {
        (Some(_), Some(_)) => {
            return c.err(
                &p.key("start"),
                "a robot with a `route` starts on its road at the route's `start`: remove `start`",
            );
        }
        (Some(s), None) => (w.point(&p.key("start"), s)?, None),
        (None, Some(rf)) => {
            let (route, pose) = outdoor_robot::resolve_route(c, &p.key("route"), rf, roads)?;
            (pose, Some(route))
        }
        (None, None) => {
            return c.err(p, "missing key `start` ([x, y, yaw] or a place name)");
        }
    };
    w.inside(&p.key("start"), &start)?;
    if !w
        .grid
        .disc_is_clear(start.x, start.y, footprint.bounding_radius())
    {
        return c.err(
            &p.key("start"),
            format!(
                "the robot at ({:.2}, {:.2}) would overlap an obstacle (footprint radius {:.2} m)",
                start.x,
                start.y,
                footprint.bounding_radius()
            ),
        );
    }
    Ok((start, route))
}

/// A robot's `behaviour`: its kind, speed and waypoint tolerance (idle at 0.6 m/s and 0.4 m
/// without one).
fn resolve_behaviour(
    w: &World,
    bp: &KeyPath,
    b: Option<&BehaviourFile>,
    kinematics: &Kinematics,
) -> R<(BehaviourKind, f64, f64)> {
    let c = w.c;
    let Some(b) = b else {
        return Ok((BehaviourKind::Idle, 0.6, 0.4));
    };
    let speed = c.opt_positive(&bp.key("speed"), b.speed, 0.6)?;
    if speed > kinematics.max_speed() + 1e-9 {
        return c.err(
            &bp.key("speed"),
            format!(
                "{speed} m/s exceeds the drive's top speed of {:.3} m/s",
                kinematics.max_speed()
            ),
        );
    }
    let tolerance = c.opt_positive(&bp.key("tolerance"), b.tolerance, 0.4)?;
    let kind = match b.kind {
        BehaviourType::Idle | BehaviourType::Wander => {
            if b.points.is_some() {
                return c.err(
                    &bp.key("points"),
                    "only a `waypoints` behaviour takes points",
                );
            }
            if b.looping.is_some() {
                return c.err(&bp.key("loop"), "only a `waypoints` behaviour takes `loop`");
            }
            if b.kind == BehaviourType::Idle {
                BehaviourKind::Idle
            } else {
                BehaviourKind::Wander
            }
        }
        BehaviourType::Waypoints => BehaviourKind::Waypoints {
            points: w.points(bp, &b.points)?,
            looping: b.looping.unwrap_or(false),
        },
    };
    Ok((kind, speed, tolerance))
}

fn resolve_footprint(c: &Checker, p: &KeyPath, f: Option<&FootprintFile>) -> R<Footprint> {
    match f {
        None => Ok(Footprint::Circle { radius: 0.25 }),
        Some(FootprintFile {
            circle: Some(r),
            rectangle: None,
        }) => Ok(Footprint::Circle {
            radius: c.range(&p.key("circle"), *r, Some(0.0), Some(10.0), true)?,
        }),
        Some(FootprintFile {
            circle: None,
            rectangle: Some([l, w]),
        }) => {
            c.range(&p.key("rectangle"), l.min(*w), Some(0.0), None, true)?;
            c.range(&p.key("rectangle"), l.max(*w), None, Some(20.0), false)?;
            Ok(Footprint::Rectangle {
                length: *l,
                width: *w,
            })
        }
        Some(_) => c.err(
            p,
            "expected exactly one of `circle = radius` or `rectangle = [length, width]`",
        ),
    }
}

fn resolve_kinematics(c: &Checker, p: &KeyPath, k: Option<&KinematicsFile>) -> R<Kinematics> {
    let Some(k) = k else {
        return Ok(Kinematics::DiffDrive(default_diff_drive()));
    };
    let not_for = |key: &str, v: Option<f64>, kind: &str| -> R<()> {
        if v.is_some() {
            return c.err(
                &p.key(key),
                format!("`{key}` does not apply to `{kind}` kinematics"),
            );
        }
        Ok(())
    };
    match k.kind {
        KinematicsType::DiffDrive => {
            not_for("wheelbase", k.wheelbase, "diff_drive")?;
            not_for("max_steer", k.max_steer, "diff_drive")?;
            not_for("max_steer_rate", k.max_steer_rate, "diff_drive")?;
            not_for("max_speed", k.max_speed, "diff_drive")?;
            not_for("max_accel", k.max_accel, "diff_drive")?;
            let d = default_diff_drive();
            Ok(Kinematics::DiffDrive(DiffDrive {
                wheel_base: c.opt_positive(&p.key("wheel_base"), k.wheel_base, d.wheel_base)?,
                wheel_radius: c.opt_positive(
                    &p.key("wheel_radius"),
                    k.wheel_radius,
                    d.wheel_radius,
                )?,
                max_wheel_speed: c.opt_positive(
                    &p.key("max_wheel_speed"),
                    k.max_wheel_speed,
                    d.max_wheel_speed,
                )?,
                max_wheel_accel: c.opt_positive(
                    &p.key("max_wheel_accel"),
                    k.max_wheel_accel,
                    d.max_wheel_accel,
                )?,
            }))
        }
        KinematicsType::Ackermann => {
            not_for("wheel_base", k.wheel_base, "ackermann (use `wheelbase`)")?;
            not_for("max_wheel_speed", k.max_wheel_speed, "ackermann")?;
            not_for("max_wheel_accel", k.max_wheel_accel, "ackermann")?;
            let max_steer = match k.max_steer {
                Some(v) => c.range(&p.key("max_steer"), v, Some(0.0), Some(1.4), true)?,
                None => 0.45,
            };
            Ok(Kinematics::Ackermann(Ackermann {
                wheelbase: c.opt_positive(&p.key("wheelbase"), k.wheelbase, 0.35)?,
                max_steer,
                max_steer_rate: c.opt_positive(&p.key("max_steer_rate"), k.max_steer_rate, 1.5)?,
                max_speed: c.opt_positive(&p.key("max_speed"), k.max_speed, 1.5)?,
                max_accel: c.opt_positive(&p.key("max_accel"), k.max_accel, 1.0)?,
                wheel_radius: c.opt_positive(&p.key("wheel_radius"), k.wheel_radius, 0.05)?,
            }))
        }
    }
}

/// A hospital delivery robot: 0.45 m wheel base, 10 cm wheels, 1.5 m/s, 2 m/s².
pub fn default_diff_drive() -> DiffDrive {
    DiffDrive {
        wheel_base: 0.45,
        wheel_radius: 0.1,
        max_wheel_speed: 15.0,
        max_wheel_accel: 20.0,
    }
}

#[cfg(test)]
mod tests {
    use crate::scenario::OdometrySource;
    use crate::scenario::load::parse_scenario_with;
    use std::path::Path;

    const ROBOT: &str = r#"[[robots]]
name = "r1"
start = [5.0, 5.0, 0.0]
behaviour = { type = "waypoints", points = [[8.0, 5.0]] }
"#;

    fn parse(sensors: &str, odometry: OdometrySource) -> Result<(), String> {
        let room = crate::scenario::TEST_ROOM;
        let text = format!("{room}{ROBOT}{sensors}\n[[robots.localization]]\ntype = \"mcl\"\n");
        parse_scenario_with(&text, "t.toml", Path::new("."), "t", odometry)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    /// A replay of recorded odometry needs no encoders, but localizers still need the laser.
    #[test]
    fn recorded_odometry_stands_in_for_the_encoders_only() {
        let laser = "[robots.sensors.laser]";
        let e = parse(laser, OdometrySource::Encoders).unwrap_err();
        assert!(
            e.contains("t.toml:") && e.contains("[robots.sensors.encoder]"),
            "{e}"
        );
        parse(laser, OdometrySource::Recorded).unwrap();
        let e = parse("", OdometrySource::Recorded).unwrap_err();
        assert!(
            e.contains("recorded odometry")
                && e.contains("[robots.sensors.laser]")
                && !e.contains("encoder"),
            "{e}"
        );
    }
}
