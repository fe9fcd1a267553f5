//! The improved matcher: the thesis's idea — score a candidate transform by how well the moved
//! current scan overlaps the reference ([Hospital thesis §5.2, eq. 29]) and search the
//! transforms globally — rebuilt to be both right and fast, with DE kept as the global fallback.
//! The thesis's failure modes shape it (§6.2, §7.3, §8): DE stagnates in local optima, the
//! correlation mis-rotates scans, and symmetric rooms and corridors fool it. So rotations are
//! proposed deliberately, translations are searched exhaustively, and candidates are judged
//! with information the correlation ignores (free space).
//!
//! 0. **People set aside** ([`super::movable`]): free-standing compact objects — people,
//!    robots — are dropped from both scans. They may have moved between the scans, and in a
//!    corridor lining up a person who walked on outscores the few wall ends that fix the shift
//!    along it.
//! 1. **Subsampling** ([`super::subsample`]): both scans thinned to ~5 cm spacing (the near
//!    range of a scan is 10× denser than needed), a coarser set of the current scan for the
//!    searches.
//! 2. **Reference model** ([`super::ref_grid`]): a smooth score grid (0.2 m) for the coarse
//!    searches and a nearest-point index grid (0.1 m) for refinement, built once.
//! 3. **Rotation hypotheses** ([`super::orientation`]): the orientation histograms of the surface
//!    normals ([`super::normals`]) of both scans are cross-correlated (histogram correlation,
//!    thesis §3.8); its best peaks are rotation candidates, independent of the translation.
//! 4. **Translation search** ([`super::translation_search`]): for each rotation candidate, every
//!    shift of the window on the score grid's lattice (±3 m in 0.2 m steps) is scored
//!    exhaustively — the thesis's correlation for all shifts at once instead of DE samples — and
//!    a few separated maxima are kept.
//! 5. **Screening**: the best candidates by correlation are refined briefly (point-to-line
//!    Gauss–Newton, [`super::refine`], on the coarse set) and judged by
//!    `inliers − violation_weight · violations`: inliers are current points within
//!    `inlier_distance` of the reference surface, violations are points of either scan that the
//!    alignment puts in space the other scan saw as free ([`super::visibility`]). A compact run
//!    of violating points (shorter than `blob_extent`) is a person or robot that moved between
//!    the scans and counts once: counted point by point, two people ahead made a 180° flip of a
//!    corridor win.
//! 6. **Final refinement**: the best screened candidates (no two alike), plus the best of up to
//!    `extra_rotations` rotations not yet among them, are refined on the fine set and judged
//!    again; the best wins. The reference surface between two samples of one wall is the
//!    segment joining them ([`super::refine::Reference::line_at`]), and normals of sparsely
//!    sampled walls come from a gate that widens with the sample spacing
//!    ([`super::normals`]): otherwise far and grazing walls count only near their samples and
//!    shifts that line the two scans' samples up win, 0.1–0.2 m along a corridor.
//!
//!    **Corridor line search**: where the refined translation is weakly constrained (a
//!    corridor), the judged score is scanned along the weak direction (±`weak_search`); its
//!    best `weak_peaks` local maxima are refined again and judged, and the best judged answer
//!    is kept. The judge, not the inlier count, scores the line: it sees the shifts whose
//!    advantage is fewer free-space violations.
//!
//!    **Rotation polish**: when the winner explains less than `polish_below` of the fine set
//!    (little overlap, e.g. 30 steps apart), the wide starting gate lets the refinement pull the
//!    rotation towards walls only one scan saw, by a few degrees. The winner
//!    is restarted at ±1°, ±2°, ±3° with a narrow gate (`polish_gate`), each refined fully and
//!    judged; the best judged answer wins.
//! 7. **DE fallback** ([`super::de`]): if the winner's judged score is below `fallback_below`
//!    of the fine set (few normals, e.g. unordered points, or heavy clutter), a DE run on the
//!    score grid, seeded with the candidates, searches the whole window; its best member is
//!    refined and judged like the others.
//! 8. **Precise refinement**: the search refines with a Huber threshold of `inlier_distance`
//!    (8 cm), which keeps low-overlap pairs in the right basin but averages in points a few
//!    centimetres off. The winner is refined once more with `precise_distance` (5 cm) from a
//!    narrow gate and kept if it stays within `precise_reach`: consecutive scans' alignments
//!    are as precise as with 5 cm throughout.
//!
//! What each step gained in the scan-matching experiment is in sim/docs/benchmarks.md
//! ("Scan matching: what each step of the improved matcher gained").
//!
//! Everything is deterministic: no wall clock, no thread-count dependence, ties broken by order.

