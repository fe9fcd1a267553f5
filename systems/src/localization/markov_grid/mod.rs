//! Markov grid localization: a histogram Bayes filter over (x, y, θ) (Burgard, Fox, Hennig &
//! Schmidt, "Estimating the absolute position of a mobile robot using position probability
//! grids", AAAI 1996; Probabilistic Robotics §8.2, Table 8.1). The belief is a probability per
//! cell of a coarse lattice (default 0.25 m × 0.25 m × 10°) over the free space of the map:
//!
//! - prediction ([`prediction`]): every cell's mass moves by the odometry motion as seen from
//!   its heading, by whole cells with the fraction carried as a sub-cell offset per θ layer
//!   (no interpolation blur), then a Gaussian blur adds the motion noise of the shared
//!   odometry model (α1..α4) once it amounts to a quarter of a cell² (or bin²);
//! - correction ([`correction`]): the likelihood field on the map's distance field, every beam
//!   endpoint projected from every cell's pose (centre plus offset); log-likelihoods summed
//!   over beams, optionally tempered by `likelihood_exponent` (the beams of a scan are not
//!   independent, Thrun §6.4.3);
//! - a small uniform share (`uniform_mix`) keeps every free cell possible, so a kidnapped
//!   robot can be found again;
//! - the estimate is the most probable cell refined by the weighted mean of its 3 × 3 × 3
//!   neighbourhood, with that neighbourhood's covariance (plus the cells' own extent), then
//!   moved within about a cell to where the scan fits the map best ([`refine`]); while that
//!   agrees with the last estimate moved by the odometry, the search starts from the latter,
//!   stays within half a cell of it and weighs the scan by a Gaussian prior around it (the
//!   motion model's noise for that motion, at least a fifth of a cell and of a heading bin); the
//!   belief itself stays a histogram.
//!
//! Like MCL, it updates only after a minimum travel or turn of the odometry. Layers (θ) are
//! scored in parallel; each layer's result depends on that layer only. The passes over the whole
//! belief ([`belief_ops`]) each tally what the next one needs (sum, peak, the runs above the
//! selective threshold), so an update passes over it five times.

pub mod belief_ops;
pub mod correction;
pub mod layout;
pub mod prediction;
pub mod refine;

use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::mcl::{BeamSubset, InitialBelief, LaserModelParams, PoseEstimate};
use super::motion_model::{OdometryMotionModel, moved_enough};
use crate::core::{Pose2, wrap_angle};
use correction::PaddedField;
use layout::{Layout, Span};
use prediction::SubCell;
use rayon::prelude::*;
use std::borrow::Cow;

#[derive(Clone, Debug, PartialEq)]
pub struct MarkovGridConfig {
    /// Cell size (m).
    pub resolution: f64,
    /// θ bins over the full turn.
    pub angular_bins: usize,
    pub max_beams: usize,
    pub laser: LaserModelParams,
    pub motion: OdometryMotionModel,
    /// Exponent on the scan likelihood (1 = beams independent; default 0.3).
    pub likelihood_exponent: f64,
    /// Share of the belief spread uniformly over free space after each correction.
    pub uniform_mix: f64,
    pub update_min_d: f64,
    pub update_min_a: f64,
    pub init: InitialBelief,
    /// Selective update (Fox, Burgard & Thrun, JAIR 11 (1999), §4.2): cells whose belief is
    /// below this fraction of the most probable cell's are not scored; they are all weighted
    /// with the scan's likelihood averaged over the floor (estimated on a fixed sample of
    /// cells), which keeps the belief a density over all of the state space. 0 scores every cell.
    pub selective_threshold: f64,
}

