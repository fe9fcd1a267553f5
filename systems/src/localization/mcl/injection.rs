//! Where injected particles come from: a proposal drawn from the current scan instead of the
//! whole floor. Augmented MCL (Probabilistic Robotics Table 8.3) injects uniform random poses;
//! in a floor of thousands of square metres almost none lands near a kidnapped robot. Mixture
//! MCL (Thrun, Fox, Burgard & Dellaert, "Robust Monte Carlo localization for mobile robots",
//! Artificial Intelligence 128 (2001), §4, the dual proposal x ~ p(z | x)) and sensor
//! resetting (Lenser & Veloso, ICRA 2000) draw them from poses that explain the scan instead.
//!
//! p(z | x) cannot be sampled directly on a map, so it is approximated by a short search:
//! `n` uniform free poses are scored on a widened likelihood field (σ ≥ [`WIDE_SIGMA`], so poses
//! a metre off still rank well), first on a quarter of the endpoints, then the best eighth on
//! all; the best [`KEEP`] — at most [`PER_BIN`] per 1 m × 1 m × 30°
//! bin, so several look-alike places survive — each spawn `refine_n / KEEP` jittered copies,
//! scored again, for [`ROUNDS`] rounds of halving jitter, the last on the filter's own
//! likelihood field. The [`KEEP`] survivors are the proposal; the filter's weighting decides
//! between them.

use super::sensor_model::{LaserModelParams, likelihood_table, weigh_likelihood_field};
use crate::core::{SimRng, wrap_angle};
use crate::localization::map::LocalizationMap;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use std::collections::HashMap;

/// The smallest σ_hit (m) of the first rounds' likelihood field.
pub const WIDE_SIGMA: f64 = 0.5;
/// Candidates kept per round.
pub const KEEP: usize = 64;
/// At most this many kept candidates per 1 m × 1 m × 30° bin.
pub const PER_BIN: usize = 4;
/// Refinement rounds after the uniform draw.
pub const ROUNDS: usize = 3;
/// MCL's refinement rounds score `n / MCL_REFINE_FRACTION` candidates: its particles weigh
/// the proposal's poses again at every update, so a coarser search serves it; the DE filter
/// puts only the few best poses in its population and refines with all `n`.
pub const MCL_REFINE_FRACTION: usize = 4;
/// The uniform draw is screened on every `SCREEN_STRIDE`-th endpoint…
const SCREEN_STRIDE: usize = 4;
/// …and its best `1 / SCREEN_SHARE` go on to be scored on all of them: most of the draw lands
/// where a quarter of the scan already rules it out.
const SCREEN_SHARE: usize = 8;
/// Jitter of the first refinement round (m, m, rad); halved every round.
const JITTER: [f64; 3] = [0.4, 0.4, 0.15];
/// Candidates ordered at a time when picking the kept ones: usually enough, and selecting
/// them costs a pass where sorting all costs a sort.
const SELECT_BLOCK: usize = 1024;

/// Up to [`KEEP`] poses (x, y, θ) that explain the scan endpoints `points` (base frame): `n`
/// uniform candidates, then about `refine_n` per refinement round.
#[allow(clippy::too_many_arguments)]
pub fn scan_proposal(
    map: &LocalizationMap,
    laser: &LaserModelParams,
    table: &[f32; 256],
    points: &[[f32; 2]],
    range_max: f32,
    n: usize,
    refine_n: usize,
    rng: &mut SimRng,
) -> Vec<(f64, f64, f64)> {
    let counts = [n, refine_n];
    propose(map, laser, table, points, range_max, counts, rng, true)
}

/// [`scan_proposal`], its uniform draw screened or not (`screen`); `[n, refine_n]` = `counts`.
#[allow(clippy::too_many_arguments)]
fn propose(
    map: &LocalizationMap,
    laser: &LaserModelParams,
    table: &[f32; 256],
    points: &[[f32; 2]],
    range_max: f32,
    [n, refine_n]: [usize; 2],
    rng: &mut SimRng,
    screen: bool,
) -> Vec<(f64, f64, f64)> {
    if points.is_empty() || n == 0 {
        return Vec::new();
    }
    let wide_params = LaserModelParams {
        sigma_hit: laser.sigma_hit.max(WIDE_SIGMA),
        ..*laser
    };
    let wide = likelihood_table(&map.field, &wide_params, range_max as f64);
    let mut cand = map.random_free_poses(n, &mut || rng.random::<f64>());
    let mut kept = if screen {
        best_distinct(map, &wide, points, &screened(map, &wide, points, &cand))
    } else {
        best_distinct(map, &wide, points, &cand)
    };
    let per = refine_n.max(1).div_ceil(kept.len().max(1));
    for round in 0..ROUNDS {
        let sd = JITTER.map(|v| v / f64::from(1u32 << round));
        cand.clear();
        for k in &kept {
            cand.push(*k);
            for _ in 1..per {
                let mut g = || -> f64 { StandardNormal.sample(&mut *rng) };
                cand.push([
                    k[0] + sd[0] * g(),
                    k[1] + sd[1] * g(),
                    wrap_angle(k[2] + sd[2] * g()),
                ]);
            }
        }
        let t = if round + 1 == ROUNDS { table } else { &wide };
        kept = best_distinct(map, t, points, &cand);
    }
    kept.into_iter().map(|p| (p[0], p[1], p[2])).collect()
}

