//! The update cycle both DE localizers share ([`super::de_filter`], [`super::de_mc`];
//! [Hospital thesis §3.9]): move the population by odometry, (while searching) replace the
//! worst members by poses drawn from the scan, score it on the new scan, refine the best member
//! locally, let the method evolve the population, keep the elite, (while converged) let a
//! clearly better place outside the gate challenge the estimate, (while searching) weigh the
//! look-alike places over the scans so far ([`super::de_places`]), update the convergence state
//! and the estimate; once a converged filter is lost, a fresh population spread over the whole
//! floor searches again.

use super::de_places::{ANGLE as PLACE_ANGLE, Places, Prior, RADIUS as PLACE_RADIUS, modes};
use super::de_population::{ESTIMATE_FLOOR, Gate, Population, RangeMetric, close, convergence};
use super::map::LocalizationMap;
use super::mcl::injection::scan_proposal;
use super::mcl::sensor_model::likelihood_table;
use super::mcl::{BeamSubset, InitialBelief, LaserModelParams, PoseEstimate};
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
    /// Candidates per round of the scan proposal that replaces the worst members while the
    /// filter searches (0: off).
    pub injection_candidates: usize,
    /// The temperature at which the method's members sample around the best poses of their
    /// places (DE-MC's T); 0 for a method whose selection keeps only improvements.
    pub temperature: f64,
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
    /// While converged: a place outside the gate whose best member has fitted clearly better
    /// than the leader, carried by the odometry, and for how many updates in a row.
    challenger: Option<(Pose2, u32)>,
    /// The likelihood field's lookup table for the scan proposal (scans of one range_max).
    table: Option<Box<[f32; 256]>>,
    /// While searching: the look-alike places weighed over several scans.
    places: Places,
}

/// Places whose best member is within this many chains' mean excess cost of the best member
/// are refined while a sampling method searches ([`DeTracker::refine_modes`]).
const MODE_EXCESS: f64 = 3.0;