impl Default for MarkovGridConfig {
    fn default() -> Self {
        MarkovGridConfig {
            resolution: 0.25,
            angular_bins: 36,
            max_beams: 60,
            laser: LaserModelParams {
                sigma_hit: 0.25,
                ..LaserModelParams::default()
            },
            motion: OdometryMotionModel::default(),
            // the 60 beams of a scan are far from independent (one person in front shortens a
            // dozen of them): scored as independent, one occluded scan moved the belief by
            // tens of nats and it jumped to a look-alike ward 23–36 m away [Thrun 2005, §6.4.3]
            likelihood_exponent: 0.3,
            uniform_mix: 1e-6,
            update_min_d: 0.25,
            update_min_a: 10f64.to_radians(),
            init: InitialBelief::Global,
            selective_threshold: 1e-6,
        }
    }
}

#[derive(Clone, Debug)]
pub struct MarkovGrid {
    pub config: MarkovGridConfig,
    pub layout: Layout,
    /// Probability per cell, θ-layer-major (k · ny + j) · nx + i; sums to 1.
    pub belief: Vec<f32>,
    /// Where the belief's mass sits within its cells ([`prediction`]).
    pub sub_cell: SubCell,
    /// Motion noise not yet blurred in: position (cells²) and heading (bins²) variance.
    pending_noise: [f64; 2],
    /// What the pass that last wrote the belief found that the next one needs.
    carried: Option<Carried>,
    scratch: Vec<f32>,
    tmp: Vec<f32>,
    field: Option<PaddedField>,
    /// Per θ layer, the (i, j) cells whose mean likelihood stands for the floor's in the
    /// selective update: every [`SAMPLE_STRIDE`]-th free cell.
    sample: Vec<Vec<(u32, u32)>>,
    last_odom: Option<Pose2>,
    pub updates: u64,
    pub estimate: Option<PoseEstimate>,
    /// The odometry pose of the scan `estimate` was refined on.
    estimate_odom: Option<Pose2>,
}

/// What a pass over the belief found that the next needs, valid until the belief changes
/// otherwise: its largest value (the selective threshold's scale) and, after a motion, the runs
/// at or above the threshold that gives, per layer, with their number of cells.
#[derive(Clone, Debug)]
struct Carried {
    peak: f32,
    runs: Option<(Vec<Vec<Span>>, usize)>,
}

/// The motion noise variance (cells², bins²) worth a blur pass over the grid: smaller ones
/// add up until they reach it, so a tracked robot's belief is not blurred at every update
/// (about every 25th at 0.25 m per update and α = 0.01).
const BLUR_VARIANCE: f64 = 0.25;

/// Cells between two sample cells of the selective update (about 2 000 of the hospital's
/// 0.97 million free cells × bins).
const SAMPLE_STRIDE: usize = 487;

/// The selective update's sample: every `SAMPLE_STRIDE`-th cell in (layer, span) order.
fn sample_cells(l: &Layout) -> Vec<Vec<(u32, u32)>> {
    let mut c = 0usize;
    (0..l.n_theta)
        .map(|_| {
            let mut v = Vec::new();
            for s in &l.spans {
                for i in s.i0..s.i0 + s.len {
                    if c.is_multiple_of(SAMPLE_STRIDE) {
                        v.push((i, s.j));
                    }
                    c += 1;
                }
            }
            v
        })
        .collect()
}

/// How far (cells, and θ bins) the histogram's estimate may lie from the last estimate moved by
/// the odometry for the refinement to start from the latter. Along a corridor the scan says
/// little about the position along it, and the most probable cell alternated between two
/// neighbours from one update to the next: the refinement, started from each, kept the estimate
/// a quarter of a metre ahead of the robot every other update (sim/docs/benchmarks.md,
/// "Localization that holds"). Started from the tracked pose instead, it follows the robot; a
/// histogram that moves elsewhere (a kidnapped robot, a look-alike place winning) is followed
/// as before.
const TRACKING_CELLS: f64 = 2.0;

