//! What the two DE localizers share ([Hospital thesis §3.9]; [Moreno 2006]; [Martín 2009]): a
//! population of poses, its cost against the map — the L1 or L2 distance between the measured
//! ranges of a beam subset and the ranges ray-cast from the member's sensor pose, per beam — the
//! motion of the population by odometry between scans, and the estimate (best member, with the
//! covariance of the members around it).

use super::map::LocalizationMap;
use super::mcl::{BeamSubset, InitialBelief, PoseEstimate};
use super::motion_model::{OdometryDelta, OdometryMotionModel};
use crate::core::{Pose2, SimRng, wrap_angle};
use rand::{Rng, RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// The distance between measured and expected ranges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RangeMetric {
    /// Mean |z − ẑ| (m), Martín et al. 2009.
    L1,
    /// Mean (z − ẑ)² (m²), Moreno et al. 2006.
    L2,
}

/// Members per parallel work item.
const CHUNK: usize = 16;

/// A beam whose range differs from the expected one by more than this (m) counts as this much:
/// it saw something the map does not hold (a person, a trolley) or the pose is wrong there,
/// and either way its size says nothing more. Without the cap, the few metres by which a person
/// in front shortens a dozen beams outweighed the rest of the scan, and the best pose slid along
/// a corridor towards the person, then jumped to the corridor's mirror image (a truncated
/// M-estimator; the beam model's short and random readings [Thrun 2005, §6.3]).
pub const RANGE_OUTLIER_M: f32 = 1.0;

/// Cost of each pose `(xs[i], ys[i], ths[i])` for the scan `beams`: the mean over beams of
/// min(|z − ẑ|, c) (L1) or min((z − ẑ)², c²) (L2), c = [`RANGE_OUTLIER_M`], both ranges capped
/// at the scan's maximum. Ray casting on `map.rays`, members in parallel chunks (results do not
/// depend on threads).
pub fn range_costs(
    map: &LocalizationMap,
    beams: &BeamSubset,
    metric: RangeMetric,
    poses: &[[f64; 3]],
    out: &mut [f64],
) {
    let m = beams.len();
    if m == 0 {
        out.iter_mut().for_each(|c| *c = 0.0);
        return;
    }
    let rmax = beams.range_max;
    out.par_chunks_mut(CHUNK)
        .zip(poses.par_chunks(CHUNK))
        .for_each(|(oc, pc)| {
            // the chunk's beams in one stream, so the caster keeps its lanes full
            let batch: Vec<([f32; 2], f32)> = pc
                .iter()
                .flat_map(|p| {
                    let sensor = Pose2::new(p[0], p[1], p[2]).compose(&beams.mount);
                    let origin = [sensor.x as f32, sensor.y as f32];
                    let th = p[2] as f32;
                    beams.angles.iter().map(move |&a| (origin, th + a))
                })
                .collect();
            let mut all = vec![0.0f32; batch.len()];
            map.rays.cast_many(&batch, rmax, &mut all);
            for (o, expected) in oc.iter_mut().zip(all.chunks_exact(m)) {
                let mut sum = 0.0f64;
                for (z, zs) in beams.ranges.iter().zip(expected) {
                    let d = (z.min(rmax) - zs.min(rmax)).abs().min(RANGE_OUTLIER_M) as f64;
                    sum += match metric {
                        RangeMetric::L1 => d,
                        RangeMetric::L2 => d * d,
                    };
                }
                *o = sum / m as f64;
            }
        });
}

/// A population of poses with their costs (lower is better).
#[derive(Clone, Debug, Default)]
pub struct Population {
    pub poses: Vec<[f64; 3]>,
    pub costs: Vec<f64>,
}

impl Population {
    /// `n` members drawn from the initial belief.
    pub fn initial(
        n: usize,
        init: &InitialBelief,
        map: &LocalizationMap,
        rng: &mut SimRng,
    ) -> Self {
        let poses = (0..n.max(1))
            .map(|_| match init {
                InitialBelief::Global => {
                    let (x, y, t) = map.random_free_pose(&mut || rng.random::<f64>());
                    [x, y, t]
                }
                InitialBelief::Gaussian { pose, sd } => {
                    let mut g = || -> f64 { StandardNormal.sample(rng) };
                    [
                        pose.x + sd[0] * g(),
                        pose.y + sd[1] * g(),
                        wrap_angle(pose.theta + sd[2] * g()),
                    ]
                }
            })
            .collect::<Vec<_>>();
        let costs = vec![f64::INFINITY; poses.len()];
        Population { poses, costs }
    }

    pub fn len(&self) -> usize {
        self.poses.len()
    }

    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    /// Re-scores every member on a new scan.
    pub fn evaluate(&mut self, map: &LocalizationMap, beams: &BeamSubset, metric: RangeMetric) {
        self.costs.resize(self.poses.len(), 0.0);
        range_costs(map, beams, metric, &self.poses, &mut self.costs);
    }

