//! Local refinement of a transform by point-to-line ICP solved with Gauss–Newton (Censi,
//! "An ICP variant using a point-to-line metric", ICRA 2008; Chen & Medioni 1992): the final
//! step of the improved matcher, which polishes the coarse hypothesis the way the thesis's DE
//! polishes its best member over thousands of generations ([Hospital thesis §6]), but in
//! a handful of iterations.
//!
//! Each iteration moves the current points by the estimate, looks their nearest reference point
//! up in the nearest-index grid ([`super::ref_grid`]) and checks the two beams on either side of
//! it (the grid stores the point nearest to the cell centre, its scan neighbours may be nearer to
//! the query), then minimises `Σ w · (nᵀ(R b + t − a))²` over `(t_x, t_y, θ)` with the
//! reference normal `n`. Between two samples of one surface the line is the segment joining
//! them ([`Reference::line_at`]). Where the reference has no normal, or where the moved point
//! lies beyond the end of the reference surface (its offset along the surface exceeds
//! `end_tangent`, e.g. past a door jamb), the residual is point-to-point instead:
//! point-to-line alone would let a scan slide along a corridor, since only the ends of walls
//! say where along it the robot is.
//! Pairs farther apart than a gate are dropped; the gate shrinks geometrically from `gate_start`
//! to `gate_end`, and a Huber weight tempers the remaining outliers. A tiny Levenberg damping
//! keeps directions the scene does not constrain at all where the coarse search put them.

use super::de::Vector;
use super::ref_grid::NearestGrid;

/// Refinement settings.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RefineParams {
    pub iterations: usize,
    pub gate_start: f32,
    pub gate_end: f32,
    /// Huber threshold (m).
    pub huber: f32,
    /// Offset along the reference surface beyond which a pair is point-to-point (m).
    pub end_tangent: f32,
}

/// The reference side of the refinement.
pub(crate) struct Reference<'a> {
    pub points: &'a [[f32; 2]],
    pub normals: &'a [Option<[f32; 2]>],
    pub grid: &'a NearestGrid,
}

impl Reference<'_> {
    /// The nearest reference point to `q` among the grid's candidate and its scan neighbours:
    /// (index, squared distance).
    #[inline]
    pub fn nearest(&self, q: [f32; 2]) -> Option<(usize, f32)> {
        let a = self.grid.lookup(q)?;
        let lo = a.saturating_sub(2);
        let hi = (a + 3).min(self.points.len());
        let mut best = (a, f32::INFINITY);
        for (j, p) in self.points[lo..hi].iter().enumerate() {
            let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
            if d2 < best.1 {
                best = (lo + j, d2);
            }
        }
        Some(best)
    }

    /// The reference surface at `q`, nearest point `a`: `Some((anchor, normal))` where `q` lies
    /// on a line of the reference (within `end_tangent` along it of point `a`, or over the
    /// segment from `a` to its scan neighbour on the same surface), `None` where it lies beyond
    /// the end of a surface or `a` has no normal (then point to point).
    ///
    /// The segments matter where the reference samples a wall sparsely (far away or at a grazing
    /// angle): with `a`'s tangent alone, a point between two samples 0.2 m apart would count as
    /// off the surface, and the judgement and the refinement would favour shifts that line the
    /// samples of the two scans up, 0.1–0.2 m along a corridor from the truth.
    #[inline]
    pub fn line_at(&self, q: [f32; 2], a: usize, end_tangent: f32) -> Option<([f32; 2], [f32; 2])> {
        let n = self.normals[a]?;
        let p = self.points[a];
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let along = dx * n[1] - dy * n[0];
        if along.abs() <= end_tangent {
            return Some((p, n));
        }
        // the scan neighbour on the side of q, if it continues the same surface
        for b in [a.checked_sub(1), Some(a + 1)].into_iter().flatten() {
            let (Some(&pb), Some(Some(nb))) = (self.points.get(b), self.normals.get(b)) else {
                continue;
            };
            let (ex, ey) = (pb[0] - p[0], pb[1] - p[1]);
            let len2 = ex * ex + ey * ey;
            let across = ex * n[0] + ey * n[1];
            // near enough, facing the same way, and along a's line (not a step behind it)
            let continues = len2 > 0.0
                && len2 <= SEGMENT_GAP * SEGMENT_GAP
                && n[0] * nb[0] + n[1] * nb[1] >= SEGMENT_COS
                && across * across <= SEGMENT_SLOPE * SEGMENT_SLOPE * len2;
            if !continues {
                continue;
            }
            // q's offset along the segment from a: past a, and at most end_tangent past b
            let len = len2.sqrt();
            let inv = 1.0 / len;
            let offset = (dx * ex + dy * ey) * inv;
            if offset > 0.0 && offset <= len + end_tangent {
                let mut m = [-ey * inv, ex * inv];
                if m[0] * n[0] + m[1] * n[1] < 0.0 {
                    m = [-m[0], -m[1]];
                }
                return Some((p, m));
            }
        }
        None
    }

    /// Distance from `q` to the reference surface: point to line where [`Self::line_at`] finds
    /// a line, else point to point. `None` if no reference point is near.
    #[inline]
    pub fn distance(&self, q: [f32; 2], end_tangent: f32) -> Option<f32> {
        let (a, d2) = self.nearest(q)?;
        Some(match self.line_at(q, a, end_tangent) {
            Some((p, n)) => ((q[0] - p[0]) * n[0] + (q[1] - p[1]) * n[1]).abs(),
            None => d2.sqrt(),
        })
    }
}

