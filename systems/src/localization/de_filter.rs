//! The differential-evolution localization filter ([Hospital thesis §3.9.1]): Moreno,
//! Garrido & Muñoz, "Evolutionary filter for robust mobile robot global localization", RAS 54
//! (2006), with the extensions of Martín, Muñoz, Garrido, Blanco & Moreno, "L1-norm global
//! localization based on a differential evolution filter", WISP 2009.
//!
//! A population of poses, spread over free space (or around a given pose), is scored against
//! the map by the distance between the measured ranges and the ranges expected from each pose
//! (L1 or L2 over a beam subset, [`super::de_population::range_costs`]). At every update:
//!
//! 1. the population moves by the odometry since the last update (motion model samples);
//! 2. every member is re-scored on the new scan;
//! 3. a few generations of evolution: perturbation `v = x_i + L(x_best − x_i) + F(x_r2 − x_r3)`
//!    (eq. 16), crossover `u_j = v_j if p_j < δ else x_ij` (eq. 17, at least one component from
//!    v), and selection with a *rejection band*: the trial replaces the member only if its cost
//!    is lower by more than `rejection` (relative), so noise does not shuffle the population;
//! 4. *adaptive F*: when a generation does not improve the best member, F grows (×`f_growth`, up
//!    to `f_max`) to push the search out of where it stalls; an improvement resets it;
//! 5. the *discarding operator* drops the worst `discard` share of the members (down to
//!    `min_population`), which speeds convergence;
//! 6. estimate = the best member, covariance from the members around it; the filter declares
//!    itself converged when the best member's cost has stayed low for a few updates, and then
//!    runs only `tracking_generations` per update.
//!
//! Additions of ours make it work on a floor as large and repetitive as the hospital's (without
//! them the best member wanders between look-alike places, or settles on one): the best member
//! is refined locally at every update ([`Population::refine_best`]); it moves with the
//! noise-free odometry while the others draw from the motion model; while the filter searches,
//! the worst members are replaced by poses drawn from the scan (Mixture MCL's dual proposal
//! [Thrun 2001, §4], `injection_candidates`), so the true place is in the population from the
//! first scans on; while searching, the estimate follows the look-alike place that has fitted
//! best over the scans so far, and the filter converges only once that place stands out
//! ([`super::de_places`]); once converged, the member the estimate follows is chosen, and
//! refined, by its cost plus a Gaussian prior around where the odometry carried the last
//! estimate (a maximum a posteriori choice, [`super::de_population::Gate`]), so it does not slide
//! along a corridor to a pose that fits one scan marginally better; and a place outside the
//! gate that fits clearly better for several updates in a row takes the estimate over (the
//! sequential test of [`super::de_tracker`]), so a filter that settled on a look-alike wing
//! moves to the right one without searching the whole floor again.

use super::de_population::{Population, RangeMetric, range_costs, three_others};
use super::de_tracker::{CycleSettings, DeTracker};
use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::mcl::{BeamSubset, InitialBelief, PoseEstimate};
use super::motion_model::OdometryMotionModel;
use crate::core::{Pose2, SimRng, wrap_angle};
use rand::RngExt;

#[derive(Clone, Debug, PartialEq)]
pub struct DeFilterConfig {
    pub population: usize,
    pub min_population: usize,
    /// Generations per update before convergence, and after it.
    pub generations: usize,
    pub tracking_generations: usize,
    /// Weight L of the pull towards the best member.
    pub best_weight: f64,
    /// Initial mutation factor F, its growth factor and cap (adaptive F).
    pub f: f64,
    pub f_growth: f64,
    pub f_max: f64,
    /// Crossover control δ (probability of taking a component of v).
    pub cr: f64,
    /// Relative rejection band of the selection.
    pub rejection: f64,
    /// Share of the worst members discarded per update.
    pub discard: f64,
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
    /// Local refinement of the best member at each update ([`Population::refine_best`]):
    /// rounds, samples per round, initial spread (m, m, rad); 0 rounds disables it.
    pub refine_rounds: usize,
    pub refine_samples: usize,
    pub refine_sd: [f64; 3],
    /// While the filter searches (not converged), the worst members are replaced at every
    /// update by poses drawn from the scan, as Mixture MCL's dual proposal does
    /// ([`super::mcl::injection`]): this many candidates per round (0: off, the thesis's filter).
    pub injection_candidates: usize,
}