mod config;

pub use config::ImprovedConfig;

use super::de::{self, Bounds, Vector};
use super::error::MatchError;
use super::judge::{Judge, RUN_GAP};
use super::movable::{Movable, without_movable};
use super::normals::estimate_normals;
use super::orientation::{orientation_histogram, rotation_hypotheses};
use super::ref_grid::{GridGeom, MAX_INDEXED, NearestGrid, ScoreGrid};
use super::refine::{Reference, RefineParams, refine};
use super::subsample::subsample;
use super::translation_search::{Shift, best_shifts};
use super::visibility::RangeImage;
use crate::core::{SimRng, wrap_angle};
use std::borrow::Cow;

/// Fewest points a scan keeps when its free-standing objects are dropped (otherwise it is
/// matched whole).
const MIN_KEPT: usize = 20;

/// The outcome of [`match_improved`].
pub(crate) struct ImprovedOutcome {
    pub transform: Vector,
    /// Inlier fraction of the fine current set at the answer.
    pub inliers: f64,
    /// Candidate transforms scored: shifts, refinement iterations, judgements, DE evaluations.
    pub evaluations: u64,
}

/// The screened candidates (best first) that are refined fully: the best `n` that are not
/// duplicates of each other (within 0.1 m and 1°), then up to `extra_rotations` more, each the
/// best candidate of a rotation more than 10° from every one taken so far. Screening judges on
/// the coarse sets, where a few people in view cost a right answer as much as a shift costs a
/// flipped one; without the extra rotations the slots fill with shifted copies of one flip.
fn pick_finalists(screened: &[(Vector, f64)], n: usize, extra_rotations: usize) -> Vec<Vector> {
    let near = |a: &Vector, b: &Vector, xy: f64, theta_deg: f64| {
        (a[0] - b[0]).hypot(a[1] - b[1]) <= xy
            && wrap_angle(a[2] - b[2]).abs() <= theta_deg.to_radians()
    };
    let mut picked: Vec<Vector> = Vec::with_capacity(n + extra_rotations);
    for (t, _) in screened {
        if picked.len() == n {
            break;
        }
        if !picked.iter().any(|p| near(p, t, 0.1, 1.0)) {
            picked.push(*t);
        }
    }
    let mut extra = 0;
    for (t, _) in screened {
        if extra == extra_rotations {
            break;
        }
        if !picked.iter().any(|p| near(p, t, f64::INFINITY, 10.0)) {
            picked.push(*t);
            extra += 1;
        }
    }
    picked
}

/// Indices of the best `n` strict local maxima of `scores` (a maximum's right neighbour is
/// lower, its left one not higher; `None` is outside the window and lower than any score),
/// best first, then nearest the middle; the middle itself (the refined answer) is left out.
fn line_peaks(scores: &[Option<f64>], n: usize) -> Vec<i32> {
    let mid = (scores.len() / 2) as i32;
    let at = |j: Option<usize>| {
        j.and_then(|j| scores.get(j).copied().flatten())
            .unwrap_or(f64::NEG_INFINITY)
    };
    let mut peaks: Vec<(f64, i32)> = (0..scores.len())
        .filter_map(|i| {
            let c = scores[i]?;
            let (left, right) = (at(i.checked_sub(1)), at(Some(i + 1)));
            (i as i32 != mid && c >= left && c > right).then_some((c, i as i32))
        })
        .collect();
    peaks.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then((a.1 - mid).abs().cmp(&(b.1 - mid).abs()))
    });
    peaks.into_iter().take(n).map(|(_, i)| i).collect()
}

/// A candidate judged: its transform, judged score and inlier count on the fine current set.
type Judged = (Vector, f64, usize);

