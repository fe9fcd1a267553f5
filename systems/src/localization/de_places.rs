//! The look-alike places a searching DE localizer weighs over several scans before it commits to
//! one (multiple-hypothesis tracking, [Jensfelt 2001]). The hospital's wings repeat every 27 m:
//! from a ward's corridor, one scan fits the robot's ward and its twin almost alike, and a filter
//! that followed the best member of each scan could settle on the twin and hold it for tens of
//! seconds. Here every distinct place the population finds plausible is carried by the odometry
//! and sums its cost (mean range error) over the scans since it was found; the estimate follows
//! the place of lowest sum, and the filter may declare itself converged only once that place
//! leads every other by [`SETTLED`]: several scans' evidence, or one scan that tells the places
//! apart. A place found late starts behind the best (it must earn the lead), but that start is
//! no evidence against it: the filter settles only once every other place has also trailed the
//! leader by [`SETTLED`] on the scans it was seen on, so a robot's own ward found a few scans
//! after its twin keeps the twin from settling. A place moves to a better-fitting member only as
//! far as the odometry's prior allows ([`Prior`]), as a converged filter's estimate does.
//!
//! The sums are of costs, not of log-likelihoods under a per-beam noise model: what tells
//! look-alike places apart is a few beams that see a different doorway or corridor end, and a
//! noise model fitted to the scan (a Laplace scale from the best fit, tempered as the Markov
//! grid's likelihood) rated such differences so highly that the filter settled on a twin again.

use super::de_population::{Gate, Population, RangeMetric, close, range_costs};
use super::map::LocalizationMap;
use super::mcl::BeamSubset;
use crate::core::Pose2;

/// The summed cost (m of mean range error for L1, m² for L2) by which the best place must lead
/// every other, and a newcomer's start behind it.
pub const SETTLED: f64 = 0.15;
/// A place whose sum trails the best's by more than this is dropped.
const DROP: f64 = 0.6;
/// A member starts a place if its cost is at most this multiple of the best place's.
pub const PLAUSIBLE: f64 = 1.25;
/// Places kept by their sums at most; as many again that the scans have not ruled out.
const MAX_PLACES: usize = 8;
/// Members within this distance (m) and turn (rad) of a place belong to it.
pub const RADIUS: f64 = 1.0;
pub const ANGLE: f64 = 0.3;

/// One place: its pose, its cost summed over the scans since it was found (a newcomer's
/// starting behind), and by how much its costs exceeded the leading place's over those scans.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Place {
    pose: [f64; 3],
    sum: f64,
    trail: f64,
}

/// How far a place believes the odometry that carried it: the spread of a [`Gate`]'s prior
/// (m, rad) and its cost per nat. A place moves to a member of its reach only if that member
/// fits better by more than its distance costs under this prior, so a place does not slide
/// along a corridor to whichever of many chains fitted one scan marginally better.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prior {
    pub sigma: [f64; 2],
    pub cost_per_nat: f64,
}

impl Prior {
    /// The gate of a place at `pose`.
    fn around(&self, pose: &[f64; 3]) -> Gate {
        Gate {
            centre: *pose,
            radius: RADIUS,
            angle: ANGLE,
            sigma: self.sigma,
            cost_per_nat: self.cost_per_nat,
        }
    }
}

/// The places of a searching filter, best first after [`Places::update`].
#[derive(Clone, Debug, Default)]
pub struct Places {
    places: Vec<Place>,
}

impl Places {
    /// Places held.
    pub fn len(&self) -> usize {
        self.places.len()
    }

    pub fn is_empty(&self) -> bool {
        self.places.is_empty()
    }

    /// Forgets every place (the filter converged, or searches the whole floor again).
    pub fn clear(&mut self) {
        self.places.clear();
    }

    /// Moves every place by the odometry `step` (robot frame).
    pub fn carry(&mut self, step: &Pose2) {
        for p in &mut self.places {
            let q = Pose2::new(p.pose[0], p.pose[1], p.pose[2]).compose(step);
            p.pose = [q.x, q.y, q.theta];
        }
    }

