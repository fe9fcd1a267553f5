//! Road-grid localization, the thesis's localizer ([Park thesis §5.3.2 "Lokalizace na mřížce",
//! §5.3.3, §5.5]): a Bayes filter over a 1-D grid of 2 m cells laid along candidate road edges
//! (code listing 5.3).
//!
//! - **Candidates** (§5.5, first step): the directed edges within `candidate_radius` (10–30 m
//!   "depending on the environment"; 20 m) of the first GPS fix whose azimuth matches the
//!   compass within `compass_tolerance`. Every cell starts with the same probability.
//! - **Prediction** (listing 5.3 line 3, §5.3.3 "odometry model"): every cell's mass moves by the
//!   encoder distance u_t driven since the previous iteration and spreads as N(0, σ²), σ² = half
//!   the 2 m cell = 1 m² (eq. 14), widened by the cosine-law error of the step (eq. 12; about
//!   0.02 m per metre, negligible as the thesis says). The mass is integrated over each cell
//!   (Φ differences) rather than sampled at cell centres. Mass that runs past the node ahead
//!   flows onto the edges leaving that node — split evenly, never the U-turn (dead ends
//!   excepted) — and the compass then sorts out which one is driven; mass reversing past the
//!   node behind flows back onto the edges arriving there.
//! - **Correction** (line 4): the log-normal GPS likelihood LN(1, 0.506) of the distance from
//!   the fix to each cell centre (eqs. 15–16, held at its peak below the 2.1 m mode), times an
//!   optional compass term (not in the thesis, which uses the compass only to pick candidates),
//!   then normalization (§5.5: "after every iteration the probabilities are normalized").
//!   An iteration runs on every GPS fix (z_t), or without one once `cell_size` has been driven.
//! - **Acceptance** (§5.5): a cell becomes the position only when it is the strict global
//!   maximum, exceeds `ratio` (2) × the `percentile` (0.9) of the other cells, and at least
//!   `min_iterations` iterations have run (so odometry has moved). Once accepted, the estimate
//!   is the most probable cell (refined by its neighbours) plus the distance driven since.
//! - **New grid at every node** (§5.5): when the accepted position passes a node, a new grid is
//!   built over every edge within `rebuild_radius` of it, both directions, any azimuth, except
//!   the U-turn back along the edge driven; the probabilities of directed edges in both grids
//!   are copied, and the new edges share `rebuild_share` of the mass (the thesis does not say
//!   what they get; with nothing they could never win).

use super::kernels::{accept_cell, apply_log_likelihood, spread_gaussian};
use super::{
    DirEdge, GpsModel, RoadLocalizer, RoadObservation, RoadPosition, angle_diff, candidates,
    compass_likelihood, cosine_law_error, next_edges, prev_edges,
};
use crate::core::SimRng;
use crate::world::roads::{EdgeId, NodeId, RoadGraph};
use rustc_hash::FxHashMap;

#[derive(Clone, Debug, PartialEq)]
pub struct RoadGridConfig {
    /// Cell length (m); edges are split into `round(length / cell_size)` equal cells.
    pub cell_size: f64,
    /// Radius (m) around the first fix in which candidate edges are sought.
    pub candidate_radius: f64,
    /// Largest azimuth difference (rad) of a candidate from the compass.
    pub compass_tolerance: f64,
    /// Radius (m) of the new grid built at each node.
    pub rebuild_radius: f64,
    /// Share of the probability given to the edges new in a rebuilt grid.
    pub rebuild_share: f64,
    /// σ (m) of the motion model per iteration (σ² = half the cell: 1 m²).
    pub motion_sigma: f64,
    /// Relative encoder error and compass error (rad) of the cosine-law term.
    pub odometry_scale_error: f64,
    pub heading_error: f64,
    pub gps: GpsModel,
    /// σ (rad) of the compass likelihood; `None`: the compass only picks the candidates.
    pub compass_sigma: Option<f64>,
    pub compass_floor: f64,
    /// Acceptance: max > `ratio` × the `percentile` of the other cells, after `min_iterations`.
    pub ratio: f64,
    pub percentile: f64,
    pub min_iterations: usize,
}