/// Longest gap (m) between two scan neighbours of the reference that [`Reference::line_at`]
/// bridges as one surface, the smallest cosine between their normals (20°) and the largest
/// slope of the segment across the first one's line.
const SEGMENT_GAP: f32 = 0.5;
const SEGMENT_COS: f32 = 0.94;
const SEGMENT_SLOPE: f32 = 0.25;

/// The result of [`refine`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Refined {
    pub x: Vector,
    /// The translation direction the last iteration's correspondences constrain least (unit),
    /// and the ratio of its information to that of the best constrained direction (the
    /// eigenvalues of the translation block of JᵀWJ): near 0 in a featureless corridor.
    pub weak_direction: [f64; 2],
    pub weak_ratio: f64,
}

/// Refines `start` (the transform moving `current` into the reference frame).
pub(crate) fn refine(
    reference: &Reference,
    current: &[[f32; 2]],
    start: Vector,
    params: &RefineParams,
) -> Refined {
    let mut x = start;
    let mut weak = ([1.0, 0.0], 1.0);
    let mut gate = params.gate_start.max(params.gate_end);
    for _ in 0..params.iterations.max(1) {
        let g2 = gate * gate;
        let (s, c) = x[2].sin_cos();
        let (sf, cf, tx, ty) = (s as f32, c as f32, x[0] as f32, x[1] as f32);
        let mut hm = [[0f64; 3]; 3];
        let mut g = [0f64; 3];
        let mut used = 0usize;
        let mut add = |j: [f64; 3], r: f64, w: f64| {
            for a in 0..3 {
                g[a] += w * j[a] * r;
                for b in 0..3 {
                    hm[a][b] += w * j[a] * j[b];
                }
            }
        };
        for b in current {
            let rx = cf * b[0] - sf * b[1];
            let ry = sf * b[0] + cf * b[1];
            let q = [rx + tx, ry + ty];
            let Some((a, d2)) = reference.nearest(q) else {
                continue;
            };
            if d2 > g2 {
                continue;
            }
            // ∂q/∂θ = (−ry, rx)
            let (jx, jy) = (-ry as f64, rx as f64);
            used += 1;
            // point-to-line unless the pair lies off the end of the reference surface
            match reference.line_at(q, a, params.end_tangent) {
                Some((p, n)) => {
                    let (dx, dy) = ((q[0] - p[0]) as f64, (q[1] - p[1]) as f64);
                    let (nx, ny) = (n[0] as f64, n[1] as f64);
                    let r = nx * dx + ny * dy;
                    add([nx, ny, nx * jx + ny * jy], r, huber(r, params.huber));
                }
                None => {
                    let p = reference.points[a];
                    let (dx, dy) = ((q[0] - p[0]) as f64, (q[1] - p[1]) as f64);
                    let w = huber((dx * dx + dy * dy).sqrt(), params.huber);
                    add([1.0, 0.0, jx], dx, w);
                    add([0.0, 1.0, jy], dy, w);
                }
            }
        }
        if used < 3 {
            break;
        }
        weak = weakest_translation(hm[0][0], hm[0][1], hm[1][1]);
        let damping = 1e-6 * (hm[0][0] + hm[1][1] + hm[2][2]) + 1e-12;
        for (d, row) in hm.iter_mut().enumerate() {
            row[d] += damping;
        }
        let Some(delta) = solve3(&hm, &[-g[0], -g[1], -g[2]]) else {
            break;
        };
        x[0] += delta[0];
        x[1] += delta[1];
        x[2] = crate::core::wrap_angle(x[2] + delta[2]);
        let small = delta[0].abs() < 1e-5 && delta[1].abs() < 1e-5 && delta[2].abs() < 1e-6;
        if small && gate <= params.gate_end {
            break;
        }
        gate = (gate * 0.7).max(params.gate_end);
    }
    Refined {
        x,
        weak_direction: weak.0,
        weak_ratio: weak.1,
    }
}