    /// Weighs the places on the scan the population was just scored on: each place moves to its
    /// best member if that fits better than its own pose under the `prior`, adds its cost to its
    /// sum, and every plausible member away from the known places starts a new one (behind the
    /// best place by [`SETTLED`] once there is one: a newcomer must earn the lead). Returns the
    /// member the estimate follows (the best place's; its pose replaces the worst member if no
    /// member is near it) and whether that place has settled: it leads every other place by
    /// [`SETTLED`] both in its sum and on the scans that place was seen on.
    pub fn update(
        &mut self,
        pop: &mut Population,
        map: &LocalizationMap,
        beams: &BeamSubset,
        metric: RangeMetric,
        prior: &Prior,
    ) -> (usize, bool) {
        if pop.is_empty() {
            return (0, false);
        }
        let own: Vec<[f64; 3]> = self.places.iter().map(|p| p.pose).collect();
        let mut own_costs = vec![0.0; own.len()];
        range_costs(map, beams, metric, &own, &mut own_costs);
        let start = self.places.iter().map(|p| p.sum).reduce(f64::min);
        let mut member: Vec<Option<usize>> = Vec::with_capacity(MAX_PLACES);
        let mut costs: Vec<f64> = Vec::with_capacity(MAX_PLACES);
        for (p, &c) in self.places.iter_mut().zip(&own_costs) {
            let gate = prior.around(&p.pose);
            match nearest_best(pop, &gate) {
                Some(i) if gate.weighed(&pop.poses[i], pop.costs[i]) < c => {
                    p.pose = pop.poses[i];
                    member.push(Some(i));
                    costs.push(pop.costs[i]);
                }
                _ => {
                    member.push(None);
                    costs.push(c);
                }
            }
        }
        // members in order of cost, each starting a place if away from every known one
        let mut order: Vec<usize> = (0..pop.len()).collect();
        order.sort_by(|&a, &b| pop.costs[a].total_cmp(&pop.costs[b]).then(a.cmp(&b)));
        let newcomer = start.map_or(0.0, |s| s + SETTLED);
        for i in order {
            let best = costs
                .iter()
                .copied()
                .reduce(f64::min)
                .unwrap_or(pop.costs[i]);
            if self.places.len() >= 2 * MAX_PLACES || pop.costs[i] > PLAUSIBLE * best {
                break;
            }
            let p = pop.poses[i];
            if self
                .places
                .iter()
                .any(|q| close(&p, &q.pose, RADIUS, ANGLE))
            {
                continue;
            }
            self.places.push(Place {
                pose: p,
                sum: newcomer,
                trail: 0.0,
            });
            member.push(Some(i));
            costs.push(pop.costs[i]);
        }
        for (p, c) in self.places.iter_mut().zip(&costs) {
            p.sum += c;
        }
        let mut ranked: Vec<usize> = (0..self.places.len()).collect();
        ranked.sort_by(|&a, &b| {
            let (pa, pb) = (&self.places[a], &self.places[b]);
            pa.sum.total_cmp(&pb.sum).then(a.cmp(&b))
        });
        let Some(&first) = ranked.first() else {
            return (pop.best(), false);
        };
        let (best_sum, best_cost) = (self.places[first].sum, costs[first]);
        for (p, c) in self.places.iter_mut().zip(&costs) {
            p.trail += c - best_cost;
        }
        // the best places by their sums, then any place followed so far that the scans it was
        // seen on have not ruled out: a burst of newcomers, which start just behind the leader,
        // must not push out a place that fits as well as the leader but trails by its own start
        let mut keep: Vec<usize> = Vec::with_capacity(2 * MAX_PLACES);
        for followed in [false, true] {
            let cap = if followed { 2 * MAX_PLACES } else { MAX_PLACES };
            for &k in &ranked {
                let p = &self.places[k];
                if keep.len() == cap || p.sum > best_sum + DROP {
                    break;
                }
                let open = !followed || (k < own.len() && p.trail < SETTLED);
                // two places that drifted together are one: the better sum stays (and a place
                // kept by the first pass is close to itself)
                if !open
                    || keep
                        .iter()
                        .any(|&q| close(&p.pose, &self.places[q].pose, RADIUS, ANGLE))
                {
                    continue;
                }
                keep.push(k);
            }
        }
        keep.sort_by_key(|&k| ranked.iter().position(|&r| r == k));
        let kept: Vec<(Place, Option<usize>, f64)> = keep
            .iter()
            .map(|&k| (self.places[k], member[k], costs[k]))
            .collect();
        self.places = kept.iter().map(|k| k.0).collect();
        // a newcomer's start behind ranks it, but only the scans it was seen on tell it apart:
        // a look-alike found late must trail on its own evidence too
        let settled = self
            .places
            .iter()
            .skip(1)
            .all(|q| q.sum - best_sum >= SETTLED && q.trail >= SETTLED);
        let Some(&(first, at, cost)) = kept.first() else {
            return (pop.best(), false);
        };
        let lead = match at {
            Some(i) => i,
            None => {
                // no member near the best place: it takes the worst member's slot
                let worst = pop.worst();
                pop.poses[worst] = first.pose;
                pop.costs[worst] = cost;
                worst
            }
        };
        (lead, settled)
    }
}

