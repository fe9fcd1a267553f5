//! Outdoor runs in the Rerun recording:
//! - `world/roads`: the road network, each road a line strip as wide as the road, coloured by
//!   surface (asphalt grey, gravel tan, paving ochre), with node ids as labels at junctions
//!   (`world/roads/nodes`), static;
//! - `world/zones`: the GPS/compass zones as outlines (trees green, buildings brown, EM
//!   interference magenta), static;
//! - `robots/<name>/gps`: every GPS fix in local metres (a point) and its error against the
//!   truth as a scalar series at `robots/<name>/error/gps`;
//! - `robots/<name>/estimate/<road localizer>`: each road localizer's position (a point labelled
//!   with its edge and confidence) whenever it has one, at the pose rate;
//! - `robots/<name>/particles/<road localizer>`: the grid's cells (points along the edges, size
//!   and colour by probability, the thesis's bar plot laid on the map) and the MCL's particles,
//!   at the particle rate;
//! - `robots/<name>/error/<road localizer>`: its position error against the truth;
//! - `robots/<name>/path`: the planned road route (line strip) whenever it changes, and
//!   `robots/<name>/task`: the navigator's events (plans, re-plans, junction moves, arrival);
//!
//! The camera images (`robots/<name>/camera`) come from [`crate::record::frames`].

use super::RrdRecorder;
use super::rows;
use bevy_ecs::prelude::*;
use rerun::components::{Position3D, Radius};
use systems::body::TruePose;
use systems::core::{RobotId, RobotIndex, SimClock};
use systems::localization::road_wiring::RoadLocalization;
use systems::navigation::road_drive::RoadNavigator;
use systems::world::roads::{RoadGraph, RoadMap, Surface};
use systems::world::{ZoneKind, ZoneShape, Zones};

/// Per robot: what has been logged already.
#[derive(Default, Clone)]
struct Logged {
    events: usize,
    route_length: Option<f64>,
    route_start: Option<usize>,
    particles_at: f64,
    poses_at: f64,
    /// Its entity paths, made at its first row.
    paths: Option<Paths>,
}

/// A robot's entity paths (made once: a run logs thousands of rows to them).
#[derive(Clone)]
struct Paths {
    gps: String,
    gps_error: String,
    path: String,
    task: String,
    /// Per road localizer (in the robot's order): estimate, error and particles.
    slots: Vec<[String; 3]>,
}

impl Paths {
    fn new(robot: &str, slots: &[String]) -> Self {
        let base = format!("robots/{robot}");
        Paths {
            gps: format!("{base}/gps"),
            gps_error: format!("{base}/error/gps"),
            path: format!("{base}/path"),
            task: format!("{base}/task"),
            slots: slots
                .iter()
                .map(|name| {
                    [
                        format!("{base}/estimate/{name}"),
                        format!("{base}/error/{name}"),
                        format!("{base}/particles/{name}"),
                    ]
                })
                .collect(),
        }
    }
}

#[derive(Resource)]
pub struct OutdoorRecording {
    pose_period: f64,
    particle_period: f64,
    started: bool,
    robots: Vec<Logged>,
}

impl OutdoorRecording {
    pub fn new(pose_rate: f64, particle_rate: f64) -> Self {
        OutdoorRecording {
            pose_period: 1.0 / pose_rate,
            particle_period: 1.0 / particle_rate,
            started: false,
            robots: Vec::new(),
        }
    }
}

fn surface_colour(s: Surface) -> rerun::Color {
    let c = match s {
        Surface::Asphalt => [90, 90, 95],
        Surface::Gravel => [196, 170, 120],
        Surface::Paving => [180, 140, 90],
        Surface::Concrete => [170, 170, 165],
        Surface::Dirt => [130, 95, 60],
        Surface::Unknown => [150, 150, 150],
    };
    rerun::Color::from_rgb(c[0], c[1], c[2])
}