    /// Moves every member by the odometry motion `d`, drawn from the motion model (Table 5.6),
    /// so the population keeps the spread the motion noise gives it — except member `best`,
    /// which moves by the noise-free motion: it is the filter's estimate, and a random kick
    /// would throw away what the last update learned.
    pub fn move_by(
        &mut self,
        model: &OdometryMotionModel,
        d: &OdometryDelta,
        best: usize,
        rng: &mut SimRng,
    ) {
        let seed = rng.next_u64();
        let mut r = SimRng::seed_from_u64(seed);
        let exact = OdometryDelta {
            sd_rot1: 0.0,
            sd_trans: 0.0,
            sd_rot2: 0.0,
            ..*d
        };
        for (i, p) in self.poses.iter_mut().enumerate() {
            let q = model.sample(
                if i == best { &exact } else { d },
                &Pose2::new(p[0], p[1], p[2]),
                &mut r,
            );
            *p = [q.x, q.y, q.theta];
        }
    }

    /// Index of the best member (lowest cost, first on ties).
    pub fn best(&self) -> usize {
        (0..self.costs.len())
            .min_by(|&a, &b| self.costs[a].total_cmp(&self.costs[b]).then(a.cmp(&b)))
            .unwrap_or(0)
    }

    /// Index of the worst member (highest cost, first on ties).
    pub fn worst(&self) -> usize {
        (0..self.costs.len())
            .max_by(|&a, &b| self.costs[a].total_cmp(&self.costs[b]).then(b.cmp(&a)))
            .unwrap_or(0)
    }

    /// The member the estimate follows: with a `gate` (a tracking filter's prediction), the
    /// member within the gate of lowest cost weighed by the gate's prior, so the estimate does
    /// not jump to a look-alike place that fits one scan as well (the filter's convergence
    /// bookkeeping lets go of the gate if the fit stays bad); otherwise the best member.
    pub fn leader(&self, gate: Option<&Gate>) -> usize {
        if let Some(g) = gate {
            let weighed = |i: usize| g.weighed(&self.poses[i], self.costs[i]);
            let inside = (0..self.len())
                .filter(|&i| close(&self.poses[i], &g.centre, g.radius, g.angle))
                .min_by(|&a, &b| weighed(a).total_cmp(&weighed(b)).then(a.cmp(&b)));
            if let Some(i) = inside {
                return i;
            }
        }
        self.best()
    }

    /// After an evolution step: the leader under `gate`; if the evolution moved every member out
    /// of the gate (a DE-MC chain accepting a jump to a look-alike place), the `elite` (pose,
    /// cost) recorded before it replaces the worst member and leads.
    pub fn keep_elite(&mut self, elite: ([f64; 3], f64), gate: Option<&Gate>) -> usize {
        let lead = self.leader(gate);
        if let Some(g) = gate
            && !close(&self.poses[lead], &g.centre, g.radius, g.angle)
            && !self.is_empty()
        {
            let worst = self.worst();
            self.poses[worst] = elite.0;
            self.costs[worst] = elite.1;
            return worst;
        }
        lead
    }

    /// Share of the members within `radius` (m) and `angle` (rad) of the best.
    pub fn share_near_best(&self, radius: f64, angle: f64) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let b = self.poses[self.best()];
        let near = self
            .poses
            .iter()
            .filter(|p| close(p, &b, radius, angle))
            .count();
        near as f64 / self.len() as f64
    }

    /// The best member with the covariance of the members within `radius` / `angle` of it
    /// (about the best), floored at `floor` (variances of x, y, θ). `weight` is their share.
    pub fn estimate(
        &self,
        leader: usize,
        radius: f64,
        angle: f64,
        floor: [f64; 3],
    ) -> Option<PoseEstimate> {
        let b = *self.poses.get(leader)?;
        let near: Vec<&[f64; 3]> = self
            .poses
            .iter()
            .filter(|p| close(p, &b, radius, angle))
            .collect();
        let mut cov = [[0.0; 3]; 3];
        for p in &near {
            let d = [p[0] - b[0], p[1] - b[1], wrap_angle(p[2] - b[2])];
            for (a, row) in cov.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v += d[a] * d[c] / near.len() as f64;
                }
            }
        }
        for (k, f) in floor.iter().enumerate() {
            cov[k][k] = cov[k][k].max(*f);
        }
        Some(PoseEstimate {
            pose: Pose2::new(b[0], b[1], b[2]),
            covariance: cov,
            weight: near.len() as f64 / self.len() as f64,
        })
    }
}

