//! The road graph and the road surface it carries: nodes in local metres, straight edges with
//! length and compass azimuth, each edge belonging to a road (an OSM way or a GPX track) that
//! gives its surface type and width. The graph is what the planner and the road-grid
//! localization walk ([Park thesis §5.1]: a graph of points and road segments); the
//! edges widened to their road's width are the road surface the camera sees and off-road
//! detection tests against.

use super::geo::{LocalProjection, azimuth_of};
use super::surface::Surface;

/// Index of a node in [`RoadGraph::nodes`].
pub type NodeId = usize;
/// Index of an edge in [`RoadGraph::edges`].
pub type EdgeId = usize;

#[derive(Clone, Debug, PartialEq)]
pub struct RoadNode {
    /// Position in local metres (x east, y north).
    pub pos: [f64; 2],
    /// The node's name in the source file (the OSM node id, or `trkpt N` of a GPX track).
    pub source: String,
}

/// A road: an OSM way with a highway tag, or a GPX track.
#[derive(Clone, Debug, PartialEq)]
pub struct Road {
    pub name: String,
    /// The OSM highway value (`footway`, `service`, ...), or `track` for GPX.
    pub kind: String,
    pub surface: Surface,
    /// Full width (m).
    pub width: f64,
    /// The road's nodes in order.
    pub nodes: Vec<NodeId>,
}

/// A straight piece of road between two nodes; traversable both ways.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadEdge {
    pub a: NodeId,
    pub b: NodeId,
    pub road: usize,
    /// Length (m).
    pub length: f64,
    /// Compass azimuth from `a` to `b` (radians clockwise from north, [0, 2π)).
    pub azimuth: f64,
}

/// Where a point projects onto an edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePoint {
    pub edge: EdgeId,
    /// Distance along the edge from `a` (m), clamped to [0, length].
    pub along: f64,
    /// Distance from the point to the edge (m).
    pub distance: f64,
}

/// Where the robot is: on `edge`, driving towards its end `toward`, `remaining` metres before it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadStart {
    pub edge: EdgeId,
    pub toward: NodeId,
    pub remaining: f64,
}

/// A road network in local metres around its reference point.
#[derive(Clone, Debug)]
pub struct RoadGraph {
    pub projection: LocalProjection,
    pub nodes: Vec<RoadNode>,
    pub roads: Vec<Road>,
    pub edges: Vec<RoadEdge>,
    /// Per node: (edge, other node) of every edge at it.
    pub adjacency: Vec<Vec<(EdgeId, NodeId)>>,
}

impl RoadGraph {
    /// Builds the edges and adjacency from nodes and roads. Consecutive repeats of a node are
    /// skipped; an edge that two roads share is kept once (the first road's).
    pub(crate) fn build(
        projection: LocalProjection,
        nodes: Vec<RoadNode>,
        roads: Vec<Road>,
    ) -> Self {
        let mut edges = Vec::new();
        let mut adjacency: Vec<Vec<(EdgeId, NodeId)>> = vec![Vec::new(); nodes.len()];
        let mut seen = rustc_hash::FxHashSet::default();
        for (r, road) in roads.iter().enumerate() {
            for w in road.nodes.windows(2) {
                let (a, b) = (w[0], w[1]);
                if a == b || !seen.insert((a.min(b), a.max(b))) {
                    continue;
                }
                let (pa, pb) = (nodes[a].pos, nodes[b].pos);
                let d = [pb[0] - pa[0], pb[1] - pa[1]];
                let id = edges.len();
                edges.push(RoadEdge {
                    a,
                    b,
                    road: r,
                    length: d[0].hypot(d[1]),
                    azimuth: azimuth_of(d),
                });
                adjacency[a].push((id, b));
                adjacency[b].push((id, a));
            }
        }
        RoadGraph {
            projection,
            nodes,
            roads,
            edges,
            adjacency,
        }
    }

    pub fn degree(&self, n: NodeId) -> usize {
        self.adjacency[n].len()
    }

