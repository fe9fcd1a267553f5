//! Differential-evolution Markov-chain global localization ([Hospital thesis §3.9.2],
//! algorithm DE_MC_GL; Martín, Moreno, Garrido & Blanco, "Kullback-Leibler divergence-based
//! differential evolution Markov chain filter for global localization of mobile robots",
//! Sensors 15 (2015); the sampler is ter Braak's DE-MC, Statistics and Computing 16 (2006)).
//!
//! Every member of the population is a Markov chain over poses, started uniformly over free
//! space (or around a given pose). An iteration proposes for every chain
//! `x* = x_i + F(x_r1 − x_r2) + e` (eq. 18, e ~ N(0, diag(noise_sd²))) and accepts it with the
//! Metropolis rule on the fitness difference: the target density is exp(−m·cost/T), m the number
//! of beams and cost the mean L1 (or L2) range error, so `x*` replaces `x_i` when
//! ln u < −m·(cost(x*) − cost(x_i))/T. (The printed pseudo-code compares `rlog < log u` with
//! rlog = fitness(x*) − fitness(x_i) for a cost to be minimised, which accepts the worse
//! proposals; the Metropolis rule is what the cited paper means.) Between scans the chains move
//! by odometry; the estimate is the best member (refined locally and moved without noise, as in
//! [`super::de_filter`]); the filter is converged when the best cost has stayed low. The Kullback-Leibler-based sizing of the population in \[20\] is not
//! implemented: the population is fixed.

use super::de_population::{RangeMetric, range_costs, three_others};
use super::de_tracker::{CycleSettings, DeTracker};
use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::mcl::{BeamSubset, InitialBelief, PoseEstimate};
use super::motion_model::OdometryMotionModel;
use crate::core::{Pose2, SimRng, wrap_angle};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

#[derive(Clone, Debug, PartialEq)]
pub struct DeMcConfig {
    pub population: usize,
    /// Chain iterations per update before convergence, and after it.
    pub iterations: usize,
    pub tracking_iterations: usize,
    /// DE-MC's jump factor (ter Braak's 2.38/√(2d) ≈ 0.97 for d = 3).
    pub f: f64,
    /// Standard deviations of the jitter e (m, m, rad).
    pub noise_sd: [f64; 3],
    /// Temperature T of the target density (m for L1, m² for L2).
    pub temperature: f64,
    pub metric: RangeMetric,
    pub max_beams: usize,
    pub motion: OdometryMotionModel,
    pub update_min_d: f64,
    pub update_min_a: f64,
    pub init: InitialBelief,
    /// Converged once the best member's cost has stayed at or below `converge_cost` (mean range
    /// error: m for L1, m² for L2) for `converge_updates` updates; lost again once it has
    /// stayed above twice that for as many.
    pub converge_cost: f64,
    pub converge_updates: u32,
    /// Local refinement of the best member at each update (`Population::refine_best`):
    /// rounds, samples per round, initial spread (m, m, rad); 0 rounds disables it.
    pub refine_rounds: usize,
    pub refine_samples: usize,
    pub refine_sd: [f64; 3],
    /// While the filter searches (not converged), the worst members are replaced at every
    /// update by poses drawn from the scan, as Mixture MCL's dual proposal does
    /// ([`super::mcl::injection`]): this many candidates per round (0: off, the thesis's
    /// filter). Together with the weighing of look-alike places over several scans
    /// ([`super::de_places`]) it puts the true place among the chains from the first scans.
    pub injection_candidates: usize,
}

impl Default for DeMcConfig {
    fn default() -> Self {
        DeMcConfig {
            population: 1000,
            iterations: 10,
            tracking_iterations: 3,
            f: 0.97,
            noise_sd: [0.02, 0.02, 0.01],
            temperature: 0.5,
            metric: RangeMetric::L1,
            max_beams: 60,
            motion: OdometryMotionModel::default(),
            update_min_d: 0.2,
            update_min_a: std::f64::consts::PI / 6.0,
            init: InitialBelief::Global,
            converge_cost: 0.1,
            converge_updates: 3,
            refine_rounds: 4,
            refine_samples: 32,
            refine_sd: [0.2, 0.2, 0.05],
            injection_candidates: 20_000,
        }
    }
}

#[derive(Clone, Debug)]
pub struct DeMc {
    pub config: DeMcConfig,
    /// Population (the chains' current states), convergence state and estimate.
    pub tracker: DeTracker,
    /// Accepted proposals / proposals, over the last update.
    pub acceptance: f64,
}

impl DeMc {
    pub fn new(config: DeMcConfig, map: &LocalizationMap, rng: SimRng) -> Self {
        DeMc {
            tracker: DeTracker::new(config.population, &config.init, map, rng),
            config,
            acceptance: 0.0,
        }
    }

