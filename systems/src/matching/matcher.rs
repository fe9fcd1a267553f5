//! The scan-matcher entry point: find the rigid transform `p = (p_x, p_y, ω)` that moves the
//! CURRENT scan's points into the REFERENCE scan's frame, `b ↦ R(ω) b + (p_x, p_y)`
//! ([Hospital thesis §5]: "nalézt afinní transformaci p, která nejlépe spojí testovací
//! snímek s referenčním"). If the current scan was taken at pose `P_cur` and the reference at
//! `P_ref`, the answer is `P_ref⁻¹ ⊕ P_cur` (`Pose2::between`).
//!
//! Two families:
//! * [`Method::Thesis`] — the thesis's plain DE (§5.1, §6) with its correlation fitness (eq. 29)
//!   or the Euclidean reference (§7.1, brute force or on a distance field), kept so that its
//!   experiments can be reproduced;
//! * [`Method::Improved`] — rotation hypotheses from orientation histograms, exhaustive
//!   correlative translation search, point-to-line refinement and a DE fallback
//!   ([`super::improved`]).

use super::correlation::{CorrelationFitness, RasterSpec};
use super::de::{self, Bounds, DeParams, Vector};
use super::error::MatchError;
use super::euclidean::{EuclideanField, euclidean_brute};
use super::improved::{ImprovedConfig, match_improved};
use crate::core::{Pose2, SimRng};
use rand::SeedableRng;
use std::time::{Duration, Instant};

/// Where the transform is searched: `|p_x|, |p_y| ≤ max_xy`, `|ω| ≤ max_theta`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchWindow {
    /// Metres.
    pub max_xy: f64,
    /// Radians; π (or more) means the full circle.
    pub max_theta: f64,
}

impl Default for SearchWindow {
    /// ±3 m, ±180°.
    fn default() -> Self {
        SearchWindow {
            max_xy: 3.0,
            max_theta: std::f64::consts::PI,
        }
    }
}

impl SearchWindow {
    pub fn bounds(&self) -> Bounds {
        Bounds::window(self.max_xy, self.max_theta.min(std::f64::consts::PI))
    }

    fn validate(&self) -> Result<(), MatchError> {
        if !(self.max_xy.is_finite() && self.max_xy >= 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "window.max_xy",
                value: self.max_xy,
                expected: "a finite distance >= 0 m",
            });
        }
        if !(self.max_theta.is_finite() && self.max_theta >= 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "window.max_theta",
                value: self.max_theta,
                expected: "a finite angle >= 0 rad",
            });
        }
        Ok(())
    }
}

/// The fitness of the thesis's DE.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThesisFitness {
    /// Raster cross-correlation, eq. 29 (the proposed method).
    Correlation,
    /// Sum over reference points of the minimum distance to the moved current scan, §7.1.
    EuclideanBrute,
    /// Truncated distance of the moved current points on a field of the reference
    /// ([`EuclideanField`]).
    EuclideanField,
}

/// The thesis's matcher: plain DE with one of its fitness functions.
#[derive(Clone, Debug, PartialEq)]
pub struct ThesisConfig {
    pub fitness: ThesisFitness,
    pub de: DeParams,
    /// Correlation map (default: the thesis's 100 × 100 cells over ±10 m).
    pub raster: RasterSpec,
    /// Distance-field cell (m) of [`ThesisFitness::EuclideanField`].
    pub field_cell: f32,
    /// Distance-field truncation τ (m).
    pub field_truncation: f32,
}

impl ThesisConfig {
    /// The given fitness and DE parameters, default raster (100 × 100 over ±10 m) and field
    /// (5 cm cells, τ = 0.5 m).
    pub fn new(fitness: ThesisFitness, de: DeParams) -> Self {
        ThesisConfig {
            fitness,
            de,
            raster: RasterSpec::default(),
            field_cell: 0.05,
            field_truncation: 0.5,
        }
    }
}

/// Which matcher runs.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    Thesis(ThesisConfig),
    Improved(ImprovedConfig),
}

/// Everything [`match_scans`] needs.
#[derive(Clone, Debug, PartialEq)]
pub struct MatchConfig {
    pub window: SearchWindow,
    pub method: Method,
    /// Seed of the matcher's random stream (DE); the same seed gives the same answer.
    pub seed: u64,
}

impl Default for MatchConfig {
    /// The improved matcher over ±3 m, ±180°.
    fn default() -> Self {
        MatchConfig::improved()
    }
}

impl MatchConfig {
    /// The improved matcher with default tunables, window ±3 m, ±180°.
    pub fn improved() -> Self {
        MatchConfig {
            window: SearchWindow::default(),
            method: Method::Improved(ImprovedConfig::default()),
            seed: 0,
        }
    }

