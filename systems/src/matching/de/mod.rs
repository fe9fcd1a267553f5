//! Differential evolution (Storn & Price 1995) over 3-D vectors `(x, y, θ)` in a box, as
//! [Hospital thesis §5.1] describes it and its C++ program (§6) runs it:
//!
//! * initial generation `P₀`: `NP` members drawn uniformly in the box (§6 "inicializace");
//! * for every member `xᵢ` a mutant `u` by one of the nine strategies, eqs. 19–27 (below), then a
//!   trial `y` by binomial or exponential crossover of `u` with `xᵢ`;
//! * selection: `y` replaces `xᵢ` if `f(y) ≤ f(xᵢ)` — "trial replaces member if not worse", the
//!   §5.1 pseudo-code `if f(y) ≤ f(xᵢ)`; `f` is minimised;
//! * generation-synchronous: all trials of generation g are built from `P_g` (the pseudo-code's
//!   `Q_g = P_g`), and `x_best` is the best member of `P_g`.
//!
//! Mutation strategies (`r1 … r5` mutually distinct random members, all different from `xᵢ`):
//!
//! | strategy | mutant | thesis |
//! |---|---|---|
//! | rand/1 | `r1 + F(r2 − r3)` | eq. 19 (and eq. 30, the program's default) |
//! | rand/2 | `r1 + F(r2 − r3) + F(r4 − r5)` | eq. 20 |
//! | best/1 | `x_best + F(r1 − r2)` | eq. 21 |
//! | best/2 | `x_best + F(r1 − r2) + F(r3 − r4)` | eq. 22 |
//! | current-to-best/1 | `xᵢ + F(x_best − xᵢ) + F(r1 − r2)` | eq. 23 |
//! | current-to-best/2 | `xᵢ + F(x_best − xᵢ) + F(r1 − r2) + F(r3 − r4)` | eq. 24 |
//! | rand-to-best/1 | `r1 + F(x_best − r1) + F(r2 − r3)` | eq. 25 |
//! | rand-to-best/2 | `r1 + F(x_best − r1) + F(r2 − r3) + F(r4 − r5)` | eq. 26 (see note) |
//! | either-or | `r1 + F(r2 − r3)` if `rnd < p_F`, else `r1 + ½(F + 1)(r2 + r3 − 2 r1)` | eq. 27 |
//!
//! Notes where the thesis text is ambiguous:
//! * eq. 26 as printed reads `… + F(r2 − r3) + F(r3 − r4)`, which telescopes to `F(r2 − r4)` and
//!   would make rand-to-best/2 a rand-to-best/1; we use Storn & Price's second difference
//!   `F(r4 − r5)`.
//! * eq. 27 switches on `rnd < F`; `p_F` defaults to `F` as printed ([`DeParams::either_or_probability`]
//!   = `None`), Price's original uses a separate probability, which can be set.
//! * crossover: §5.1 (after Zelinka \[12\]) takes the mutant's component when `rnd < CR`; §6's prose
//!   says the opposite ("if the number is higher than CR the components are swapped"). We follow
//!   §5.1 and Storn & Price: binomial takes `uⱼ` when `rnd < CR` or `j = j_rand` (so at least one
//!   component comes from the mutant); exponential copies a run of components starting at a
//!   random index while `rnd < CR`. Crossover applies after every strategy, either-or included
//!   (CR = 1 gives Price's crossover-free either-or).
//! * the thesis does not say how components leaving the box are repaired: a bounded component is
//!   set half way between the member `xᵢ` and the violated bound (no extra random draws, keeps the
//!   search inside the window); θ wraps to (−π, π] when its range spans the full circle, and the
//!   differences of θ are then taken the short way round, so ±180° is one neighbourhood.
//!
//! Determinism: trials are generated serially from one [`SimRng`], a generation's trials are
//! evaluated in parallel with rayon (results collected in member order), and selection is serial,
//! so the outcome depends only on the seed, never on the thread count.
//!
//! Stopping: after `generations`, or earlier when the next generation would exceed the evaluation
//! budget, when the best cost has improved by no more than a tolerance over K generations
//! (stall), when every member lies within a tolerance of the best on every axis (collapse), or
//! when a wall-time limit is reached. The wall-time limit breaks determinism: use it only
//! outside the simulation schedule (e.g. the CLI), never inside it (systems/ARCHITECTURE.md,
//! "Determinism").

