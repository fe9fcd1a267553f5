//! A robot's outdoor parts: `[robots.sensors.gps]`, `[robots.sensors.compass]`,
//! `[robots.sensors.camera]`, the `thesis_car` preset (the RC car of [Park thesis]:
//! 520 × 400 mm, Ackermann steering, one drive-shaft encoder with under 1 % distance
//! error, four SRF02 sonars, GPS, compass and camera) and `[robots.route]` (drive to a node of
//! the road network, localizing on the roads).

use super::check::{Checker, R};
use super::error::KeyPath;
use super::outdoor::RoadsConfig;
use serde::Deserialize;
use systems::body::{Ackermann, Footprint, Kinematics};
use systems::core::Pose2;
use systems::sensors::gps::{COLD_START_S, HOT_START_S};
use systems::sensors::{CameraSpec, CompassSpec, EncoderSpec, GpsSpec};
use systems::world::roads::{NodeId, RoadGraph, geo::heading_of_azimuth};

/// `[robots.sensors.gps]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct GpsFile {
    /// Fixes per second (1–10 Hz).
    pub rate: Option<f64>,
    /// `hot` (first fix after 2 s) or `cold` (35 s).
    pub start: Option<String>,
    /// Seconds before the first fix (overrides `start`).
    pub first_fix: Option<f64>,
    pub altitude: Option<f64>,
}

/// `[robots.sensors.compass]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct CompassFile {
    pub rate: Option<f64>,
    pub noise_std_deg: Option<f64>,
    pub bias_deg: Option<f64>,
}

/// `[robots.sensors.camera]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub hfov_deg: Option<f64>,
    /// Height of the lens above the ground (m).
    pub mount_height: Option<f64>,
    /// Forward offset of the lens from the robot's origin (m).
    pub mount_x: Option<f64>,
    /// Downward tilt (degrees).
    pub pitch_deg: Option<f64>,
    pub rate: Option<f64>,
    /// Per-pixel noise (0–255 units).
    pub noise_std: Option<f64>,
    /// Frame-to-frame relative brightness variation.
    pub brightness_std: Option<f64>,
}

/// `[robots.route]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct RouteFile {
    /// The road node the robot starts at (its id in the road file: the OSM node id).
    pub start: String,
    /// A neighbour of `start` the robot faces (needed when `start` has several).
    pub toward: Option<String>,
    /// Metres from `start` towards `toward` (default 0).
    pub along: Option<f64>,
    /// The road node to drive to.
    pub goal: String,
    /// The road localizer the robot navigates by: `road_grid` or `road_mcl` (default).
    pub navigate_by: Option<String>,
    /// Cruise speed (m/s, default 1).
    pub speed: Option<f64>,
    /// The robot stops when its belief is this close to the goal node (m, default 1). The run
    /// counts as reached when it truly stopped within 5 m.
    pub tolerance: Option<f64>,
}

/// The road localizers every robot with a route runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoadLocalizerKind {
    Grid,
    Mcl,
}

impl RoadLocalizerKind {
    pub const ALL: [RoadLocalizerKind; 2] = [RoadLocalizerKind::Grid, RoadLocalizerKind::Mcl];

    pub fn as_str(self) -> &'static str {
        match self {
            RoadLocalizerKind::Grid => "road_grid",
            RoadLocalizerKind::Mcl => "road_mcl",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.as_str() == s)
    }
}

/// A resolved route.
#[derive(Clone, Debug, PartialEq)]
pub struct RouteConfig {
    pub start: NodeId,
    pub toward: NodeId,
    pub goal: NodeId,
    pub navigate_by: RoadLocalizerKind,
    pub speed: f64,
    pub tolerance: f64,
}

/// The parts the `thesis_car` preset fills in where the robot does not give them.
pub struct Preset {
    pub footprint: Footprint,
    pub kinematics: Kinematics,
    pub encoder: EncoderSpec,
    pub gps: GpsSpec,
    pub compass: CompassSpec,
    pub camera: CameraSpec,
    /// The robot gets the seed's four sonars (front, ±45°, rear).
    pub sonars: bool,
}

pub const PRESETS: [&str; 1] = ["thesis_car"];

pub fn preset(name: &str) -> Option<Preset> {
    match name {
        "thesis_car" => Some(Preset {
            footprint: Footprint::Rectangle {
                length: 0.52,
                width: 0.40,
            },
            kinematics: Kinematics::Ackermann(Ackermann {
                wheelbase: 0.34,
                max_steer: 0.45,
                max_steer_rate: 1.5,
                max_speed: 2.0,
                max_accel: 1.0,
                wheel_radius: 0.055,
            }),
            // one encoder on the drive shaft; the thesis measured 0.31–1.06 % distance error
            // after calibration (10 runs of 10 m): 0.8 % too long, plus slip
            encoder: EncoderSpec {
                ticks_per_rev: 512,
                left_radius_error: 0.008,
                right_radius_error: 0.008,
                wheel_base_error: 0.0,
                slip_std: 0.01,
                rate: 50.0,
            },
            gps: GpsSpec::default(),
            compass: CompassSpec::default(),
            camera: CameraSpec::default(),
            sonars: true,
        }),
        _ => None,
    }
}

