//! The update cycle both DE localizers share ([`super::de_filter`], [`super::de_mc`];
//! [Hospital thesis §3.9]): move the population by odometry, score it on the new scan,
//! refine the best member locally, let the method evolve the population, keep the elite, update
//! the convergence state and the estimate; once a converged filter is lost, a fresh population
//! spread over the whole floor searches again.

use super::de_population::{ESTIMATE_FLOOR, Gate, Population, RangeMetric, convergence};
use super::map::LocalizationMap;
use super::mcl::{BeamSubset, InitialBelief, PoseEstimate};
use super::motion_model::{OdometryMotionModel, moved_enough};
use crate::core::{Pose2, SimRng};

/// The settings of the shared cycle (fields of each method's configuration).
#[derive(Clone, Copy, Debug)]
pub struct CycleSettings<'a> {
    pub motion: &'a OdometryMotionModel,
    pub update_min_d: f64,
    pub update_min_a: f64,
    pub metric: RangeMetric,
    pub converge_cost: f64,
    pub converge_updates: u32,
    pub refine_rounds: usize,
    pub refine_samples: usize,
    pub refine_sd: [f64; 3],
    /// Members of a fresh global population when the filter loses convergence (0: never).
    pub reseed: usize,
}

/// The state of a DE localizer apart from its method's own parameters.
#[derive(Clone, Debug)]
pub struct DeTracker {
    pub population: Population,
    pub converged: bool,
    /// The estimate, carried along by odometry between updates.
    tracked: Option<Pose2>,
    /// Consecutive updates on the other side of the convergence threshold.
    streak: u32,
    pub rng: SimRng,
    last_odom: Option<Pose2>,
    pub updates: u64,
    /// Cost evaluations so far.
    pub evaluations: u64,
    pub estimate: Option<PoseEstimate>,
    /// The motion model's standard deviations (m, rad) for the last motion the population made.
    step_sd: [f64; 2],
    /// The gate prior's cost per nat for the scan being scored ([`Gate::cost_per_nat`]).
    cost_per_nat: f64,
}

/// The gate prior's smallest standard deviations (1.25 cm, 0.5°): the estimate's own
/// uncertainty before the motion's is added. Narrow, so that between look-alike poses along a
/// corridor the one the odometry predicts wins unless the scan clearly prefers another.
const PRIOR_FLOOR: [f64; 2] = [0.0125, 0.0087];

impl DeTracker {
    /// `n` members drawn from the initial belief.
    pub fn new(n: usize, init: &InitialBelief, map: &LocalizationMap, mut rng: SimRng) -> Self {
        let population = Population::initial(n, init, map, &mut rng);
        DeTracker {
            population,
            converged: false,
            tracked: None,
            streak: 0,
            rng,
            last_odom: None,
            updates: 0,
            evaluations: 0,
            estimate: None,
            step_sd: [0.0; 2],
            cost_per_nat: 0.0,
        }
    }

    /// While converged, the estimate follows the best member within 1 m and 0.3 rad of where the
    /// last estimate has moved to, weighed by a prior around it as wide as [`PRIOR_FLOOR`] and
    /// the motion's noise.
    fn gate(&self) -> Option<Gate> {
        let t = self.tracked.filter(|_| self.converged)?;
        let sd = |k: usize| PRIOR_FLOOR[k].hypot(self.step_sd[k]);
        Some(Gate {
            centre: [t.x, t.y, t.theta],
            radius: 1.0,
            angle: 0.3,
            sigma: [sd(0), sd(1)],
            cost_per_nat: self.cost_per_nat,
        })
    }

    /// Consumes a scan taken at odometry pose `odom`; `evolve(tracker, converged)` runs the
    /// method's generations on the scored population. Returns true if the filter updated (the
    /// first scan, or enough motion since the last update).
    pub fn update(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
        odom: &Pose2,
        s: &CycleSettings,
        evolve: impl FnOnce(&mut DeTracker, bool),
    ) -> bool {
        self.predict(odom, s) && self.correct(map, beams, s, evolve)
    }

    /// The motion half of [`DeTracker::update`]: false (nothing changed) unless this is the first
    /// scan or the odometry has moved enough since the last update; otherwise the population
    /// moves by the odometry since then.
    pub fn predict(&mut self, odom: &Pose2, s: &CycleSettings) -> bool {
        if let Some(last) = self.last_odom {
            if !moved_enough(&last, odom, s.update_min_d, s.update_min_a) {
                return false;
            }
            let d = s.motion.delta(&last, odom);
            self.step_sd = [
                d.sd_trans.hypot(d.trans * d.sd_rot1),
                d.sd_rot1.hypot(d.sd_rot2),
            ];
            let lead = self.population.leader(self.gate().as_ref());
            self.population.move_by(s.motion, &d, lead, &mut self.rng);
            // the estimate moves with the noise-free odometry
            self.tracked = self
                .tracked
                .map(|t| t.compose(&last.inverse().compose(odom)));
        }
        self.last_odom = Some(*odom);
        true
    }

    /// The scan half of [`DeTracker::update`], after a [`DeTracker::predict`] that returned true:
    /// scoring, refinement, `evolve`, elite, convergence and estimate. Always true.
    pub fn correct(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
        s: &CycleSettings,
        evolve: impl FnOnce(&mut DeTracker, bool),
    ) -> bool {
        if beams.is_empty() {
            return true;
        }
        self.population.evaluate(map, beams, s.metric);
        self.evaluations += self.population.len() as u64;
        // a cost of `converge_cost` (a good fit's mean range error) is worth about a nat per beam
        self.cost_per_nat = s.converge_cost / beams.len() as f64;
        let gate = self.gate();
        let lead = self.population.leader(gate.as_ref());
        self.evaluations += self.population.refine_best(
            map,
            beams,
            s.metric,
            lead,
            gate.as_ref(),
            s.refine_rounds,
            s.refine_samples,
            s.refine_sd,
            &mut self.rng,
        );
        let elite = (self.population.poses[lead], self.population.costs[lead]);
        evolve(self, self.converged);
        let lead = self.population.keep_elite(elite, self.gate().as_ref());
        let was_converged = self.converged;
        (self.converged, self.streak) = convergence(
            self.converged,
            self.streak,
            self.population.costs[lead],
            s.converge_cost,
            s.converge_updates,
        );
        self.updates += 1;
        self.estimate = self.population.estimate(lead, 0.5, 0.2, ESTIMATE_FLOOR);
        self.tracked = self.estimate.map(|e| e.pose);
        if was_converged && !self.converged && s.reseed > 0 {
            // lost (kidnapped, or slid off to a look-alike place): search the whole floor
            // again, the best member kept so a false alarm costs nothing
            let best = (self.population.poses[lead], self.population.costs[lead]);
            self.population =
                Population::initial(s.reseed, &InitialBelief::Global, map, &mut self.rng);
            (self.population.poses[0], self.population.costs[0]) = best;
        }
        true
    }
}