/// A challenger must cost at most this share of the leader's cost…
const CHALLENGE_RATIO: f64 = 0.8;
/// …for this many updates in a row before the estimate moves to it.
const CHALLENGE_UPDATES: u32 = 4;

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
            challenger: None,
            table: None,
            places: Places::default(),
        }
    }

    /// While converged, the estimate follows the best member within 1 m and 0.3 rad of where the
    /// last estimate has moved to, weighed by a prior around it as wide as [`PRIOR_FLOOR`] and
    /// the motion's noise.
    fn gate(&self) -> Option<Gate> {
        let t = self.tracked.filter(|_| self.converged)?;
        let prior = self.prior();
        Some(Gate {
            centre: [t.x, t.y, t.theta],
            radius: 1.0,
            angle: 0.3,
            sigma: prior.sigma,
            cost_per_nat: prior.cost_per_nat,
        })
    }

    /// The prior around where the odometry carried a pose since the last update.
    fn prior(&self) -> Prior {
        let sd = |k: usize| PRIOR_FLOOR[k].hypot(self.step_sd[k]);
        Prior {
            sigma: [sd(0), sd(1)],
            cost_per_nat: self.cost_per_nat,
        }
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

    /// The sequential test that lets a converged filter move to a look-alike place it settled
    /// next to by mistake (the gate would otherwise hold it there until the fit turned bad and
    /// the whole floor had to be searched again): the best member outside the `gate` becomes
    /// the leader once a place there has cost at most [`CHALLENGE_RATIO`] of the leader's for
    /// [`CHALLENGE_UPDATES`] updates in a row, moving with the odometry. Returns the leader.
    fn challenge(&mut self, gate: &Gate, lead: usize) -> usize {
        let p = &self.population;
        let best = p.best();
        if gate.contains(&p.poses[best]) || p.costs[best] > CHALLENGE_RATIO * p.costs[lead] {
            self.challenger = None;
            return lead;
        }
        let b = p.poses[best];
        let near = |c: &Pose2| {
            let centre = [c.x, c.y, c.theta];
            Gate { centre, ..*gate }.contains(&b)
        };
        let wins = match self.challenger {
            Some((c, n)) if near(&c) => n + 1,
            _ => 1,
        };
        if wins >= CHALLENGE_UPDATES {
            self.challenger = None;
            best
        } else {
            self.challenger = Some((Pose2::new(b[0], b[1], b[2]), wins));
            lead
        }
    }

    /// Replaces the worst members (by their last cost) with poses drawn from the scan proposal,
    /// poses that explain the scan's endpoints on the likelihood field.
    fn inject_proposal(&mut self, map: &LocalizationMap, beams: &BeamSubset, n: usize) {
        let laser = LaserModelParams::default();
        let table = self.table.get_or_insert_with(|| {
            Box::new(likelihood_table(&map.field, &laser, beams.range_max as f64))
        });
        let pool = scan_proposal(
            map,
            &laser,
            table,
            &beams.returns(),
            beams.range_max,
            n,
            n,
            &mut self.rng,
        );
        let p = &mut self.population;
        let mut order: Vec<usize> = (0..p.len()).collect();
        order.sort_by(|&a, &b| p.costs[b].total_cmp(&p.costs[a]).then(a.cmp(&b)));
        for (&i, &(x, y, th)) in order.iter().zip(&pool) {
            p.poses[i] = [x, y, th];
        }
    }

    /// While searching with a sampling method: refines the best member of every other place
    /// within [`MODE_EXCESS`] sampling excesses of the best cost, as the leader (`lead`) was.
    /// The chains sample exp(−m·cost/T) over m beams [ter Braak 2006], near a place's minimum a
    /// Gaussian in three dimensions, so they sit on average 3T/2m above it, while the leader's
    /// refined cost sits at its minimum: unrefined, the robot's own place could never look as
    /// plausible as a refined look-alike to [`Places::update`]. Returns the evaluations.
    fn refine_modes(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
        s: &CycleSettings,
        lead: usize,
    ) -> u64 {
        let margin = MODE_EXCESS * 1.5 * s.temperature / beams.len().max(1) as f64;
        let lead_pose = self.population.poses[lead];
        let mut evaluations = 0;
        for i in modes(&self.population, margin) {
            if close(
                &self.population.poses[i],
                &lead_pose,
                PLACE_RADIUS,
                PLACE_ANGLE,
            ) {
                continue;
            }
            evaluations += self.population.refine_best(
                map,
                beams,
                s.metric,
                i,
                None,
                s.refine_rounds,
                s.refine_samples,
                s.refine_sd,
                &mut self.rng,
            );
        }
        evaluations
    }

    /// What [`DeTracker::predict`] would answer, without moving anything.
    pub fn due(&self, odom: &Pose2, s: &CycleSettings) -> bool {
        self.last_odom
            .is_none_or(|last| moved_enough(&last, odom, s.update_min_d, s.update_min_a))
    }

    /// The motion half of [`DeTracker::update`]: false (nothing changed) unless this is the first
    /// scan or the odometry has moved enough since the last update; otherwise the population
    /// moves by the odometry since then.
    pub fn predict(&mut self, odom: &Pose2, s: &CycleSettings) -> bool {
        if !self.due(odom, s) {
            return false;
        }
        if let Some(last) = self.last_odom {
            let d = s.motion.delta(&last, odom);
            self.step_sd = d.end_sd();
            let lead = self.population.leader(self.gate().as_ref());
            self.population.move_by(s.motion, &d, lead, &mut self.rng);
            // the estimate moves with the noise-free odometry
            let step = last.inverse().compose(odom);
            self.tracked = self.tracked.map(|t| t.compose(&step));
            if let Some((c, _)) = &mut self.challenger {
                *c = c.compose(&step);
            }
            self.places.carry(&step);
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
        if !self.converged && s.injection_candidates > 0 {
            self.inject_proposal(map, beams, s.injection_candidates);
        }
        self.population.evaluate(map, beams, s.metric);
        self.evaluations += self.population.len() as u64;
        // a sampling method's target density exp(−m·cost/T) says what a nat of cost is; for a
        // greedy one, a cost of `converge_cost` (a good fit's mean range error) is worth about a
        // nat per beam
        self.cost_per_nat = if s.temperature > 0.0 {
            s.temperature
        } else {
            s.converge_cost
        } / beams.len() as f64;
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
        let gate = self.gate();
        let mut lead = self.population.keep_elite(elite, gate.as_ref());
        if let Some(g) = &gate {
            lead = self.challenge(g, lead);
        }
        // while searching, the estimate follows the place that fits best over the scans so far,
        // and the filter converges only once that place stands out
        let mut settled = true;
        if !self.converged {
            if s.temperature > 0.0 {
                self.evaluations += self.refine_modes(map, beams, s, lead);
            }
            self.evaluations += self.places.len() as u64;
            let prior = self.prior();
            (lead, settled) =
                self.places
                    .update(&mut self.population, map, beams, s.metric, &prior);
        }
        let was_converged = self.converged;
        (self.converged, self.streak) = convergence(
            self.converged,
            self.streak,
            if settled {
                self.population.costs[lead]
            } else {
                f64::INFINITY
            },
            s.converge_cost,
            s.converge_updates,
        );
        self.updates += 1;
        if self.converged {
            self.places.clear();
        } else {
            self.challenger = None;
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::localization::test_drive::hospital;

    /// A converged tracker at (10, 7, 0) with one member there and one at a look-alike place
    /// 27 m east, at the given costs.
    fn converged_at(costs: [f64; 2]) -> DeTracker {
        let map = hospital();
        let mut t = DeTracker::new(2, &InitialBelief::Global, &map, stream_rng(1, "t", "de"));
        t.population = Population {
            poses: vec![[10.0, 7.0, 0.0], [37.0, 7.0, 0.0]],
            costs: costs.to_vec(),
        };
        t.converged = true;
        t.tracked = Some(Pose2::new(10.0, 7.0, 0.0));
        t
    }

    /// While a sampling method searches, the best chain at the robot's place (a few centimetres
    /// off, as chains at temperature sit) is refined like the leader at its look-alike, so the
    /// places can weigh the two alike; without a temperature there is no margin for it.
    #[test]
    fn a_sampling_method_refines_every_plausible_place_not_just_its_leader() {
        use crate::localization::de_places::PLAUSIBLE;
        use crate::localization::test_drive::scan_at;
        let map = hospital();
        let mut rng = stream_rng(5, "test", "modes");
        // r4's start facing west along the north corridor, and the look-alike 27 m west
        let truth = Pose2::new(61.8, 24.75, std::f64::consts::PI);
        let scan = scan_at(&map, &truth, &mut rng);
        let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60);
        let motion = OdometryMotionModel::default();
        let settings = |temperature: f64| CycleSettings {
            motion: &motion,
            update_min_d: 0.2,
            update_min_a: 0.5,
            metric: RangeMetric::L1,
            converge_cost: 0.1,
            converge_updates: 3,
            refine_rounds: 4,
            refine_samples: 32,
            refine_sd: [0.2, 0.2, 0.05],
            reseed: 0,
            injection_candidates: 0,
            temperature,
        };
        let refined = |temperature: f64| {
            let mut t = DeTracker::new(2, &InitialBelief::Global, &map, stream_rng(1, "t", "de"));
            let off = truth.compose(&Pose2::new(0.02, -0.02, 0.003));
            t.population = Population {
                poses: vec![[34.8, 24.75, truth.theta], [off.x, off.y, off.theta]],
                costs: vec![0.0; 2],
            };
            t.population.evaluate(&map, &beams, RangeMetric::L1);
            let before = t.population.costs.clone();
            t.refine_modes(&map, &beams, &settings(temperature), 0);
            (before, t.population.costs)
        };
        let (before, after) = refined(0.5);
        assert!(before[1] > PLAUSIBLE * before[0], "{before:?}");
        assert!(after[1] <= PLAUSIBLE * after[0], "{after:?}");
        assert_eq!(
            after[0], before[0],
            "the leader is refined by the cycle, not again"
        );
        let (_, greedy) = refined(0.0);
        assert_eq!(greedy, before);
    }

    /// The estimate moves to a place outside the gate only after that place has fitted clearly
    /// better for `CHALLENGE_UPDATES` updates in a row; a marginally better fit never moves it.
    #[test]
    fn a_converged_tracker_moves_to_a_clearly_better_place_only_after_a_run_of_wins() {
        let mut t = converged_at([0.05, 0.03]);
        for update in 1..=CHALLENGE_UPDATES {
            let gate = t.gate().expect("converged");
            let lead = t.challenge(&gate, 0);
            assert_eq!(lead == 1, update == CHALLENGE_UPDATES, "update {update}");
        }
        let mut t = converged_at([0.05, 0.045]);
        for _ in 0..3 * CHALLENGE_UPDATES {
            let gate = t.gate().expect("converged");
            assert_eq!(t.challenge(&gate, 0), 0);
        }
        // a win at another place starts the count again
        let mut t = converged_at([0.05, 0.03]);
        for _ in 1..CHALLENGE_UPDATES {
            let gate = t.gate().expect("converged");
            assert_eq!(t.challenge(&gate, 0), 0);
        }
        t.population.poses[1] = [60.0, 24.7, 3.1];
        let gate = t.gate().expect("converged");
        assert_eq!(t.challenge(&gate, 0), 0);
    }
}
