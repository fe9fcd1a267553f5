//! The correction of the belief by a scan (Probabilistic Robotics §8.2, Table 8.1 line 5) with
//! the selective update of Fox, Burgard & Thrun (JAIR 11 (1999), §4.2): the cells at or above
//! a fraction of the most probable one's are scored on the likelihood field ([`super::correction`]),
//! the others weighted alike by the scan's likelihood averaged over a fixed sample of the floor.

use super::correction::reachable;
use super::layout::{Layout, Span, counted};
use super::{MarkovGrid, belief_ops, correction, normaliser};
use crate::localization::map::LocalizationMap;
use correction::PaddedField;
use rayon::prelude::*;

/// Cells between two sample cells of the selective update (about 500 of the hospital's
/// 0.97 million free cells × bins): the floor only weighs the cells below the threshold, whose
/// share of the belief is too small for a finer average to change an estimate.
const SAMPLE_STRIDE: usize = 1949;

/// The selective update's sample: every `SAMPLE_STRIDE`-th cell in (layer, span) order, of the
/// whole lattice.
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

impl MarkovGrid {
    /// Log-likelihood of the scan endpoints `points` (base frame) into the scratch buffer, for
    /// every free cell or, given `active` (per layer), for those runs only; then also for the
    /// sample cells, whose values are returned.
    pub(super) fn score(
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
        if self.sample.is_empty() {
            self.sample = sample_cells(&self.whole);
        }
        // the padded field, rebuilt when the scan reaches farther than it was built for
        let field = match &mut self.field {
            Some(f) if f.reach >= reach => &*f,
            slot => &*slot.insert(PaddedField::new(&map.field, reach.max(1.0))),
        };
        let (layout, whole) = (&self.layout, &self.whole);
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
                let mut v = Vec::with_capacity(sample[k].len());
                correction::cells_log_likelihood(
                    field, &tables, whole, &offsets, &sample[k], &mut v,
                );
                v
            })
            .collect();
        sampled.concat()
    }

    /// The runs of cells at or above `threshold`, per layer, and their number.
    pub(super) fn active_runs(&self, threshold: f32) -> (Vec<Vec<Span>>, usize) {
        let l = &self.layout;
        let runs: Vec<Vec<Span>> = self
            .belief
            .par_chunks(l.layer())
            .map(|b| l.runs(|cells, emit| belief_ops::runs_at_or_above(&b[cells], threshold, emit)))
            .collect();
        counted(runs)
    }

    /// Correction of the belief by a scan's endpoints (base frame, max-range readings left out).
    /// Endpoints that are not finite, or farther than the map's diagonal (outside the map seen
    /// from every cell, so they weigh every cell alike), are left out.
    pub fn apply_scan(&mut self, map: &LocalizationMap, points: &[[f32; 2]], range_max: f32) {
        self.weigh(map, &reachable(map, points), range_max);
    }

    /// [`MarkovGrid::apply_scan`] for endpoints already [`reachable`], returning where the
    /// corrected belief is largest (the first such cell) if its last pass found it.
    pub(super) fn weigh(
        &mut self,
        map: &LocalizationMap,
        points: &[[f32; 2]],
        range_max: f32,
    ) -> Option<usize> {
        if points.is_empty() {
            // nothing to weigh by: only the normalisation the motion left to the correction
            if !self.normalise_carried() {
                self.fill_uniform();
            }
            return None;
        }
        let lambda = self.config.likelihood_exponent as f32;
        let tallied = |g: &Self| {
            let mut t = belief_ops::Tally::default();
            t.add(&g.belief);
            g.carry(&t)
        };
        let mut before = self.carried.take().unwrap_or_else(|| tallied(self));
        let mut threshold = self.threshold(before.peak);
        // the cells outside the window count again once the background reaches the threshold
        if self.is_windowed()
            && (self.background() >= threshold || self.config.selective_threshold <= 0.0)
        {
            self.unwindow();
            before = tallied(self);
            threshold = self.threshold(before.peak);
        }
        // selective update only when it skips at least half of the cells (always on a window)
        let cells = self.layout.free_count() * self.layout.n_theta;
        let selective = (self.config.selective_threshold > 0.0)
            .then(|| self.active_runs(threshold))
            .filter(|(_, n)| self.is_windowed() || 2 * n < cells);
        let sampled = self.score(map, points, range_max, selective.as_ref().map(|a| &a.0[..]));
        let l = &self.layout;
        // the belief's sum after the weighing, and, for the selective update, the weight of the
        // cells it did not score (the scored ones hold their weighed values in the scratch)
        let (total, unscored) = match &selective {
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
                    (belief_ops::sum(&self.belief), None)
                } else {
                    (before.sum, None)
                }
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
                    let floor = (sampled
                        .iter()
                        .map(|&v| (lambda * (v - best)).exp() as f64)
                        .sum::<f64>()
                        / sampled.len().max(1) as f64) as f32;
                    // the scored cells (those at or above the threshold) weighed into the
                    // scratch; the sum: the others' scaled by the floor, plus these
                    let (mut unweighed, mut weighed) = (0.0f64, 0.0f64);
                    for (k, rs) in runs.iter().enumerate() {
                        for r in rs {
                            let a = k * layer + r.j as usize * l.nx + r.i0 as usize;
                            let cells = a..a + r.len as usize;
                            for (&p, v) in self.belief[cells.clone()]
                                .iter()
                                .zip(&mut self.scratch[cells])
                            {
                                unweighed += p as f64;
                                *v = p * (lambda * (*v - best)).exp();
                                weighed += *v as f64;
                            }
                        }
                    }
                    // (before.sum holds the mass outside the window too)
                    let rest = (before.sum - unweighed).max(0.0) * floor as f64;
                    (rest + weighed, Some((threshold, floor)))
                } else {
                    (before.sum, None)
                }
            }
        };
        // normalised and mixed with the uniform share in one pass over the free cells, which
        // also finds the most probable cell (and, in the selective update, weighs the cells)
        let (s, unscored) = match normaliser(total) {
            Some(s) => (s, unscored),
            None => {
                self.fill_uniform();
                (1.0, None)
            }
        };
        let mix = self.config.uniform_mix as f32;
        let l = &self.layout;
        let (keep, u) = if mix > 0.0 {
            (
                1.0 - mix,
                mix / (self.whole.free_count() * l.n_theta).max(1) as f32,
            )
        } else {
            (1.0, 0.0)
        };
        let mut t = belief_ops::Tally::default();
        for k in 0..l.n_theta {
            for sp in &l.spans {
                let a = k * l.layer() + sp.j as usize * l.nx + sp.i0 as usize;
                let cells = a..a + sp.len as usize;
                match unscored {
                    Some((threshold, floor)) => belief_ops::weigh_and_mix(
                        &mut self.belief[cells.clone()],
                        &self.scratch[cells],
                        threshold,
                        floor,
                        [s, keep, u],
                        &mut t,
                    ),
                    None => belief_ops::scale_and_mix(&mut self.belief[cells], s, keep, u, &mut t),
                }
            }
        }
        // the background as its cells: weighed by the floor, normalised, mixed
        let floor = unscored.map_or(1.0, |(_, floor)| floor as f64);
        self.outside = keep as f64 * (self.outside * floor * s as f64)
            + u as f64 * self.outside_cells() as f64;
        // the most probable cell is the first holding the largest value (for positive, finite
        // values, the first maximum in total_cmp's order)
        let peak = t.peak();
        self.carried = Some(self.carry(&t));
        let best = (peak > 0.0)
            .then(|| belief_ops::find(&self.belief, peak))
            .flatten();
        match (unscored, selective) {
            (Some(_), Some((runs, _))) => self.follow(&runs, best),
            _ => best,
        }
    }
}