impl Population {
    /// Local refinement of the best member (our addition, as in the improved scan matcher):
    /// `rounds` rounds of `samples` Gaussian perturbations of it, the spread `sd` (m, m, rad)
    /// halving each round; the best candidate replaces it if better (weighed by the `gate`'s
    /// prior when there is one). Returns the evaluations.
    #[allow(clippy::too_many_arguments)]
    pub fn refine_best(
        &mut self,
        map: &LocalizationMap,
        beams: &BeamSubset,
        metric: RangeMetric,
        leader: usize,
        gate: Option<&Gate>,
        rounds: usize,
        samples: usize,
        sd: [f64; 3],
        rng: &mut SimRng,
    ) -> u64 {
        if leader >= self.len() || samples == 0 {
            return 0;
        }
        let b = leader;
        let mut sd = sd;
        let mut candidates = Vec::with_capacity(samples);
        let mut costs = vec![0.0; samples];
        for _ in 0..rounds {
            let x = self.poses[b];
            candidates.clear();
            for _ in 0..samples {
                let mut g = || -> f64 { StandardNormal.sample(rng) };
                candidates.push([
                    x[0] + sd[0] * g(),
                    x[1] + sd[1] * g(),
                    wrap_angle(x[2] + sd[2] * g()),
                ]);
            }
            range_costs(map, beams, metric, &candidates, &mut costs);
            let weighed = |p: &[f64; 3], cost: f64| gate.map_or(cost, |g| g.weighed(p, cost));
            let w: Vec<f64> = (0..samples)
                .map(|i| weighed(&candidates[i], costs[i]))
                .collect();
            let k = (0..samples)
                .min_by(|&i, &j| w[i].total_cmp(&w[j]).then(i.cmp(&j)))
                .unwrap_or(0);
            if w[k] < weighed(&self.poses[b], self.costs[b]) {
                self.poses[b] = candidates[k];
                self.costs[b] = costs[k];
            }
            sd = sd.map(|v| v / 2.0);
        }
        (rounds * samples) as u64
    }
}

/// Where a tracking filter expects its estimate: within `radius` (m) and `angle` (rad) of
/// `centre`, most likely near it. Within the gate a member's cost is weighed with a Gaussian
/// prior around `centre` (standard deviations `sigma`: m, rad), `cost_per_nat` of cost for each
/// unit of its negative log-density: the member the estimate follows is then the most probable
/// one given the odometry as well as the scan, not one that fits a single scan marginally better
/// farther along a corridor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gate {
    pub centre: [f64; 3],
    pub radius: f64,
    pub angle: f64,
    pub sigma: [f64; 2],
    pub cost_per_nat: f64,
}

impl Gate {
    /// Whether `p` is within the gate.
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        close(p, &self.centre, self.radius, self.angle)
    }

    /// `cost` of a member at `p` plus the prior's share.
    pub fn weighed(&self, p: &[f64; 3], cost: f64) -> f64 {
        let c = &self.centre;
        let d2 = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)) / self.sigma[0].powi(2)
            + (wrap_angle(p[2] - c[2]) / self.sigma[1]).powi(2);
        cost + self.cost_per_nat * 0.5 * d2
    }
}

/// Smallest variances of the DE estimates (5 cm, 5 cm, 1°): a lone best member says nothing
/// about its own spread.
pub const ESTIMATE_FLOOR: [f64; 3] = [0.0025, 0.0025, 3.0e-4];

/// Convergence bookkeeping of the DE localizers: returns the new (converged, streak) after an
/// update whose best cost is `best`. Converged after `updates` updates in a row at or below
/// `threshold`; lost after as many above twice the threshold.
pub fn convergence(
    converged: bool,
    streak: u32,
    best: f64,
    threshold: f64,
    updates: u32,
) -> (bool, u32) {
    let against = if converged {
        best > 2.0 * threshold
    } else {
        best <= threshold
    };
    let streak = if against { streak + 1 } else { 0 };
    if streak >= updates.max(1) {
        (!converged, 0)
    } else {
        (converged, streak)
    }
}

/// Whether `p` is within `radius` (m) and `angle` (rad) of `b`.
pub fn close(p: &[f64; 3], b: &[f64; 3], radius: f64, angle: f64) -> bool {
    (p[0] - b[0]).hypot(p[1] - b[1]) <= radius && wrap_angle(p[2] - b[2]).abs() <= angle
}

/// Three distinct indices in 0..n other than `i` (n ≥ 4).
pub fn three_others(rng: &mut impl Rng, n: usize, i: usize) -> [usize; 3] {
    let mut out = [usize::MAX; 3];
    let mut k = 0;
    while k < 3 {
        let c = rng.random_range(0..n);
        if c != i && !out[..k].contains(&c) {
            out[k] = c;
            k += 1;
        }
    }
    out
}
