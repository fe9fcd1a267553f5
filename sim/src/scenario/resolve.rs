//! Validation and defaults: turns a [`ScenarioFile`] into a [`Scenario`], reporting the first
//! problem with the file, line and key.

use super::check::{Checker, PointOrPlace, R, check_name};
use super::error::{ErrorContext, KeyPath};
use super::file::*;
use super::model::{RecordConfig, RobotConfig, Scenario};
use super::outdoor::RoadsConfig;
use super::outdoor_robot;
use super::outdoor_robot::RouteConfig;
use super::sensors::{resolve_encoder, resolve_laser};
use super::sonar::SonarConfig;
use std::collections::BTreeMap;
use std::path::Path;
use systems::body::{Ackermann, DiffDrive, Footprint, Kinematics};
use systems::core::Pose2;
use systems::navigation::BehaviourKind;
use systems::sensors::{CameraSpec, CompassSpec, EncoderSpec, GpsSpec, LaserSpec};
use systems::world::shapes::{Shape, grid_for_shapes, rasterize};
use systems::world::{Cell, OccupancyGrid, load_map};

/// Scenario text: parsed into its [`ScenarioFile`] and resolved; errors name `file_label`, the
/// line and the key.
pub fn resolve(text: &str, file_label: &str, base_dir: &Path, default_name: &str) -> R<Scenario> {
    let c = Checker {
        cx: ErrorContext::new(file_label.to_string(), text),
    };
    let f: ScenarioFile = toml::from_str(text).map_err(|e| c.cx.from_toml(&e))?;
    resolve_file(&c, f, base_dir, default_name)
}

/// A scenario given as its file model (built in code by the scenario builder): the same checks
/// and defaults as its text would get; errors name `label` and the key (there are no lines).
pub fn resolve_model(
    f: ScenarioFile,
    label: &str,
    base_dir: &Path,
    default_name: &str,
) -> R<Scenario> {
    let c = Checker {
        cx: ErrorContext::new(label.to_string(), ""),
    };
    resolve_file(&c, f, base_dir, default_name)
}

fn resolve_file(c: &Checker, f: ScenarioFile, base_dir: &Path, default_name: &str) -> R<Scenario> {
    let root = KeyPath::default();
    let header = resolve_header(c, &root, &f, default_name)?;
    let shapes = resolve_shapes(c, &root, &f)?;
    let roads = match &f.roads {
        Some(r) => Some(super::outdoor::resolve_roads(
            c,
            &root.key("roads"),
            r,
            base_dir,
        )?),
        None => None,
    };
    let zones = super::outdoor::resolve_zones(c, &root.key("zones"), &f.zones)?;
    let map = f.map.as_ref();
    let grid = resolve_grid(c, &root, map, &shapes, roads.as_ref(), base_dir)?;
    let (mut places, mut doors) = match map.and_then(|m| m.places.as_ref()) {
        Some(pf) => super::places::load_places(
            c,
            &root.key("map").key("places"),
            &base_dir.join(pf),
            &grid,
        )?,
        None => (BTreeMap::new(), Vec::new()),
    };
    let own = super::places::PlacesFile {
        places: f.places.clone(),
        doors: f.doors.clone(),
    };
    super::places::add_places(&c.cx, &own, &grid, &mut places, &mut doors)?;
    let world = World {
        c,
        grid: &grid,
        places: &places,
    };
    let record = resolve_record(c, &root.key("record"), f.record.as_ref())?;
    let mut robots: Vec<RobotConfig> = Vec::new();
    for (i, r) in f.robots.iter().enumerate() {
        let robot = resolve_robot(
            &world,
            &root.key("robots").index(i),
            i,
            r,
            roads.as_ref(),
            &robots,
        )?;
        robots.push(robot);
    }
    let events = super::events::resolve_events(
        c,
        &root.key("events"),
        &f.events,
        header.duration,
        super::events::Known {
            robots: &robots,
            doors: &doors,
            grid: &grid,
        },
        &|p, v| world.point(p, v),
        &|p, v| world.inside(p, v),
        &|p, v| world.points(p, v),
    )?;
    let people = super::people::resolve_people(
        c,
        &root.key("people"),
        &f.people,
        &|p, v| world.point(p, v),
        &|p, v| world.inside(p, v),
        &grid,
    )?;
    Ok(Scenario {
        name: header.name,
        description: f.description.unwrap_or_default(),
        seed: header.seed,
        dt: header.dt,
        duration: header.duration,
        source: c.cx.file.clone(),
        grid,
        places,
        record,
        robots,
        events,
        doors,
        end_when_done: f.end_when_done.unwrap_or(false),
        people,
        roads,
        zones,
    })
}