/// Runs the pipeline of the module docs. Points must be finite and both sets non-empty.
pub(crate) fn match_improved(
    reference: &[[f32; 2]],
    current: &[[f32; 2]],
    bounds: &Bounds,
    cfg: &ImprovedConfig,
    rng: &mut SimRng,
) -> Result<ImprovedOutcome, MatchError> {
    cfg.validate()?;
    bounds.validate()?;
    // 0. people and robots set aside: they may have moved between the scans
    let (reference, current) = (without_people(reference, cfg), without_people(current, cfg));
    let (reference, current) = (&reference[..], &current[..]);
    // 1. subsampling
    let sets = Sets::new(reference, current, cfg);
    // 2. reference model (its grids refused, not allocated, if the scan is absurdly wide)
    GridGeom::check_size(&sets.ref_fine, cfg.coarse_cell, cfg.coarse_radius)?;
    GridGeom::check_size(&sets.ref_fine, cfg.fine_cell, cfg.gate)?;
    let score_grid = ScoreGrid::build(&sets.ref_fine, cfg.coarse_cell, cfg.coarse_radius, 2);
    let nearest = NearestGrid::build(&sets.ref_fine, cfg.fine_cell, cfg.gate, 3);
    let judge = Judge {
        model: Reference {
            points: &sets.ref_fine,
            normals: &sets.ref_normals,
            grid: &nearest,
        },
        ref_image: RangeImage::build(reference),
        cur_image: RangeImage::build(current),
        inlier_distance: cfg.inlier_distance,
        end_tangent: 1.2 * cfg.inlier_distance,
        margin: cfg.violation_margin,
        weight: cfg.violation_weight,
        blob_extent: cfg.blob_extent,
    };
    let mut evaluations = 0u64;
    // 3.–4. rotation hypotheses, and a translation search for each
    let candidates = search_candidates(&sets, &score_grid, bounds, cfg, &mut evaluations);
    let search = Search::new(judge, &sets, bounds, cfg);
    // 5. screening
    let screened = search.screen(&candidates, &mut evaluations);
    // 6. final refinement, then the rotation polish of a low-overlap winner
    let mut best = search.final_refinement(&screened, &mut evaluations);
    search.polish(&mut best, &mut evaluations);
    // 7. DE fallback
    let n_fine = sets.cur_fine.len().max(1) as f64;
    let weak = best.is_none_or(|b| b.1 / n_fine < cfg.fallback_below as f64);
    if weak && cfg.fallback_below > 0.0 {
        let seeds: Vec<Vector> = screened
            .iter()
            .map(|s| s.0)
            .chain(candidates.iter().map(|c| c.0))
            .collect();
        let cost = |p: &Vector| -(score_grid.correlate(&sets.cur_coarse, p) as f64);
        let out = de::minimize(&cost, bounds, &cfg.fallback, &seeds, rng)?;
        evaluations += out.evaluations;
        let c = search.fallback_candidate(out.best, &mut evaluations);
        if best.is_none_or(|b| c.1 > b.1) {
            best = Some(c);
        }
    }
    // 8. precise refinement of the winner
    let (transform, inliers) = search.precise(best, &mut evaluations);
    Ok(ImprovedOutcome {
        transform: [transform[0], transform[1], wrap_angle(transform[2])],
        inliers: inliers as f64 / n_fine,
        evaluations,
    })
}

/// `points` without their free-standing compact objects (step 0), or all of them when
/// `movable_extent` is 0.
fn without_people<'a>(points: &'a [[f32; 2]], cfg: &ImprovedConfig) -> Cow<'a, [[f32; 2]]> {
    if cfg.movable_extent > 0.0 {
        let m = Movable {
            gap: RUN_GAP,
            extent: cfg.movable_extent,
            jump: cfg.movable_jump,
        };
        Cow::Owned(without_movable(points, &m, MIN_KEPT))
    } else {
        Cow::Borrowed(points)
    }
}

/// The point sets a match works on (step 1) and the surface normals of the fine ones.
struct Sets {
    ref_fine: Vec<[f32; 2]>,
    cur_fine: Vec<[f32; 2]>,
    ref_coarse: Vec<[f32; 2]>,
    cur_coarse: Vec<[f32; 2]>,
    ref_normals: Vec<Option<[f32; 2]>>,
    cur_normals: Vec<Option<[f32; 2]>>,
}

