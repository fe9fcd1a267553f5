//! Road networks for outdoor navigation ([Park thesis §5.1]): OSM XML
//! (nodes and ways with `highway=*`, their `surface` and `width` tags) and GPX 1.1 tracks
//! (`trk/trkseg/trkpt`, also `rte/rtept`), read with `roxmltree`, projected to local metres
//! ([`geo`]) and turned into a [`RoadGraph`].
//!
//! - **Reference point**: the scenario may give one; otherwise it is the centre of the
//!   latitude/longitude bounding box of every road point. Local x points east, y north.
//! - **OSM**: every node of a road way becomes a graph node (shape points too, as the thesis's
//!   graph of points); ways share nodes by id. Ways tagged `area=yes` and highways that are not
//!   roads yet (`proposed`, `construction`, ...) are skipped, as are all other ways and
//!   relations (buildings, woods). Width: the `width` tag in metres (`3.5`, `3.5 m`), else a
//!   default per highway type ([`default_width`]).
//! - **GPX**: each track segment (and route) is a road; points closer than
//!   [`RoadOptions::merge_distance`] become one node, so tracks that pass through the same
//!   junction point are connected. The track's `<type>` names the surface.
//!
//! Malformed input is an error with the file, line and column: not XML, a missing or
//! non-numeric coordinate, a way referring to a node the file lacks, a bad width, no roads.

pub mod geo;
mod gpx;
pub mod graph;
mod osm;
pub mod surface_raster;

pub use geo::{GeoPoint, LocalProjection, haversine};
pub use graph::{EdgeId, EdgePoint, NodeId, Road, RoadEdge, RoadGraph, RoadNode, RoadStart};
pub use surface_raster::{RoadSurface, SurfaceRaster};

use std::path::{Path, PathBuf};

/// The world's road network, shared by the planner, the road localizers, the camera's road
/// surface and evaluation.
#[derive(bevy_ecs::prelude::Resource, Clone, Debug)]
pub struct RoadMap(pub std::sync::Arc<RoadGraph>);

/// The world's geographic frame: local metres ↔ latitude/longitude, for GPS fixes and roads.
#[derive(bevy_ecs::prelude::Resource, Clone, Copy, Debug, PartialEq)]
pub struct GeoFrame(pub LocalProjection);

#[derive(Debug, thiserror::Error)]
pub enum RoadError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not well-formed XML: {message}")]
    Xml { path: PathBuf, message: String },
    #[error("{path}:{line}:{column}: {message}")]
    At {
        path: PathBuf,
        line: u32,
        column: u32,
        message: String,
    },
    #[error("{path}: {message}")]
    Content { path: PathBuf, message: String },
}

/// The surface of a road, from OSM `surface=*` or a GPX track's `<type>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Surface {
    Asphalt,
    /// gravel, fine_gravel, compacted, pebblestone
    Gravel,
    /// paving_stones, sett, cobblestone, concrete:plates, bricks
    Paving,
    Concrete,
    /// dirt, earth, ground, mud, sand, grass, unpaved
    Dirt,
    /// No tag, or a value none of the above covers.
    Unknown,
}

impl Surface {
    pub fn from_tag(v: &str) -> Surface {
        match v.trim().to_ascii_lowercase().as_str() {
            "asphalt" | "paved" | "chipseal" => Surface::Asphalt,
            "gravel" | "fine_gravel" | "compacted" | "pebblestone" => Surface::Gravel,
            "paving_stones" | "sett" | "cobblestone" | "unhewn_cobblestone" | "concrete:plates"
            | "bricks" => Surface::Paving,
            "concrete" | "concrete:lanes" => Surface::Concrete,
            "dirt" | "earth" | "ground" | "mud" | "sand" | "grass" | "unpaved" => Surface::Dirt,
            _ => Surface::Unknown,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Surface::Asphalt => "asphalt",
            Surface::Gravel => "gravel",
            Surface::Paving => "paving",
            Surface::Concrete => "concrete",
            Surface::Dirt => "dirt",
            Surface::Unknown => "unknown",
        }
    }
}

/// Width (m) of a road without a `width` tag, by OSM highway type (`gpx` for GPX tracks).
pub fn default_width(kind: &str) -> f64 {
    match kind {
        "motorway" | "trunk" | "primary" | "secondary" | "tertiary" => 7.0,
        "residential" | "unclassified" | "living_street" | "road" => 5.5,
        "pedestrian" => 4.0,
        "service" => 3.5,
        "track" | "gpx" => 3.0,
        _ => 2.0, // footway, path, cycleway, bridleway, steps, ...
    }
}

/// Options of [`load_roads`].
#[derive(Clone, Debug, PartialEq)]
pub struct RoadOptions {
    /// Origin of the local frame; `None`: the centre of the roads' bounding box.
    pub reference: Option<GeoPoint>,
    /// GPX points closer than this (m) are one node.
    pub merge_distance: f64,
    /// Width (m) of every road without a width tag, instead of [`default_width`].
    pub width: Option<f64>,
}

impl Default for RoadOptions {
    fn default() -> Self {
        RoadOptions {
            reference: None,
            merge_distance: 0.5,
            width: None,
        }
    }
}