/// Unit eigenvector of the smaller eigenvalue of [[a, b], [b, c]] and the ratio small / large.
fn weakest_translation(a: f64, b: f64, c: f64) -> ([f64; 2], f64) {
    let half_tr = 0.5 * (a + c);
    let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l_max, l_min) = (half_tr + disc, half_tr - disc);
    let (u, v) = ([b, l_min - a], [l_min - c, b]);
    let (nu, nv) = (u[0] * u[0] + u[1] * u[1], v[0] * v[0] + v[1] * v[1]);
    let (e, n2) = if nu >= nv { (u, nu) } else { (v, nv) };
    if n2.is_nan() || n2 <= 1e-30 || l_max.is_nan() || l_max <= 0.0 {
        // isotropic (or empty): any direction is as weak as any other
        return ([1.0, 0.0], 1.0);
    }
    let inv = 1.0 / n2.sqrt();
    ([e[0] * inv, e[1] * inv], (l_min / l_max).max(0.0))
}

#[inline]
fn huber(r: f64, k: f32) -> f64 {
    let a = r.abs();
    let k = k as f64;
    if a <= k { 1.0 } else { k / a }
}

/// Solves the symmetric 3 × 3 system by Cramer's rule; `None` if singular.
fn solve3(m: &[[f64; 3]; 3], b: &[f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    if !d.is_finite() || d.abs() <= 1e-300 {
        return None;
    }
    let mut out = [0.0; 3];
    for (col, o) in out.iter_mut().enumerate() {
        let mut mc = *m;
        for row in 0..3 {
            mc[row][col] = b[row];
        }
        *o = det(&mc) / d;
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matching::normals::estimate_normals;

    #[test]
    fn converges_on_a_room() {
        // a 6 × 4 m room outline with a pillar, sampled every 2 cm
        let mut pts = Vec::new();
        for k in 0..300 {
            pts.push([3.0, -2.0 + 4.0 * k as f32 / 300.0]);
        }
        for k in 0..300 {
            pts.push([3.0 - 6.0 * k as f32 / 300.0, 2.0]);
        }
        for k in 0..200 {
            pts.push([-3.0, 2.0 - 4.0 * k as f32 / 200.0]);
        }
        for k in 0..30 {
            pts.push([0.5 + 0.01 * k as f32, -1.0]);
        }
        let normals = estimate_normals(&pts, 0.3, 0.3);
        let grid = NearestGrid::build(&pts, 0.1, 0.4, 3);
        let reference = Reference {
            points: &pts,
            normals: &normals,
            grid: &grid,
        };
        // current = reference seen from a pose displaced by truth
        let truth = [0.12f64, -0.08, 0.03];
        let (s, c) = truth[2].sin_cos();
        let current: Vec<[f32; 2]> = pts
            .iter()
            .map(|p| {
                let (dx, dy) = (p[0] as f64 - truth[0], p[1] as f64 - truth[1]);
                [(c * dx + s * dy) as f32, (-s * dx + c * dy) as f32]
            })
            .collect();
        let params = RefineParams {
            iterations: 15,
            gate_start: 0.4,
            gate_end: 0.1,
            huber: 0.05,
            end_tangent: 0.06,
        };
        let x = refine(&reference, &current, [0.0, 0.0, 0.0], &params).x;
        assert!((x[0] - truth[0]).abs() < 2e-3, "{x:?}");
        assert!((x[1] - truth[1]).abs() < 2e-3, "{x:?}");
        assert!((x[2] - truth[2]).abs() < 1e-3, "{x:?}");
    }

    #[test]
    fn a_sparsely_sampled_wall_is_a_surface_between_its_samples() {
        // a wall y = 3 sampled every 0.3 m (far away or at a grazing angle), then a step back
        // to y = 3.4 (a door recess) and a wall at right angles
        let mut pts: Vec<[f32; 2]> = (0..10).map(|k| [0.3 * k as f32, 3.0]).collect();
        pts.extend((0..5).map(|k| [3.0 + 0.3 * k as f32, 3.4]));
        let normals = estimate_normals(&pts, 0.5, 1.5);
        assert!(normals.iter().all(|n| n.is_some()), "{normals:?}");
        let grid = NearestGrid::build(&pts, 0.1, 0.5, 3);
        let reference = Reference {
            points: &pts,
            normals: &normals,
            grid: &grid,
        };
        // between two samples, 1 cm off the wall: 1 cm, not the 15 cm to the nearer sample
        let d = reference.distance([1.05, 2.99], 0.06).unwrap();
        assert!((d - 0.01).abs() < 1e-3, "{d}");
        // the gap from the wall to the recess is not bridged: point to point there
        let q = [2.85, 3.19];
        let d = reference.distance(q, 0.06).unwrap();
        let nearest = pts
            .iter()
            .map(|p| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(f32::INFINITY, f32::min);
        assert!((d - nearest).abs() < 1e-5, "{d} vs {nearest}");
        // past the wall's last sample by more than end_tangent: point to point
        let d = reference.distance([-0.2, 3.0], 0.06).unwrap();
        assert!((d - 0.2).abs() < 1e-5, "{d}");
    }

    #[test]
    fn weak_direction_is_along_a_corridor() {
        // two walls along x: translation along x is unconstrained
        let (d, ratio) = weakest_translation(0.0, 0.0, 50.0);
        assert!((d[0].abs() - 1.0).abs() < 1e-12 && d[1].abs() < 1e-12 && ratio == 0.0);
        // walls at 45°: normals along (1, −1)/√2, weak direction (1, 1)/√2
        let (d, ratio) = weakest_translation(25.0, -25.0, 25.0);
        assert!((d[0] - d[1]).abs() < 1e-9 && ratio < 1e-12);
        let (_, ratio) = weakest_translation(10.0, 0.0, 10.0);
        assert_eq!(ratio, 1.0);
    }

    #[test]
    fn singular_systems_are_reported() {
        assert!(solve3(&[[0.0; 3]; 3], &[1.0, 1.0, 1.0]).is_none());
        let x = solve3(
            &[[2.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 1.0]],
            &[2.0, 2.0, 3.0],
        )
        .unwrap();
        assert_eq!(x, [1.0, 0.5, 3.0]);
    }
}