/// The scenario's own keys: name, seed, time step, duration.
struct Header {
    name: String,
    seed: u64,
    dt: f64,
    duration: f64,
}

fn resolve_header(c: &Checker, root: &KeyPath, f: &ScenarioFile, default_name: &str) -> R<Header> {
    let name = f.name.clone().unwrap_or_else(|| default_name.to_string());
    if !check_name(&name) {
        return c.err(
            &root.key("name"),
            format!("expected letters, digits, `_` or `-` (it names output files), got `{name}`"),
        );
    }
    let dt = match f.dt {
        Some(v) => c.range(&root.key("dt"), v, Some(0.0), Some(1.0), true)?,
        None => 0.05,
    };
    let Some(duration) = f.duration else {
        return c.err(root, "missing key `duration` (simulated seconds)");
    };
    let duration = c.positive(&root.key("duration"), duration)?;
    Ok(Header {
        name,
        seed: f.seed.unwrap_or(0),
        dt,
        duration,
    })
}

/// `[[walls]]`, `[[boxes]]` and `[[discs]]`: the vector shapes rasterised into the map.
fn resolve_shapes(c: &Checker, root: &KeyPath, f: &ScenarioFile) -> R<Vec<Shape>> {
    let mut shapes = Vec::new();
    for (i, w) in f.walls.iter().enumerate() {
        let p = root.key("walls").index(i);
        c.finite(&p.key("from"), &w.from)?;
        c.finite(&p.key("to"), &w.to)?;
        let thickness = c.opt_positive(&p.key("thickness"), w.thickness, 0.1)?;
        shapes.push(Shape::Wall {
            from: w.from,
            to: w.to,
            thickness,
        });
    }
    for (i, b) in f.boxes.iter().enumerate() {
        let p = root.key("boxes").index(i);
        c.finite(&p.key("center"), &b.center)?;
        c.positive(&p.key("size"), b.size[0].min(b.size[1]))?;
        let yaw = b.yaw.unwrap_or(0.0);
        c.finite(&p.key("yaw"), &[yaw])?;
        shapes.push(Shape::Box {
            center: b.center,
            size: b.size,
            yaw,
        });
    }
    for (i, d) in f.discs.iter().enumerate() {
        let p = root.key("discs").index(i);
        c.finite(&p.key("center"), &d.center)?;
        let radius = c.positive(&p.key("radius"), d.radius)?;
        shapes.push(Shape::Disc {
            center: d.center,
            radius,
        });
    }
    Ok(shapes)
}

