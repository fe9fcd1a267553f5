//! Validation and defaults: turns a [`ScenarioFile`] into a [`Scenario`], reporting the first
//! problem with the file, line and key.

use super::check::{Checker, OdometrySource, R, check_name};
use super::error::{ErrorContext, KeyPath};
use super::file::*;
use super::model::{RecordConfig, RobotConfig, Scenario};
use crate::scenario::outdoor::RoadsConfig;
use std::collections::BTreeMap;
use std::path::Path;
use systems::world::shapes::{Shape, rasterize, shapes_bounds};
use systems::world::{Cell, OccupancyGrid, load_map};

mod robot;
mod world;

pub use robot::default_diff_drive;
use robot::resolve_robot;
use world::World;

/// Scenario text: parsed into its [`ScenarioFile`] and resolved, for robots whose odometry
/// comes from `odometry`; errors name `file_label`, the line and the key.
pub fn resolve(
    text: &str,
    file_label: &str,
    base_dir: &Path,
    default_name: &str,
    odometry: OdometrySource,
) -> R<Scenario> {
    let c = Checker {
        cx: ErrorContext::new(file_label.to_string(), text),
        odometry,
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
        odometry: OdometrySource::Encoders,
    };
    resolve_file(&c, f, base_dir, default_name)
}

fn resolve_file(c: &Checker, f: ScenarioFile, base_dir: &Path, default_name: &str) -> R<Scenario> {
    let root = KeyPath::default();
    let header = resolve_header(c, &root, &f, default_name)?;
    let shapes = resolve_shapes(c, &root, &f)?;
    let roads = match &f.roads {
        Some(r) => Some(crate::scenario::outdoor::resolve_roads(
            c,
            &root.key("roads"),
            r,
            base_dir,
        )?),
        None => None,
    };
    let zones = crate::scenario::outdoor::resolve_zones(c, &root.key("zones"), &f.zones)?;
    let map = f.map.as_ref();
    let grid = resolve_grid(c, &root, map, &shapes, roads.as_ref(), base_dir)?;
    let (mut places, mut doors) = match map.and_then(|m| m.places.as_ref()) {
        Some(pf) => crate::scenario::places::load_places(
            c,
            &root.key("map").key("places"),
            &base_dir.join(pf),
            &grid,
        )?,
        None => (BTreeMap::new(), Vec::new()),
    };
    let own = crate::scenario::places::PlacesFile {
        places: f.places.clone(),
        doors: f.doors.clone(),
    };
    crate::scenario::places::add_places(&c.cx, &own, &grid, &mut places, &mut doors)?;
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
    // every robot's localizers: its own and, with a route, the road localizers
    let names: std::collections::BTreeSet<&str> = robots
        .iter()
        .flat_map(|r| {
            let road = r.route.as_ref().map_or(&[][..], |_| {
                &crate::scenario::outdoor_robot::RoadLocalizerKind::ALL[..]
            });
            r.localizers
                .iter()
                .map(|x| x.name.as_str())
                .chain(road.iter().map(|k| k.as_str()))
        })
        .collect();
    if let Some(l) = &record.map_localizer
        && !names.contains(l.as_str())
    {
        let names: Vec<&str> = names.into_iter().collect();
        return c.err(
            &root.key("record").key("map_localizer"),
            format!(
                "no robot has a localizer named '{l}' (the robots' localizers: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
        );
    }
    let events = crate::scenario::events::resolve_events(
        c,
        &root.key("events"),
        &f.events,
        header.duration,
        crate::scenario::events::Known {
            robots: &robots,
            doors: &doors,
            grid: &grid,
        },
        &|p, v| world.point(p, v),
        &|p, v| world.inside(p, v),
        &|p, v| world.points(p, v),
    )?;
    let people = crate::scenario::people::resolve_people(
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
    if let Some(why) = super::model::too_many_ticks(duration, dt) {
        return c.err(&root.key("duration"), why);
    }
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
                Ok(Some(g)) => g,
                Ok(None) => {
                    return c.err(
                        root,
                        "the world is empty: give `map.file` (a ROS map_server YAML), `[roads]` or walls, boxes or discs",
                    );
                }
                Err(why) => return c.err(&mpath, why),
            }
        }
    };
    if file.is_some() && resolution.is_some() {
        return c.err(
            &mpath.key("resolution"),
            "the resolution comes from the map file; remove this key",
        );
    }
    if grid.width * grid.height > MAX_CELLS {
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
        map_localizer: rec.map_localizer.clone(),
        slam_rate: match rec.slam_rate {
            Some(v) => c.range(&rp.key("slam_rate"), v, Some(0.0), None, false)?,
            None => d.slam_rate,
        },
    })
}

/// The grid of a world without a map file: over the shapes (2 m around them) and the road
/// network (its margin around the roads), or `None` when there is neither.
fn grid_for_world(
    shapes: &[Shape],
    roads: Option<([f64; 4], f64)>,
    resolution: f64,
) -> Result<Option<OccupancyGrid>, String> {
    // the bounds of the grid `grid_for_shapes` would make with a 2 m margin, cells included
    let from_shapes = shapes_bounds(shapes).map(|b| {
        let origin = [b[0] - 2.0, b[1] - 2.0];
        let w = ((b[2] + 2.0 - origin[0]) / resolution).ceil().max(1.0);
        let h = ((b[3] + 2.0 - origin[1]) / resolution).ceil().max(1.0);
        [
            origin[0],
            origin[1],
            origin[0] + w * resolution,
            origin[1] + h * resolution,
        ]
    });
    let from_roads = roads.map(|(b, m)| [b[0] - m, b[1] - m, b[2] + m, b[3] + m]);
    let b = match (from_shapes, from_roads) {
        (Some(a), Some(b)) => [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ],
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => return Ok(None),
    };
    // sized before allocating: a far-away shape or road reference must not take the memory
    let (w, h) = ((b[2] - b[0]) / resolution, (b[3] - b[1]) / resolution);
    let (w, h) = (w.ceil().max(1.0), h.ceil().max(1.0));
    let fits = w * h <= MAX_CELLS as f64; // false for NaN too
    if !fits {
        return Err(format!(
            "the world spans {:.0} × {:.0} m (from ({:.0}, {:.0}) to ({:.0}, {:.0}): walls, boxes, \
             discs and roads), {:.3e} cells at {resolution} m; at most 400 million",
            b[2] - b[0],
            b[3] - b[1],
            b[0],
            b[1],
            b[2],
            b[3],
            w * h
        ));
    }
    let (w, h) = (w as usize, h as usize);
    Ok(Some(OccupancyGrid::new(
        w,
        h,
        resolution,
        [b[0], b[1]],
        Cell::Free,
    )))
}

/// The most cells a scenario's map may have (400 MB of cells, before the distance fields).
const MAX_CELLS: usize = 400_000_000;

#[cfg(test)]
mod tests;