/// The tracked refinement's prior, in cells and heading bins (5 cm and 2° at the default
/// 0.25 m and 10°): the refinement maximises the scan's likelihood times a Gaussian around the
/// last estimate moved by the odometry, so a corridor's flat likelihood along its length leaves
/// the estimate where the odometry puts it instead of where one scan's noise peaks. Without it
/// the estimate slid ahead along the hospital's corridors on single scans.
const PRIOR_CELLS: f64 = 0.2;

/// The endpoints of `points` a cell can see: finite and within the map's diagonal. Borrowed
/// when that is all of them (a scan of the map always is).
fn reachable<'a>(map: &LocalizationMap, points: &'a [[f32; 2]]) -> Cow<'a, [[f32; 2]]> {
    let g = &map.grid;
    let diagonal = (g.width as f64 * g.resolution).hypot(g.height as f64 * g.resolution);
    let ok = |p: &[f32; 2]| (p[0] as f64).hypot(p[1] as f64) <= diagonal;
    if points.iter().all(ok) {
        Cow::Borrowed(points)
    } else {
        Cow::Owned(points.iter().copied().filter(ok).collect())
    }
}

/// The runs of one θ layer: `find(cells, emit)` is called for each span of free cells (its
/// place in the layer) and reports runs within it as `emit(start, len)`.
fn layer_runs(
    l: &Layout,
    mut find: impl FnMut(std::ops::Range<usize>, &mut dyn FnMut(usize, usize)),
) -> Vec<Span> {
    let mut out = Vec::new();
    for sp in &l.spans {
        let a = sp.j as usize * l.nx + sp.i0 as usize;
        find(a..a + sp.len as usize, &mut |i, n| {
            out.push(Span {
                j: sp.j,
                i0: sp.i0 + i as u32,
                len: n as u32,
            })
        });
    }
    out
}

/// Runs per layer with their number of cells.
fn counted(runs: Vec<Vec<Span>>) -> (Vec<Vec<Span>>, usize) {
    let n = runs.iter().flatten().map(|r| r.len as usize).sum();
    (runs, n)
}

/// The factor that scales a belief summing to `total` to sum 1, if it holds mass.
fn normaliser(total: f64) -> Option<f32> {
    (total > 0.0 && total.is_finite()).then(|| (1.0 / total) as f32)
}

/// A cell centre `(x, y, heading offset, belief)` in the estimate's neighbourhood.
type WeightedCell = (f64, f64, f64, f64);

impl MarkovGrid {
    pub fn new(config: MarkovGridConfig, map: &LocalizationMap) -> Self {
        let layout = Layout::new(&map.grid, config.resolution, config.angular_bins);
        let mut g = MarkovGrid {
            belief: vec![0.0; layout.len()],
            sub_cell: SubCell::centred(&layout),
            pending_noise: [0.0; 2],
            carried: None,
            scratch: vec![0.0; layout.len()],
            tmp: Vec::new(),
            sample: sample_cells(&layout),
            layout,
            config,
            field: None,
            last_odom: None,
            updates: 0,
            estimate: None,
            estimate_odom: None,
        };
        g.initialise();
        g.estimate = g.estimate_pose();
        g
    }

    fn initialise(&mut self) {
        let l = &self.layout;
        let layer = l.layer();
        match self.config.init {
            InitialBelief::Global => {}
            InitialBelief::Gaussian { pose, sd } => {
                let sx = sd[0].max(0.5 * l.resolution);
                let sy = sd[1].max(0.5 * l.resolution);
                let st = sd[2].max(0.5 * l.theta_step());
                for k in 0..l.n_theta {
                    let dt = wrap_angle(l.theta(k) - pose.theta) / st;
                    for s in &l.spans {
                        for i in s.i0..s.i0 + s.len {
                            let (x, y) = l.centre(i as usize, s.j as usize);
                            let (dx, dy) = ((x - pose.x) / sx, (y - pose.y) / sy);
                            let e = -0.5 * (dx * dx + dy * dy + dt * dt);
                            self.belief[k * layer + s.j as usize * l.nx + i as usize] =
                                e.exp() as f32;
                        }
                    }
                }
            }
        }
        if !self.normalise() {
            self.fill_uniform();
        }
    }

