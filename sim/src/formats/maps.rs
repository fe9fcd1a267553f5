//! `--save-map PATH`: maps exported as ROS map_server YAML + PGM
//! (`systems::world::save_map`, trinary, occupied_thresh 0.65, free_thresh 0.196).
//!
//! `sim run` saves every SLAM system's final map, and for each robot with a laser but no SLAM a
//! map built with known poses: log-odds occupancy mapping ([`LogOddsMap`], Probabilistic
//! Robotics §9.2) of every scan from the laser's *true* pose, at the scenario map's
//! resolution. It is built only when `--save-map` is given, by an observer in the Record set, so
//! it never changes the run. One map goes to `PATH` (`.yaml` added when missing, the `.pgm` next
//! to it); several get `-<robot>-<name>` after the stem, `<name>` being the SLAM system's name
//! or `known_poses`.

use bevy_ecs::prelude::*;
use std::path::{Path, PathBuf};
use systems::core::{Pose2, RobotId, RobotIndex, SimPlugin, SimSet};
use systems::localization::{Filter, Localizers};
use systems::mapping::{LogOddsMap, MapQuality, OccupancyParams, map_quality};
use systems::sensors::{Laser, LaserScans, LaserTruth};
use systems::world::OccupancyGrid;
use systems::world::map_file::save_map;

/// The name a known-pose map is saved under.
pub const KNOWN_POSES: &str = "known_poses";

/// Known-pose maps of the robots with a laser and no SLAM (a resource while the run lasts).
#[derive(Resource)]
pub struct KnownPoseMaps {
    /// (robot index, map), robots in index order.
    maps: Vec<(u32, LogOddsMap)>,
}

impl KnownPoseMaps {
    /// Maps for the robots of a built world that carry a laser and run no SLAM system, at
    /// `resolution` (m).
    pub fn new(world: &mut World, resolution: f64) -> Self {
        let mut q = world.query::<(&RobotIndex, &Laser, Option<&Localizers>)>();
        let mut maps: Vec<(u32, LogOddsMap)> = q
            .iter(world)
            .filter(|(_, _, locs)| {
                !locs.is_some_and(|l| l.items.iter().any(|l| l.filter.is_scan()))
            })
            .map(|(i, laser, _)| {
                let params = OccupancyParams {
                    max_range: laser.spec.max_range as f32,
                    ..OccupancyParams::default()
                };
                (i.0, LogOddsMap::new(resolution, params))
            })
            .collect();
        maps.sort_by_key(|(i, _)| *i);
        KnownPoseMaps { maps }
    }
}

/// Whether a robot of a built world can map: every map (a SLAM system's or a known-pose map)
/// is made from a laser's scans.
pub fn can_map(world: &mut World) -> bool {
    world.query::<&Laser>().iter(world).next().is_some()
}

/// `--save-map`: the known-pose maps of the world's robots ([`KnownPoseMaps::new`]) and
/// [`map_known_poses`] in the Record set.
pub struct KnownPoseMapsPlugin {
    /// The maps' resolution (m).
    pub resolution: f64,
}

impl SimPlugin for KnownPoseMapsPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        let maps = KnownPoseMaps::new(world, self.resolution);
        world.insert_resource(maps);
        schedule.add_systems(map_known_poses.in_set(SimSet::Record));
    }
}

/// Record set: inserts this tick's scans from the true laser poses.
pub fn map_known_poses(
    mut maps: ResMut<KnownPoseMaps>,
    robots: Query<(&RobotIndex, &LaserScans, &LaserTruth)>,
) {
    for (idx, scans, truth) in robots.iter() {
        if let Some((_, map)) = maps.maps.iter_mut().find(|(i, _)| *i == idx.0) {
            for (scan, pose) in scans.scans.iter().zip(&truth.poses) {
                map.insert_scan(pose, scan);
            }
        }
    }
}

/// A map to save: whose, from what, and the thresholded grid.
#[derive(Clone, Debug)]
pub struct MapToSave {
    pub robot: String,
    /// The SLAM system's name, or [`KNOWN_POSES`].
    pub name: String,
    pub grid: OccupancyGrid,
}

