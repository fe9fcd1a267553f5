//! Errors of the scan matcher: every bad configuration or input is reported, never a panic.

use super::de::strategy::Strategy;

/// What is wrong with a matching request.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MatchError {
    #[error("the reference scan has no finite points")]
    EmptyReference,
    #[error("the current scan has no finite points")]
    EmptyCurrent,
    #[error(
        "population size {population} is too small for the {strategy} strategy: it needs at least {min}"
    )]
    PopulationTooSmall {
        population: usize,
        min: usize,
        strategy: Strategy,
    },
    #[error("the mutation constant F must be in (0, 2], got {0}")]
    InvalidF(f64),
    #[error("the crossover rate CR must be in [0, 1], got {0}")]
    InvalidCr(f64),
    #[error(
        "the evaluation budget {budget} cannot evaluate the initial population of {population}"
    )]
    BudgetTooSmall { budget: u64, population: usize },
    #[error("search bounds of axis {axis} are invalid: [{lo}, {hi}] (need finite lo <= hi)")]
    InvalidBounds { axis: usize, lo: f64, hi: f64 },
    #[error(
        "the reference scan's points span {width_m:.0} × {height_m:.0} m, more than the matcher's \
         grids of at most 64 Mi cells of {cell_m} m cover (readings far beyond the laser's real \
         range?)"
    )]
    ReferenceTooWide {
        width_m: f32,
        height_m: f32,
        cell_m: f32,
    },
    #[error("parameter `{name}` = {value} is invalid: expected {expected}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
}