/// The 1 m × 1 m × 30° bin of a candidate.
fn bin_of(c: &[f64; 3]) -> (i64, i64, i64) {
    (
        c[0].floor() as i64,
        c[1].floor() as i64,
        (c[2] / (std::f64::consts::PI / 6.0)).floor() as i64,
    )
}

/// The best `1 / SCREEN_SHARE` of the candidates `cand` on every `SCREEN_STRIDE`-th endpoint
/// (ties by index), in their order in `cand`; all of them when the scan or the draw is too small
/// to screen.
fn screened(
    map: &LocalizationMap,
    table: &[f32; 256],
    points: &[[f32; 2]],
    cand: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let keep = cand.len() / SCREEN_SHARE;
    if points.len() < 4 * SCREEN_STRIDE || keep < KEEP {
        return cand.to_vec();
    }
    let few: Vec<[f32; 2]> = points.iter().step_by(SCREEN_STRIDE).copied().collect();
    let score = scores(map, table, &few, cand);
    let mut order: Vec<usize> = (0..cand.len()).collect();
    order.select_nth_unstable_by(keep - 1, best_first(&score));
    let mut best = order[..keep].to_vec();
    best.sort_unstable();
    best.into_iter().map(|i| cand[i]).collect()
}

/// Candidate indices ordered by `score`, best first, ties by index: a total order, so a
/// selection, a sort and a sort block by block agree.
fn best_first(score: &[f64]) -> impl Fn(&usize, &usize) -> std::cmp::Ordering + Copy + '_ {
    |a, b| score[*b].total_cmp(&score[*a]).then(a.cmp(b))
}

/// The likelihood-field score of each candidate for the scan endpoints `points`.
fn scores(
    map: &LocalizationMap,
    table: &[f32; 256],
    points: &[[f32; 2]],
    cand: &[[f64; 3]],
) -> Vec<f64> {
    let xs: Vec<f64> = cand.iter().map(|c| c[0]).collect();
    let ys: Vec<f64> = cand.iter().map(|c| c[1]).collect();
    let ths: Vec<f64> = cand.iter().map(|c| c[2]).collect();
    let mut score = vec![1.0; cand.len()];
    weigh_likelihood_field(&map.field, table, points, &xs, &ys, &ths, &mut score);
    score
}

