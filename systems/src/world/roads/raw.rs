//! Roads as read from an OSM XML or GPX file, before they become a [`RoadGraph`]: the reading
//! options and errors, the parsed document with positions for errors, the raw roads and their
//! projection into the graph. A leaf of the readers (`osm`, `gpx`) and of [`super::load_roads`],
//! which picks the reader, so none of them imports another.

use super::geo::{GeoPoint, LocalProjection};
use super::graph::{Road, RoadGraph, RoadNode};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum RoadError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
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

/// Options of [`load_roads`](super::load_roads).
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
    pub fn into_graph(self, path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
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