    /// Total length of all edges (m).
    pub fn total_length(&self) -> f64 {
        self.edges.iter().map(|e| e.length).sum()
    }

    /// Compass azimuth of `edge` when driven away from `from` (one of its ends).
    pub fn azimuth_from(&self, edge: EdgeId, from: NodeId) -> f64 {
        let e = &self.edges[edge];
        if from == e.a {
            e.azimuth
        } else {
            (e.azimuth + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
        }
    }

    /// The point `along` metres from `a` on `edge` (clamped to the edge).
    pub fn point_on(&self, edge: EdgeId, along: f64) -> [f64; 2] {
        let e = &self.edges[edge];
        let (pa, pb) = (self.nodes[e.a].pos, self.nodes[e.b].pos);
        let t = if e.length > 0.0 {
            (along / e.length).clamp(0.0, 1.0)
        } else {
            0.0
        };
        [pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])]
    }

    /// Projection of `p` onto `edge`.
    pub fn project(&self, edge: EdgeId, p: [f64; 2]) -> EdgePoint {
        let e = &self.edges[edge];
        let (pa, pb) = (self.nodes[e.a].pos, self.nodes[e.b].pos);
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        let l2 = d[0] * d[0] + d[1] * d[1];
        let t = if l2 > 0.0 {
            (((p[0] - pa[0]) * d[0] + (p[1] - pa[1]) * d[1]) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [pa[0] + t * d[0], pa[1] + t * d[1]];
        EdgePoint {
            edge,
            along: t * e.length,
            distance: (p[0] - q[0]).hypot(p[1] - q[1]),
        }
    }

    /// The edge nearest to `p` (ties: the lower edge id); `None` for a graph without edges.
    pub fn nearest_edge(&self, p: [f64; 2]) -> Option<EdgePoint> {
        (0..self.edges.len())
            .map(|e| self.project(e, p))
            .min_by(|x, y| x.distance.total_cmp(&y.distance))
    }

    /// Every edge within `radius` of `p`, nearest first.
    pub fn edges_within(&self, p: [f64; 2], radius: f64) -> Vec<EdgePoint> {
        let mut v: Vec<EdgePoint> = (0..self.edges.len())
            .map(|e| self.project(e, p))
            .filter(|q| q.distance <= radius)
            .collect();
        v.sort_by(|x, y| x.distance.total_cmp(&y.distance).then(x.edge.cmp(&y.edge)));
        v
    }

    /// The road surface at `p`: the surface of the nearest edge whose road, at its width,
    /// covers `p` (`None` off the roads).
    pub fn surface_at(&self, p: [f64; 2]) -> Option<(EdgeId, Surface)> {
        let mut best: Option<EdgePoint> = None;
        for e in 0..self.edges.len() {
            let q = self.project(e, p);
            let half = 0.5 * self.roads[self.edges[e].road].width;
            if q.distance <= half && best.is_none_or(|b| q.distance < b.distance) {
                best = Some(q);
            }
        }
        best.map(|q| (q.edge, self.roads[self.edges[q.edge].road].surface))
    }

    /// The bounding box of the nodes: [min x, min y, max x, max y] (m).
    pub fn bounds(&self) -> [f64; 4] {
        self.nodes.iter().fold(
            [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ],
            |b, n| {
                [
                    b[0].min(n.pos[0]),
                    b[1].min(n.pos[1]),
                    b[2].max(n.pos[0]),
                    b[3].max(n.pos[1]),
                ]
            },
        )
    }

    /// The node named `source` in the file (an OSM node id).
    pub fn node_by_source(&self, source: &str) -> Option<NodeId> {
        self.nodes.iter().position(|n| n.source == source)
    }

    /// The edge between two nodes, if any.
    pub fn edge_between(&self, a: NodeId, b: NodeId) -> Option<EdgeId> {
        self.adjacency[a]
            .iter()
            .find(|&&(_, other)| other == b)
            .map(|&(e, _)| e)
    }
}
