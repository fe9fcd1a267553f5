//! Localization on the road graph: where on which road, driving which way, from the drive-shaft
//! encoder, GPS fixes and the compass ([Park thesis §5.3 "Lokalizace", §5.5 "Proces navigace"]).
//!
//! - [`grid`]: the thesis's road-grid localization, a Bayes filter over 2 m cells along
//!   candidate edges (§5.3.2, §5.3.3, §5.5);
//! - [`mcl`]: Monte Carlo localization on the same state space (directed edge, distance along),
//!   with a GPS likelihood robust to outliers — the thesis's failure case (§7.2.3, a 40 m error)
//!   is what it is for;
//! - [`kernels`]: their inner loops as plain functions over slices.
//!
//! The state is a **directed edge** ([`DirEdge`]: the edge and the node the robot faces) and the
//! distance driven along it from the node behind; that is exactly what the road planner starts
//! from ([`RoadStart`]). Reversing (a negative encoder distance) moves back along the same
//! directed edge: `toward` is the node the robot faces, not the sign of its speed.
//!
//! Rate: the thesis iterates about once a second, about 1 m of driving (§5.3.3); pass fixes at
//! about 1 Hz (a 5 Hz receiver's fixes share their bias and are not independent), the encoder
//! distance and the compass on every update.
//!
//! Shared models: the thesis's GPS model, a log-normal LN(μ = 1, σ = 0.506) of the distance
//! between fix and truth (§5.3.3, eqs. 15–16), and the cosine-law odometry error (eq. 12).

pub mod grid;
pub mod kernels;
pub mod mcl;

#[cfg(test)]
mod test_track;
#[cfg(test)]
mod tests;

pub use grid::{RoadGrid, RoadGridConfig};
pub use mcl::{RoadMcl, RoadMclConfig, RoadParticle};

use crate::core::SimRng;
use crate::world::roads::RoadStart;
use crate::world::roads::{EdgeId, EdgePoint, NodeId, RoadGraph};
use std::f64::consts::{PI, TAU};

/// What the robot measured since the previous update.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoadObservation {
    /// Distance driven since the last update (m), from the drive-shaft encoder; negative when
    /// reversing.
    pub distance: f64,
    /// A GPS fix received since the last update, in local metres (x east, y north).
    pub gps: Option<[f64; 2]>,
    /// Compass azimuth the robot faces (rad, clockwise from north).
    pub compass: Option<f64>,
}

/// A localized position on the road graph.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadPosition {
    pub edge: EdgeId,
    /// The end of `edge` the robot faces.
    pub toward: NodeId,
    /// Distance left to `toward` (m).
    pub remaining: f64,
    /// The position in local metres.
    pub xy: [f64; 2],
    /// Azimuth of the directed edge (rad clockwise from north): the direction of travel.
    pub azimuth: f64,
    /// Share of the belief on this directed edge, in [0, 1].
    pub confidence: f64,
}

impl RoadPosition {
    /// Where the planner starts from.
    pub fn start(&self) -> RoadStart {
        RoadStart {
            edge: self.edge,
            toward: self.toward,
            remaining: self.remaining,
        }
    }

    /// `along` metres from the node behind on `dir`.
    pub fn on(graph: &RoadGraph, dir: DirEdge, along: f64, confidence: f64) -> Self {
        let along = along.clamp(0.0, dir.length(graph));
        RoadPosition {
            edge: dir.edge,
            toward: dir.toward,
            remaining: dir.length(graph) - along,
            xy: dir.point(graph, along),
            azimuth: dir.azimuth(graph),
            confidence,
        }
    }
}

/// A road localizer. It reads sensor data only; the navigator only reads its estimates.
pub trait RoadLocalizer {
    fn update(&mut self, graph: &RoadGraph, obs: &RoadObservation, rng: &mut SimRng);
    /// `None` until a hypothesis has been accepted.
    fn estimate(&self) -> Option<RoadPosition>;
    fn name(&self) -> &'static str;
    /// The belief for recording: (edge, node faced, metres along from the edge's `a`, weight)
    /// per grid cell or particle.
    fn belief_cells(&self, graph: &RoadGraph) -> Vec<(EdgeId, NodeId, f64, f64)>;
    /// Forget everything; localize again from the next GPS fix.
    fn reset(&mut self);
}

/// An edge driven towards one of its ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DirEdge {
    pub edge: EdgeId,
    pub toward: NodeId,
}

impl DirEdge {
    pub fn new(edge: EdgeId, toward: NodeId) -> Self {
        DirEdge { edge, toward }
    }

    /// The node behind.
    pub fn from(self, graph: &RoadGraph) -> NodeId {
        let e = &graph.edges[self.edge];
        if e.b == self.toward { e.a } else { e.b }
    }

    pub fn length(self, graph: &RoadGraph) -> f64 {
        graph.edges[self.edge].length
    }

    /// Azimuth of the direction of travel.
    pub fn azimuth(self, graph: &RoadGraph) -> f64 {
        graph.azimuth_from(self.edge, self.from(graph))
    }

    /// The same edge driven the other way.
    pub fn reversed(self, graph: &RoadGraph) -> Self {
        DirEdge::new(self.edge, self.from(graph))
    }

