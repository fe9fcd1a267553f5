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
//! Once the belief has gathered, it is held cell by cell only on a window of the lattice around
//! the cells the selective update scores, the rest as one background value ([`window`]).
//!
//! Like MCL, it updates only after a minimum travel or turn of the odometry. Layers (θ) are
//! scored in parallel; each layer's result depends on that layer only. The passes over the whole
//! belief ([`belief_ops`]) each tally what the next one needs (sum, peak), and the motion leaves
//! its normalisation to the correction's last pass, which also weighs the cells: an update
//! writes the belief twice and reads it twice (the runs above the selective threshold, the
//! most probable cell).

pub mod belief_ops;
pub mod correction;
mod estimate;
pub mod layout;
pub mod prediction;
pub mod refine;
mod weighing;
pub mod window;

use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::mcl::{BeamSubset, InitialBelief, LaserModelParams, PoseEstimate};
use super::motion_model::{OdometryMotionModel, moved_enough};
use crate::core::{Pose2, wrap_angle};
use correction::PaddedField;
use layout::Layout;
use prediction::SubCell;

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
            // every 1.6 cells of travel: a pass over the whole belief per update is most of
            // the filter's cost, and a scan per cell of travel converged no better
            update_min_d: 0.4,
            update_min_a: 10f64.to_radians(),
            init: InitialBelief::Global,
            selective_threshold: 1e-6,
        }
    }
}

#[derive(Clone, Debug)]
pub struct MarkovGrid {
    pub config: MarkovGridConfig,
    /// The lattice of the map's free space.
    pub whole: Layout,
    /// The lattice the belief is held on: the whole one, or a window of it ([`window`]).
    pub layout: Layout,
    /// The window's first column and row in the whole lattice.
    at: [usize; 2],
    /// Probability per cell of `layout`, θ-layer-major (k · ny + j) · nx + i; with the mass
    /// outside the window, sums to 1 after every update (between a motion and its correction,
    /// to what the motion left).
    pub belief: Vec<f32>,
    /// The mass outside the window, spread evenly over its free cells (0 without a window).
    outside: f64,
    /// Never hold the belief on a window (the plain filter the window is tested against).
    hold_whole: bool,
    /// Where the belief's mass sits within its cells ([`prediction`]).
    pub sub_cell: SubCell,
    /// Motion noise not yet blurred in: position (cells²) and heading (bins²) variance.
    pending_noise: [f64; 2],
    /// What the pass that last wrote the belief tallied.
    carried: Option<Carried>,
    scratch: Vec<f32>,
    field: Option<PaddedField>,
    /// Per θ layer, the (i, j) cells whose mean likelihood stands for the floor's in the
    /// selective update (built at the first correction).
    sample: Vec<Vec<(u32, u32)>>,
    last_odom: Option<Pose2>,
    pub updates: u64,
    pub estimate: Option<PoseEstimate>,
    /// The odometry pose of the scan `estimate` was refined on.
    estimate_odom: Option<Pose2>,
}

/// What the pass that last wrote the belief tallied, valid until the belief changes otherwise:
/// its sum with the mass outside the window (1 up to rounding after a correction, less after a
/// motion that dropped mass, which the next correction's normalisation takes back) and its
/// largest value (the selective threshold's scale).
#[derive(Clone, Copy, Debug)]
struct Carried {
    sum: f64,
    peak: f32,
}

impl MarkovGrid {
    /// What a pass that wrote the window and tallied `t` leaves.
    fn carry(&self, t: &belief_ops::Tally) -> Carried {
        Carried {
            sum: t.sum() + self.outside,
            peak: t.peak(),
        }
    }
}

/// The motion noise variance (cells², bins²) worth a blur pass over the grid: smaller ones
/// add up until they reach it, so a tracked robot's belief is not blurred at every update
/// (about every 25th at 0.25 m per update and α = 0.01).
const BLUR_VARIANCE: f64 = 0.25;

/// Cells of the belief's window ([`window`]) beyond the cells above the selective threshold, on
/// every side (2.5 m at the default 0.25 m): the window moves when they come within half of it
/// of its edge, and a motion or a blur reaching further than that half is done on the whole
/// lattice.
pub const WINDOW_MARGIN: usize = 10;

/// The factor that scales a belief summing to `total` to sum 1, if it holds mass.
fn normaliser(total: f64) -> Option<f32> {
    (total > 0.0 && total.is_finite()).then(|| (1.0 / total) as f32)
}