    fn fill_uniform(&mut self) {
        self.carried = None;
        let l = &self.layout;
        let n = (l.free_count() * l.n_theta).max(1) as f32;
        self.belief.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..l.n_theta {
            for s in &l.spans {
                let a = k * l.layer() + s.j as usize * l.nx + s.i0 as usize;
                self.belief[a..a + s.len as usize]
                    .iter_mut()
                    .for_each(|v| *v = 1.0 / n);
            }
        }
    }

    /// Scales the belief to sum 1; false if it holds no mass.
    fn normalise(&mut self) -> bool {
        self.normalise_sum(belief_ops::sum(&self.belief))
    }

    /// Scales the belief, which sums to `total`, to sum 1 and keeps its largest value; false
    /// if it holds no mass.
    fn normalise_sum(&mut self, total: f64) -> bool {
        self.carried = None;
        let Some(s) = normaliser(total) else {
            return false;
        };
        let mut t = belief_ops::Tally::default();
        belief_ops::scale(&mut self.belief, s, &mut t);
        self.carried = Some(Carried {
            peak: t.peak(),
            runs: None,
        });
        true
    }

    /// [`MarkovGrid::normalise_sum`] for a belief tallied as `t`, finding on the way the runs
    /// the next correction scores: the scaled peak is the peak scaled (rounding keeps the
    /// order), so the threshold is known before the pass.
    fn normalise_finding_runs(&mut self, t: &belief_ops::Tally) -> bool {
        self.carried = None;
        let Some(s) = normaliser(t.sum()) else {
            return false;
        };
        let peak = t.peak() * s;
        if self.config.selective_threshold <= 0.0 {
            belief_ops::scale(&mut self.belief, s, &mut belief_ops::Tally::default());
            self.carried = Some(Carried { peak, runs: None });
            return true;
        }
        let threshold = self.threshold(peak);
        let l = &self.layout;
        // the cells outside free space hold 0, scaled or not
        let runs: Vec<Vec<Span>> = self
            .belief
            .par_chunks_mut(l.layer())
            .map(|b| {
                layer_runs(l, |cells, emit| {
                    belief_ops::scale_and_find_runs(&mut b[cells], s, threshold, emit)
                })
            })
            .collect();
        self.carried = Some(Carried {
            peak,
            runs: Some(counted(runs)),
        });
        true
    }

    /// The selective update's threshold for a belief whose largest value is `peak`.
    fn threshold(&self, peak: f32) -> f32 {
        (self.config.selective_threshold as f32 * peak).max(f32::MIN_POSITIVE)
    }

    /// Prediction for the odometry motion `from` → `to`.
    pub fn apply_motion(&mut self, from: &Pose2, to: &Pose2) {
        let d = self.config.motion.delta(from, to);
        let l = &self.layout;
        let mut tally =
            prediction::shift(l, &d, &mut self.sub_cell, &self.belief, &mut self.scratch);
        std::mem::swap(&mut self.belief, &mut self.scratch);
        // a blur as wide as the grid already spreads the mass over all of it: capped there, so
        // a jump of the odometry does not ask for a kernel as long as the jump
        let cap = |n: usize| (n * n) as f64;
        let xy = (d.sd_trans.hypot(d.trans * d.sd_rot1) / l.resolution).powi(2);
        let th = (d.sd_rot1.hypot(d.sd_rot2) / l.theta_step()).powi(2);
        self.pending_noise[0] = (self.pending_noise[0] + xy).min(cap(l.nx.max(l.ny)));
        self.pending_noise[1] = (self.pending_noise[1] + th).min(cap(l.n_theta));
        if self.pending_noise[0] >= BLUR_VARIANCE {
            let k = prediction::kernel_of_variance(self.pending_noise[0]);
            prediction::blur_xy(&self.layout, &k, &mut self.belief, &mut self.tmp);
            self.pending_noise[0] = 0.0;
            tally = belief_ops::Tally::default();
            tally.add(&self.belief);
        }
        if self.pending_noise[1] >= BLUR_VARIANCE {
            let k = prediction::kernel_of_variance(self.pending_noise[1]);
            prediction::blur_theta(&self.layout, &k, &self.belief, &mut self.scratch);
            std::mem::swap(&mut self.belief, &mut self.scratch);
            self.pending_noise[1] = 0.0;
            tally = belief_ops::Tally::default();
            tally.add(&self.belief);
        }
        if !self.normalise_finding_runs(&tally) {
            self.fill_uniform();
        }
    }