impl Sets {
    fn new(reference: &[[f32; 2]], current: &[[f32; 2]], cfg: &ImprovedConfig) -> Sets {
        // normals from neighbours within 0.5 m, or within 3.5 point spacings up to 1.5 m where a
        // wall is sampled sparsely (far away, grazing)
        let (normal_gate, normal_max_gate) = (0.5, 1.5);
        let ref_fine = subsample(
            reference,
            cfg.fine_spacing,
            cfg.fine_points.max(2 * cfg.coarse_points).min(MAX_INDEXED),
        );
        let cur_fine = subsample(current, cfg.fine_spacing, cfg.fine_points);
        Sets {
            ref_normals: estimate_normals(&ref_fine, normal_gate, normal_max_gate),
            cur_normals: estimate_normals(&cur_fine, normal_gate, normal_max_gate),
            ref_coarse: subsample(reference, cfg.coarse_spacing, cfg.coarse_points),
            cur_coarse: subsample(current, cfg.coarse_spacing, cfg.coarse_points),
            ref_fine,
            cur_fine,
        }
    }
}

/// Steps 3 and 4: the rotation hypotheses, and for each the best separated shifts of the coarse
/// current set on the score grid inside `bounds`, with their correlation; best first (ties in
/// hypothesis order).
fn search_candidates(
    sets: &Sets,
    score_grid: &ScoreGrid,
    bounds: &Bounds,
    cfg: &ImprovedConfig,
    evaluations: &mut u64,
) -> Vec<(Vector, u32)> {
    let max_theta = if bounds.theta_periodic() {
        std::f64::consts::PI
    } else {
        bounds.hi[2].abs().min(bounds.lo[2].abs())
    };
    let hyps = rotation_hypotheses(
        &orientation_histogram(&sets.ref_fine, &sets.ref_normals),
        &orientation_histogram(&sets.cur_fine, &sets.cur_normals),
        cfg.rotation_hypotheses,
        max_theta,
    );
    let cell = cfg.coarse_cell as f64;
    let reach_x = (bounds.hi[0].min(-bounds.lo[0]) / cell).floor().max(0.0) as i32;
    let reach_y = (bounds.hi[1].min(-bounds.lo[1]) / cell).floor().max(0.0) as i32;
    let radius = reach_x.max(reach_y);
    let separation = ((0.5 / cell).round() as i32).max(1);
    let (mut acc, mut shifts) = (Vec::new(), Vec::<Shift>::new());
    let mut cells = Vec::with_capacity(sets.cur_coarse.len());
    let mut candidates: Vec<(Vector, u32)> = Vec::new();
    for &(theta, _) in &hyps {
        let (s, c) = theta.sin_cos();
        let (s, c) = (s as f32, c as f32);
        cells.clear();
        cells.extend(sets.cur_coarse.iter().map(|b| {
            score_grid
                .geom
                .cell_coords([c * b[0] - s * b[1], s * b[0] + c * b[1]])
        }));
        shifts.clear();
        *evaluations += best_shifts(
            score_grid,
            &cells,
            radius,
            cfg.shifts_per_rotation,
            separation,
            &mut acc,
            &mut shifts,
        );
        for sh in &shifts {
            let t = [sh.i as f64 * cell, sh.k as f64 * cell, theta];
            if bounds.contains(&t) {
                candidates.push((t, sh.score));
            }
        }
    }
    // best correlation first; the sort is stable, so ties keep the hypothesis order
    candidates.sort_by_key(|c| std::cmp::Reverse(c.1));
    candidates
}

/// Steps 5 to 8: candidates refined and judged.
struct Search<'a> {
    judge: Judge<'a>,
    sets: &'a Sets,
    bounds: &'a Bounds,
    cfg: &'a ImprovedConfig,
    /// Screening's brief refinement.
    quick: RefineParams,
    /// The final refinement.
    full: RefineParams,
    /// The rotation polish's: the final refinement from a narrow gate.
    narrow: RefineParams,
}

impl<'a> Search<'a> {
    fn new(judge: Judge<'a>, sets: &'a Sets, bounds: &'a Bounds, cfg: &'a ImprovedConfig) -> Self {
        let quick = RefineParams {
            iterations: cfg.screen_iterations,
            gate_start: cfg.gate,
            gate_end: (3.0 * cfg.inlier_distance).min(cfg.gate),
            huber: cfg.inlier_distance,
            end_tangent: judge.end_tangent,
        };
        let full = RefineParams {
            iterations: cfg.final_iterations,
            gate_end: (2.0 * cfg.inlier_distance).min(cfg.gate),
            ..quick
        };
        let narrow = RefineParams {
            gate_start: cfg.polish_gate.max(full.gate_end),
            ..full
        };
        Search {
            judge,
            sets,
            bounds,
            cfg,
            quick,
            full,
            narrow,
        }
    }