/// The best member of each distinct place whose cost is within `margin` of the best member's,
/// best first, at most eight: the members a sampling method refines before the places
/// are weighed ([`super::de_tracker`]).
pub fn modes(pop: &Population, margin: f64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..pop.len()).collect();
    order.sort_by(|&a, &b| pop.costs[a].total_cmp(&pop.costs[b]).then(a.cmp(&b)));
    let Some(&first) = order.first() else {
        return Vec::new();
    };
    let bound = pop.costs[first] + margin;
    let mut out: Vec<usize> = Vec::with_capacity(MAX_PLACES);
    for i in order {
        if out.len() == MAX_PLACES || pop.costs[i].total_cmp(&bound).is_gt() {
            break;
        }
        if out
            .iter()
            .all(|&k| !close(&pop.poses[i], &pop.poses[k], RADIUS, ANGLE))
        {
            out.push(i);
        }
    }
    out
}

/// The member of lowest cost within a place's `gate`, weighed by its prior.
fn nearest_best(pop: &Population, gate: &Gate) -> Option<usize> {
    let weighed = |i: usize| gate.weighed(&pop.poses[i], pop.costs[i]);
    (0..pop.len())
        .filter(|&i| gate.contains(&pop.poses[i]))
        .min_by(|&a, &b| weighed(a).total_cmp(&weighed(b)).then(a.cmp(&b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::localization::test_drive::{hospital, scan_at};
    use rand_distr::{Distribution, StandardNormal};

    /// Where r4 of the patrol starts, facing west along the north corridor, and the same spot of
    /// the look-alike wing 27 m west.
    const TRUTH: [f64; 3] = [61.8, 24.75, std::f64::consts::PI];
    const TWIN: [f64; 3] = [34.8, 24.75, std::f64::consts::PI];

    /// A laser five times noisier than the LMS100 (or a crowd in view).
    const NOISE: f64 = 0.06;

    /// The gate prior of the tests: a 2 cm, 0.6° spread, a cost of 0.1 worth a nat per beam.
    const PRIOR: Prior = Prior {
        sigma: [0.02, 0.01],
        cost_per_nat: 0.1 / 60.0,
    };

    /// A noisy scan from `truth`, 60 beams of it.
    fn noisy_beams(
        map: &LocalizationMap,
        truth: &Pose2,
        rng: &mut crate::core::SimRng,
    ) -> BeamSubset {
        let mut scan = scan_at(map, truth, rng);
        for r in scan.ranges.iter_mut().filter(|r| r.is_finite()) {
            let e: f64 = StandardNormal.sample(rng);
            *r += NOISE as f32 * e as f32;
        }
        BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60)
    }

    /// Drives west from r4's start with a member at the twin and, from update `found` on, one at
    /// the robot's place; returns the update after which the places settled. Whenever they are
    /// settled from then on, the estimate follows the robot's place; the twin is dropped in the
    /// end.
    fn settle_with_the_robot_found_at(found: usize) -> usize {
        let map = hospital();
        let mut rng = stream_rng(2, "test", "places");
        // until it is found, the robot's member stands where no scan fits
        let mut pop = Population {
            poses: vec![TWIN, [10.0, 14.0, 1.0], [10.0, 7.0, 0.0]],
            costs: vec![0.0; 3],
        };
        let mut places = Places::default();
        let step = Pose2::new(0.25, 0.0, 0.0);
        let mut truth = Pose2::new(TRUTH[0], TRUTH[1], TRUTH[2]);
        let mut settled_at = None;
        for k in 0..40 {
            if k > 0 {
                truth = truth.compose(&step);
                places.carry(&step);
                for p in &mut pop.poses {
                    let q = Pose2::new(p[0], p[1], p[2]).compose(&step);
                    *p = [q.x, q.y, q.theta];
                }
            }
            if k == found {
                pop.poses[1] = [truth.x, truth.y, truth.theta];
            }
            let beams = noisy_beams(&map, &truth, &mut rng);
            pop.evaluate(&map, &beams, RangeMetric::L1);
            if k == found {
                // the twin is a look-alike: it fits the scan about as well
                assert!(pop.costs[0] < PLAUSIBLE * pop.costs[1], "{:?}", pop.costs);
            }
            let (lead, settled) = places.update(&mut pop, &map, &beams, RangeMetric::L1, &PRIOR);
            assert!(places.len() <= 2, "update {k}");
            if k == found {
                assert!(places.len() == 2 && !settled);
            }
            // (alone, the twin settles before the robot's place is found)
            let settled = settled && k >= found;
            if settled && settled_at.is_none() {
                settled_at = Some(k);
            }
            if settled {
                let at = Pose2::new(pop.poses[lead][0], pop.poses[lead][1], pop.poses[lead][2]);
                assert!(at.distance(&truth) < 0.1, "update {k}: {at:?} {truth:?}");
            }
        }
        assert_eq!(places.len(), 1, "the twin is dropped once far behind");
        settled_at.expect("never settled")
    }

    /// Driving west from the start, the robot's place and its twin fit the first scans alike: the
    /// places do not settle on them, and once the scans tell them apart (after about 2.5 m) the
    /// robot's place leads by [`SETTLED`], the estimate follows it and the twin is dropped.
    #[test]
    fn look_alike_places_settle_only_once_the_scans_tell_them_apart() {
        let k = settle_with_the_robot_found_at(0);
        assert!((5..=20).contains(&k), "settled after {k} updates");
    }

    /// The robot's place found three scans after its twin starts behind it, but the twin may not
    /// settle while the two fit alike: the newcomer must trail on the scans it was seen on.
    #[test]
    fn a_look_alike_found_late_keeps_the_places_from_settling() {
        let k = settle_with_the_robot_found_at(3);
        assert!((8..=35).contains(&k), "settled after {k} updates");
    }

    /// A burst of plausible newcomers does not push out a followed place the scans have not
    /// ruled out: the robot's own place, trailing its twin by no more than its start behind.
    #[test]
    fn newcomers_do_not_push_out_a_place_already_followed() {
        let map = hospital();
        let mut rng = stream_rng(4, "test", "places");
        let truth = Pose2::new(TRUTH[0], TRUTH[1], TRUTH[2]);
        let beams = noisy_beams(&map, &truth, &mut rng);
        let mut places = Places {
            places: vec![
                Place {
                    pose: TWIN,
                    sum: 0.10,
                    trail: 0.0,
                },
                Place {
                    pose: TRUTH,
                    sum: 0.26,
                    trail: 0.0,
                },
            ],
        };
        let mut pop = Population {
            poses: vec![TRUTH],
            costs: vec![0.0],
        };
        pop.evaluate(&map, &beams, RangeMetric::L1);
        let fit = pop.costs[0];
        // members at MAX_PLACES other places, each fitting this scan well
        pop.poses = (0..MAX_PLACES)
            .map(|k| [5.0 + 3.0 * k as f64, 7.25, 0.0])
            .collect();
        pop.costs = vec![0.5 * fit; MAX_PLACES];
        places.update(&mut pop, &map, &beams, RangeMetric::L1, &PRIOR);
        assert_eq!(places.len(), MAX_PLACES + 1);
        for kept in [TWIN, TRUTH] {
            let at = |p: &Place| close(&p.pose, &kept, RADIUS, ANGLE);
            assert!(places.places.iter().any(at), "{kept:?} dropped");
        }
    }

    /// A place does not slide along the corridor to a member half a metre ahead that fits one
    /// scan marginally better; it moves to one a centimetre away that fits better.
    #[test]
    fn a_place_moves_to_a_better_member_only_as_far_as_its_prior_allows() {
        let map = hospital();
        let mut rng = stream_rng(3, "test", "places");
        let truth = Pose2::new(TRUTH[0], TRUTH[1], TRUTH[2]);
        let beams = noisy_beams(&map, &truth, &mut rng);
        let mut places = Places::default();
        let mut pop = Population {
            poses: vec![TRUTH],
            costs: vec![0.0],
        };
        pop.evaluate(&map, &beams, RangeMetric::L1);
        let own = pop.costs[0];
        places.update(&mut pop, &map, &beams, RangeMetric::L1, &PRIOR);
        let ahead = truth.compose(&Pose2::new(0.5, 0.0, 0.0));
        let near = truth.compose(&Pose2::new(0.01, 0.0, 0.0));
        let mut pop = Population {
            poses: vec![
                [ahead.x, ahead.y, ahead.theta],
                [near.x, near.y, near.theta],
            ],
            costs: vec![own - 0.004, own - 0.001],
        };
        let (lead, _) = places.update(&mut pop, &map, &beams, RangeMetric::L1, &PRIOR);
        assert_eq!(lead, 1);
        assert_eq!(places.places[0].pose, pop.poses[1]);
    }
}