    /// Log-likelihood of the scan endpoints `points` (base frame) into the scratch buffer, for
    /// every free cell or, given `active` (per layer), for those runs only; then also for the
    /// sample cells, whose values are returned.
    fn score(
        &mut self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
        active: Option<&[Vec<Span>]>,
    ) -> Vec<f32> {
        let reach = points
            .iter()
            .map(|p| (p[0] as f64).hypot(p[1] as f64))
            .fold(0.0, f64::max);
        if self.field.as_ref().is_none_or(|f| f.reach < reach) {
            self.field = Some(PaddedField::new(&map.field, reach.max(1.0)));
        }
        let laser = self.config.laser;
        let tables: Vec<[f32; 256]> = points
            .iter()
            .map(|p| {
                let range = (p[0] as f64).hypot(p[1] as f64);
                correction::beam_table(
                    &map.field,
                    &laser,
                    range_max as f64,
                    self.layout.resolution,
                    self.layout.theta_step(),
                    range,
                )
            })
            .collect();
        let field = self.field.as_ref().expect("built above");
        let layout = &self.layout;
        let (sample, sub) = (&self.sample, &self.sub_cell);
        let sampled: Vec<Vec<f32>> = self
            .scratch
            .par_chunks_mut(layout.layer())
            .enumerate()
            .map(|(k, out)| {
                // the endpoints seen from this layer's cell poses: centre plus offset
                let (s, c) = sub.heading(layout, k).sin_cos();
                let (ox, oy) = sub.offset(layout, k);
                let offsets: Vec<isize> = points
                    .iter()
                    .map(|p| {
                        let (x, y) = (p[0] as f64, p[1] as f64);
                        field.offset(ox + c * x - s * y, oy + s * x + c * y)
                    })
                    .collect();
                let spans = active.map_or(&layout.spans[..], |a| &a[k][..]);
                for r in spans {
                    let a = r.j as usize * layout.nx + r.i0 as usize;
                    out[a..a + r.len as usize].iter_mut().for_each(|v| *v = 0.0);
                }
                correction::layer_log_likelihood(field, &tables, layout, spans, &offsets, out);
                if active.is_none() {
                    return Vec::new();
                }
                sample[k]
                    .iter()
                    .map(|&(i, j)| {
                        correction::cell_log_likelihood(
                            field, &tables, layout, &offsets, i as usize, j as usize,
                        )
                    })
                    .collect()
            })
            .collect();
        sampled.concat()
    }

    /// The runs of cells at or above `threshold`, per layer, and their number.
    fn active_runs(&self, threshold: f32) -> (Vec<Vec<Span>>, usize) {
        let l = &self.layout;
        let runs: Vec<Vec<Span>> = self
            .belief
            .par_chunks(l.layer())
            .map(|b| {
                layer_runs(l, |cells, emit| {
                    belief_ops::runs_at_or_above(&b[cells], threshold, emit)
                })
            })
            .collect();
        counted(runs)
    }