impl MarkovGrid {
    pub fn new(config: MarkovGridConfig, map: &LocalizationMap) -> Self {
        let layout = Layout::new(&map.grid, config.resolution, config.angular_bins);
        let mut g = MarkovGrid {
            whole: layout.clone(),
            at: [0, 0],
            outside: 0.0,
            hold_whole: false,
            belief: vec![0.0; layout.len()],
            sub_cell: SubCell::centred(&layout),
            pending_noise: [0.0; 2],
            carried: None,
            scratch: vec![0.0; layout.len()],
            sample: Vec::new(),
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
        if self.is_windowed() {
            self.layout = self.whole.clone();
            self.at = [0, 0];
            self.belief = vec![0.0; self.layout.len()];
            self.scratch = vec![0.0; self.layout.len()];
        }
        self.outside = 0.0;
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
        self.normalise_sum(self.total_mass())
    }

    /// [`MarkovGrid::normalise`] by the sum the last pass tallied, where there is one.
    fn normalise_carried(&mut self) -> bool {
        match self.carried {
            Some(c) => self.normalise_sum(c.sum),
            None => self.normalise(),
        }
    }

    /// Scales the belief, which sums to `total`, to sum 1 and keeps its tally; false if it
    /// holds no mass.
    fn normalise_sum(&mut self, total: f64) -> bool {
        self.carried = None;
        let Some(s) = normaliser(total) else {
            return false;
        };
        let mut t = belief_ops::Tally::default();
        belief_ops::scale(&mut self.belief, s, &mut t);
        self.outside *= s as f64;
        self.carried = Some(self.carry(&t));
        true
    }

    /// The selective update's threshold for a belief whose largest value is `peak`.
    fn threshold(&self, peak: f32) -> f32 {
        (self.config.selective_threshold as f32 * peak).max(f32::MIN_POSITIVE)
    }

    /// Prediction for the odometry motion `from` → `to`, the belief normalised again.
    pub fn apply_motion(&mut self, from: &Pose2, to: &Pose2) {
        self.move_belief(from, to);
        if !self.normalise_carried() {
            self.fill_uniform();
        }
    }

    /// The prediction without its normalisation, which the correction that follows it folds
    /// into its own last pass: the belief then sums to what the motion left of it (mass that
    /// left free space is dropped), and [`Carried`] holds that sum and its peak.
    fn move_belief(&mut self, from: &Pose2, to: &Pose2) {
        let d = self.config.motion.delta(from, to);
        // a window holds a motion of up to half its margin (its cells above the threshold lie
        // at least that far from its edge)
        if (d.trans / self.layout.resolution).ceil() + 1.0 > (WINDOW_MARGIN / 2) as f64 {
            self.unwindow();
        }
        let (windowed, value) = (self.is_windowed(), self.background());
        let edge = windowed.then_some(prediction::Edge {
            whole: &self.whole,
            at: self.at,
            value,
        });
        let l = &self.layout;
        let mut tally = prediction::shift(
            l,
            &d,
            &mut self.sub_cell,
            &self.belief,
            &mut self.scratch,
            edge,
        );
        std::mem::swap(&mut self.belief, &mut self.scratch);
        // a blur as wide as the grid already spreads the mass over all of it: capped there, so
        // a jump of the odometry does not ask for a kernel as long as the jump
        let cap = |n: usize| (n * n) as f64;
        let xy = (d.sd_trans.hypot(d.trans * d.sd_rot1) / l.resolution).powi(2);
        let th = (d.sd_rot1.hypot(d.sd_rot2) / l.theta_step()).powi(2);
        self.pending_noise[0] =
            (self.pending_noise[0] + xy).min(cap(self.whole.nx.max(self.whole.ny)));
        self.pending_noise[1] = (self.pending_noise[1] + th).min(cap(l.n_theta));
        // a window is blurred as if nothing lay outside it (its edge cells lose the little mass
        // the blur moves outward), unless the kernel reaches past half its margin
        let reach = |var: f64| prediction::kernel_of_variance(var).len() / 2;
        if self.is_windowed()
            && self.pending_noise[0] >= BLUR_VARIANCE
            && reach(self.pending_noise[0]) > WINDOW_MARGIN / 2
        {
            // (the blur below tallies the whole lattice again)
            self.unwindow();
        }
        if self.pending_noise[0] >= BLUR_VARIANCE {
            let k = prediction::kernel_of_variance(self.pending_noise[0]);
            prediction::blur_xy(&self.layout, &k, &mut self.belief);
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
        self.carried = Some(self.carry(&tally));
        if normaliser(tally.sum() + self.outside).is_none() {
            self.fill_uniform();
        }
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
        let points = correction::reachable(map, points);
        let best = self.weigh(map, &points, range_max);
        self.updates += 1;
        self.estimate = self.tracked_estimate(map, &points, range_max, best);
        self.estimate_odom = self.last_odom;
        true
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

    fn due(&self, odom: &Pose2) -> bool {
        self.last_odom.is_none_or(|last| {
            moved_enough(
                &last,
                odom,
                self.config.update_min_d,
                self.config.update_min_a,
            )
        })
    }

    fn predict(&mut self, odom: &Pose2) -> bool {
        if !self.due(odom) {
            return false;
        }
        if let Some(last) = self.last_odom {
            self.move_belief(&last, odom);
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
