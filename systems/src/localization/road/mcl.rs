//! Monte Carlo localization on the road graph: the state space of the thesis's road grid
//! ([Park thesis §5.3.2, §5.5]: a directed edge and the distance along it) sampled
//! by particles instead of 2 m cells (Probabilistic Robotics Table 8.2), so that the failure
//! the thesis reports in §7.2.3 — a 40 m GPS error in the first fix localized the robot on the
//! wrong road — can be recovered from:
//!
//! - **initialization** on the directed edges within `init_radius` (50 m) of the first fix
//!   whose azimuth matches the compass (§5.5's first step, with a generous radius);
//! - **motion**: the encoder distance × (1 + N(0, 1 %)) (the calibrated encoder of Tab. 3 errs
//!   0.31–1.06 %) plus a random walk; a particle that runs past the node ahead picks one of the
//!   edges leaving it, never the U-turn (dead ends excepted), with probability by how well its
//!   azimuth matches the compass (uniformly without one); reversing past the node behind backs
//!   onto an edge arriving there;
//! - **weights**: the thesis's log-normal GPS likelihood LN(1, 0.506) (eqs. 15–16) mixed with a
//!   uniform outlier density, so one 40 m fix cannot wipe out the truth, times a compass
//!   likelihood (a Gaussian on the azimuth difference over a floor). A correction runs on
//!   every fix, or on the compass alone once `correction_distance` has been driven;
//! - **injection**: on every fix the `inject_fraction` lightest particles are replaced by
//!   particles near the fix on candidate edges (within `candidate_radius`, matching the
//!   compass), at the mean weight, so a wrong start is left as soon as the fixes disagree;
//! - **resampling**: low-variance, only when N_eff = 1/Σw² < `resample_ess` × N;
//! - **estimate**: the directed edge holding the most weight, at the weighted mean distance of
//!   its particles; confidence = that edge's weight share.

use super::kernels::{effective_sample_size, low_variance_indices};
use super::{
    DirEdge, GpsModel, RoadLocalizer, RoadObservation, RoadPosition, angle_diff, candidates,
    choose_by_compass, compass_likelihood, next_edges, prev_edges,
};
use crate::core::SimRng;
use crate::world::roads::{EdgeId, NodeId, RoadGraph};
use rand::RngExt;
use rand_distr::StandardNormal;
use rustc_hash::FxHashMap;

#[derive(Clone, Debug, PartialEq)]
pub struct RoadMclConfig {
    pub particles: usize,
    /// Radius (m) around the first fix for the initial particles.
    pub init_radius: f64,
    /// Radius (m) around a fix for injected particles.
    pub candidate_radius: f64,
    /// Largest azimuth difference (rad) from the compass of an initial or injected edge.
    pub compass_tolerance: f64,
    /// σ of the relative encoder error, and of the random walk (m per √m driven).
    pub scale_sigma: f64,
    pub walk_sigma: f64,
    pub gps: GpsModel,
    /// Weight of the uniform outlier term and the distance (m) it is uniform over.
    pub outlier_weight: f64,
    pub outlier_range: f64,
    /// σ (rad) and floor of the compass likelihood.
    pub compass_sigma: f64,
    pub compass_floor: f64,
    /// Floor of the compass score of an edge when a particle chooses at a node.
    pub turn_floor: f64,
    /// Resample when N_eff < `resample_ess` × N.
    pub resample_ess: f64,
    pub inject_fraction: f64,
    /// σ (m) of injected particles along the edge around the fix's projection.
    pub inject_spread: f64,
    /// Distance (m) after which the compass alone corrects.
    pub correction_distance: f64,
}

impl Default for RoadMclConfig {
    fn default() -> Self {
        RoadMclConfig {
            particles: 500,
            init_radius: 50.0,
            candidate_radius: 20.0,
            compass_tolerance: 30f64.to_radians(),
            scale_sigma: 0.01,
            walk_sigma: 0.05,
            gps: GpsModel::default(),
            outlier_weight: 0.1,
            outlier_range: 100.0,
            compass_sigma: 20f64.to_radians(),
            compass_floor: 0.05,
            turn_floor: 0.1,
            resample_ess: 0.5,
            inject_fraction: 0.02,
            inject_spread: 4.0,
            correction_distance: 2.0,
        }
    }
}

/// A particle: `along` metres from the node behind on `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadParticle {
    pub dir: DirEdge,
    pub along: f64,
    pub weight: f64,
}

/// Multiplies `weights` by the robust GPS likelihood of each particle's position and the
/// compass likelihood of its azimuth, and normalizes. False if no weight is left.
pub fn weigh(
    weights: &mut [f64],
    xy: &[[f64; 2]],
    azimuth: &[f64],
    gps: Option<[f64; 2]>,
    compass: Option<f64>,
    c: &RoadMclConfig,
) -> bool {
    let uniform = c.outlier_weight / c.outlier_range;
    let mut sum = 0.0;
    for ((w, q), az) in weights.iter_mut().zip(xy).zip(azimuth) {
        if let Some(f) = gps {
            let d = (q[0] - f[0]).hypot(q[1] - f[1]);
            *w *= (1.0 - c.outlier_weight) * c.gps.likelihood(d) + uniform;
        }
        if let Some(h) = compass {
            *w *= compass_likelihood(angle_diff(*az, h), c.compass_sigma, c.compass_floor);
        }
        sum += *w;
    }
    if !(sum > 0.0 && sum.is_finite()) {
        return false;
    }
    weights.iter_mut().for_each(|w| *w /= sum);
    true
}

