//! The improved matcher's tunables ([`ImprovedConfig`]), their defaults and their checks.

use crate::matching::de::{Crossover, DeParams, StallStop, Strategy};
use crate::matching::error::MatchError;
use crate::matching::ref_grid::MAX_INDEXED;
use crate::matching::translation_search::MAX_POINTS;

/// Tunables of the improved matcher (defaults tuned on SICK LMS100 scans in the hospital map).
#[derive(Clone, Debug, PartialEq)]
pub struct ImprovedConfig {
    /// Cell of the score grid and step of the translation search (m).
    pub coarse_cell: f32,
    /// Radius of the score kernel (m).
    pub coarse_radius: f32,
    /// Cell of the nearest-point grid of the refinement (m).
    pub fine_cell: f32,
    /// Rotation hypotheses taken from the orientation histogram correlation.
    pub rotation_hypotheses: usize,
    /// Separated translation maxima kept per rotation hypothesis.
    pub shifts_per_rotation: usize,
    /// Smallest spacing (m) and largest number (≤ 257) of current points in the searches.
    pub coarse_spacing: f32,
    pub coarse_points: usize,
    /// Smallest spacing (m) and largest number (≤ 65 535) of points of each scan in the
    /// refinement and the final judgement.
    pub fine_spacing: f32,
    pub fine_points: usize,
    /// Candidates (best correlation first) refined briefly and judged.
    pub screened: usize,
    /// Screened candidates (best judged first, no two within 0.1 m and 1°) refined fully.
    pub finalists: usize,
    /// Further finalists, each the best screened candidate of a rotation not yet among them.
    pub extra_rotations: usize,
    /// Gauss–Newton iterations of the brief and the full refinement.
    pub screen_iterations: usize,
    pub final_iterations: usize,
    /// Correspondence gate at the start of refinement (m); it shrinks to `2 · inlier_distance`.
    pub gate: f32,
    /// A current point is an inlier if it is within this of the reference surface (m); also the
    /// Huber threshold of the search's refinements.
    pub inlier_distance: f32,
    /// Huber threshold (m) of the winner's last, precise refinement (which starts with a gate
    /// of twice this); its result is kept if it moves the answer less than `precise_reach` (m)
    /// and `precise_reach_deg`.
    pub precise_distance: f32,
    pub precise_reach: f32,
    pub precise_reach_deg: f32,
    /// A point more than this in front of the other scan's reading is a free-space violation (m).
    pub violation_margin: f32,
    /// Weight of a violation against an inlier in the judgement.
    pub violation_weight: f32,
    /// A run of violating points shorter than this (m) is one moving object and counts once
    /// (0 counts every point).
    pub blob_extent: f32,
    /// Free-standing compact objects (people, robots) are dropped from both scans before
    /// matching (`matching::movable`): runs of points spanning less than
    /// `movable_extent` (m; 0 keeps every point) that stand at least `movable_jump` (m) in front
    /// of the points beside them.
    pub movable_extent: f32,
    pub movable_jump: f32,
    /// A refined translation whose least-constrained direction carries less than this share of
    /// the information of the best-constrained one is searched along that direction.
    pub weak_ratio: f64,
    /// Half-length (m) and step (m) of that line search.
    pub weak_search: f32,
    pub weak_step: f32,
    /// The best local maxima of the judged score along that line (other than the refined
    /// answer itself) that are refined again and judged.
    pub weak_peaks: usize,
    /// Run the rotation polish when the winner's inlier fraction of the fine set is below this
    /// (0 disables it).
    pub polish_below: f32,
    /// Starting correspondence gate (m) of the polish refinements.
    pub polish_gate: f32,
    /// Run the DE fallback when the winner's judged score, as a fraction of the fine set, is
    /// below this (0 disables the fallback).
    pub fallback_below: f32,
    /// The DE fallback (evaluation-budgeted; serial by default: the matcher is single-core).
    pub fallback: DeParams,
}

impl Default for ImprovedConfig {
    fn default() -> Self {
        ImprovedConfig {
            coarse_cell: 0.2,
            coarse_radius: 0.5,
            fine_cell: 0.1,
            rotation_hypotheses: 8,
            shifts_per_rotation: 6,
            coarse_spacing: 0.3,
            coarse_points: 128,
            fine_spacing: 0.05,
            fine_points: 400,
            screened: 24,
            finalists: 3,
            extra_rotations: 2,
            screen_iterations: 6,
            final_iterations: 15,
            gate: 0.5,
            inlier_distance: 0.08,
            precise_distance: 0.05,
            precise_reach: 0.05,
            precise_reach_deg: 1.0,
            violation_margin: 0.2,
            violation_weight: 8.0,
            blob_extent: 0.7,
            movable_extent: 0.7,
            movable_jump: 0.3,
            weak_ratio: 0.3,
            weak_search: 0.6,
            weak_step: 0.1,
            weak_peaks: 1,
            polish_below: 0.5,
            polish_gate: 0.15,
            fallback_below: 0.2,
            fallback: DeParams {
                population: 24,
                generations: 100,
                f: 0.5,
                cr: 0.9,
                strategy: Strategy::RandToBest1,
                crossover: Crossover::Binomial,
                either_or_probability: None,
                max_evaluations: Some(2_400),
                time_limit: None,
                stall: Some(StallStop {
                    generations: 20,
                    tolerance: 0.0,
                }),
                collapse_tolerance: Some(1e-3),
                parallel: false,
            },
        }
    }
}