/// The occupancy grid: the map file, or a grid over the shapes and roads, with the shapes drawn
/// in.
fn resolve_grid(
    c: &Checker,
    root: &KeyPath,
    map: Option<&MapFile>,
    shapes: &[Shape],
    roads: Option<&RoadsConfig>,
    base_dir: &Path,
) -> R<OccupancyGrid> {
    let mpath = root.key("map");
    let file = map.and_then(|m| m.file.as_ref());
    let resolution = map.and_then(|m| m.resolution);
    let mut grid: OccupancyGrid = match file {
        Some(file) => {
            let path = base_dir.join(file);
            load_map(&path).map_err(|e| c.cx.at(&mpath.key("file"), e.to_string()))?
        }
        None => {
            // outdoors the grid only carries obstacles (trees, buildings): 0.2 m cells
            let default_res = if roads.is_some() { 0.2 } else { 0.05 };
            let res = c.opt_positive(&mpath.key("resolution"), resolution, default_res)?;
            let outdoor = roads.map(|r| (r.graph.bounds(), r.margin));
            match grid_for_world(shapes, outdoor, res) {
                Some(g) => g,
                None => {
                    return c.err(
                        root,
                        "the world is empty: give `map.file` (a ROS map_server YAML), `[roads]` or walls, boxes or discs",
                    );
                }
            }
        }
    };
    if file.is_some() && resolution.is_some() {
        return c.err(
            &mpath.key("resolution"),
            "the resolution comes from the map file; remove this key",
        );
    }
    if grid.width * grid.height > 400_000_000 {
        return c.err(&mpath, "the map has more than 400 million cells");
    }
    for s in shapes {
        rasterize(&mut grid, s);
    }
    Ok(grid)
}

/// `[record]`: the recording's rates, over [`RecordConfig::default`].
fn resolve_record(c: &Checker, rp: &KeyPath, rec: Option<&RecordFile>) -> R<RecordConfig> {
    let d = RecordConfig::default();
    let Some(rec) = rec else {
        return Ok(d);
    };
    Ok(RecordConfig {
        rate: c.opt_positive(&rp.key("rate"), rec.rate, d.rate)?,
        scan_rate: c.opt_positive(&rp.key("scan_rate"), rec.scan_rate, d.scan_rate)?,
        path_rate: c.opt_positive(&rp.key("path_rate"), rec.path_rate, d.path_rate)?,
        particle_rate: c.opt_positive(
            &rp.key("particle_rate"),
            rec.particle_rate,
            d.particle_rate,
        )?,
        particle_points: rec.particle_points.unwrap_or(d.particle_points),
        camera_rate: c.opt_positive(&rp.key("camera_rate"), rec.camera_rate, d.camera_rate)?,
        slam_rate: match rec.slam_rate {
            Some(v) => c.range(&rp.key("slam_rate"), v, Some(0.0), None, false)?,
            None => d.slam_rate,
        },
    })
}

/// The map and its places, as every robot, event and person reads points from them.
struct World<'a> {
    c: &'a Checker<'a>,
    grid: &'a OccupancyGrid,
    places: &'a BTreeMap<String, Pose2>,
}

impl World<'_> {
    /// A pose from coordinates (`[x, y]` or `[x, y, yaw]`) or a place name.
    fn point(&self, path: &KeyPath, p: &PointOrPlace) -> R<Pose2> {
        let c = self.c;
        match p {
            PointOrPlace::Coords(v) if v.len() == 2 || v.len() == 3 => {
                c.finite(path, v)?;
                Ok(Pose2::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0)))
            }
            PointOrPlace::Coords(v) => c.err(
                path,
                format!("expected [x, y] or [x, y, yaw], got {} numbers", v.len()),
            ),
            PointOrPlace::Place(name) => self.places.get(name).copied().ok_or_else(|| {
                let known: Vec<&str> = self.places.keys().map(String::as_str).collect();
                c.cx.at(
                    path,
                    if known.is_empty() {
                        format!("unknown place `{name}` (the map has no places file)")
                    } else {
                        format!("unknown place `{name}`; known places: {}", known.join(", "))
                    },
                )
            }),
        }
    }

    /// An error unless `p` lies on the map.
    fn inside(&self, path: &KeyPath, p: &Pose2) -> R<()> {
        let b = self.grid.bounds();
        if p.x < b[0] || p.y < b[1] || p.x > b[2] || p.y > b[3] {
            return self.c.err(
                path,
                format!(
                    "({:.3}, {:.3}) lies outside the map [{:.2}, {:.2}] × [{:.2}, {:.2}]",
                    p.x, p.y, b[0], b[2], b[1], b[3]
                ),
            );
        }
        Ok(())
    }

    /// The `points` key under `path`: at least one point, each on the map.
    fn points(&self, path: &KeyPath, pts: &Option<Vec<PointOrPlace>>) -> R<Vec<[f64; 2]>> {
        let Some(pts) = pts else {
            return self
                .c
                .err(path, "missing `points` (a list of [x, y] or place names)");
        };
        if pts.is_empty() {
            return self
                .c
                .err(&path.key("points"), "expected at least one point");
        }
        let mut out = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            let pp = path.key("points").index(i);
            let pose = self.point(&pp, p)?;
            self.inside(&pp, &pose)?;
            out.push([pose.x, pose.y]);
        }
        Ok(out)
    }

    /// A point on the map.
    fn point_inside(&self, path: &KeyPath, v: &PointOrPlace) -> R<Pose2> {
        let pose = self.point(path, v)?;
        self.inside(path, &pose)?;
        Ok(pose)
    }
}

