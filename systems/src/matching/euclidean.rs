//! The thesis's reference fitness — sum of minimum Euclidean distances — in its brute-force form
//! ([Hospital thesis §7.1], the pseudo-code "Sumační minimální euklidovská vzdálenost"),
//! and a fast form on a precomputed distance field.
//!
//! **Brute force** ([`euclidean_brute`]), exactly as §7.1 describes it: move the current scan B
//! by `p` (`b ↦ R(ω) b + (p_x, p_y)`), then for every reference point `a ∈ A` find the nearest
//! moved point and add that distance:
//! `E(p) = Σ_{a ∈ A} min_{b ∈ B} ‖a − (R(ω) b + t)‖`. O(|A|·|B|) per evaluation; lower is better.
//!
//! **Distance field** ([`EuclideanField`]): the field is built once per match from the reference
//! A, so the fast form sums over the other set:
//! `E_field(p) = Σ_{b ∈ B} D(R(ω) b + t)`, where
//! `D(q) = min(τ, min_{a ∈ A} ‖c(q) − a‖)` and `c(q)` is the centre of the field cell containing
//! `q` (outside the field, `D = τ`). It therefore differs from the brute force in three ways:
//! 1. it sums over the *current* points (distance to the nearest *reference* point), not over the
//!    reference points — the two sums agree when both scans see the same surfaces, and differ by
//!    what only one of the scans sees;
//! 2. each term is truncated at τ, so points without a counterpart (occlusions, the part of the
//!    room only one scan sees) add at most τ instead of dominating the sum;
//! 3. the distance is looked up at the cell centre: since the exact distance is 1-Lipschitz,
//!    `|D(q) − min(τ, d_A(q))| ≤ cell/√2` for every point, so
//!    `|E_field(p) − Σ_b min(τ, d_A(R b + t))| ≤ |B| · cell/√2`.
//!
//! Cost: O(|A| · (2τ/cell)²) to build (each reference point stamps the cells within τ with its
//! exact distance, keeping the minimum), O(|B|) per evaluation.

use super::de::Vector;
use super::error::MatchError;
use super::ref_grid::MAX_GRID_CELLS;

/// §7.1: `Σ_{a ∈ reference} min_{b ∈ current} ‖a − (R(ω) b + t)‖`, brute force. Non-finite
/// points are skipped; returns +∞ if either set has no finite point.
pub fn euclidean_brute(reference: &[[f32; 2]], current: &[[f32; 2]], p: &Vector) -> f64 {
    let (s, c) = p[2].sin_cos();
    let (s, c) = (s as f32, c as f32);
    let (tx, ty) = (p[0] as f32, p[1] as f32);
    // moved current scan, as two coordinate arrays so the inner loop vectorises
    let (mut xs, mut ys) = (
        Vec::with_capacity(current.len()),
        Vec::with_capacity(current.len()),
    );
    for b in current {
        if b[0].is_finite() && b[1].is_finite() {
            xs.push(c * b[0] - s * b[1] + tx);
            ys.push(s * b[0] + c * b[1] + ty);
        }
    }
    if xs.is_empty() {
        return f64::INFINITY;
    }
    let mut sum = 0.0f64;
    let mut any = false;
    for a in reference {
        if !(a[0].is_finite() && a[1].is_finite()) {
            continue;
        }
        any = true;
        let mut best = f32::INFINITY;
        for (x, y) in xs.iter().zip(&ys) {
            let (dx, dy) = (x - a[0], y - a[1]);
            best = best.min(dx * dx + dy * dy);
        }
        sum += (best as f64).sqrt();
    }
    if any { sum } else { f64::INFINITY }
}

/// Truncated Euclidean distance to a reference point set, sampled at cell centres.
#[derive(Clone, Debug)]
pub struct EuclideanField {
    origin: [f32; 2],
    cell: f32,
    inv_cell: f32,
    w: usize,
    h: usize,
    truncation: f32,
    /// Row-major distances (m), ≤ truncation.
    dist: Vec<f32>,
}