pub(super) mod strategy;

pub use strategy::Strategy;

use super::error::MatchError;
use crate::core::SimRng;
use crate::core::wrap_angle;
use rand::RngExt;
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::time::{Duration, Instant};

/// A candidate transform `(x, y, θ)`: metres, metres, radians.
pub type Vector = [f64; 3];

/// Index of the angle in a [`Vector`].
const THETA: usize = 2;

/// Crossover of the mutant with the current member (§5.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Crossover {
    Binomial,
    Exponential,
}

/// Stop when the best cost has not improved by more than `tolerance` over `generations`
/// consecutive generations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StallStop {
    pub generations: usize,
    pub tolerance: f64,
}

/// Parameters of one DE run.
#[derive(Clone, Debug, PartialEq)]
pub struct DeParams {
    /// NP, the number of members.
    pub population: usize,
    /// Maximum number of generations after the initial one.
    pub generations: usize,
    /// Mutation constant F (> 0).
    pub f: f64,
    /// Crossover rate CR in [0, 1].
    pub cr: f64,
    pub strategy: Strategy,
    pub crossover: Crossover,
    /// Probability of the difference branch of either-or; `None` = F, as eq. 27 is printed.
    pub either_or_probability: Option<f64>,
    /// Maximum number of cost evaluations, the initial population included. A generation is
    /// only started if all its NP trials fit.
    pub max_evaluations: Option<u64>,
    /// Wall-time limit, checked between generations. Breaks determinism: for use outside the
    /// simulation schedule only (CLI, experiments); inside it, budget by evaluations.
    pub time_limit: Option<Duration>,
    /// Early stop on stagnation of the best cost.
    pub stall: Option<StallStop>,
    /// Early stop when every member is within this distance of the best on every axis
    /// (metres for x, y; radians for θ).
    pub collapse_tolerance: Option<f64>,
    /// Evaluate each generation's trials on the current rayon pool (true) or serially. The
    /// result is identical either way.
    pub parallel: bool,
}

/// Largest mutation constant F: DE's range is (0, 2] (Storn and Price 1997); larger steps only
/// throw the trials out of the search box.
pub const MAX_F: f64 = 2.0;

impl DeParams {
    /// The defaults of the thesis's program (§6): population 100, 10 000 generations, CR 0.9,
    /// F 0.9, rand/1 (eq. 30), binomial crossover, no early stop.
    pub fn thesis_program() -> DeParams {
        DeParams {
            population: 100,
            generations: 10_000,
            f: 0.9,
            cr: 0.9,
            strategy: Strategy::Rand1,
            crossover: Crossover::Binomial,
            either_or_probability: None,
            max_evaluations: None,
            time_limit: None,
            stall: None,
            collapse_tolerance: None,
            parallel: true,
        }
    }

    /// The run of figures 9–10 (§6): population 100, 10 000 generations, F 0.5, CR 0.9.
    pub fn thesis_figure_run() -> DeParams {
        DeParams {
            f: 0.5,
            ..DeParams::thesis_program()
        }
    }

    /// The final experiment (§7.2): population 20, 5 000 generations, CR 0.9 and "F = 50",
    /// read as F = 0.5 (the program takes F as an integer percentage, table 1).
    pub fn thesis_final_experiment() -> DeParams {
        DeParams {
            population: 20,
            generations: 5_000,
            f: 0.5,
            ..DeParams::thesis_program()
        }
    }