    /// `r`, or `start` when `r` left the search window.
    fn keep_inside(&self, r: Vector, start: Vector) -> Vector {
        if self.bounds.contains(&r) { r } else { start }
    }

    /// Step 5: the best `screened` candidates refined briefly on the coarse sets and judged,
    /// best judged first.
    fn screen(&self, candidates: &[(Vector, u32)], evaluations: &mut u64) -> Vec<(Vector, f64)> {
        let (sets, cfg) = (self.sets, self.cfg);
        let mut screened: Vec<(Vector, f64)> = Vec::new();
        for &(t, _) in candidates.iter().take(cfg.screened) {
            let refined = refine(&self.judge.model, &sets.cur_coarse, t, &self.quick).x;
            let r = self.keep_inside(refined, t);
            let (score, _) = self.judge.score(&sets.cur_coarse, &sets.ref_coarse, &r);
            *evaluations += cfg.screen_iterations as u64 + 1;
            screened.push((r, score));
        }
        screened.sort_by(|a, b| b.1.total_cmp(&a.1));
        screened
    }

    /// Step 6: the finalists of `screened` refined fully and judged; the best judged (the first
    /// of equals).
    fn final_refinement(
        &self,
        screened: &[(Vector, f64)],
        evaluations: &mut u64,
    ) -> Option<Judged> {
        let mut best: Option<Judged> = None;
        for t in pick_finalists(screened, self.cfg.finalists, self.cfg.extra_rotations) {
            let c = self.finalize(t, &self.full);
            *evaluations += self.cfg.final_iterations as u64 + 1;
            if best.is_none_or(|b| c.1 > b.1) {
                best = Some(c);
            }
        }
        best
    }

    /// Step 6, rotation polish: a winner explaining less than `polish_below` of the fine set is
    /// restarted at ±1°, ±2°, ±3° from a narrow gate; the best judged answer wins.
    fn polish(&self, best: &mut Option<Judged>, evaluations: &mut u64) {
        let cfg = self.cfg;
        if let Some(b) = *best
            && (b.2 as f64) < cfg.polish_below as f64 * self.sets.cur_fine.len() as f64
        {
            let centre = b.0;
            for deg in [-3.0f64, -2.0, -1.0, 1.0, 2.0, 3.0] {
                let t = [centre[0], centre[1], centre[2] + deg.to_radians()];
                let c = self.finalize(t, &self.narrow);
                *evaluations += cfg.final_iterations as u64 + 1;
                if best.is_none_or(|bb| c.1 > bb.1) {
                    *best = Some(c);
                }
            }
        }
    }

    /// Step 7's candidate: the DE fallback's best member refined briefly, then finalized.
    fn fallback_candidate(&self, start: Vector, evaluations: &mut u64) -> Judged {
        let refined = refine(&self.judge.model, &self.sets.cur_coarse, start, &self.quick).x;
        let quick_r = self.keep_inside(refined, start);
        let c = self.finalize(quick_r, &self.full);
        *evaluations += (self.cfg.screen_iterations + self.cfg.final_iterations) as u64 + 1;
        c
    }

    /// Refines `start` on the fine set with `params` and judges it. Where the translation is
    /// weakly constrained (a corridor), point-to-line barely feels the few wall ends that fix
    /// the position along it, so that line is searched with the judge and the best points are
    /// refined again ([`line_peaks`]).
    fn finalize(&self, start: Vector, params: &RefineParams) -> Judged {
        let (judge, sets, cfg) = (&self.judge, self.sets, self.cfg);
        let (cur_fine, ref_fine) = (&sets.cur_fine[..], &sets.ref_fine[..]);
        let refined = refine(&judge.model, cur_fine, start, params);
        let mut r = self.keep_inside(refined.x, start);
        if refined.weak_ratio < cfg.weak_ratio {
            let (d, origin) = (refined.weak_direction, r);
            let steps = (cfg.weak_search / cfg.weak_step).round() as i32;
            let at = |k: i32| {
                let o = k as f64 * cfg.weak_step as f64;
                [origin[0] + o * d[0], origin[1] + o * d[1], origin[2]]
            };
            let scores: Vec<Option<f64>> = (-steps..=steps)
                .map(|k| {
                    let t = at(k);
                    self.bounds
                        .contains(&t)
                        .then(|| judge.score(cur_fine, ref_fine, &t).0)
                })
                .collect();
            let mut best_score = judge.score(cur_fine, ref_fine, &r).0;
            for k in line_peaks(&scores, cfg.weak_peaks) {
                let t = at(k - steps);
                let again = self.keep_inside(refine(&judge.model, cur_fine, t, params).x, t);
                let score = judge.score(cur_fine, ref_fine, &again).0;
                if score > best_score {
                    (best_score, r) = (score, again);
                }
            }
        }
        let (score, inl) = judge.score(cur_fine, ref_fine, &r);
        (r, score, inl)
    }