/// A map written, with its quality against the scenario's map when there is one.
#[derive(Clone, Debug)]
pub struct SavedMap {
    pub robot: String,
    pub name: String,
    pub yaml: PathBuf,
    pub width: usize,
    pub height: usize,
    pub quality: Option<MapQuality>,
}

/// The maps of a finished run: every SLAM system's (robots and localizers in order), then the
/// known-pose maps.
pub fn run_maps(world: &mut World) -> Vec<MapToSave> {
    let mut q = world.query::<(&RobotIndex, &RobotId, Option<&Localizers>)>();
    let mut robots: Vec<_> = q.iter(world).collect();
    robots.sort_by_key(|(i, ..)| **i);
    let known = world.get_resource::<KnownPoseMaps>();
    let mut out = Vec::new();
    for (idx, id, locs) in robots {
        for l in locs.map_or(&[][..], |l| &l.items[..]) {
            if let Filter::Scan(e) = &l.filter
                && let Some(map) = e.map()
            {
                out.push(MapToSave {
                    robot: id.0.clone(),
                    name: l.name.clone(),
                    grid: map.to_occupancy(),
                });
            }
        }
        if let Some((_, m)) = known.and_then(|k| k.maps.iter().find(|(i, _)| *i == idx.0)) {
            out.push(MapToSave {
                robot: id.0.clone(),
                name: KNOWN_POSES.to_string(),
                grid: m.to_occupancy(),
            });
        }
    }
    out
}

/// The YAML file of map `robot`/`name` when `count` maps are saved to `path`.
pub fn map_file(path: &Path, robot: &str, name: &str, count: usize) -> PathBuf {
    let stem = match path.extension().and_then(|e| e.to_str()) {
        Some("yaml" | "yml") => path.with_extension(""),
        _ => path.to_path_buf(),
    };
    let mut file = stem.into_os_string();
    if count > 1 {
        file.push(format!("-{robot}-{name}"));
    }
    file.push(".yaml");
    PathBuf::from(file)
}

/// Saves `maps` (see [`map_file`]); with `truth` (a map in the same frame as theirs), judges each
/// against it.
pub fn save_maps(
    path: &Path,
    maps: &[MapToSave],
    truth: Option<(&OccupancyGrid, &Pose2)>,
) -> anyhow::Result<Vec<SavedMap>> {
    let mut saved = Vec::new();
    for m in maps {
        let yaml = map_file(path, &m.robot, &m.name, maps.len());
        save_map(&m.grid, &yaml)
            .map_err(|e| anyhow::anyhow!("{}: cannot write the map: {e}", yaml.display()))?;
        saved.push(SavedMap {
            robot: m.robot.clone(),
            name: m.name.clone(),
            yaml,
            width: m.grid.width,
            height: m.grid.height,
            quality: truth.map(|(t, est_to_truth)| map_quality(&m.grid, t, est_to_truth)),
        });
    }
    Ok(saved)
}

impl SavedMap {
    /// One line for the terminal.
    pub fn describe(&self) -> String {
        let q = match &self.quality {
            Some(q) => format!(
                "; precision {:.1} %, recall {:.1} % against the scenario map",
                100.0 * q.precision,
                100.0 * q.recall
            ),
            None => String::new(),
        };
        format!(
            "map of {}/{} written to {} ({} × {} cells{q})",
            self.robot,
            self.name,
            self.yaml.display(),
            self.width,
            self.height
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_map_takes_the_path_several_get_robot_and_name() {
        assert_eq!(
            map_file(Path::new("out/m"), "r", "s", 1),
            PathBuf::from("out/m.yaml")
        );
        assert_eq!(
            map_file(Path::new("m.yaml"), "r", "s", 1),
            PathBuf::from("m.yaml")
        );
        assert_eq!(
            map_file(Path::new("m.yaml"), "r1", KNOWN_POSES, 2),
            PathBuf::from("m-r1-known_poses.yaml")
        );
        assert_eq!(
            map_file(Path::new("a.b"), "r1", "g", 2),
            PathBuf::from("a.b-r1-g.yaml")
        );
    }
}