    /// Checks the parameters; every problem is an error, never a panic.
    pub fn validate(&self) -> Result<(), MatchError> {
        let min = self.strategy.min_population();
        if self.population < min {
            return Err(MatchError::PopulationTooSmall {
                population: self.population,
                min,
                strategy: self.strategy,
            });
        }
        if !(self.f > 0.0 && self.f <= MAX_F) {
            return Err(MatchError::InvalidF(self.f));
        }
        if !(0.0..=1.0).contains(&self.cr) {
            return Err(MatchError::InvalidCr(self.cr));
        }
        if let Some(p) = self.either_or_probability
            && !(0.0..=1.0).contains(&p)
        {
            return Err(MatchError::InvalidParameter {
                name: "either_or_probability",
                value: p,
                expected: "a probability in [0, 1]",
            });
        }
        if let Some(b) = self.max_evaluations
            && b < self.population as u64
        {
            return Err(MatchError::BudgetTooSmall {
                budget: b,
                population: self.population,
            });
        }
        if let Some(s) = self.stall {
            if s.generations == 0 {
                return Err(MatchError::InvalidParameter {
                    name: "stall.generations",
                    value: 0.0,
                    expected: "at least 1",
                });
            }
            if !(s.tolerance.is_finite() && s.tolerance >= 0.0) {
                return Err(MatchError::InvalidParameter {
                    name: "stall.tolerance",
                    value: s.tolerance,
                    expected: "a finite value >= 0",
                });
            }
        }
        if let Some(t) = self.collapse_tolerance
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(MatchError::InvalidParameter {
                name: "collapse_tolerance",
                value: t,
                expected: "a finite value >= 0",
            });
        }
        Ok(())
    }
}

impl Default for DeParams {
    /// [`DeParams::thesis_program`].
    fn default() -> Self {
        DeParams::thesis_program()
    }
}

/// The search box. θ (axis 2) is periodic when `hi − lo ≥ 2π`: values then wrap to (−π, π] and
/// differences are taken the short way round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub lo: Vector,
    pub hi: Vector,
}

impl Bounds {
    /// `[−max_xy, max_xy]² × [−max_theta, max_theta]`.
    pub fn window(max_xy: f64, max_theta: f64) -> Bounds {
        Bounds {
            lo: [-max_xy, -max_xy, -max_theta],
            hi: [max_xy, max_xy, max_theta],
        }
    }

    /// Whether θ wraps around.
    pub fn theta_periodic(&self) -> bool {
        self.hi[THETA] - self.lo[THETA] >= TAU - 1e-9
    }

    /// Checks that every axis is finite with lo ≤ hi.
    pub fn validate(&self) -> Result<(), MatchError> {
        for axis in 0..3 {
            let (lo, hi) = (self.lo[axis], self.hi[axis]);
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(MatchError::InvalidBounds { axis, lo, hi });
            }
        }
        Ok(())
    }

    /// Whether a point lies in the box (θ always does when periodic).
    pub fn contains(&self, v: &Vector) -> bool {
        (0..3).all(|j| {
            (j == THETA && self.theta_periodic()) || (v[j] >= self.lo[j] && v[j] <= self.hi[j])
        })
    }

    /// `a − b` on one axis (short way round on a periodic θ).
    #[inline]
    fn diff(&self, periodic: bool, axis: usize, a: f64, b: f64) -> f64 {
        let d = a - b;
        if periodic && axis == THETA {
            wrap_angle(d)
        } else {
            d
        }
    }

    /// Brings a trial back into the box: wraps a periodic θ, and moves a component that left
    /// its range half way from the parent component `parent` (inside the box) to the bound.
    fn repair(&self, periodic: bool, v: &mut Vector, parent: &Vector) {
        for j in 0..3 {
            if periodic && j == THETA {
                v[j] = wrap_angle(v[j]);
            } else if v[j].is_nan() || v[j] < self.lo[j] {
                v[j] = 0.5 * (parent[j] + self.lo[j]);
            } else if v[j] > self.hi[j] {
                v[j] = 0.5 * (parent[j] + self.hi[j]);
            }
        }
    }

    /// Puts an arbitrary (seed) vector into the box: wrap or clamp.
    fn clamp(&self, periodic: bool, v: &Vector) -> Vector {
        let mut out = *v;
        for j in 0..3 {
            if periodic && j == THETA {
                out[j] = wrap_angle(if v[j].is_finite() { v[j] } else { 0.0 });
            } else if v[j].is_finite() {
                out[j] = v[j].clamp(self.lo[j], self.hi[j]);
            } else {
                out[j] = 0.5 * (self.lo[j] + self.hi[j]);
            }
        }
        out
    }
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All requested generations ran.
    Generations,
    /// The next generation would have exceeded the evaluation budget.
    Budget,
    /// The wall-time limit was reached.
    TimeLimit,
    /// The best cost stagnated ([`DeParams::stall`]).
    Stalled,
    /// The population collapsed onto the best member ([`DeParams::collapse_tolerance`]).
    Collapsed,
}