/// The best-scoring [`KEEP`] candidates on free cells, at most [`PER_BIN`] per bin.
fn best_distinct(
    map: &LocalizationMap,
    table: &[f32; 256],
    points: &[[f32; 2]],
    cand: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let score = scores(map, table, points, cand);
    // best first, ties by index: a total order, so sorting the best block after selecting it
    // gives the order of a full sort, block by block, until enough are kept
    let better = best_first(&score);
    let mut order: Vec<usize> = (0..cand.len()).collect();
    let mut per_bin: HashMap<(i64, i64, i64), usize> = HashMap::new();
    let mut kept = Vec::with_capacity(KEEP);
    let mut rest = &mut order[..];
    while kept.len() < KEEP && !rest.is_empty() {
        let m = SELECT_BLOCK.min(rest.len());
        if m < rest.len() {
            rest.select_nth_unstable_by(m - 1, better);
        }
        let (block, tail) = rest.split_at_mut(m);
        block.sort_unstable_by(better);
        for &i in block.iter() {
            let c = cand[i];
            if !map.is_free(c[0], c[1]) {
                continue;
            }
            let bin = bin_of(&c);
            let count = per_bin.entry(bin).or_insert(0);
            if *count >= PER_BIN {
                continue;
            }
            *count += 1;
            kept.push(c);
            if kept.len() == KEEP {
                break;
            }
        }
        rest = tail;
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{Pose2, stream_rng};
    use crate::localization::fixtures::{CORRIDOR, hospital, scan_at};

    /// [`best_distinct`] with every candidate sorted at once.
    fn best_distinct_plain(
        map: &LocalizationMap,
        table: &[f32; 256],
        points: &[[f32; 2]],
        cand: &[[f64; 3]],
    ) -> Vec<[f64; 3]> {
        let score = scores(map, table, points, cand);
        let mut order: Vec<usize> = (0..cand.len()).collect();
        order.sort_by(best_first(&score));
        let mut per_bin: HashMap<(i64, i64, i64), usize> = HashMap::new();
        let mut kept = Vec::new();
        for i in order {
            let c = cand[i];
            let bin = bin_of(&c);
            if map.is_free(c[0], c[1]) && *per_bin.get(&bin).unwrap_or(&0) < PER_BIN {
                *per_bin.entry(bin).or_insert(0) += 1;
                kept.push(c);
                if kept.len() == KEEP {
                    break;
                }
            }
        }
        kept
    }

    /// Picking from the best block at a time keeps exactly the candidates, in the order, that
    /// sorting them all does: with uniform draws, with thousands crowding the true pose's bin
    /// (so later blocks are needed), and with repeated candidates whose scores tie.
    #[test]
    fn picking_block_by_block_keeps_what_a_full_sort_keeps() {
        let map = hospital();
        let mut rng = stream_rng(5, "test", "injection");
        let truth = Pose2::new(CORRIDOR[0][0] + 4.0, CORRIDOR[0][1], 0.1);
        let scan = scan_at(&map, &truth, &mut rng);
        let points: Vec<[f32; 2]> = scan.points().step_by(18).collect();
        let table = likelihood_table(&map.field, &LaserModelParams::default(), 20.0);
        let mut cand = map.random_free_poses(5000, &mut || rng.random::<f64>());
        for _ in 0..3000 {
            let mut g = || -> f64 { StandardNormal.sample(&mut rng) };
            cand.push([
                truth.x + 0.05 * g(),
                truth.y + 0.05 * g(),
                truth.theta + 0.02 * g(),
            ]);
        }
        let repeated: Vec<[f64; 3]> = cand[5000..5400].to_vec();
        cand.extend(repeated);
        let kept = best_distinct(&map, &table, &points, &cand);
        assert_eq!(kept.len(), KEEP);
        assert_eq!(kept, best_distinct_plain(&map, &table, &points, &cand));
        let few = &cand[..700];
        assert_eq!(
            best_distinct(&map, &table, &points, few),
            best_distinct_plain(&map, &table, &points, few)
        );
    }

    /// Screening the uniform draw on a quarter of the endpoints keeps the candidates that
    /// scoring all of it on every endpoint keeps (nearly all, the best always), and the proposal
    /// that follows is the same as without it: at poses along the hospital's corridor, some of
    /// which one scan cannot tell from a look-alike place.
    #[test]
    fn screening_the_draw_keeps_the_best_candidates_and_the_proposal() {
        let map = hospital();
        let laser = LaserModelParams::default();
        let wide = likelihood_table(
            &map.field,
            &LaserModelParams {
                sigma_hit: WIDE_SIGMA,
                ..laser
            },
            20.0,
        );
        let table = likelihood_table(&map.field, &laser, 20.0);
        let (mut found, mut same) = (0, 0);
        for seed in 0..8u64 {
            let mut rng = stream_rng(seed, "test", "screening");
            let truth = Pose2::new(
                CORRIDOR[0][0] + 2.0 + 2.0 * seed as f64,
                CORRIDOR[0][1],
                0.1 + 0.7 * seed as f64,
            );
            let scan = scan_at(&map, &truth, &mut rng);
            let points: Vec<[f32; 2]> = scan.points().step_by(18).collect();
            let cand = map.random_free_poses(20_000, &mut || rng.random::<f64>());
            let all = best_distinct(&map, &wide, &points, &cand);
            let few = screened(&map, &wide, &points, &cand);
            assert_eq!(few.len(), cand.len() / SCREEN_SHARE);
            let kept = best_distinct(&map, &wide, &points, &few);
            assert_eq!(all[0], kept[0], "seed {seed}");
            let shared = all.iter().filter(|p| kept.contains(p)).count();
            assert!(shared >= KEEP * 3 / 4, "seed {seed}: {shared} of {KEEP}");
            let pools = [true, false].map(|screen| {
                let mut rng = stream_rng(seed, "test", "proposal");
                let counts = [20_000, 5_000];
                propose(
                    &map, &laser, &table, &points, 20.0, counts, &mut rng, screen,
                )
            });
            let near = |pool: &[(f64, f64, f64)]| {
                pool.iter().any(|p| {
                    Pose2::new(p.0, p.1, p.2).distance(&truth) < 0.3
                        && wrap_angle(p.2 - truth.theta).abs() < 0.1
                })
            };
            assert_eq!(near(&pools[0]), near(&pools[1]), "seed {seed}");
            found += usize::from(near(&pools[0]));
            same += usize::from(pools[0] == pools[1]);
        }
        // not vacuous: where one scan tells the place, both find the robot
        assert!(found >= 2, "the proposal found the robot in {found} of 8");
        assert!(same >= 6, "the same proposal in {same} of 8");
    }
}