impl Default for RoadGridConfig {
    fn default() -> Self {
        RoadGridConfig {
            cell_size: 2.0,
            candidate_radius: 20.0,
            compass_tolerance: 30f64.to_radians(),
            rebuild_radius: 30.0,
            rebuild_share: 0.05,
            motion_sigma: 1.0,
            odometry_scale_error: 0.01,
            heading_error: 1f64.to_radians(),
            gps: GpsModel::default(),
            compass_sigma: Some(20f64.to_radians()),
            compass_floor: 0.05,
            ratio: 2.0,
            percentile: 0.9,
            min_iterations: 5,
        }
    }
}

/// One directed edge's cells: `p[start..start + n]`, cell j covering [j·h, (j+1)·h] metres
/// from the node behind.
#[derive(Clone, Debug)]
struct Span {
    dir: DirEdge,
    start: usize,
    n: usize,
    h: f64,
    length: f64,
    /// `toward` is the edge's `b` end.
    forward: bool,
    azimuth: f64,
}

/// Which tails of a spread continue onto neighbouring edges.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Both,
    Ahead,
    Behind,
}

/// The road-grid localizer.
#[derive(Clone, Debug)]
pub struct RoadGrid {
    pub config: RoadGridConfig,
    spans: Vec<Span>,
    index: FxHashMap<DirEdge, usize>,
    p: Vec<f64>,
    centres: Vec<[f64; 2]>,
    next: Vec<f64>,
    ll: Vec<f64>,
    scratch: Vec<f64>,
    iterations: usize,
    pending: f64,
    accepted: bool,
    /// The most probable cell after the last iteration: (directed edge, along, edge share).
    best: Option<(DirEdge, f64, f64)>,
    estimate: Option<RoadPosition>,
}

impl Default for RoadGrid {
    fn default() -> Self {
        Self::new(RoadGridConfig::default())
    }
}

impl RoadGrid {
    pub fn new(config: RoadGridConfig) -> Self {
        RoadGrid {
            config,
            spans: Vec::new(),
            index: FxHashMap::default(),
            p: Vec::new(),
            centres: Vec::new(),
            next: Vec::new(),
            ll: Vec::new(),
            scratch: Vec::new(),
            iterations: 0,
            pending: 0.0,
            accepted: false,
            best: None,
            estimate: None,
        }
    }