/// The result of a DE run.
#[derive(Clone, Debug, PartialEq)]
pub struct DeOutcome {
    /// The best member of the last generation.
    pub best: Vector,
    pub best_cost: f64,
    /// Cost evaluations performed, the initial population included.
    pub evaluations: u64,
    /// Generations run after the initial one.
    pub generations: usize,
    pub stop: StopReason,
    /// The last generation and its costs (member order).
    pub population: Vec<Vector>,
    pub costs: Vec<f64>,
}

/// Minimises `cost` over `bounds` by DE. `seeds` (may be empty) become the first members of the
/// initial generation, put into the box; the rest is drawn uniformly. NaN costs count as +∞.
pub fn minimize<C>(
    cost: &C,
    bounds: &Bounds,
    params: &DeParams,
    seeds: &[Vector],
    rng: &mut SimRng,
) -> Result<DeOutcome, MatchError>
where
    C: Fn(&Vector) -> f64 + Sync,
{
    params.validate()?;
    bounds.validate()?;
    let start = Instant::now();
    let np = params.population;
    let periodic = bounds.theta_periodic();

    let mut pop: Vec<Vector> = Vec::with_capacity(np);
    for s in seeds.iter().take(np) {
        pop.push(bounds.clamp(periodic, s));
    }
    while pop.len() < np {
        let v: Vector = std::array::from_fn(|j| {
            if periodic && j == THETA {
                wrap_angle(-std::f64::consts::PI + TAU * rng.random::<f64>())
            } else {
                bounds.lo[j] + (bounds.hi[j] - bounds.lo[j]) * rng.random::<f64>()
            }
        });
        pop.push(v);
    }
    let mut costs = evaluate(cost, &pop, params.parallel);
    let mut evaluations = np as u64;
    let mut best = argmin(&costs);
    let mut history = vec![costs[best]];
    let mut generations = 0;
    let mut stop = StopReason::Generations;
    let mut trials: Vec<Vector> = Vec::with_capacity(np);

    while generations < params.generations {
        if let Some(budget) = params.max_evaluations
            && evaluations + np as u64 > budget
        {
            stop = StopReason::Budget;
            break;
        }
        if let Some(limit) = params.time_limit
            && start.elapsed() >= limit
        {
            stop = StopReason::TimeLimit;
            break;
        }
        trials.clear();
        for i in 0..np {
            trials.push(make_trial(i, &pop, best, bounds, periodic, params, rng));
        }
        let trial_costs = evaluate(cost, &trials, params.parallel);
        evaluations += np as u64;
        for i in 0..np {
            if trial_costs[i] <= costs[i] {
                pop[i] = trials[i];
                costs[i] = trial_costs[i];
            }
        }
        best = argmin(&costs);
        generations += 1;
        history.push(costs[best]);

        if let Some(s) = params.stall
            && history.len() > s.generations
        {
            let before = history[history.len() - 1 - s.generations];
            if before - costs[best] <= s.tolerance {
                stop = StopReason::Stalled;
                break;
            }
        }
        if let Some(tol) = params.collapse_tolerance {
            let b = pop[best];
            let collapsed = pop
                .iter()
                .all(|m| (0..3).all(|j| bounds.diff(periodic, j, m[j], b[j]).abs() <= tol));
            if collapsed {
                stop = StopReason::Collapsed;
                break;
            }
        }
    }

    Ok(DeOutcome {
        best: pop[best],
        best_cost: costs[best],
        evaluations,
        generations,
        stop,
        population: pop,
        costs,
    })
}

/// Index of the smallest cost (the first on ties, so the choice is deterministic).
fn argmin(costs: &[f64]) -> usize {
    let mut b = 0;
    for (i, &c) in costs.iter().enumerate() {
        if c < costs[b] {
            b = i;
        }
    }
    b
}