/// Reads an OSM XML or GPX file (told apart by the root element).
pub fn load_roads(path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
    let text = std::fs::read_to_string(path).map_err(|source| RoadError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_roads(&text, path, options)
}

/// Parses OSM XML or GPX text; `path` only names the source in errors.
pub fn parse_roads(text: &str, path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| RoadError::Xml {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let src = Source { doc: &doc, path };
    let raw = match doc.root_element().tag_name().name() {
        "osm" => osm::read(&src, options)?,
        "gpx" => gpx::read(&src, options)?,
        other => {
            return Err(src.at(
                doc.root_element(),
                format!("root element <{other}>: expected <osm> (OSM XML) or <gpx> (GPX 1.1)"),
            ));
        }
    };
    raw.into_graph(path, options)
}

/// The parsed document and its path, for errors with positions.
pub(crate) struct Source<'a, 'input> {
    pub doc: &'a roxmltree::Document<'input>,
    pub path: &'a Path,
}

impl Source<'_, '_> {
    pub fn at(&self, node: roxmltree::Node, message: String) -> RoadError {
        let pos = self.doc.text_pos_at(node.range().start);
        RoadError::At {
            path: self.path.to_path_buf(),
            line: pos.row,
            column: pos.col,
            message,
        }
    }

    /// A required attribute.
    pub fn attr<'n>(
        &self,
        node: roxmltree::Node<'n, '_>,
        name: &str,
    ) -> Result<&'n str, RoadError> {
        node.attribute(name).ok_or_else(|| {
            self.at(
                node,
                format!("<{}> has no `{name}` attribute", node.tag_name().name()),
            )
        })
    }

    /// The `lat` and `lon` attributes of a node or track point.
    pub fn geo(&self, node: roxmltree::Node) -> Result<GeoPoint, RoadError> {
        let num = |name: &str, limit: f64| -> Result<f64, RoadError> {
            let v = self.attr(node, name)?;
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && x.abs() <= limit)
                .ok_or_else(|| {
                    self.at(
                        node,
                        format!(
                            "<{}> attribute `{name}` = {v:?}: expected degrees in [-{limit}, {limit}]",
                            node.tag_name().name()
                        ),
                    )
                })
        };
        Ok(GeoPoint::new(num("lat", 90.0)?, num("lon", 180.0)?))
    }
}

/// Roads as read, before projection.
pub(crate) struct RawRoads {
    /// (position, name in the source) of every point.
    pub points: Vec<(GeoPoint, String)>,
    pub roads: Vec<Road>,
    /// Merge points closer than `merge_distance` (GPX, where junctions are repeated points).
    pub merge: bool,
    /// What the file calls a road, for the "no roads" error.
    pub what: &'static str,
}

impl RawRoads {
    fn into_graph(self, path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
        let content = |message: String| RoadError::Content {
            path: path.to_path_buf(),
            message,
        };
        if self.roads.is_empty() {
            return Err(content(format!("no roads: {}", self.what)));
        }
        let reference = match options.reference {
            Some(r) => r,
            None => {
                let used = self.roads.iter().flat_map(|r| r.nodes.iter());
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for &i in used {
                    let p = self.points[i].0;
                    lo = [lo[0].min(p.lat), lo[1].min(p.lon)];
                    hi = [hi[0].max(p.lat), hi[1].max(p.lon)];
                }
                GeoPoint::new(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))
            }
        };
        let projection = LocalProjection::new(reference).ok_or_else(|| {
            content(format!(
                "reference point ({}, {}) is not a valid latitude/longitude away from the poles",
                reference.lat, reference.lon
            ))
        })?;
        let mut nodes: Vec<RoadNode> = Vec::new();
        // point index → node index (points no road uses are dropped)
        let mut node_of = vec![usize::MAX; self.points.len()];
        let mut grid: rustc_hash::FxHashMap<(i64, i64), Vec<usize>> = Default::default();
        let cell = options.merge_distance.max(1e-6);
        let mut roads = self.roads;
        for road in &mut roads {
            for i in road.nodes.iter_mut() {
                if node_of[*i] == usize::MAX {
                    let (g, name) = &self.points[*i];
                    let pos = projection.to_local(*g);
                    let key = (
                        (pos[0] / cell).floor() as i64,
                        (pos[1] / cell).floor() as i64,
                    );
                    let near = if self.merge {
                        (-1..=1)
                            .flat_map(|dx| (-1..=1).map(move |dy| (key.0 + dx, key.1 + dy)))
                            .filter_map(|k| grid.get(&k))
                            .flatten()
                            .copied()
                            .find(|&n| {
                                let q: [f64; 2] = nodes[n].pos;
                                (q[0] - pos[0]).hypot(q[1] - pos[1]) < options.merge_distance
                            })
                    } else {
                        None
                    };
                    node_of[*i] = near.unwrap_or_else(|| {
                        nodes.push(RoadNode {
                            pos,
                            source: name.clone(),
                        });
                        grid.entry(key).or_default().push(nodes.len() - 1);
                        nodes.len() - 1
                    });
                }
                *i = node_of[*i];
            }
        }
        let graph = RoadGraph::build(projection, nodes, roads);
        if graph.edges.is_empty() {
            return Err(content(format!(
                "no road has two distinct points ({} roads read)",
                graph.roads.len()
            )));
        }
        Ok(graph)
    }
}

/// A `width` value in metres: `3.5`, `3.5 m` or `3.5m`; positive and under 100 m.
pub(crate) fn parse_width(v: &str) -> Option<f64> {
    let t = v.trim();
    let t = t.strip_suffix('m').unwrap_or(t).trim_end();
    t.parse::<f64>()
        .ok()
        .filter(|w| w.is_finite() && *w > 0.0 && *w < 100.0)
}

#[cfg(test)]
mod tests;