/// The road MCL localizer.
#[derive(Clone, Debug)]
pub struct RoadMcl {
    pub config: RoadMclConfig,
    particles: Vec<RoadParticle>,
    since_correction: f64,
    estimate: Option<RoadPosition>,
    weights: Vec<f64>,
    xy: Vec<[f64; 2]>,
    azimuth: Vec<f64>,
    options: Vec<DirEdge>,
    picks: Vec<usize>,
}

impl Default for RoadMcl {
    fn default() -> Self {
        Self::new(RoadMclConfig::default())
    }
}

impl RoadMcl {
    pub fn new(config: RoadMclConfig) -> Self {
        RoadMcl {
            config,
            particles: Vec::new(),
            since_correction: 0.0,
            estimate: None,
            weights: Vec::new(),
            xy: Vec::new(),
            azimuth: Vec::new(),
            options: Vec::new(),
            picks: Vec::new(),
        }
    }

    pub fn particles(&self) -> &[RoadParticle] {
        &self.particles
    }

    /// Every particle: (edge, toward, distance from the edge's `a` end, weight).
    pub fn particle_cells<'a>(
        &'a self,
        graph: &'a RoadGraph,
    ) -> impl Iterator<Item = (EdgeId, NodeId, f64, f64)> + 'a {
        self.particles.iter().map(move |p| {
            let along = p.dir.along_from_a(graph, p.along);
            (p.dir.edge, p.dir.toward, along, p.weight)
        })
    }

    /// A particle near `fix` on one of `cands` (by the fix's projection ± `spread`).
    fn sample_near(
        graph: &RoadGraph,
        cands: &[(DirEdge, crate::world::roads::EdgePoint)],
        spread: f64,
        rng: &mut SimRng,
    ) -> (DirEdge, f64) {
        let (dir, q) = cands[rng.random_range(0..cands.len())];
        let foot = dir.along_from_a(graph, q.along); // symmetric: a-based ↔ directed
        let n: f64 = rng.sample(StandardNormal);
        (dir, (foot + spread * n).clamp(0.0, dir.length(graph)))
    }

    fn init(&mut self, graph: &RoadGraph, fix: [f64; 2], compass: Option<f64>, rng: &mut SimRng) {
        let c = &self.config;
        let cands = candidates(graph, fix, c.init_radius, compass, c.compass_tolerance);
        if cands.is_empty() || c.particles == 0 {
            return;
        }
        // uniform over the stretches of the candidates within the radius
        let stretch = |dir: DirEdge, q: &crate::world::roads::EdgePoint| {
            let half = (c.init_radius.powi(2) - q.distance.powi(2)).max(0.0).sqrt();
            let foot = dir.along_from_a(graph, q.along);
            let (lo, hi) = ((foot - half).max(0.0), (foot + half).min(dir.length(graph)));
            (lo, hi.max(lo))
        };
        let total: f64 = cands
            .iter()
            .map(|(d, q)| stretch(*d, q))
            .map(|(lo, hi)| hi - lo)
            .sum();
        let n = c.particles;
        for _ in 0..n {
            let mut x = rng.random::<f64>() * total;
            let mut pick = (cands[0].0, 0.0);
            for (d, q) in &cands {
                let (lo, hi) = stretch(*d, q);
                pick = (*d, lo + x.min(hi - lo));
                if x < hi - lo {
                    break;
                }
                x -= hi - lo;
            }
            self.particles.push(RoadParticle {
                dir: pick.0,
                along: pick.1,
                weight: 1.0 / n as f64,
            });
        }
    }

    /// Moves a particle `d` metres, choosing edges at nodes.
    fn advance(&mut self, graph: &RoadGraph, i: usize, d: f64, compass: Option<f64>, u: f64) {
        let c = &self.config;
        let RoadParticle {
            mut dir, mut along, ..
        } = self.particles[i];
        along += d;
        for _ in 0..64 {
            let len = dir.length(graph);
            // past the edge's head: on along an edge leaving it; before its tail: back onto
            // an edge arriving there
            let ahead = along > len;
            if !ahead && along >= 0.0 {
                break;
            }
            if ahead {
                next_edges(graph, dir, &mut self.options);
            } else {
                prev_edges(graph, dir, &mut self.options);
            }
            let Some(o) = choose_by_compass(
                graph,
                &self.options,
                compass,
                c.compass_sigma,
                c.turn_floor,
                u,
            ) else {
                break;
            };
            along += if ahead { -len } else { o.length(graph) };
            dir = o;
        }
        self.particles[i].dir = dir;
        self.particles[i].along = along.clamp(0.0, dir.length(graph));
    }

    fn correct(&mut self, graph: &RoadGraph, gps: Option<[f64; 2]>, compass: Option<f64>) {
        self.weights.clear();
        self.xy.clear();
        self.azimuth.clear();
        for p in &self.particles {
            self.weights.push(p.weight);
            self.xy.push(p.dir.point(graph, p.along));
            self.azimuth.push(p.dir.azimuth(graph));
        }
        let ok = weigh(
            &mut self.weights,
            &self.xy,
            &self.azimuth,
            gps,
            compass,
            &self.config,
        );
        let n = self.particles.len() as f64;
        for (p, w) in self.particles.iter_mut().zip(&self.weights) {
            p.weight = if ok { *w } else { 1.0 / n };
        }
    }

    /// Replaces the lightest particles by particles near the fix, at the mean weight.
    fn inject(&mut self, graph: &RoadGraph, fix: [f64; 2], compass: Option<f64>, rng: &mut SimRng) {
        let c = &self.config;
        let k = (c.inject_fraction * self.particles.len() as f64).round() as usize;
        let cands = candidates(graph, fix, c.candidate_radius, compass, c.compass_tolerance);
        if k == 0 || cands.is_empty() {
            return;
        }
        let mut order: Vec<usize> = (0..self.particles.len()).collect();
        order.sort_by(|&a, &b| {
            let (pa, pb) = (&self.particles[a], &self.particles[b]);
            pa.weight.total_cmp(&pb.weight).then(a.cmp(&b))
        });
        let mean = 1.0 / self.particles.len() as f64;
        for &i in order.iter().take(k) {
            let (dir, along) = Self::sample_near(graph, &cands, c.inject_spread, rng);
            self.particles[i] = RoadParticle {
                dir,
                along,
                weight: mean,
            };
        }
        let sum: f64 = self.particles.iter().map(|p| p.weight).sum();
        self.particles.iter_mut().for_each(|p| p.weight /= sum);
    }

    fn resample_if_needed(&mut self, rng: &mut SimRng) {
        self.weights.clear();
        self.weights.extend(self.particles.iter().map(|p| p.weight));
        let n = self.particles.len();
        if effective_sample_size(&self.weights) >= self.config.resample_ess * n as f64 {
            return;
        }
        low_variance_indices(&self.weights, rng.random::<f64>(), &mut self.picks);
        let old = self.particles.clone();
        for (p, &i) in self.particles.iter_mut().zip(&self.picks) {
            *p = RoadParticle {
                weight: 1.0 / n as f64,
                ..old[i]
            };
        }
    }

    fn refresh_estimate(&mut self, graph: &RoadGraph) {
        let mut per: FxHashMap<DirEdge, (f64, f64)> = FxHashMap::default();
        for p in &self.particles {
            let e = per.entry(p.dir).or_default();
            e.0 += p.weight;
            e.1 += p.weight * p.along;
        }
        let total: f64 = self.particles.iter().map(|p| p.weight).sum();
        self.estimate = per
            .into_iter()
            .max_by(|a, b| a.1.0.total_cmp(&b.1.0).then(b.0.cmp(&a.0)))
            .filter(|(_, (w, _))| *w > 0.0)
            .map(|(dir, (w, wx))| RoadPosition::on(graph, dir, wx / w, w / total));
    }
}