    /// Step 8: the winner refined once more with `precise_distance` from a narrow gate, kept if
    /// it stays within `precise_reach`; the answer and its inlier count (zero without a winner).
    fn precise(&self, best: Option<Judged>, evaluations: &mut u64) -> (Vector, usize) {
        let cfg = self.cfg;
        let Some((transform, _, inliers)) = best else {
            return ([0.0; 3], 0);
        };
        let precise = RefineParams {
            iterations: cfg.final_iterations,
            gate_start: 2.0 * cfg.precise_distance,
            gate_end: 2.0 * cfg.precise_distance,
            huber: cfg.precise_distance,
            end_tangent: 1.2 * cfg.precise_distance,
        };
        let cur_fine = &self.sets.cur_fine;
        let r = self.keep_inside(
            refine(&self.judge.model, cur_fine, transform, &precise).x,
            transform,
        );
        *evaluations += cfg.final_iterations as u64 + 1;
        let near = (r[0] - transform[0]).hypot(r[1] - transform[1]) < cfg.precise_reach as f64
            && wrap_angle(r[2] - transform[2]).abs() < (cfg.precise_reach_deg as f64).to_radians();
        if near {
            (r, self.judge.inliers(cur_fine, &r))
        } else {
            (transform, inliers)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{ImprovedConfig, line_peaks};
    use crate::matching::error::MatchError;

    #[test]
    fn a_bad_precise_refinement_setting_names_its_field() {
        for (field, cfg) in [
            (
                "improved.precise_distance",
                ImprovedConfig {
                    precise_distance: 0.0,
                    ..ImprovedConfig::default()
                },
            ),
            (
                "improved.precise_reach_deg",
                ImprovedConfig {
                    precise_reach_deg: f32::NAN,
                    ..ImprovedConfig::default()
                },
            ),
            (
                "improved.movable_extent",
                ImprovedConfig {
                    movable_extent: -0.7,
                    ..ImprovedConfig::default()
                },
            ),
            (
                "improved.movable_jump",
                ImprovedConfig {
                    movable_jump: f32::INFINITY,
                    ..ImprovedConfig::default()
                },
            ),
        ] {
            match cfg.validate() {
                Err(MatchError::InvalidParameter { name, .. }) => assert_eq!(name, field),
                other => panic!("{field}: {other:?}"),
            }
        }
        assert!(ImprovedConfig::default().validate().is_ok());
    }

    #[test]
    fn line_peaks_are_the_best_local_maxima_other_than_the_middle() {
        // middle index 4 (the refined answer) is a maximum but left out; 9 at index 7 beats
        // the plateau 7, 7 at 1–2 (its right end is the maximum); None is outside the window
        let counts = judged(&[
            Some(3),
            Some(7),
            Some(7),
            Some(2),
            Some(10),
            Some(4),
            Some(5),
            Some(9),
            None,
        ]);
        assert_eq!(line_peaks(&counts, 5), vec![7, 2]);
        assert_eq!(line_peaks(&counts, 1), vec![7]);
        // equal peaks: the nearer to the middle first
        let even = judged(&[
            Some(6),
            Some(1),
            Some(1),
            Some(1),
            Some(0),
            Some(1),
            Some(6),
        ]);
        assert_eq!(line_peaks(&even, 2), vec![0, 6]);
        let near = judged(&[
            Some(6),
            Some(1),
            Some(6),
            Some(1),
            Some(0),
            Some(1),
            Some(1),
        ]);
        assert_eq!(line_peaks(&near, 1), vec![2]);
        assert!(line_peaks(&[None, Some(3.0), None], 2).is_empty());
        // judged scores may be negative: a window edge (None) is lower still
        let negative = judged(&[Some(-5), Some(-9), Some(-9), Some(-9), None]);
        assert_eq!(line_peaks(&negative, 3), vec![0, 3]);
    }

    fn judged(v: &[Option<i32>]) -> Vec<Option<f64>> {
        v.iter().map(|x| x.map(f64::from)).collect()
    }
}
