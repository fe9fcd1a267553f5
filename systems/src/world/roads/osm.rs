//! OSM XML 0.6 (as exported by openstreetmap.org, JOSM or Overpass with `out body; >;`):
//! `<node id lat lon>` and `<way id>` with `<nd ref>` and `<tag k v>` children. Roads are the
//! ways with a `highway` tag (see the module docs of [`super`] for what is skipped).

use super::graph::Road;
use super::raw::{RawRoads, RoadError, RoadOptions, Source, default_width, parse_width};
use super::surface::Surface;

/// Highway values that are not drivable roads (yet or any more).
const NOT_ROADS: &[&str] = &[
    "proposed",
    "construction",
    "abandoned",
    "razed",
    "disused",
    "platform",
];

pub(super) fn read(src: &Source, options: &RoadOptions) -> Result<RawRoads, RoadError> {
    let root = src.doc.root_element();
    let mut points = Vec::new();
    let mut index: rustc_hash::FxHashMap<&str, usize> = Default::default();
    for node in root.children().filter(|n| n.has_tag_name("node")) {
        let id = src.attr(node, "id")?;
        let g = src.geo(node)?;
        if index.insert(id, points.len()).is_some() {
            return Err(src.at(node, format!("node id {id} is defined twice")));
        }
        points.push((g, id.to_string()));
    }
    let mut roads = Vec::new();
    for way in root.children().filter(|n| n.has_tag_name("way")) {
        let id = src.attr(way, "id")?;
        let tag = |k: &str| {
            way.children()
                .find(|t| t.has_tag_name("tag") && t.attribute("k") == Some(k))
        };
        let Some(highway) = tag("highway") else {
            continue;
        };
        let kind = src.attr(highway, "v")?.trim();
        if NOT_ROADS.contains(&kind) || tag("area").and_then(|t| t.attribute("v")) == Some("yes") {
            continue;
        }
        let mut nodes = Vec::new();
        for nd in way.children().filter(|n| n.has_tag_name("nd")) {
            let r = src.attr(nd, "ref")?;
            let &i = index.get(r).ok_or_else(|| {
                src.at(
                    nd,
                    format!("way {id} refers to node {r}, which the file does not define"),
                )
            })?;
            nodes.push(i);
        }
        if nodes.len() < 2 {
            return Err(src.at(
                way,
                format!(
                    "way {id} (highway={kind}) has {} node(s): a road needs at least 2",
                    nodes.len()
                ),
            ));
        }
        let width = match tag("width") {
            Some(t) => {
                let v = src.attr(t, "v")?;
                parse_width(v).ok_or_else(|| {
                    src.at(
                        t,
                        format!(
                            "way {id}: width = {v:?}: expected metres, e.g. \"3.5\" or \"3.5 m\""
                        ),
                    )
                })?
            }
            None => options.width.unwrap_or_else(|| default_width(kind)),
        };
        let name = tag("name")
            .and_then(|t| t.attribute("v"))
            .map(str::to_string)
            .unwrap_or_else(|| format!("way {id}"));
        roads.push(Road {
            name,
            kind: kind.to_string(),
            surface: tag("surface")
                .and_then(|t| t.attribute("v"))
                .map_or(Surface::Unknown, Surface::from_tag),
            width,
            nodes,
        });
    }
    Ok(RawRoads {
        points,
        roads,
        merge: false,
        what: "no <way> with a highway tag",
    })
}