pub(super) fn resolve_gps(c: &Checker, p: &KeyPath, f: &GpsFile, base: GpsSpec) -> R<GpsSpec> {
    let mut s = base;
    if let Some(v) = f.rate {
        s.rate = c.range(&p.key("rate"), v, Some(1.0), Some(10.0), false)?;
    }
    if let Some(start) = &f.start {
        s.first_fix = match start.as_str() {
            "hot" => HOT_START_S,
            "cold" => COLD_START_S,
            other => {
                return c.err(
                    &p.key("start"),
                    format!("expected `hot` or `cold`, got `{other}`"),
                );
            }
        };
    }
    if let Some(v) = f.first_fix {
        s.first_fix = c.range(&p.key("first_fix"), v, Some(0.0), Some(3600.0), false)?;
    }
    if let Some(v) = f.altitude {
        s.altitude = c.range(&p.key("altitude"), v, Some(-500.0), Some(9000.0), false)?;
    }
    Ok(s)
}

pub(super) fn resolve_compass(
    c: &Checker,
    p: &KeyPath,
    f: &CompassFile,
    base: CompassSpec,
) -> R<CompassSpec> {
    let mut s = base;
    if let Some(v) = f.rate {
        s.rate = c.range(&p.key("rate"), v, Some(0.0), Some(1000.0), true)?;
    }
    if let Some(v) = f.noise_std_deg {
        s.noise_std_deg = c.range(&p.key("noise_std_deg"), v, Some(0.0), Some(90.0), false)?;
    }
    if let Some(v) = f.bias_deg {
        s.bias_deg = c.range(&p.key("bias_deg"), v, Some(-180.0), Some(180.0), false)?;
    }
    Ok(s)
}

pub(super) fn resolve_camera(
    c: &Checker,
    p: &KeyPath,
    f: &CameraFile,
    base: CameraSpec,
) -> R<CameraSpec> {
    let mut s = base;
    if let Some(v) = f.width {
        s.width = c.range(&p.key("width"), v as f64, Some(8.0), Some(4096.0), false)? as u32;
    }
    if let Some(v) = f.height {
        s.height = c.range(&p.key("height"), v as f64, Some(8.0), Some(4096.0), false)? as u32;
    }
    if let Some(v) = f.hfov_deg {
        s.hfov = c
            .range(&p.key("hfov_deg"), v, Some(1.0), Some(170.0), false)?
            .to_radians();
    }
    if let Some(v) = f.mount_height {
        s.mount_height = c.range(&p.key("mount_height"), v, Some(0.0), Some(10.0), true)?;
    }
    if let Some(v) = f.mount_x {
        s.mount_x = c.range(&p.key("mount_x"), v, Some(-5.0), Some(5.0), false)?;
    }
    if let Some(v) = f.pitch_deg {
        s.pitch = c
            .range(&p.key("pitch_deg"), v, Some(1.0), Some(89.0), false)?
            .to_radians();
    }
    if let Some(v) = f.rate {
        s.rate = c.range(&p.key("rate"), v, Some(0.0), Some(100.0), true)?;
    }
    if let Some(v) = f.noise_std {
        s.noise_std = c.range(&p.key("noise_std"), v, Some(0.0), Some(128.0), false)?;
    }
    if let Some(v) = f.brightness_std {
        s.brightness_std = c.range(&p.key("brightness_std"), v, Some(0.0), Some(1.0), false)?;
    }
    Ok(s)
}

/// A node named by its id in the road file.
fn node(c: &Checker, p: &KeyPath, graph: &RoadGraph, id: &str) -> R<NodeId> {
    graph.node_by_source(id).map_or_else(
        || {
            c.err(
                p,
                format!("the road network has no node `{id}` (use the node's id in the road file)"),
            )
        },
        Ok,
    )
}

