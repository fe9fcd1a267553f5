//! Scan-matching kernels shared by localization and mapping (systems/ARCHITECTURE.md, "Layers of
//! `systems`"): the differential-evolution scan matcher of the [Hospital thesis] and its fitness
//! functions, plus an improved matcher built from the same ideas.
//!
//! Entry point: [`match_scans`]`(reference, current, &MatchConfig) -> MatchResult`, which finds
//! the transform `(x, y, θ)` moving the current scan's points into the reference scan's frame.
//! Points come from [`scan_to_points`] (eq. 28). [`MatchConfig::default`] is the improved matcher
//! over ±3 m, ±180°; [`MatchConfig::thesis_program`], [`MatchConfig::thesis_figure_run`] and
//! [`MatchConfig::thesis_final_experiment`] reproduce the thesis's settings.
//!
//! Modules (one algorithm each):
//! * [`scan_points`] — scan → Cartesian points (eq. 28);
//! * [`de`] — the DE optimizer: nine strategies (eqs. 19–27), two crossovers, selection, stops;
//! * [`correlation`] — the thesis's raster cross-correlation fitness (eqs. 29, 31, 32);
//! * [`euclidean`] — the thesis's Euclidean reference fitness (§7.1) and its distance-field form;
//! * `movable`, `normals`, `orientation`, `ref_grid`, `translation_search`, `refine`,
//!   `subsample`, `improved` — the improved matcher's stages (private);
//! * `matcher` — configuration and the entry point;
//! * [`prob_grid`] — the probability occupancy grid scan-to-map matchers and SLAM maps share;
//! * [`map_pyramid`] — its multi-resolution form for Gauss-Newton matching (Hector SLAM, §IV.C);
//! * [`gauss_newton`] — Hector-style scan-to-map matching, [`match_scan`]`(pyramid, points,
//!   initial, prior, &params) -> GnResult` (Kohlbrecher et al., SSRR 2011, §IV);
//! * [`likelihood`] — an occupancy map blurred into a point-likelihood grid (Olson 2009);
//! * [`branch_bound`] — real-time correlative scan matching by branch-and-bound over
//!   precomputed max grids (Hess et al. 2016 §V, Olson 2009), the loop-closure matcher.

pub mod branch_bound;
pub mod correlation;
pub mod de;
pub mod euclidean;
pub mod gauss_newton;
pub mod likelihood;
pub mod map_pyramid;
pub mod prob_grid;
pub mod scan_points;

mod error;
mod fast_atan2;
mod improved;
mod judge;
mod matcher;
mod movable;
mod normals;
mod orientation;
mod ref_grid;
mod refine;
mod subsample;
mod translation_search;
mod visibility;

#[cfg(test)]
mod tests;

pub use branch_bound::{
    BnbMatch, BnbWindow, PrecomputedGrids, angular_step, match_bnb, match_exhaustive,
};
pub use correlation::{CorrelationFitness, RasterSpec};
pub use de::{Bounds, Crossover, DeOutcome, DeParams, StallStop, StopReason, Strategy, Vector};
pub use error::MatchError;
pub use euclidean::{EuclideanField, euclidean_brute};
pub use gauss_newton::{GaussNewtonParams, GnResult, OdometryPrior, match_scan};
pub use improved::ImprovedConfig;
pub use likelihood::likelihood_grid;
pub use map_pyramid::{
    Combine, MapPyramid, MapSample, PyramidLevel, PyramidOptions, Surfaces, UPDATE_TILE,
};
pub use matcher::{
    MatchConfig, MatchResult, Method, SearchWindow, ThesisConfig, ThesisFitness, match_scans,
    match_scans_with_rng,
};
pub use prob_grid::ProbGrid;
pub use scan_points::{laser_scan_points, scan_to_points, scan_to_points_into};