    /// The thesis's DE with a given fitness and parameters, window ±3 m, ±180°.
    pub fn thesis(fitness: ThesisFitness, de: DeParams) -> Self {
        MatchConfig {
            window: SearchWindow::default(),
            method: Method::Thesis(ThesisConfig::new(fitness, de)),
            seed: 0,
        }
    }

    /// The thesis program's defaults (§6): correlation, population 100, 10 000 generations,
    /// CR 0.9, F 0.9, rand/1, binomial.
    pub fn thesis_program() -> Self {
        Self::thesis(ThesisFitness::Correlation, DeParams::thesis_program())
    }

    /// The run of the thesis's figures 9–10: as [`Self::thesis_program`] with F 0.5.
    pub fn thesis_figure_run() -> Self {
        Self::thesis(ThesisFitness::Correlation, DeParams::thesis_figure_run())
    }

    /// The thesis's final experiment (§7.2) with the given fitness (correlation, or the
    /// Euclidean reference): population 20, 5 000 generations, CR 0.9, F 0.5.
    pub fn thesis_final_experiment(fitness: ThesisFitness) -> Self {
        Self::thesis(fitness, DeParams::thesis_final_experiment())
    }

    /// The same configuration with another seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
}

/// The answer of a matcher.
#[derive(Clone, Debug, PartialEq)]
pub struct MatchResult {
    /// The transform moving current points into the reference frame.
    pub transform: Pose2,
    /// The winner's fitness. Thesis correlation: common cells (higher is better; the thesis
    /// treats < 30 as a failed alignment, §7.3). Euclidean: the minimised sum (metres, lower is
    /// better). Improved: the inlier fraction in [0, 1] of the current points within
    /// `inlier_distance` of the reference surface (higher is better).
    pub fitness: f64,
    /// Candidate transforms evaluated (DE cost evaluations; for the improved matcher also every
    /// translation-search shift and refinement iteration).
    pub evaluations: u64,
    /// Wall time of the call (informative only; never feeds back into the result).
    pub elapsed: Duration,
}

/// Matches `current` against `reference` (points in their sensor frames, in beam order) with a
/// matcher seeded from `config.seed`. Non-finite points are ignored.
pub fn match_scans(
    reference: &[[f32; 2]],
    current: &[[f32; 2]],
    config: &MatchConfig,
) -> Result<MatchResult, MatchError> {
    let mut rng = SimRng::seed_from_u64(config.seed);
    match_scans_with_rng(reference, current, config, &mut rng)
}

/// [`match_scans`] drawing from a caller's random stream (e.g. a per-entity stream) instead of
/// `config.seed`.
pub fn match_scans_with_rng(
    reference: &[[f32; 2]],
    current: &[[f32; 2]],
    config: &MatchConfig,
    rng: &mut SimRng,
) -> Result<MatchResult, MatchError> {
    let start = Instant::now();
    config.window.validate()?;
    let finite = |p: &&[f32; 2]| p[0].is_finite() && p[1].is_finite();
    let reference: Vec<[f32; 2]> = reference.iter().filter(finite).copied().collect();
    let current: Vec<[f32; 2]> = current.iter().filter(finite).copied().collect();
    if reference.is_empty() {
        return Err(MatchError::EmptyReference);
    }
    if current.is_empty() {
        return Err(MatchError::EmptyCurrent);
    }
    let bounds = config.window.bounds();
    let (transform, fitness, evaluations): (Vector, f64, u64) = match &config.method {
        Method::Thesis(t) => {
            t.de.validate()?;
            match t.fitness {
                ThesisFitness::Correlation => {
                    let f = CorrelationFitness::new(&reference, &current, t.raster)?;
                    let out = de::minimize(&|p: &Vector| f.cost(p), &bounds, &t.de, &[], rng)?;
                    (out.best, -out.best_cost, out.evaluations)
                }
                ThesisFitness::EuclideanBrute => {
                    let cost = |p: &Vector| euclidean_brute(&reference, &current, p);
                    let out = de::minimize(&cost, &bounds, &t.de, &[], rng)?;
                    (out.best, out.best_cost, out.evaluations)
                }
                ThesisFitness::EuclideanField => {
                    let field = EuclideanField::new(&reference, t.field_cell, t.field_truncation)?;
                    let cost = |p: &Vector| field.sum(&current, p);
                    let out = de::minimize(&cost, &bounds, &t.de, &[], rng)?;
                    (out.best, out.best_cost, out.evaluations)
                }
            }
        }
        Method::Improved(cfg) => {
            let out = match_improved(&reference, &current, &bounds, cfg, rng)?;
            (out.transform, out.inliers, out.evaluations)
        }
    };
    Ok(MatchResult {
        transform: Pose2::new(transform[0], transform[1], transform[2]),
        fitness,
        evaluations,
        elapsed: start.elapsed(),
    })
}