impl EuclideanField {
    /// Builds the field of `reference` with square cells of `cell` metres, truncated at
    /// `truncation` metres. The field covers the reference points' bounding box plus the
    /// truncation distance; non-finite points are ignored.
    pub fn new(reference: &[[f32; 2]], cell: f32, truncation: f32) -> Result<Self, MatchError> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "field.cell",
                value: cell as f64,
                expected: "a finite cell size > 0 m",
            });
        }
        if !(truncation.is_finite() && truncation > 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "field.truncation",
                value: truncation as f64,
                expected: "a finite distance > 0 m",
            });
        }
        let pts: Vec<[f32; 2]> = reference
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .copied()
            .collect();
        if pts.is_empty() {
            return Err(MatchError::EmptyReference);
        }
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for p in &pts {
            for j in 0..2 {
                lo[j] = lo[j].min(p[j]);
                hi[j] = hi[j].max(p[j]);
            }
        }
        let origin = [lo[0] - truncation - cell, lo[1] - truncation - cell];
        let w = ((hi[0] - origin[0] + truncation) / cell).ceil() as usize + 2;
        let h = ((hi[1] - origin[1] + truncation) / cell).ceil() as usize + 2;
        let cells = w.checked_mul(h).filter(|&n| n <= MAX_GRID_CELLS).ok_or(
            MatchError::InvalidParameter {
                name: "field.cell",
                value: cell as f64,
                expected: "a cell size giving at most 64 Mi cells over the reference scan",
            },
        )?;
        let mut dist = vec![truncation; cells];
        let inv_cell = 1.0 / cell;
        let reach = (truncation * inv_cell).ceil() as i64 + 1;
        let t2 = truncation * truncation;
        for a in &pts {
            let ac = ((a[0] - origin[0]) * inv_cell).floor() as i64;
            let ar = ((a[1] - origin[1]) * inv_cell).floor() as i64;
            let (c0, c1) = ((ac - reach).max(0), (ac + reach).min(w as i64 - 1));
            let (r0, r1) = ((ar - reach).max(0), (ar + reach).min(h as i64 - 1));
            for r in r0..=r1 {
                let cy = origin[1] + (r as f32 + 0.5) * cell - a[1];
                let row = &mut dist[r as usize * w..(r as usize + 1) * w];
                for col in c0..=c1 {
                    let cx = origin[0] + (col as f32 + 0.5) * cell - a[0];
                    let d2 = cx * cx + cy * cy;
                    if d2 < t2 {
                        let d = d2.sqrt();
                        let slot = &mut row[col as usize];
                        if d < *slot {
                            *slot = d;
                        }
                    }
                }
            }
        }
        Ok(EuclideanField {
            origin,
            cell,
            inv_cell,
            w,
            h,
            truncation,
            dist,
        })
    }

    /// Cell size (m).
    pub fn cell(&self) -> f32 {
        self.cell
    }

    /// Truncation distance τ (m).
    pub fn truncation(&self) -> f32 {
        self.truncation
    }

    /// `D(q)`: the truncated distance at the centre of the cell containing `q` (τ outside).
    #[inline(always)]
    pub fn distance(&self, q: [f32; 2]) -> f32 {
        let u = (q[0] - self.origin[0]) * self.inv_cell;
        let v = (q[1] - self.origin[1]) * self.inv_cell;
        if u >= 0.0 && v >= 0.0 && u < self.w as f32 && v < self.h as f32 {
            let (c, r) = ((u as usize).min(self.w - 1), (v as usize).min(self.h - 1));
            self.dist[r * self.w + c]
        } else {
            self.truncation
        }
    }

    /// `E_field(p) = Σ_{b ∈ current} D(R(ω) b + t)` (lower is better). Non-finite points add τ.
    pub fn sum(&self, current: &[[f32; 2]], p: &Vector) -> f64 {
        let (s, c) = p[2].sin_cos();
        let (s, c) = (s as f32, c as f32);
        let (tx, ty) = (p[0] as f32, p[1] as f32);
        let mut sum = 0.0f64;
        for b in current {
            let q = [c * b[0] - s * b[1] + tx, s * b[0] + c * b[1] + ty];
            sum += self.distance(q) as f64;
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brute_force_is_the_sum_over_reference_points() {
        let a = [[0.0, 0.0], [1.0, 0.0], [5.0, 0.0]];
        let b = [[0.0, 0.5], [1.0, 0.0]];
        // distances: (0,0)->(0,0.5) 0.5; (1,0)->(1,0) 0; (5,0)->(1,0) 4
        assert!((euclidean_brute(&a, &b, &[0.0; 3]) - 4.5).abs() < 1e-6);
        // swapping the roles sums over b: 0.5 + 0
        assert!((euclidean_brute(&b, &a, &[0.0; 3]) - 0.5).abs() < 1e-6);
        // moving b by (0, −0.5) puts its first point on (0, 0)
        assert!(
            (euclidean_brute(&a, &b, &[0.0, -0.5, 0.0]) - (0.5 + 4.0f64.hypot(0.5))).abs() < 1e-5
        );
        assert!(euclidean_brute(&a, &[], &[0.0; 3]).is_infinite());
    }

    #[test]
    fn field_is_exact_at_cell_centres_and_truncated() {
        let f = EuclideanField::new(&[[0.0, 0.0]], 0.1, 0.5).unwrap();
        // the cell containing (0.32, 0.0) has its centre within 0.05 m of it on each axis
        let d = f.distance([0.32, 0.0]);
        assert!((d - 0.32).abs() <= 0.1 / 2f32.sqrt() + 1e-6, "{d}");
        assert_eq!(f.distance([3.0, 0.0]), 0.5);
        assert_eq!(f.distance([0.0, 0.45 + 0.2]), 0.5);
        assert_eq!(f.sum(&[[3.0, 0.0], [f32::NAN, 0.0]], &[0.0; 3]), 1.0);
    }

    #[test]
    fn bad_field_parameters_are_errors() {
        assert!(EuclideanField::new(&[[0.0, 0.0]], 0.0, 0.5).is_err());
        assert!(EuclideanField::new(&[[0.0, 0.0]], 0.1, f32::NAN).is_err());
        assert_eq!(
            EuclideanField::new(&[], 0.1, 0.5).unwrap_err(),
            MatchError::EmptyReference
        );
        assert!(EuclideanField::new(&[[0.0, 0.0], [1e6, 1e6]], 1e-3, 0.5).is_err());
    }
}