    /// Correction of the belief by a scan's endpoints (base frame, max-range readings left out).
    /// Endpoints that are not finite, or farther than the map's diagonal (outside the map seen
    /// from every cell, so they weigh every cell alike), are left out.
    pub fn apply_scan(&mut self, map: &LocalizationMap, points: &[[f32; 2]], range_max: f32) {
        self.weigh(map, points, range_max);
    }

    /// [`MarkovGrid::apply_scan`], returning where the corrected belief is largest (the first
    /// such cell) if its last pass found it.
    fn weigh(
        &mut self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
    ) -> Option<usize> {
        let points = reachable(map, points);
        let points = &points[..];
        if points.is_empty() {
            return None;
        }
        let lambda = self.config.likelihood_exponent as f32;
        // selective update only when it skips at least half of the cells
        let cells = self.layout.free_count() * self.layout.n_theta;
        let carried = self.carried.take();
        let peak = match &carried {
            Some(c) => c.peak,
            None => belief_ops::peak(&self.belief),
        };
        let threshold = self.threshold(peak);
        let selective = (self.config.selective_threshold > 0.0)
            .then(|| match carried.and_then(|c| c.runs) {
                Some(runs) => runs,
                None => self.active_runs(threshold),
            })
            .filter(|(_, n)| 2 * n < cells);
        let sampled = self.score(map, points, range_max, selective.as_ref().map(|a| &a.0[..]));
        let l = &self.layout;
        // the belief's sum after the weighing, tallied by it where it passes over every cell
        let total = match selective {
            None => {
                let best = self
                    .belief
                    .iter()
                    .zip(&self.scratch)
                    .filter(|(p, _)| **p > 0.0)
                    .map(|(_, l)| *l)
                    .fold(f32::NEG_INFINITY, f32::max);
                if best.is_finite() {
                    for (p, &l) in self.belief.iter_mut().zip(&self.scratch) {
                        if *p > 0.0 {
                            *p *= (lambda * (l - best)).exp();
                        }
                    }
                }
                belief_ops::sum(&self.belief)
            }
            Some((runs, _)) => {
                let layer = l.layer();
                let best = runs
                    .iter()
                    .enumerate()
                    .flat_map(|(k, rs)| rs.iter().map(move |r| (k, r)))
                    .flat_map(|(k, r)| {
                        let a = k * layer + r.j as usize * l.nx + r.i0 as usize;
                        self.scratch[a..a + r.len as usize].iter().copied()
                    })
                    .chain(sampled.iter().copied())
                    .fold(f32::NEG_INFINITY, f32::max);
                if best.is_finite() {
                    let floor = sampled
                        .iter()
                        .map(|&v| (lambda * (v - best)).exp() as f64)
                        .sum::<f64>()
                        / sampled.len().max(1) as f64;
                    // the cells not scored first, then the scored runs: those are the cells at
                    // or above the threshold, which the first pass leaves as they are
                    let mut all = belief_ops::Tally::default();
                    belief_ops::scale_below(&mut self.belief, threshold, floor as f32, &mut all);
                    // the sum: the tally's, with the scored cells' weighed values for their own
                    let (mut unweighed, mut weighed) = (0.0f64, 0.0f64);
                    for (k, rs) in runs.iter().enumerate() {
                        for r in rs {
                            let a = k * layer + r.j as usize * l.nx + r.i0 as usize;
                            let cells = a..a + r.len as usize;
                            for (p, &v) in self.belief[cells.clone()]
                                .iter_mut()
                                .zip(&self.scratch[cells])
                            {
                                unweighed += *p as f64;
                                *p *= (lambda * (v - best)).exp();
                                weighed += *p as f64;
                            }
                        }
                    }
                    all.sum() - unweighed + weighed
                } else {
                    belief_ops::sum(&self.belief)
                }
            }
        };
        // normalised and mixed with the uniform share in one pass over the free cells, which
        // also finds the most probable cell
        let s = match normaliser(total) {
            Some(s) => s,
            None => {
                self.fill_uniform();
                1.0
            }
        };
        let mix = self.config.uniform_mix as f32;
        let l = &self.layout;
        let u = mix / (l.free_count() * l.n_theta).max(1) as f32;
        let mut t = belief_ops::Tally::default();
        if mix > 0.0 {
            for k in 0..l.n_theta {
                for sp in &l.spans {
                    let a = k * l.layer() + sp.j as usize * l.nx + sp.i0 as usize;
                    let cells = &mut self.belief[a..a + sp.len as usize];
                    belief_ops::scale_and_mix(cells, s, 1.0 - mix, u, &mut t);
                }
            }
        } else {
            belief_ops::scale(&mut self.belief, s, &mut t);
        }
        // the most probable cell is the first holding the largest value (for positive, finite
        // values, the first maximum in total_cmp's order)
        let peak = t.peak();
        self.carried = Some(Carried { peak, runs: None });
        (peak > 0.0)
            .then(|| belief_ops::find(&self.belief, peak))
            .flatten()
    }