    pub fn estimate(&self) -> Option<PoseEstimate> {
        self.tracker.estimate
    }

    /// Consumes a scan taken at odometry pose `odom`. Returns true if the filter updated.
    pub fn update(&mut self, map: &LocalizationMap, beams: &BeamSubset, odom: &Pose2) -> bool {
        MapLocalizer::predict(self, odom) && MapLocalizer::correct(self, map, beams)
    }
}

impl DeMcConfig {
    /// The settings of the cycle shared with the other DE localizer.
    fn cycle(&self) -> CycleSettings<'_> {
        CycleSettings {
            motion: &self.motion,
            update_min_d: self.update_min_d,
            update_min_a: self.update_min_a,
            metric: self.metric,
            converge_cost: self.converge_cost,
            converge_updates: self.converge_updates,
            refine_rounds: self.refine_rounds,
            refine_samples: self.refine_samples,
            refine_sd: self.refine_sd,
            reseed: self.population,
            injection_candidates: self.injection_candidates,
            temperature: self.temperature,
        }
    }
}

/// The shared cycle split in two ([`DeTracker::predict`], [`DeTracker::correct`]).
impl MapLocalizer for DeMc {
    fn kind(&self) -> &'static str {
        "de_mc"
    }

    fn max_beams(&self) -> usize {
        self.config.max_beams
    }

    fn due(&self, odom: &Pose2) -> bool {
        self.tracker.due(odom, &self.config.cycle())
    }

    fn predict(&mut self, odom: &Pose2) -> bool {
        self.tracker.predict(odom, &self.config.cycle())
    }

    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool {
        let c = &self.config;
        let settings = c.cycle();
        let acceptance = &mut self.acceptance;
        self.tracker.correct(map, beams, &settings, |t, converged| {
            let iters = if converged {
                c.tracking_iterations
            } else {
                c.iterations
            };
            let accepted: usize = (0..iters).map(|_| iterate(t, c, map, beams)).sum();
            *acceptance = accepted as f64 / (iters * t.population.len()).max(1) as f64;
        })
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.tracker.estimate
    }

    fn box_clone(&self) -> Box<dyn MapLocalizer> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// One DE-MC iteration over all chains; returns the number of accepted proposals.
fn iterate(t: &mut DeTracker, c: &DeMcConfig, map: &LocalizationMap, beams: &BeamSubset) -> usize {
    let pop = &mut t.population;
    let n = pop.len();
    if n < 4 {
        return 0;
    }
    let mut proposals = Vec::with_capacity(n);
    for i in 0..n {
        let x = pop.poses[i];
        let [r1, r2, _] = three_others(&mut t.rng, n, i);
        let (a, b) = (pop.poses[r1], pop.poses[r2]);
        let mut e = [0.0; 3];
        for (k, v) in e.iter_mut().enumerate() {
            let g: f64 = StandardNormal.sample(&mut t.rng);
            *v = c.noise_sd[k] * g;
        }
        proposals.push([
            x[0] + c.f * (a[0] - b[0]) + e[0],
            x[1] + c.f * (a[1] - b[1]) + e[1],
            wrap_angle(x[2] + c.f * wrap_angle(a[2] - b[2]) + e[2]),
        ]);
    }
    let mut costs = vec![0.0; n];
    range_costs(map, beams, c.metric, &proposals, &mut costs);
    t.evaluations += n as u64;
    let scale = beams.len() as f64 / c.temperature;
    let mut accepted = 0;
    for i in 0..n {
        let log_ratio = -scale * (costs[i] - pop.costs[i]);
        let u: f64 = t.rng.random::<f64>();
        if u.ln() < log_ratio {
            pop.poses[i] = proposals[i];
            pop.costs[i] = costs[i];
            accepted += 1;
        }
    }
    accepted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::localization::test_drive::{convergence, corridor_errors, de_motion, hospital};

    /// On the hospital map, from global initialisation the chains converge on the corridor
    /// drive and then track.
    #[test]
    fn de_mc_converges_from_global_initialisation() {
        let map = hospital();
        let mut f = DeMc::new(
            DeMcConfig {
                motion: de_motion(),
                ..DeMcConfig::default()
            },
            &map,
            stream_rng(4, "test", "demc"),
        );
        let errors = corridor_errors(|beams, odom| {
            f.update(&map, beams, odom).then(|| f.estimate().unwrap())
        });
        let (since, tracked, n) = convergence(&errors);
        let since = since.unwrap_or_else(|| panic!("never converged in {n} updates"));
        assert!(since < 40 && tracked > 0.9, "{since} {tracked}");
    }
}