/// Evaluates the costs of `xs` in order, in parallel or serially; NaN becomes +∞.
fn evaluate<C>(cost: &C, xs: &[Vector], parallel: bool) -> Vec<f64>
where
    C: Fn(&Vector) -> f64 + Sync,
{
    let f = |x: &Vector| {
        let c = cost(x);
        if c.is_nan() { f64::INFINITY } else { c }
    };
    if parallel {
        xs.par_iter().map(f).collect()
    } else {
        xs.iter().map(f).collect()
    }
}

/// Draws `k` mutually distinct member indices, all different from `i` (rejection sampling;
/// `np ≥ k + 1` is guaranteed by validation).
fn distinct(i: usize, np: usize, k: usize, rng: &mut SimRng) -> [usize; 5] {
    let mut r = [usize::MAX; 5];
    for n in 0..k {
        loop {
            let c = rng.random_range(0..np);
            if c != i && !r[..n].contains(&c) {
                r[n] = c;
                break;
            }
        }
    }
    r
}

/// Mutation (eqs. 19–27), crossover and repair of the trial for member `i`.
fn make_trial(
    i: usize,
    pop: &[Vector],
    best: usize,
    bounds: &Bounds,
    periodic: bool,
    params: &DeParams,
    rng: &mut SimRng,
) -> Vector {
    let np = pop.len();
    let s = params.strategy;
    let r = distinct(i, np, s.random_members(), rng);
    let f = params.f;
    let x = &pop[i];
    let xb = &pop[best];
    let m = |n: usize| &pop[r[n]];
    let d = |j: usize, a: &Vector, b: &Vector| bounds.diff(periodic, j, a[j], b[j]);
    let mut u = [0.0; 3];
    match s {
        Strategy::Rand1 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = m(0)[j] + f * d(j, m(1), m(2));
            }
        }
        Strategy::Rand2 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = m(0)[j] + f * d(j, m(1), m(2)) + f * d(j, m(3), m(4));
            }
        }
        Strategy::Best1 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = xb[j] + f * d(j, m(0), m(1));
            }
        }
        Strategy::Best2 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = xb[j] + f * d(j, m(0), m(1)) + f * d(j, m(2), m(3));
            }
        }
        Strategy::CurrentToBest1 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = x[j] + f * d(j, xb, x) + f * d(j, m(0), m(1));
            }
        }
        Strategy::CurrentToBest2 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = x[j] + f * d(j, xb, x) + f * d(j, m(0), m(1)) + f * d(j, m(2), m(3));
            }
        }
        Strategy::RandToBest1 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = m(0)[j] + f * d(j, xb, m(0)) + f * d(j, m(1), m(2));
            }
        }
        Strategy::RandToBest2 => {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = m(0)[j] + f * d(j, xb, m(0)) + f * d(j, m(1), m(2)) + f * d(j, m(3), m(4));
            }
        }
        Strategy::EitherOr => {
            let p = params.either_or_probability.unwrap_or(f);
            let difference_branch = rng.random::<f64>() < p;
            let k = 0.5 * (f + 1.0);
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = if difference_branch {
                    m(0)[j] + f * d(j, m(1), m(2))
                } else {
                    // r1 + K(r2 + r3 − 2 r1) = r1 + K((r2 − r1) + (r3 − r1))
                    m(0)[j] + k * (d(j, m(1), m(0)) + d(j, m(2), m(0)))
                };
            }
        }
    }

    let mut y = *x;
    match params.crossover {
        Crossover::Binomial => {
            let j_rand = rng.random_range(0..3);
            for j in 0..3 {
                let take = rng.random::<f64>() < params.cr;
                if take || j == j_rand {
                    y[j] = u[j];
                }
            }
        }
        Crossover::Exponential => {
            let mut j = rng.random_range(0..3);
            let mut copied = 0;
            loop {
                y[j] = u[j];
                j = (j + 1) % 3;
                copied += 1;
                if copied == 3 || rng.random::<f64>() >= params.cr {
                    break;
                }
            }
        }
    }
    bounds.repair(periodic, &mut y, x);
    y
}

#[cfg(test)]
mod tests;