    /// Consumes a scan (endpoints in the base frame) taken at odometry pose `odom`. Returns true
    /// if the filter updated.
    pub fn update(
        &mut self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
        odom: &Pose2,
    ) -> bool {
        MapLocalizer::predict(self, odom) && self.correct_points(map, points, range_max)
    }

    /// The scan half of [`MarkovGrid::update`]: correction, then the estimate. Always true.
    fn correct_points(
        &mut self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
    ) -> bool {
        let points = reachable(map, points);
        let points = &points[..];
        let best = self.weigh(map, points, range_max);
        self.updates += 1;
        let carried = self.carried_estimate();
        let l = &self.layout;
        let histogram = match best {
            Some(i) => self.estimate_at(i),
            None => self.estimate_pose(),
        };
        self.estimate = histogram.map(|mut e| {
            // tracking: the last estimate moved by the odometry, where the histogram agrees
            // with it, searched within half a cell; otherwise the histogram's own estimate
            // within a cell
            let (start, reach, prior) = match carried {
                Some(prior)
                    if prior.pose.distance(&e.pose) < TRACKING_CELLS * l.resolution
                        && wrap_angle(prior.pose.theta - e.pose.theta).abs()
                            < TRACKING_CELLS * l.theta_step() =>
                {
                    (prior.pose, 0.5, Some(prior))
                }
                _ => (e.pose, 1.0, None),
            };
            e.pose = refine::refine_pose(
                map,
                &self.config.laser,
                points,
                range_max,
                start,
                reach * l.resolution,
                reach * l.theta_step(),
                prior,
            );
            e
        });
        self.estimate_odom = self.last_odom;
        true
    }

    /// The last estimate moved by the odometry since the scan it was refined on, with the
    /// spread the tracked refinement allows around it: [`PRIOR_CELLS`] of a cell and of a
    /// heading bin, widened by the motion model's noise for that motion.
    fn carried_estimate(&self) -> Option<refine::Prior> {
        let (e, from, to) = (self.estimate?, self.estimate_odom?, self.last_odom?);
        let [sd_xy, sd_theta] = self.config.motion.delta(&from, &to).end_sd();
        let l = &self.layout;
        Some(refine::Prior {
            pose: e.pose.compose(&from.between(&to)),
            sigma_xy: (PRIOR_CELLS * l.resolution).hypot(sd_xy),
            sigma_theta: (PRIOR_CELLS * l.theta_step()).hypot(sd_theta),
        })
    }

    /// The most probable cell, refined over its 3 × 3 × 3 neighbourhood.
    pub fn estimate_pose(&self) -> Option<PoseEstimate> {
        self.estimate_at(belief_ops::argmax(&self.belief)?.0)
    }