/// One `[[robots]]` table (`others`: the robots before it).
fn resolve_robot(
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
    let mut localizers =
        super::localizers::resolve_localizers(c, &lp, &r.localization, &start, &|path, v| {
            w.point_inside(path, v)
        })?;
    let slam = super::slam::resolve_slam(c, &p.key("slam"), r.slam.as_ref(), &start, &localizers)?;
    if !slam.is_empty() && (laser.is_none() || encoder.is_none()) {
        return c.err(
            &p.key("slam"),
            "SLAM reads the laser and the wheel odometry: give the robot \
             `[robots.sensors.laser]` and `[robots.sensors.encoder]`",
        );
    }
    localizers.extend(slam);
    if !localizers.is_empty() && (laser.is_none() || encoder.is_none()) {
        return c.err(
            &lp,
            "localizers read the laser and the wheel odometry: give the robot \
             `[robots.sensors.laser]` and `[robots.sensors.encoder]`",
        );
    }
    let navigation = super::navigation::resolve_navigation(
        c,
        p,
        r.navigation.as_ref(),
        &r.tasks,
        super::navigation::RobotParts {
            kinematics: &kinematics,
            footprint: &footprint,
            localizers: &localizers,
            index: i,
        },
        &|path, v| {
            let pose = w.point_inside(path, v)?;
            super::navigation::goal_clear(c, path, w.grid, &pose, footprint.bounding_radius())?;
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
        if encoder.is_none() {
            return c.err(
                &p.key("tasks"),
                "a robot with tasks navigates by its odometry and localization: give it `[robots.sensors.encoder]`",
            );
        }
    }
    if matches!(behaviour, BehaviourKind::Waypoints { .. }) && encoder.is_none() {
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
    let default_sonar = super::sonar::SonarFile::default();
    let sonar = match sensors.and_then(|s| s.sonar.as_ref()) {
        Some(s) => Some(s),
        None if preset.is_some_and(|pr| pr.sonars) => Some(&default_sonar),
        None => None,
    };
    let sonar = match sonar {
        Some(s) => Some(super::sonar::resolve_sonar(
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

/// The grid of a world without a map file: over the shapes (2 m around them) and the road
/// network (its margin around the roads), or `None` when there is neither.
fn grid_for_world(
    shapes: &[Shape],
    roads: Option<([f64; 4], f64)>,
    resolution: f64,
) -> Option<OccupancyGrid> {
    let from_shapes = grid_for_shapes(shapes, resolution, 2.0).map(|g| g.bounds());
    let from_roads = roads.map(|(b, m)| [b[0] - m, b[1] - m, b[2] + m, b[3] + m]);
    let b = match (from_shapes, from_roads) {
        (Some(a), Some(b)) => [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ],
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => return None,
    };
    let w = ((b[2] - b[0]) / resolution).ceil().max(1.0) as usize;
    let h = ((b[3] - b[1]) / resolution).ceil().max(1.0) as usize;
    Some(OccupancyGrid::new(
        w,
        h,
        resolution,
        [b[0], b[1]],
        Cell::Free,
    ))
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