fn log_roads(r: &mut RrdRecorder, g: &RoadGraph, zones: Option<&Zones>) {
    let strips: Vec<Vec<[f32; 3]>> = g
        .roads
        .iter()
        .map(|road| {
            road.nodes
                .iter()
                .map(|&n| [g.nodes[n].pos[0] as f32, g.nodes[n].pos[1] as f32, -0.1])
                .collect()
        })
        .collect();
    let res = r.rec.log_static(
        "world/roads",
        &rerun::LineStrips3D::new(strips)
            .with_radii(g.roads.iter().map(|road| road.width as f32 / 2.0))
            .with_colors(g.roads.iter().map(|road| surface_colour(road.surface)))
            .with_labels(g.roads.iter().map(|road| road.name.clone())),
    );
    r.check(res);
    let junctions: Vec<usize> = (0..g.nodes.len()).filter(|&n| g.degree(n) != 2).collect();
    let res = r.rec.log_static(
        "world/roads/nodes",
        &rerun::Points3D::new(
            junctions
                .iter()
                .map(|&n| [g.nodes[n].pos[0] as f32, g.nodes[n].pos[1] as f32, 0.0]),
        )
        .with_radii([Radius::new_ui_points(3.0)])
        .with_colors([rerun::Color::from_rgb(250, 250, 250)])
        .with_labels(junctions.iter().map(|&n| g.nodes[n].source.clone())),
    );
    r.check(res);
    let Some(zones) = zones else { return };
    for z in &zones.zones {
        let pts: Vec<[f32; 3]> = match &z.shape {
            ZoneShape::Polygon(v) => v
                .iter()
                .chain(v.first())
                .map(|p| [p[0] as f32, p[1] as f32, 0.01])
                .collect(),
            ZoneShape::Circle { centre, radius } => (0..=48)
                .map(|k| {
                    let a = k as f64 / 48.0 * std::f64::consts::TAU;
                    [
                        (centre[0] + radius * a.cos()) as f32,
                        (centre[1] + radius * a.sin()) as f32,
                        0.01,
                    ]
                })
                .collect(),
        };
        let c = match z.kind {
            ZoneKind::Trees => [40, 150, 60],
            ZoneKind::Buildings => [150, 90, 50],
            ZoneKind::EmInterference => [220, 50, 200],
            ZoneKind::Open => [200, 200, 200],
        };
        let res = r.rec.log_static(
            format!("world/zones/{}", z.name),
            &rerun::LineStrips3D::new([pts])
                .with_radii([Radius::new_ui_points(1.5)])
                .with_colors([rerun::Color::from_rgb(c[0], c[1], c[2])])
                .with_labels([format!("{} ({})", z.name, z.kind.as_str())]),
        );
        r.check(res);
    }
}

/// Viridis-like ramp for weights in [0, 1].
fn ramp(t: f32) -> rerun::Color {
    let t = t.clamp(0.0, 1.0);
    rerun::Color::from_rgb(
        (68.0 + t * 185.0) as u8,
        (1.0 + t * 230.0) as u8,
        (84.0 + (0.5 - (t - 0.5).abs()) * 120.0) as u8,
    )
}