    /// Cell `best` refined over its 3 × 3 × 3 neighbourhood, if it holds mass.
    fn estimate_at(&self, best: usize) -> Option<PoseEstimate> {
        let l = &self.layout;
        if self.belief[best] <= 0.0 {
            return None;
        }
        let layer = l.layer();
        let (k0, rest) = (best / layer, best % layer);
        let (j0, i0) = (rest / l.nx, rest % l.nx);
        let mut cells = Vec::with_capacity(27);
        for dk in -1..=1isize {
            let k = (k0 as isize + dk).rem_euclid(l.n_theta as isize) as usize;
            for dj in -1..=1isize {
                for di in -1..=1isize {
                    let (i, j) = (i0 as isize + di, j0 as isize + dj);
                    if i < 0 || j < 0 || i >= l.nx as isize || j >= l.ny as isize {
                        continue;
                    }
                    let (i, j) = (i as usize, j as usize);
                    let w = self.belief[k * layer + j * l.nx + i] as f64;
                    if w > 0.0 {
                        let (x, y) = self.sub_cell.position(l, k, i, j);
                        // heading relative to the best cell's, so the mean does not wrap
                        cells.push((x, y, dk as f64 * l.theta_step(), w));
                    }
                }
            }
        }
        let total: f64 = cells.iter().map(|c| c.3).sum();
        let mean = |f: &dyn Fn(&WeightedCell) -> f64| {
            cells.iter().map(|c| c.3 * f(c)).sum::<f64>() / total
        };
        let (mx, my, mt) = (mean(&|c| c.0), mean(&|c| c.1), mean(&|c| c.2));
        let d = |c: &WeightedCell| [c.0 - mx, c.1 - my, c.2 - mt];
        let mut cov = [[0.0; 3]; 3];
        for (a, row) in cov.iter_mut().enumerate() {
            for (b, v) in row.iter_mut().enumerate() {
                *v = mean(&|c| d(c)[a] * d(c)[b]);
            }
        }
        cov[0][0] += l.resolution * l.resolution / 12.0;
        cov[1][1] += l.resolution * l.resolution / 12.0;
        cov[2][2] += l.theta_step() * l.theta_step() / 12.0;
        Some(PoseEstimate {
            pose: Pose2::new(mx, my, wrap_angle(self.sub_cell.heading(l, k0) + mt)),
            covariance: cov,
            weight: total,
        })
    }

    /// Probability mass within `radius` (m) and `angle` (rad) of a pose.
    pub fn mass_near(&self, pose: &Pose2, radius: f64, angle: f64) -> f64 {
        let l = &self.layout;
        let mut m = 0.0;
        for k in 0..l.n_theta {
            if wrap_angle(self.sub_cell.heading(l, k) - pose.theta).abs() > angle {
                continue;
            }
            for s in &l.spans {
                for i in s.i0..s.i0 + s.len {
                    let (x, y) = self.sub_cell.position(l, k, i as usize, s.j as usize);
                    if (x - pose.x).hypot(y - pose.y) <= radius {
                        m += self.belief[k * l.layer() + s.j as usize * l.nx + i as usize] as f64;
                    }
                }
            }
        }
        m
    }
}

/// [`MarkovGrid::update`] in two halves: the motion gate and prediction, then the correction by
/// the scan's returns and the estimate.
impl MapLocalizer for MarkovGrid {
    fn kind(&self) -> &'static str {
        "markov_grid"
    }

    fn max_beams(&self) -> usize {
        self.config.max_beams
    }

    fn predict(&mut self, odom: &Pose2) -> bool {
        if let Some(last) = self.last_odom {
            if !moved_enough(
                &last,
                odom,
                self.config.update_min_d,
                self.config.update_min_a,
            ) {
                return false;
            }
            self.apply_motion(&last, odom);
        }
        self.last_odom = Some(*odom);
        true
    }

    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool {
        self.correct_points(map, &beams.returns(), beams.range_max)
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn box_clone(&self) -> Box<dyn MapLocalizer> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

#[cfg(test)]
mod tests;