    /// Every cell: (edge, toward, distance of its centre from the edge's `a` end, probability).
    pub fn cells(&self) -> impl Iterator<Item = (EdgeId, NodeId, f64, f64)> + '_ {
        self.spans.iter().flat_map(move |s| {
            (0..s.n).map(move |j| {
                let c = (j as f64 + 0.5) * s.h;
                let along = if s.forward { c } else { s.length - c };
                (s.dir.edge, s.dir.toward, along, self.p[s.start + j])
            })
        })
    }

    /// Iterations run since the grid was made.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Whether a hypothesis has been accepted.
    pub fn accepted(&self) -> bool {
        self.accepted
    }

    fn add_span(&mut self, graph: &RoadGraph, dir: DirEdge) -> usize {
        if let Some(&k) = self.index.get(&dir) {
            return k;
        }
        let length = dir.length(graph);
        let n = ((length / self.config.cell_size).round() as usize).max(1);
        let h = length / n as f64;
        let start = self.p.len();
        self.p.resize(start + n, 0.0);
        self.next.resize(start + n, 0.0);
        self.centres
            .extend((0..n).map(|j| dir.point(graph, (j as f64 + 0.5) * h)));
        self.spans.push(Span {
            dir,
            start,
            n,
            h,
            length,
            forward: graph.edges[dir.edge].b == dir.toward,
            azimuth: dir.azimuth(graph),
        });
        self.index.insert(dir, self.spans.len() - 1);
        self.spans.len() - 1
    }

    fn clear(&mut self) {
        self.spans.clear();
        self.index.clear();
        self.p.clear();
        self.centres.clear();
        self.next.clear();
    }

    /// The first step of §5.5: candidate edges around the first fix, uniform probability.
    fn init(&mut self, graph: &RoadGraph, fix: [f64; 2], compass: Option<f64>) {
        let c = &self.config;
        let found = candidates(graph, fix, c.candidate_radius, compass, c.compass_tolerance);
        for (dir, _) in found {
            self.add_span(graph, dir);
        }
        let n = self.p.len();
        self.p.iter_mut().for_each(|p| *p = 1.0 / n as f64);
    }

    /// Listing 5.3 line 3: shift by `s` metres with the Gaussian motion model.
    fn predict(&mut self, graph: &RoadGraph, s: f64) {
        let c = &self.config;
        let sigma =
            c.motion_sigma
                .hypot(cosine_law_error(s, c.odometry_scale_error, c.heading_error));
        self.next.clear();
        self.next.resize(self.p.len(), 0.0);
        for k in 0..self.spans.len() {
            let (start, n, h) = (self.spans[k].start, self.spans[k].n, self.spans[k].h);
            for j in 0..n {
                let mass = self.p[start + j];
                if mass > 0.0 {
                    self.spread(
                        graph,
                        k,
                        (j as f64 + 0.5) * h + s,
                        mass,
                        sigma,
                        Side::Both,
                        0,
                    );
                }
            }
        }
        std::mem::swap(&mut self.p, &mut self.next);
    }

    /// Spreads N(t, σ²) × `mass` over span `k` and carries the tails onto neighbouring edges.
    #[allow(clippy::too_many_arguments)]
    fn spread(
        &mut self,
        graph: &RoadGraph,
        k: usize,
        t: f64,
        mass: f64,
        sigma: f64,
        side: Side,
        depth: usize,
    ) {
        let Span {
            dir,
            start,
            n,
            h,
            length,
            ..
        } = self.spans[k];
        let (below, above) = spread_gaussian(&mut self.next[start..start + n], h, t, sigma, mass);
        let tiny = (1e-12 * mass).max(1e-30); // tails worth carrying onto other edges
        let mut others = Vec::new();
        if side != Side::Behind {
            if above > tiny && depth < 4 {
                next_edges(graph, dir, &mut others);
            }
            if others.is_empty() {
                self.next[start + n - 1] += above;
            }
            let share = mass / others.len().max(1) as f64;
            for &o in &others {
                let ko = self.add_span(graph, o);
                self.spread(graph, ko, t - length, share, sigma, Side::Ahead, depth + 1);
            }
        }
        if side != Side::Ahead {
            others.clear();
            if below > tiny && depth < 4 {
                prev_edges(graph, dir, &mut others);
            }
            if others.is_empty() {
                self.next[start] += below;
            }
            let share = mass / others.len().max(1) as f64;
            for &o in &others {
                let ko = self.add_span(graph, o);
                let t_o = o.length(graph) + t;
                self.spread(graph, ko, t_o, share, sigma, Side::Behind, depth + 1);
            }
        }
    }

    /// Listing 5.3 line 4: GPS (and compass) likelihood, normalized.
    fn correct(&mut self, gps: Option<[f64; 2]>, compass: Option<f64>) {
        let compass = compass.zip(self.config.compass_sigma);
        if gps.is_none() && compass.is_none() {
            return;
        }
        self.ll.clear();
        for s in &self.spans {
            let lc = compass.map_or(0.0, |(c, sigma)| {
                compass_likelihood(angle_diff(s.azimuth, c), sigma, self.config.compass_floor).ln()
            });
            self.ll
                .extend(self.centres[s.start..s.start + s.n].iter().map(|q| {
                    lc + gps.map_or(0.0, |f| {
                        self.config
                            .gps
                            .log_likelihood((q[0] - f[0]).hypot(q[1] - f[1]))
                    })
                }));
        }
        if !apply_log_likelihood(&mut self.p, &self.ll) {
            let n = self.p.len() as f64;
            self.p.iter_mut().for_each(|p| *p = 1.0 / n);
        }
    }

    /// The most probable cell: (directed edge, along refined by its neighbours, edge share).
    fn most_probable(&mut self) -> Option<(DirEdge, f64, f64)> {
        let i = (0..self.p.len()).fold(None, |b: Option<usize>, i| match b {
            Some(b) if self.p[b] >= self.p[i] => Some(b),
            _ => Some(i),
        })?;
        let s = self.spans.iter().find(|s| i < s.start + s.n)?;
        let j = i - s.start;
        let (mut w, mut wx) = (0.0, 0.0);
        for jj in j.saturating_sub(1)..(j + 2).min(s.n) {
            w += self.p[s.start + jj];
            wx += self.p[s.start + jj] * (jj as f64 + 0.5) * s.h;
        }
        let along = if w > 0.0 {
            wx / w
        } else {
            (j as f64 + 0.5) * s.h
        };
        let share: f64 = self.p[s.start..s.start + s.n].iter().sum();
        Some((s.dir, along, share))
    }

    /// Acceptance, and a new grid when the accepted position has passed a node.
    fn select(&mut self, graph: &RoadGraph) {
        let c = &self.config;
        let passes = accept_cell(&self.p, c.ratio, c.percentile, &mut self.scratch).is_some();
        if passes && self.iterations >= c.min_iterations {
            self.accepted = true;
        }
        let mut best = self.most_probable();
        if let (true, Some((prev, ..)), Some((now, ..))) = (self.accepted, self.best, best)
            && now != prev
            && now.from(graph) == prev.toward
        {
            self.rebuild(graph, prev.toward, prev);
            best = self.most_probable();
        }
        self.best = best;
    }

    /// §5.5: a new grid over every edge near `node`, probabilities of shared edges copied.
    fn rebuild(&mut self, graph: &RoadGraph, node: NodeId, arrival: DirEdge) {
        let uturn = arrival.reversed(graph);
        let old: FxHashMap<DirEdge, Vec<f64>> = (self.spans.iter())
            .map(|s| (s.dir, self.p[s.start..s.start + s.n].to_vec()))
            .collect();
        self.clear();
        for q in graph.edges_within(graph.nodes[node].pos, self.config.rebuild_radius) {
            let e = &graph.edges[q.edge];
            for toward in [e.b, e.a] {
                if DirEdge::new(q.edge, toward) != uturn {
                    self.add_span(graph, DirEdge::new(q.edge, toward));
                }
            }
        }
        let (mut copied, mut fresh) = (0.0, 0);
        for s in &self.spans {
            match old.get(&s.dir) {
                Some(v) => {
                    self.p[s.start..s.start + s.n].copy_from_slice(v);
                    copied += v.iter().sum::<f64>();
                }
                None => fresh += s.n,
            }
        }
        // the new cells share `rebuild_share` of the mass (all of it if nothing was copied)
        let share = self.config.rebuild_share.clamp(0.0, 0.99);
        let new = if copied > 0.0 {
            share / (1.0 - share) * copied / fresh.max(1) as f64
        } else {
            1.0
        };
        for s in self.spans.iter().filter(|s| !old.contains_key(&s.dir)) {
            self.p[s.start..s.start + s.n].fill(new);
        }
        let sum: f64 = self.p.iter().sum();
        if sum > 0.0 {
            self.p.iter_mut().for_each(|p| *p /= sum);
        }
    }

    fn refresh_estimate(&mut self, graph: &RoadGraph) {
        self.estimate = match (self.accepted, self.best) {
            (true, Some((dir, along, share))) => {
                Some(RoadPosition::on(graph, dir, along + self.pending, share))
            }
            _ => None,
        };
    }
}

impl RoadLocalizer for RoadGrid {
    fn update(&mut self, graph: &RoadGraph, obs: &RoadObservation, _rng: &mut SimRng) {
        if self.spans.is_empty() {
            if let Some(fix) = obs.gps {
                self.init(graph, fix, obs.compass);
            }
        } else {
            self.pending += obs.distance;
            if obs.gps.is_some() || self.pending.abs() >= self.config.cell_size {
                let s = std::mem::take(&mut self.pending);
                self.predict(graph, s);
                self.correct(obs.gps, obs.compass);
                self.iterations += 1;
                self.select(graph);
            }
        }
        self.refresh_estimate(graph);
    }

    fn estimate(&self) -> Option<RoadPosition> {
        self.estimate
    }

    fn belief_cells(&self, _graph: &RoadGraph) -> Vec<(EdgeId, NodeId, f64, f64)> {
        self.cells().collect()
    }

    fn name(&self) -> &'static str {
        "road-grid"
    }

    fn reset(&mut self) {
        *self = RoadGrid::new(self.config.clone());
    }
}