impl RoadLocalizer for RoadMcl {
    fn update(&mut self, graph: &RoadGraph, obs: &RoadObservation, rng: &mut SimRng) {
        if self.particles.is_empty() {
            let Some(fix) = obs.gps else { return };
            self.init(graph, fix, obs.compass, rng);
            self.since_correction = 0.0;
        } else {
            let d = obs.distance;
            for i in 0..self.particles.len() {
                let n0: f64 = rng.sample(StandardNormal);
                let n1: f64 = rng.sample(StandardNormal);
                let di = d * (1.0 + self.config.scale_sigma * n0)
                    + self.config.walk_sigma * d.abs().sqrt() * n1;
                let u = rng.random::<f64>();
                self.advance(graph, i, di, obs.compass, u);
            }
            self.since_correction += d.abs();
        }
        let due = obs.gps.is_some()
            || (obs.compass.is_some() && self.since_correction >= self.config.correction_distance);
        if due && !self.particles.is_empty() {
            self.correct(graph, obs.gps, obs.compass);
            if let Some(fix) = obs.gps {
                self.inject(graph, fix, obs.compass, rng);
            }
            self.resample_if_needed(rng);
            self.since_correction = 0.0;
        }
        self.refresh_estimate(graph);
    }

    fn estimate(&self) -> Option<RoadPosition> {
        self.estimate
    }

    fn belief_cells(&self, graph: &RoadGraph) -> Vec<(EdgeId, NodeId, f64, f64)> {
        self.particle_cells(graph).collect()
    }

    fn name(&self) -> &'static str {
        "road-mcl"
    }

    fn reset(&mut self) {
        *self = RoadMcl::new(self.config.clone());
    }
}
