//! The places file beside a map (the ROS map YAML has no room for them): named poses
//! (`[places.<name>] pose = [x, y, yaw]`) and doors (`[doors.<name>] from, to, thickness`), with
//! errors naming the places file and key. The scenario may carry the same tables itself (a
//! scenario built in code puts its places there); they join the file's.

use super::check::{Checker, R};
use super::error::{ErrorContext, KeyPath};
use super::model::DoorConfig;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use systems::core::Pose2;
use systems::core::input::{MAX_CONFIG_BYTES, read_text_bounded};
use systems::world::OccupancyGrid;

/// Named places next to a map: `[places.<name>] pose = [x, y, yaw]`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct PlacesFile {
    #[serde(default)]
    pub places: std::collections::BTreeMap<String, PlaceFile>,
    /// Doors: `[doors.<name>] from = [x, y], to = [x, y], thickness = 0.15`.
    #[serde(default)]
    pub doors: std::collections::BTreeMap<String, DoorFile>,
}

/// A door: a wall segment, open in the map, that `door` events close and open.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct DoorFile {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: Option<f64>,
}

/// A named pose.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct PlaceFile {
    pub pose: [f64; 3],
    pub kind: Option<String>,
    pub description: Option<String>,
}

/// Reads `ppath` (named by `key` of the scenario): its places and doors.
pub(super) fn load_places(
    c: &Checker,
    key: &KeyPath,
    ppath: &Path,
    grid: &OccupancyGrid,
) -> R<(BTreeMap<String, Pose2>, Vec<DoorConfig>)> {
    let ptext = read_text_bounded(ppath, MAX_CONFIG_BYTES).map_err(|e| {
        c.cx.at(key, format!("cannot read {}: {e}", ppath.display()))
    })?;
    let pcx = ErrorContext::new(ppath.display().to_string(), &ptext);
    let parsed: PlacesFile = toml::from_str(&ptext).map_err(|e| pcx.from_toml(&e))?;
    let mut places = BTreeMap::new();
    let mut doors = Vec::new();
    add_places(&pcx, &parsed, grid, &mut places, &mut doors)?;
    Ok((places, doors))
}

/// Checks the places and doors of `table` (a places file, or the scenario's own `[places]` and
/// `[doors]`, whose errors `cx` names) and adds them; a name already taken is an error.
pub(super) fn add_places(
    cx: &ErrorContext,
    table: &PlacesFile,
    grid: &OccupancyGrid,
    places: &mut BTreeMap<String, Pose2>,
    doors: &mut Vec<DoorConfig>,
) -> R<()> {
    for (name, place) in &table.places {
        let pp = KeyPath::default().key("places").key(name);
        if places.contains_key(name) {
            return Err(cx.at(&pp, format!("place `{name}` is also in the places file")));
        }
        if place.pose.iter().any(|v| !v.is_finite()) {
            return Err(cx.at(&pp.key("pose"), "expected [x, y, yaw] finite numbers"));
        }
        places.insert(
            name.clone(),
            Pose2::new(place.pose[0], place.pose[1], place.pose[2]),
        );
    }
    for (name, d) in &table.doors {
        let dp = KeyPath::default().key("doors").key(name);
        if doors.iter().any(|o| &o.name == name) {
            return Err(cx.at(&dp, format!("door `{name}` is also in the places file")));
        }
        let b = grid.bounds();
        for (key, v) in [("from", d.from), ("to", d.to)] {
            if v.iter().any(|x| !x.is_finite())
                || v[0] < b[0]
                || v[1] < b[1]
                || v[0] > b[2]
                || v[1] > b[3]
            {
                return Err(cx.at(
                    &dp.key(key),
                    format!("expected a finite [x, y] inside the map, got {v:?}"),
                ));
            }
        }
        let thickness = d.thickness.unwrap_or(0.15);
        if !(thickness > 0.0 && thickness <= 2.0) {
            return Err(cx.at(
                &dp.key("thickness"),
                format!("expected a number in (0, 2] m, got {thickness}"),
            ));
        }
        doors.push(DoorConfig {
            name: name.clone(),
            from: d.from,
            to: d.to,
            thickness,
        });
    }
    Ok(())
}