/// Record: roads and zones once, then each outdoor robot's GPS, road beliefs and route.
#[allow(clippy::type_complexity)]
pub fn record_outdoor(
    clock: Res<SimClock>,
    mut r: ResMut<RrdRecorder>,
    mut state: ResMut<OutdoorRecording>,
    (roads, zones): (Option<Res<RoadMap>>, Option<Res<Zones>>),
    robots: Query<(
        &RobotIndex,
        &RobotId,
        &TruePose,
        Option<&RoadLocalization>,
        Option<&RoadNavigator>,
    )>,
) {
    let Some(roads) = roads else { return };
    let g = &*roads.0;
    let r = &mut *r;
    let now = clock.now();
    if !state.started {
        state.started = true;
        log_roads(r, g, zones.as_deref());
    }
    let mut sorted: Vec<_> = robots.iter().collect();
    sorted.sort_by_key(|(i, ..)| **i);
    for (idx, id, truth, loc, nav) in sorted {
        let i = idx.0 as usize;
        if state.robots.len() <= i {
            state.robots.resize(i + 1, Logged::default());
        }
        let (pose_period, particle_period) = (state.pose_period, state.particle_period);
        let logged = &mut state.robots[i];
        if logged.paths.is_none() {
            let names: Vec<String> = loc
                .map(|l| l.slots.iter().map(|s| s.name.to_string()).collect())
                .unwrap_or_default();
            let paths = Paths::new(&id.0, &names);
            // legends name the robot; the GPS in the robot's colour, road localizers as shades
            let series = std::iter::once((&paths.gps_error, "gps", super::colour(idx.0))).chain(
                names
                    .iter()
                    .zip(&paths.slots)
                    .enumerate()
                    .map(|(k, (n, s))| (&s[1], n.as_str(), super::localizer_colour(idx.0, k))),
            );
            for (path, name, c) in series {
                let res = r.rec.log_static(
                    path.as_str(),
                    &rerun::SeriesLines::new()
                        .with_names([format!("{} {name}", id.0)])
                        .with_colors([c]),
                );
                r.check(res);
            }
            logged.paths = Some(paths);
        }
        let Some(paths) = &logged.paths else { continue };
        r.rec.set_duration_secs("sim_time", now);
        let p = [truth.pose.x, truth.pose.y];
        if let Some(loc) = loc {
            for &(t, xy) in &loc.fixes {
                r.rec.set_duration_secs("sim_time", t);
                rows::points(
                    &mut r.rec,
                    &paths.gps,
                    [[xy[0] as f32, xy[1] as f32, 0.05]],
                    Radius::new_ui_points(2.5),
                )
                .with(
                    rerun::Points3D::descriptor_colors(),
                    [rerun::Color::from_rgb(255, 200, 0)],
                );
                let err = (xy[0] - p[0]).hypot(xy[1] - p[1]);
                rows::scalar(&mut r.rec, &paths.gps_error, err);
                r.position_scale.push(err);
            }
            r.rec.set_duration_secs("sim_time", now);
            let pose_due = now >= logged.poses_at + pose_period - 1e-9;
            let particles_due = now >= logged.particles_at + particle_period - 1e-9;
            for (k, (s, [estimate, error, particles])) in
                loc.slots.iter().zip(&paths.slots).enumerate()
            {
                if let Some(e) = s.estimate.filter(|_| pose_due) {
                    let label = format!(
                        "{} {}→{} ({:.0} %)",
                        s.name,
                        g.nodes[systems::navigation::road_drive::other_end(g, e.edge, e.toward)]
                            .source,
                        g.nodes[e.toward].source,
                        100.0 * e.confidence
                    );
                    let at = [e.xy[0] as f32, e.xy[1] as f32, 0.1];
                    rows::points(&mut r.rec, estimate, [at], Radius::new_ui_points(5.0))
                        .with(
                            rerun::Points3D::descriptor_colors(),
                            [super::localizer_colour(idx.0, k)],
                        )
                        .with(
                            rerun::Points3D::descriptor_labels(),
                            [rerun::components::Text::from(label)],
                        );
                    let err = (e.xy[0] - p[0]).hypot(e.xy[1] - p[1]);
                    rows::scalar(&mut r.rec, error, err);
                    r.position_scale.push(err);
                }
                if particles_due {
                    let cells = s.filter.belief_cells(g);
                    let max = cells.iter().map(|c| c.3).fold(0.0, f64::max).max(1e-12);
                    let pts = cells.iter().map(|&(e, _, along, _)| {
                        let q = g.point_on(e, along);
                        Position3D::from([q[0] as f32, q[1] as f32, 0.08])
                    });
                    let radii = cells
                        .iter()
                        .map(|c| Radius::new_ui_points(1.5 + 5.0 * (c.3 / max) as f32));
                    let colors = cells.iter().map(|c| ramp((c.3 / max) as f32));
                    r.rec
                        .row(particles)
                        .with(rerun::Points3D::descriptor_positions(), pts)
                        .with(rerun::Points3D::descriptor_radii(), radii)
                        .with(rerun::Points3D::descriptor_colors(), colors);
                }
            }
            if pose_due {
                logged.poses_at = now;
            }
            if particles_due {
                logged.particles_at = now;
            }
        }
        if let Some(nav) = nav {
            let start = nav.route_start_edge();
            let length = nav.route.as_ref().map(|rt| rt.length);
            if nav.route.is_some() && (logged.route_length != length || logged.route_start != start)
            {
                logged.route_length = length;
                logged.route_start = start;
                if let (Some(route), Some(e0)) = (&nav.route, start) {
                    let first = systems::navigation::road_drive::other_end(g, e0, route.nodes[0]);
                    let pts: Vec<[f32; 3]> = std::iter::once(first)
                        .chain(route.nodes.iter().copied())
                        .map(|n| [g.nodes[n].pos[0] as f32, g.nodes[n].pos[1] as f32, 0.03])
                        .collect();
                    let res = r.rec.log(
                        &paths.path,
                        &rerun::LineStrips3D::new([pts])
                            .with_radii([Radius::new_ui_points(2.0)])
                            .with_colors([rerun::Color::from_rgb(40, 200, 80)]),
                    );
                    r.check(res);
                }
            }
            for (t, text) in &nav.events[logged.events..] {
                r.rec.set_duration_secs("sim_time", *t);
                let level = if text.starts_with("off the route") || text.starts_with("no route") {
                    rerun::TextLogLevel::WARN
                } else {
                    rerun::TextLogLevel::INFO
                };
                let res = r.rec.log(
                    &paths.task,
                    &rerun::TextLog::new(text.as_str()).with_level(level),
                );
                r.check(res);
            }
            logged.events = nav.events.len();
            r.rec.set_duration_secs("sim_time", now);
        }
    }
}