impl Default for DeFilterConfig {
    fn default() -> Self {
        DeFilterConfig {
            population: 2000,
            min_population: 100,
            // with the scan proposal in the population from the first scan, more generations
            // per update only narrowed it sooner, at times onto a look-alike place
            generations: 5,
            // once converged, the refinement of the best member and the gate do most of the
            // tracking; with one generation an estimate could slide along a corridor and stay
            // behind the robot for a second
            tracking_generations: 2,
            best_weight: 0.3,
            f: 0.5,
            f_growth: 1.2,
            f_max: 1.5,
            cr: 0.9,
            rejection: 0.01,
            discard: 0.1,
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
pub struct DeFilter {
    pub config: DeFilterConfig,
    /// Population, convergence state and estimate.
    pub tracker: DeTracker,
    /// The current (adaptive) mutation factor.
    pub f: f64,
}

impl DeFilter {
    pub fn new(config: DeFilterConfig, map: &LocalizationMap, rng: SimRng) -> Self {
        DeFilter {
            f: config.f,
            tracker: DeTracker::new(config.population, &config.init, map, rng),
            config,
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

impl DeFilterConfig {
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
            temperature: 0.0,
        }
    }
}

/// The shared cycle split in two ([`DeTracker::predict`], [`DeTracker::correct`]).
impl MapLocalizer for DeFilter {
    fn kind(&self) -> &'static str {
        "de_filter"
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
        let f = &mut self.f;
        self.tracker.correct(map, beams, &settings, |t, converged| {
            let gens = if converged {
                c.tracking_generations
            } else {
                c.generations
            };
            for _ in 0..gens {
                generation(t, c, f, map, beams);
            }
            discard(&mut t.population, c);
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

/// One generation: perturbation, crossover, evaluation of the trials, selection with the
/// rejection band, adaptation of `f`. Returns whether the best cost improved.
fn generation(
    t: &mut DeTracker,
    c: &DeFilterConfig,
    f: &mut f64,
    map: &LocalizationMap,
    beams: &BeamSubset,
) -> bool {
    let pop = &mut t.population;
    let n = pop.len();
    if n < 4 {
        return false;
    }
    let b = pop.best();
    let best_cost = pop.costs[b];
    let xb = pop.poses[b];
    let mut trials = Vec::with_capacity(n);
    for i in 0..n {
        let x = pop.poses[i];
        let [_, r2, r3] = three_others(&mut t.rng, n, i);
        let (p2, p3) = (pop.poses[r2], pop.poses[r3]);
        let v = [
            x[0] + c.best_weight * (xb[0] - x[0]) + *f * (p2[0] - p3[0]),
            x[1] + c.best_weight * (xb[1] - x[1]) + *f * (p2[1] - p3[1]),
            x[2] + c.best_weight * wrap_angle(xb[2] - x[2]) + *f * wrap_angle(p2[2] - p3[2]),
        ];
        let forced = t.rng.random_range(0..3);
        let mut u = x;
        for j in 0..3 {
            if j == forced || t.rng.random::<f64>() < c.cr {
                u[j] = v[j];
            }
        }
        u[2] = wrap_angle(u[2]);
        trials.push(u);
    }
    let mut costs = vec![0.0; n];
    range_costs(map, beams, c.metric, &trials, &mut costs);
    t.evaluations += n as u64;
    for i in 0..n {
        let old = pop.costs[i];
        if costs[i] < old - c.rejection * old.abs() {
            pop.poses[i] = trials[i];
            pop.costs[i] = costs[i];
        }
    }
    let improved = pop.costs[pop.best()] < best_cost;
    *f = if improved {
        c.f
    } else {
        (*f * c.f_growth).min(c.f_max)
    };
    improved
}

/// Drops the worst `discard` share of the members (never below `min_population`).
fn discard(pop: &mut Population, c: &DeFilterConfig) {
    let n = pop.len();
    let keep = ((n as f64 * (1.0 - c.discard)).ceil() as usize)
        .max(c.min_population)
        .min(n);
    if keep == n {
        return;
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| pop.costs[a].total_cmp(&pop.costs[b]).then(a.cmp(&b)));
    order.truncate(keep);
    order.sort_unstable();
    *pop = Population {
        poses: order.iter().map(|&i| pop.poses[i]).collect(),
        costs: order.iter().map(|&i| pop.costs[i]).collect(),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::localization::test_drive::{convergence, corridor_errors, de_motion, hospital};

    /// On the hospital map, from global initialisation the filter converges on the corridor
    /// drive and then tracks: nine in ten estimates after convergence within 10 cm.
    #[test]
    fn de_filter_converges_from_global_initialisation() {
        let map = hospital();
        let mut f = DeFilter::new(
            DeFilterConfig {
                motion: de_motion(),
                ..DeFilterConfig::default()
            },
            &map,
            stream_rng(4, "test", "de"),
        );
        let errors = corridor_errors(|beams, odom| {
            f.update(&map, beams, odom).then(|| f.estimate().unwrap())
        });
        let (since, tracked, n) = convergence(&errors);
        let since = since.unwrap_or_else(|| panic!("never converged in {n} updates"));
        // the gate's odometry prior keeps the estimate from sliding along the corridor to a pose
        // that fits one scan marginally better
        let mut after: Vec<f64> = errors[since..].iter().map(|e| e.0).collect();
        after.sort_by(f64::total_cmp);
        let p90 = after[after.len() * 9 / 10];
        assert!(
            since < 40 && tracked > 0.97 && p90 < 0.1,
            "{since} {tracked} {p90}"
        );
        let t = &f.tracker;
        assert!(t.converged && t.population.len() == f.config.min_population);
        assert!(t.evaluations < 2_000_000, "{}", t.evaluations);
    }

    /// The scan proposal puts the true place in the population from the first scans: over
    /// eight seeds the filter is within 0.2 m and 5° from its third update on (without it,
    /// from the sixth to the twentieth).
    #[test]
    fn the_scan_proposal_finds_the_robot_within_three_updates() {
        let map = hospital();
        let first: Vec<Option<usize>> = (0..8)
            .map(|seed| {
                let mut f = DeFilter::new(
                    DeFilterConfig {
                        motion: de_motion(),
                        ..DeFilterConfig::default()
                    },
                    &map,
                    stream_rng(seed, "test", "de"),
                );
                let errors = corridor_errors(|beams, odom| {
                    f.update(&map, beams, odom).then(|| f.estimate().unwrap())
                });
                convergence(&errors).0
            })
            .collect();
        assert!(first.iter().all(|s| s.is_some_and(|s| s <= 2)), "{first:?}");
    }

    /// Properties under sensor faults: the range costs of any scan from any pose are finite and
    /// non-negative, and the filter's estimate finite with a covariance.
    mod props {
        use super::*;
        use crate::core::props::{config, extreme_f64, laser_fault, range_reading};
        use crate::localization::de_population::range_costs;
        use crate::localization::props::{estimate_fault, faulted_drive, odometry_step, room};
        use crate::sensors::LaserScan;
        use proptest::prelude::*;

        fn small() -> DeFilterConfig {
            DeFilterConfig {
                population: 60,
                min_population: 20,
                generations: 3,
                tracking_generations: 1,
                refine_rounds: 2,
                refine_samples: 8,
                update_min_d: 0.0,
                update_min_a: 0.0,
                init: InitialBelief::Gaussian {
                    pose: Pose2::new(6.0, 4.0, 0.3),
                    sd: [0.3, 0.3, 0.1],
                },
                ..DeFilterConfig::default()
            }
        }

        proptest! {
            #![proptest_config(config(48))]

            #[test]
            fn range_costs_of_any_scan_from_any_pose_are_finite(
                ranges in proptest::collection::vec(range_reading(10.0), 1..60),
                poses in proptest::collection::vec(
                    (extreme_f64(), extreme_f64(), extreme_f64()), 1..20),
                l2 in any::<bool>(),
            ) {
                let map = room();
                let n = ranges.len().max(2);
                let scan = LaserScan {
                    stamp: 0.0,
                    angle_min: -2.0,
                    angle_increment: 4.0 / (n - 1) as f32,
                    range_min: 0.1,
                    range_max: 10.0,
                    ranges,
                };
                let beams = BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60);
                let poses: Vec<[f64; 3]> = poses.iter().map(|p| [p.0, p.1, p.2]).collect();
                let mut costs = vec![f64::NAN; poses.len()];
                let metric = if l2 { RangeMetric::L2 } else { RangeMetric::L1 };
                range_costs(&map, &beams, metric, &poses, &mut costs);
                prop_assert!(costs.iter().all(|c| c.is_finite() && *c >= 0.0), "{costs:?}");
            }

            #[test]
            fn the_filter_stays_finite_under_laser_faults_and_odometry_jumps(
                steps in proptest::collection::vec(
                    (proptest::option::of(laser_fault(10.0, 40)), odometry_step(0.3)),
                    1..8),
            ) {
                let map = room();
                let mut f = DeFilter::new(small(), &map, stream_rng(3, "props", "de"));
                for (odom, beams) in faulted_drive(&map, &steps) {
                    f.update(&map, &beams, &odom);
                    let pop = &f.tracker.population;
                    // +∞ marks a member not scored yet (no usable scan so far)
                    prop_assert!(pop.costs.iter().all(|c| !c.is_nan() && *c >= 0.0));
                    prop_assert!(pop.poses.iter().flatten().all(|v| v.is_finite()));
                    if let Some(e) = f.estimate() {
                        prop_assert_eq!(estimate_fault(&e), None);
                    }
                }
            }
        }
    }
}