/// Resolves `[robots.route]` into the route and the robot's start pose on the road.
pub(super) fn resolve_route(
    c: &Checker,
    p: &KeyPath,
    f: &RouteFile,
    roads: Option<&RoadsConfig>,
) -> R<(RouteConfig, Pose2)> {
    let Some(roads) = roads else {
        return c.err(p, "a route needs a road network: add `[roads] file = ...`");
    };
    let g = &*roads.graph;
    let start = node(c, &p.key("start"), g, &f.start)?;
    let goal = node(c, &p.key("goal"), g, &f.goal)?;
    let neighbours: Vec<NodeId> = g.adjacency[start].iter().map(|&(_, n)| n).collect();
    let toward = match &f.toward {
        Some(t) => {
            let n = node(c, &p.key("toward"), g, t)?;
            if !neighbours.contains(&n) {
                return c.err(
                    &p.key("toward"),
                    format!(
                        "node `{t}` is not a neighbour of the start node `{}`",
                        f.start
                    ),
                );
            }
            n
        }
        None if neighbours.len() == 1 => neighbours[0],
        None => {
            let names: Vec<&str> = neighbours
                .iter()
                .map(|&n| g.nodes[n].source.as_str())
                .collect();
            return c.err(
                p,
                format!(
                    "start node `{}` has {} neighbours: say which the robot faces with `toward` (one of {})",
                    f.start,
                    names.len(),
                    names.join(", ")
                ),
            );
        }
    };
    let Some(edge) = g.edge_between(start, toward) else {
        return c.err(&p.key("toward"), "no road joins `start` and `toward`");
    };
    let length = g.edges[edge].length;
    let along = match f.along {
        Some(v) => c.range(&p.key("along"), v, Some(0.0), Some(length), false)?,
        None => 0.0,
    };
    let navigate_by = match f.navigate_by.as_deref() {
        None => RoadLocalizerKind::Mcl,
        Some(s) => RoadLocalizerKind::parse(s).map_or_else(
            || {
                c.err(
                    &p.key("navigate_by"),
                    format!("expected `road_grid` or `road_mcl`, got `{s}`"),
                )
            },
            Ok,
        )?,
    };
    let route = RouteConfig {
        start,
        toward,
        goal,
        navigate_by,
        speed: c.opt_positive(&p.key("speed"), f.speed, 1.0)?,
        tolerance: c.opt_positive(&p.key("tolerance"), f.tolerance, 1.0)?,
    };
    let (a, b) = (g.nodes[start].pos, g.nodes[toward].pos);
    let t = along / length.max(1e-9);
    let yaw = heading_of_azimuth(g.azimuth_from(edge, start));
    let pose = Pose2::new(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, yaw);
    Ok((route, pose))
}

/// What of a robot's file its outdoor parts depend on.
pub(super) struct OutdoorTables<'a> {
    pub gps: Option<&'a GpsFile>,
    pub compass: Option<&'a CompassFile>,
    pub camera: Option<&'a CameraFile>,
    /// The robot has a wheel encoder.
    pub has_encoder: bool,
    /// The robot has a `behaviour` or `tasks` (a robot with a route may have neither).
    pub driven_otherwise: bool,
}

/// The robot's GPS, compass and camera (its tables over the preset's), and the checks a route
/// needs: the sensors it drives by, no behaviour or tasks, a goal other than the start.
#[allow(clippy::type_complexity)]
pub(super) fn resolve_outdoor_sensors(
    c: &Checker,
    p: &KeyPath,
    t: &OutdoorTables<'_>,
    preset: Option<&Preset>,
    route: Option<&RouteConfig>,
) -> R<(Option<GpsSpec>, Option<CompassSpec>, Option<CameraSpec>)> {
    let has_encoder = t.has_encoder;
    let sp = p.key("sensors");
    let gps = over_preset(t.gps, preset.map(|pr| pr.gps.clone()), |f, base| {
        resolve_gps(c, &sp.key("gps"), f, base)
    })?;
    let compass = over_preset(t.compass, preset.map(|pr| pr.compass.clone()), |f, base| {
        resolve_compass(c, &sp.key("compass"), f, base)
    })?;
    let camera = over_preset(t.camera, preset.map(|pr| pr.camera.clone()), |f, base| {
        resolve_camera(c, &sp.key("camera"), f, base)
    })?;
    if let Some(route) = route {
        let missing: Vec<&str> = [
            ("encoder", !has_encoder),
            ("gps", gps.is_none()),
            ("compass", compass.is_none()),
            ("camera", camera.is_none()),
        ]
        .into_iter()
        .filter_map(|(n, m)| m.then_some(n))
        .collect();
        if !missing.is_empty() {
            return c.err(
                &p.key("route"),
                format!(
                    "a robot with a route localizes by encoder, GPS and compass and follows the road by camera: give it {} (or `preset = \"thesis_car\"`)",
                    missing
                        .iter()
                        .map(|m| format!("`[robots.sensors.{m}]`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
        }
        if t.driven_otherwise {
            return c.err(
                &p.key("route"),
                "a robot with a route is driven by its road navigator: remove `behaviour` and `tasks`",
            );
        }
        if route.start == route.goal {
            return c.err(&p.key("route").key("goal"), "the goal is the start node");
        }
    }
    Ok((gps, compass, camera))
}

/// A sensor from its table over the preset's spec (or the default), the preset's without a table,
/// none without either.
fn over_preset<F, T: Default>(
    file: Option<&F>,
    preset: Option<T>,
    resolve: impl Fn(&F, T) -> R<T>,
) -> R<Option<T>> {
    match file {
        Some(f) => Ok(Some(resolve(f, preset.unwrap_or_default())?)),
        None => Ok(preset),
    }
}
