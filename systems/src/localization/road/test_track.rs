//! Synthetic drives for the road-localizer tests: a robot walks a list of road nodes at 1 m/s in
//! 0.2 s steps; the encoder reads 1 % long (the worst calibrated error of the thesis's Tab. 3),
//! a GPS fix comes every 1 s from the simulator's error model (LN(1, 0.506) in a random
//! direction, small Gauss–Markov bias, no random outliers), and the compass reads the heading of
//! the edge driven with 1° of noise ([Park thesis §5.3.1]).

use super::{DirEdge, RoadObservation};
use crate::core::SimRng;
use crate::sensors::gps::GpsErrorModel;
use crate::world::roads::{
    GeoPoint, LocalProjection, NodeId, Road, RoadGraph, RoadNode, RoadOptions, Surface, load_roads,
};
use crate::world::zones::{GpsZone, ZoneKind};
use rand::RngExt;
use rand_distr::StandardNormal;

/// The bundled park (assets/roads/park/park.osm).
pub fn park() -> RoadGraph {
    let path = crate::core::source::source_path("assets/roads/park/park.osm");
    load_roads(&path, &RoadOptions::default()).expect("park.osm")
}

/// A graph from named points and roads through them (names are the nodes' sources).
pub fn graph(points: &[(&str, [f64; 2])], roads: &[&[&str]]) -> RoadGraph {
    let projection = LocalProjection::new(GeoPoint::new(50.0, 14.0)).unwrap();
    let nodes = points
        .iter()
        .map(|(s, p)| RoadNode {
            pos: *p,
            source: s.to_string(),
        })
        .collect();
    let id = |s: &str| points.iter().position(|(n, _)| *n == s).unwrap();
    let roads = roads
        .iter()
        .enumerate()
        .map(|(i, r)| Road {
            name: format!("road {i}"),
            kind: "footway".into(),
            surface: Surface::Gravel,
            width: 3.0,
            nodes: r.iter().map(|s| id(s)).collect(),
        })
        .collect();
    RoadGraph::build(projection, nodes, roads)
}

pub fn node(g: &RoadGraph, source: &str) -> NodeId {
    g.node_by_source(source)
        .unwrap_or_else(|| panic!("no node {source}"))
}

/// The directed edge from `a` to `b` (sources).
pub fn dir(g: &RoadGraph, a: &str, b: &str) -> DirEdge {
    let (a, b) = (node(g, a), node(g, b));
    DirEdge::new(g.edge_between(a, b).expect("adjacent nodes"), b)
}

/// The nodes of the shortest path through the listed nodes (Dijkstra between consecutive ones).
pub fn expand(g: &RoadGraph, via: &[&str]) -> Vec<NodeId> {
    let mut out = vec![node(g, via[0])];
    for w in via.windows(2) {
        let (s, t) = (node(g, w[0]), node(g, w[1]));
        let mut dist = vec![f64::INFINITY; g.nodes.len()];
        let mut prev = vec![usize::MAX; g.nodes.len()];
        let mut done = vec![false; g.nodes.len()];
        dist[s] = 0.0;
        while let Some(u) = (0..g.nodes.len())
            .filter(|&u| !done[u] && dist[u].is_finite())
            .min_by(|&a, &b| dist[a].total_cmp(&dist[b]))
        {
            done[u] = true;
            for &(e, v) in &g.adjacency[u] {
                if dist[u] + g.edges[e].length < dist[v] {
                    dist[v] = dist[u] + g.edges[e].length;
                    prev[v] = u;
                }
            }
        }
        let mut leg = vec![t];
        while *leg.last().unwrap() != s {
            leg.push(prev[*leg.last().unwrap()]);
        }
        out.extend(leg.into_iter().rev().skip(1));
    }
    out
}

/// Where the robot truly is.
#[derive(Clone, Copy, Debug)]
pub struct Truth {
    pub dir: DirEdge,
    pub along: f64,
    pub xy: [f64; 2],
}

#[derive(Clone, Copy, Debug)]
pub struct Step {
    pub obs: RoadObservation,
    pub truth: Truth,
}

#[derive(Clone, Debug)]
pub struct Drive {
    /// Metres from the first node where the robot starts, and how far it drives.
    pub start: f64,
    pub length: f64,
    pub zone: GpsZone,
    /// Added to the first fix (the thesis's 40 m error of §7.2.3).
    pub first_fix_error: [f64; 2],
    pub compass: bool,
    /// Metres reversed (facing the same way) after the end.
    pub reverse: f64,
}

impl Default for Drive {
    fn default() -> Self {
        Drive {
            start: 0.0,
            length: f64::INFINITY,
            zone: GpsZone {
                bias_std: 0.3,
                outlier_probability: 0.0,
                ..ZoneKind::Open.gps()
            },
            first_fix_error: [0.0; 2],
            compass: true,
            reverse: 0.0,
        }
    }
}

/// Drives along `path` (consecutive nodes adjacent), then reverses `reverse` metres: one
/// [`Step`] per 0.2 s, the first at the start with distance 0 and a fix.
pub fn drive(g: &RoadGraph, path: &[NodeId], d: &Drive, rng: &mut SimRng) -> Vec<Step> {
    let legs: Vec<DirEdge> = path
        .windows(2)
        .map(|w| DirEdge::new(g.edge_between(w[0], w[1]).expect("adjacent"), w[1]))
        .collect();
    let total: f64 = legs.iter().map(|l| l.length(g)).sum();
    let end = total.min(d.start + d.length) - 1e-9;
    let at = |mut s: f64| {
        for &l in &legs {
            if s <= l.length(g) {
                return Truth {
                    dir: l,
                    along: s,
                    xy: l.point(g, s),
                };
            }
            s -= l.length(g);
        }
        unreachable!("beyond the path")
    };
    let (dt, speed): (f64, f64) = (0.2, 1.0);
    let mut gps = GpsErrorModel::new();
    let mut steps = Vec::new();
    let (mut s, mut back) = (d.start, 0.0);
    for k in 0.. {
        let moved = if k == 0 {
            0.0
        } else if s < end && back == 0.0 {
            (speed * dt).min(end - s)
        } else {
            -(speed * dt).min(d.reverse - back)
        };
        if k > 0 && moved == 0.0 {
            break;
        }
        back -= moved.min(0.0);
        s += moved;
        let truth = at(s);
        let t = k as f64 * dt;
        let fix = (k % 5 == 0).then(|| {
            let mut f = gps.sample(t, truth.xy, &d.zone, rng);
            if k == 0 {
                f = [f[0] + d.first_fix_error[0], f[1] + d.first_fix_error[1]];
            }
            f
        });
        let noise: f64 = rng.sample(StandardNormal);
        let compass = d.compass.then(|| {
            (truth.dir.azimuth(g) + 1f64.to_radians() * noise).rem_euclid(std::f64::consts::TAU)
        });
        steps.push(Step {
            obs: RoadObservation {
                distance: moved * 1.01,
                gps: fix,
                compass,
            },
            truth,
        });
    }
    steps
}