impl ImprovedConfig {
    /// Checks every tunable; errors name the field.
    pub fn validate(&self) -> Result<(), MatchError> {
        let pos = |name, v: f32| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(MatchError::InvalidParameter {
                    name,
                    value: v as f64,
                    expected: "a finite value > 0",
                })
            }
        };
        pos("improved.coarse_cell", self.coarse_cell)?;
        pos("improved.coarse_radius", self.coarse_radius)?;
        pos("improved.fine_cell", self.fine_cell)?;
        pos("improved.coarse_spacing", self.coarse_spacing)?;
        pos("improved.fine_spacing", self.fine_spacing)?;
        pos("improved.gate", self.gate)?;
        pos("improved.inlier_distance", self.inlier_distance)?;
        pos("improved.precise_distance", self.precise_distance)?;
        pos("improved.precise_reach", self.precise_reach)?;
        pos("improved.precise_reach_deg", self.precise_reach_deg)?;
        pos("improved.violation_margin", self.violation_margin)?;
        pos("improved.weak_search", self.weak_search)?;
        pos("improved.weak_step", self.weak_step)?;
        pos("improved.polish_gate", self.polish_gate)?;
        if !(0.0..=1.0).contains(&self.polish_below) {
            return Err(MatchError::InvalidParameter {
                name: "improved.polish_below",
                value: self.polish_below as f64,
                expected: "a fraction in [0, 1]",
            });
        }
        if !(0.0..=1.0).contains(&self.weak_ratio) {
            return Err(MatchError::InvalidParameter {
                name: "improved.weak_ratio",
                value: self.weak_ratio,
                expected: "a ratio in [0, 1]",
            });
        }
        if self.weak_search / self.weak_step > 1000.0 {
            return Err(MatchError::InvalidParameter {
                name: "improved.weak_step",
                value: self.weak_step as f64,
                expected: "at most 1000 steps per side of the line search",
            });
        }
        if !(self.violation_weight.is_finite() && self.violation_weight >= 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "improved.violation_weight",
                value: self.violation_weight as f64,
                expected: "a finite weight >= 0",
            });
        }
        for (name, v) in [
            ("improved.blob_extent", self.blob_extent),
            ("improved.movable_extent", self.movable_extent),
            ("improved.movable_jump", self.movable_jump),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(MatchError::InvalidParameter {
                    name,
                    value: v as f64,
                    expected: "a finite length >= 0",
                });
            }
        }
        let count = |name, v: usize, max: usize, expected| {
            if (1..=max).contains(&v) {
                Ok(())
            } else {
                Err(MatchError::InvalidParameter {
                    name,
                    value: v as f64,
                    expected,
                })
            }
        };
        count(
            "improved.rotation_hypotheses",
            self.rotation_hypotheses,
            360,
            "1 ..= 360",
        )?;
        count(
            "improved.shifts_per_rotation",
            self.shifts_per_rotation,
            64,
            "1 ..= 64",
        )?;
        count(
            "improved.coarse_points",
            self.coarse_points,
            MAX_POINTS,
            "1 ..= 257",
        )?;
        count(
            "improved.fine_points",
            self.fine_points,
            MAX_INDEXED,
            "1 ..= 65535",
        )?;
        count("improved.screened", self.screened, 10_000, "1 ..= 10000")?;
        count("improved.weak_peaks", self.weak_peaks, 100, "1 ..= 100")?;
        count("improved.finalists", self.finalists, 10_000, "1 ..= 10000")?;
        if self.extra_rotations > 10_000 {
            return Err(MatchError::InvalidParameter {
                name: "improved.extra_rotations",
                value: self.extra_rotations as f64,
                expected: "0 ..= 10000",
            });
        }
        count(
            "improved.screen_iterations",
            self.screen_iterations,
            1000,
            "1 ..= 1000",
        )?;
        count(
            "improved.final_iterations",
            self.final_iterations,
            1000,
            "1 ..= 1000",
        )?;
        if !(0.0..=1.0).contains(&self.fallback_below) {
            return Err(MatchError::InvalidParameter {
                name: "improved.fallback_below",
                value: self.fallback_below as f64,
                expected: "a fraction in [0, 1]",
            });
        }
        if self.fallback_below > 0.0 {
            self.fallback.validate()?;
        }
        Ok(())
    }
}