    /// Distance from the edge's `a` end of the point `along` metres from the node behind.
    pub fn along_from_a(self, graph: &RoadGraph, along: f64) -> f64 {
        let e = &graph.edges[self.edge];
        if e.b == self.toward {
            along
        } else {
            e.length - along
        }
    }

    /// The point `along` metres from the node behind (clamped to the edge).
    pub fn point(self, graph: &RoadGraph, along: f64) -> [f64; 2] {
        graph.point_on(self.edge, self.along_from_a(graph, along))
    }
}

/// The thesis's GPS sensor model (§5.3.3, eq. 15): the distance between fix and truth is
/// LN(μ, σ), μ = 1, σ = 0.506 (eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsModel {
    pub mu: f64,
    pub sigma: f64,
}

impl Default for GpsModel {
    fn default() -> Self {
        GpsModel {
            mu: 1.0,
            sigma: 0.506,
        }
    }
}

impl GpsModel {
    /// The density's peak, at d = exp(μ − σ²) (2.1 m for the thesis's parameters).
    pub fn mode(&self) -> f64 {
        (self.mu - self.sigma * self.sigma).exp()
    }

    /// ln of the log-normal density of eq. 15 at `d`, held at its peak below the mode. Eq. 15
    /// is 0 at d = 0, which would make a cell right under the fix the least likely of all; the
    /// guard keeps the likelihood non-increasing in the distance.
    pub fn log_likelihood(&self, d: f64) -> f64 {
        let u = d.max(self.mode());
        let z = (u.ln() - self.mu) / self.sigma;
        -0.5 * z * z - (u * self.sigma * (TAU).sqrt()).ln()
    }

    pub fn likelihood(&self, d: f64) -> f64 {
        self.log_likelihood(d).exp()
    }
}

/// End-position error (m) after driving `s` metres with a relative distance error
/// `scale_error` and a heading error `heading_error` (rad), by the cosine law (eq. 12; eq. 13:
/// 10 m at 1 % and 1° → 0.202 m).
pub fn cosine_law_error(s: f64, scale_error: f64, heading_error: f64) -> f64 {
    let sp = s.abs();
    let ss = sp * (1.0 + scale_error);
    (ss * ss + sp * sp - 2.0 * ss * sp * heading_error.cos())
        .max(0.0)
        .sqrt()
}

/// The absolute difference of two azimuths, in [0, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    if d > PI { TAU - d } else { d }
}

/// Compass likelihood of an azimuth difference: a Gaussian of width `sigma` over a `floor`
/// (so an interfered compass, 8–20° off near the substation of Tab. 2, cannot rule a road out).
pub fn compass_likelihood(diff: f64, sigma: f64, floor: f64) -> f64 {
    floor + (1.0 - floor) * (-0.5 * (diff / sigma).powi(2)).exp()
}

/// The directed edges a robot at the end of `dir` can drive on: every other edge at the node
/// it reaches; the U-turn back only at a dead end.
pub fn next_edges(graph: &RoadGraph, dir: DirEdge, out: &mut Vec<DirEdge>) {
    out.clear();
    out.extend(
        graph.adjacency[dir.toward]
            .iter()
            .filter(|&&(e, _)| e != dir.edge)
            .map(|&(e, other)| DirEdge::new(e, other)),
    );
    if out.is_empty() {
        out.push(dir.reversed(graph));
    }
}

/// The directed edges a robot reversing past the start of `dir` backs onto (facing the same
/// node it left); empty at a dead end.
pub fn prev_edges(graph: &RoadGraph, dir: DirEdge, out: &mut Vec<DirEdge>) {
    let from = dir.from(graph);
    out.clear();
    out.extend(
        graph.adjacency[from]
            .iter()
            .filter(|&&(e, _)| e != dir.edge)
            .map(|&(e, _)| DirEdge::new(e, from)),
    );
}

/// Directed edges within `radius` of `p` whose azimuth is within `tolerance` of `compass`
/// (both directions of every edge without a compass), with the projection of `p`; nearest
/// first (§5.5: "the roads farther than the limit and those leading elsewhere are excluded").
pub fn candidates(
    graph: &RoadGraph,
    p: [f64; 2],
    radius: f64,
    compass: Option<f64>,
    tolerance: f64,
) -> Vec<(DirEdge, EdgePoint)> {
    let mut out = Vec::new();
    for q in graph.edges_within(p, radius) {
        let e = &graph.edges[q.edge];
        for toward in [e.b, e.a] {
            let dir = DirEdge::new(q.edge, toward);
            if compass.is_none_or(|c| angle_diff(dir.azimuth(graph), c) <= tolerance) {
                out.push((dir, q));
            }
        }
    }
    out
}

/// Picks one of `options` with probability proportional to how well its azimuth matches the
/// compass (uniformly without one).
pub(crate) fn choose_by_compass(
    graph: &RoadGraph,
    options: &[DirEdge],
    compass: Option<f64>,
    sigma: f64,
    floor: f64,
    u: f64,
) -> Option<DirEdge> {
    let score = |d: &DirEdge| match compass {
        Some(c) => compass_likelihood(angle_diff(d.azimuth(graph), c), sigma, floor),
        None => 1.0,
    };
    let total: f64 = options.iter().map(score).sum();
    let mut acc = 0.0;
    for d in options {
        acc += score(d);
        if u * total < acc {
            return Some(*d);
        }
    }
    options.last().copied()
}
