//! Hector-style scan-to-map matching: Gauss-Newton on an occupancy probability grid, after
//! S. Kohlbrecher, O. von Stryk, J. Meyer, U. Klingauf, "A Flexible and Scalable SLAM System with
//! Full 3D Motion Estimation", SSRR 2011, §IV:
//!
//! * map access (§IV.A): M at a point is the bilinear interpolation between the four surrounding
//!   cell centres (eq. 1) and ∇M its analytic gradient (eqs. 2–3), [`PyramidLevel::sample`];
//! * scan matching (§IV.B): ξ = (pₓ, p_y, ψ), S_i(ξ) = R(ψ)·s_i + (pₓ, p_y) is end point i in the
//!   map (eq. 5), ξ* = argmin Σ [1 − M(S_i(ξ))]² (eq. 4). A first-order Taylor expansion of
//!   Σ [1 − M(S_i(ξ + Δξ))]² → 0 (eqs. 6–8) gives the Gauss-Newton step
//!   Δξ = H⁻¹ Σ [∇M(S_i(ξ)) ∂S_i/∂ξ]ᵀ [1 − M(S_i(ξ))] (eq. 9) with
//!   H = Σ [∇M ∂S_i/∂ξ]ᵀ [∇M ∂S_i/∂ξ] (eq. 10) and
//!   ∂S_i/∂ξ = [[1, 0, −sinψ s_x − cosψ s_y], [0, 1, cosψ s_x − sinψ s_y]] (eqs. 11–12);
//! * multi-resolution (§IV.C): the match runs on the coarsest level of a [`MapPyramid`] from the
//!   initial guess and each result seeds the next finer level, so a coarse, wide basin brings the
//!   estimate within reach of the fine, precise one. What M is on each level (surfaces in cells
//!   or on faces, max-combined, smoothed coarse levels) is documented in [`super::map_pyramid`].
//!
//! Our additions, each because a plain Gauss-Newton step can misbehave:
//!
//! * Levenberg damping. We solve (H + μS)Δξ = b with S = diag(1, 1, ℓ²), ℓ the RMS range of the
//!   points (so a rotation of 1/ℓ rad weighs like a 1 m shift), evaluate the objective at the
//!   candidate and accept a step only if it does not increase it (then μ ÷ 10), else retry with
//!   μ × 10. μ never drops below τ·λ_ref (τ = 1e-6, λ_ref the largest diagonal of H in S units),
//!   so an unconstrained direction — a featureless corridor's axis, where H and b vanish — moves
//!   by b/(τ·λ_ref) ≈ 0 instead of by 0/0. A step is also capped at `max_step_cells` cells of the
//!   level and `max_step_theta` (Hector caps the angle update at 0.2 rad). Nothing here produces
//!   NaN: non-finite points are skipped, a non-finite guess is returned untouched, and the solves
//!   are Cholesky factorizations of positive definite matrices.
//! * Points off the level contribute nothing to H and b; in the objective they count as M = 0
//!   (residual 1), so pushing points off the map is never rewarded.
//! * Level k uses every 2^k-th point (`thin_coarse_levels`): halves a match's time, and the
//!   tests' errors and basins did not change.
//! * An optional odometry prior (ξ̂, Λ = diag(λₓ, λ_y, λ_ψ)) makes the objective
//!   F(ξ) = Σ [1 − M(S_i(ξ))]² / σ_M² + (ξ − ξ̂)ᵀ Λ (ξ − ξ̂), ψ − ψ̂ wrapped, σ_M =
//!   `residual_sigma` the standard deviation of 1 − M at a matched end point. Its normal
//!   equations are (H/σ_M² + Λ) Δξ = b/σ_M² − Λ(ξ − ξ̂): where the scan constrains the pose the
//!   prior hardly matters (H/σ_M² is ~10⁶ m⁻² against Λ = 100 m⁻² for σ = 0.1 m), along a
//!   corridor it holds the estimate at the odometry guess.
//! * Covariance. Hector hands back H itself (an information matrix, in map-cell units); we return
//!   C = (H/σ_M² + Λ + εS)⁻¹ at the final estimate on level 0, in SI units: the Gauss-Newton
//!   (Laplace) covariance of F. ε = 1e-12·λ_ref + 1e-9 only keeps it finite: a corridor's axis
//!   without a prior reports σ ≈ 385 m, with a σ = 0.1 m prior 0.1 m. With 12 mm range noise and
//!   σ_M = 0.25 the RMS error over the predicted σ was 0.5–1.0 per axis (the noise test).
//!
//! Measured (`cargo bench -p systems --bench scan_to_map`, hospital map 1280 × 640 at 5 cm,
//! 3-level [`PyramidOptions::static_map`](super::PyramidOptions::static_map) pyramid, SICK
//! LMS100 scans with 12 mm noise from 0.2 m / 0.1 rad off; criterion medians of three runs on
//! the 2 shared cores of the dev container under a load average of 3–6, so upper bounds):
//!
//! | what | medians |
//! |---|---|
//! | match, 1081 beams | 195 / 253 / 268 µs |
//! | match, 270 beams (`max_points` 271) | 52 / 64 / 78 µs |
//! | pyramid full rebuild | 2.1 / 2.9 / 3.1 ms |
//! | `update_region`, 2 m × 2 m window | 9.9 / 15.5 / 13.6 µs |
//! | `update_cells`, the cells under one scan's end points | 107 / 269 / 168 µs |
//!
//! A match plus the pyramid update of a scan's hits is ≈ 0.3–0.55 ms, against the 2 ms a 10 Hz
//! laser at 50× real time allows (a full rebuild per scan would not fit).

use super::map_pyramid::{MapPyramid, PyramidLevel};
use crate::core::{Pose2, wrap_angle};

/// Matcher settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussNewtonParams {
    /// Pyramid levels to use, coarsest first (clamped to the pyramid's levels, at least 1).
    pub levels: usize,
    /// Gauss-Newton evaluations (accepted and rejected steps) allowed per level.
    pub iterations_per_level: usize,
    /// A level has converged when a step moves less than this (metres; scaled by 2^k on level
    /// k: a coarse level cannot resolve finer) ...
    pub min_step_xy: f64,
    /// ... and turns less than this (radians, same scaling).
    pub min_step_theta: f64,
    /// Use at most this many end points (evenly strided over the scan).
    pub max_points: usize,
    /// σ_M: standard deviation of the residual 1 − M at a matched end point; weighs the scan
    /// against the prior and scales the covariance.
    pub residual_sigma: f64,
    /// Level k uses every 2^k-th point: its cells are 2^k times wider, so neighbouring end
    /// points mostly sample the same cells (halves a match's time at no measured loss of
    /// precision or basin).
    pub thin_coarse_levels: bool,
    /// Largest translation per step, in cells of the level being matched.
    pub max_step_cells: f64,
    /// Largest rotation per step (radians).
    pub max_step_theta: f64,
}

impl Default for GaussNewtonParams {
    fn default() -> Self {
        GaussNewtonParams {
            levels: 3,
            iterations_per_level: 20,
            min_step_xy: 1e-4,
            min_step_theta: 1e-4,
            max_points: usize::MAX,
            residual_sigma: 0.25,
            thin_coarse_levels: true,
            max_step_cells: 2.0,
            max_step_theta: 0.2,
        }
    }
}

/// An odometry guess and its information (1/σ², per axis: m⁻², m⁻², rad⁻²) in the units of the
/// objective (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometryPrior {
    pub pose: Pose2,
    pub information: [f64; 3],
}

impl OdometryPrior {
    /// A prior with standard deviations σₓ, σ_y (metres) and σ_ψ (radians).
    pub fn from_std(pose: Pose2, std: [f64; 3]) -> Self {
        OdometryPrior {
            pose,
            information: std.map(|s| 1.0 / (s * s)),
        }
    }
}

/// What a match found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnResult {
    pub pose: Pose2,
    /// Covariance of (x, y, θ) (m², m·rad, rad²), see the module documentation.
    pub covariance: [[f64; 3]; 3],
    /// Mean M at the end points at `pose` on level 0, in [0, 1] (off-map points count 0).
    pub score: f64,
    /// Accepted steps over all levels.
    pub iterations: usize,
    /// Objective evaluations (one pass over the points each) over all levels.
    pub evaluations: usize,
    /// Whether the finest level stopped on a small step rather than on its iteration budget.
    pub converged: bool,
}

/// Damping floor relative to the largest diagonal of H (see the module documentation).
const TAU: f64 = 1e-6;

/// The scan term and prior summed at one pose.
#[derive(Clone, Copy, Debug)]
struct Normal {
    /// F(ξ).
    f: f64,
    /// Upper triangle of H/σ² + Λ: xx, xy, xθ, yy, yθ, θθ.
    h: [f64; 6],
    /// b/σ² − Λ(ξ − ξ̂).
    b: [f64; 3],
    /// Σ M over the points (off-map 0) and the number of points.
    m_sum: f64,
    n: usize,
}

struct Problem<'a> {
    points: &'a [[f32; 2]],
    stride: usize,
    prior: Option<OdometryPrior>,
    inv_var: f64,
}

impl Problem<'_> {
    /// The points used, every `thin`-th of the strided ones.
    fn points(&self, thin: usize) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.points
            .iter()
            .step_by(self.stride * thin)
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .map(|p| [p[0] as f64, p[1] as f64])
    }

    /// F, H and b at `pose` on `level` (eqs. 9–12 plus the prior).
    fn evaluate(&self, level: &PyramidLevel, thin: usize, pose: Pose2) -> Normal {
        let (s, c) = pose.theta.sin_cos();
        let mut h = [0f64; 6];
        let mut b = [0f64; 3];
        let (mut f, mut m_sum, mut n) = (0f64, 0f64, 0usize);
        for [px, py] in self.points(thin) {
            n += 1;
            // S_i(ξ) (eq. 5); (rx, ry) = R(ψ)s_i, so ∂S/∂ψ = (−ry, rx) (eq. 11)
            let (rx, ry) = (c * px - s * py, s * px + c * py);
            let Some(m) = level.sample(pose.x + rx, pose.y + ry) else {
                f += 1.0;
                continue;
            };
            let r = 1.0 - m.value;
            let [gx, gy] = m.gradient;
            let gt = gy * rx - gx * ry;
            f += r * r;
            m_sum += m.value;
            h[0] += gx * gx;
            h[1] += gx * gy;
            h[2] += gx * gt;
            h[3] += gy * gy;
            h[4] += gy * gt;
            h[5] += gt * gt;
            b[0] += gx * r;
            b[1] += gy * r;
            b[2] += gt * r;
        }
        let w = self.inv_var;
        let mut out = Normal {
            f: f * w,
            h: h.map(|v| v * w),
            b: b.map(|v| v * w),
            m_sum,
            n,
        };
        if let Some(p) = &self.prior {
            let e = [
                pose.x - p.pose.x,
                pose.y - p.pose.y,
                wrap_angle(pose.theta - p.pose.theta),
            ];
            for (k, d) in [0, 3, 5].into_iter().enumerate() {
                let l = p.information[k];
                out.f += l * e[k] * e[k];
                out.h[d] += l;
                out.b[k] -= l * e[k];
            }
        }
        out
    }
}

/// Full symmetric matrix of an upper triangle plus `d`·diag(1, 1, ℓ²).
fn damped(h: &[f64; 6], d: f64, l2: f64) -> [[f64; 3]; 3] {
    [
        [h[0] + d, h[1], h[2]],
        [h[1], h[3] + d, h[4]],
        [h[2], h[4], h[5] + d * l2],
    ]
}

/// Cholesky factor L (lower) of a symmetric positive definite 3 × 3 matrix.
pub(crate) fn cholesky(a: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let mut l = [[0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                let d = a[i][i] - s;
                if !(d > 0.0 && d.is_finite()) {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (a[i][j] - s) / l[j][j];
            }
        }
    }
    Some(l)
}

/// Solves L Lᵀ x = b.
fn cholesky_solve(l: &[[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let mut y = [0f64; 3];
    for i in 0..3 {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0f64; 3];
    for i in (0..3).rev() {
        x[i] = (y[i] - (i + 1..3).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

/// The largest diagonal of H in S units (θθ divided by ℓ²).
fn lambda_ref(h: &[f64; 6], l2: f64) -> f64 {
    h[0].max(h[3]).max(h[5] / l2)
}

/// Matches scan end points (sensor frame, metres) against `pyramid`, coarse to fine, from
/// `initial` (the sensor's pose in the map frame), optionally pulled towards an odometry prior.
pub fn match_scan(
    pyramid: &MapPyramid,
    points: &[[f32; 2]],
    initial: Pose2,
    prior: Option<OdometryPrior>,
    params: &GaussNewtonParams,
) -> GnResult {
    let prior = prior.map(|p| OdometryPrior {
        pose: p.pose,
        information: p
            .information
            .map(|l| if l.is_finite() && l > 0.0 { l } else { 0.0 }),
    });
    let sigma = params.residual_sigma;
    let problem = Problem {
        points,
        stride: points.len().div_ceil(params.max_points.max(1)).max(1),
        prior,
        inv_var: if sigma.is_finite() && sigma > 0.0 {
            1.0 / (sigma * sigma)
        } else {
            1.0
        },
    };
    // ℓ²: mean squared range, at least 1 m²
    let (sum_r2, count) = problem
        .points(1)
        .fold((0.0, 0usize), |(s, n), [x, y]| (s + x * x + y * y, n + 1));
    let l2 = if count > 0 {
        (sum_r2 / count as f64).max(1.0)
    } else {
        1.0
    };
    let levels = params.levels.clamp(1, pyramid.levels());
    let mut pose = initial;
    let (mut iterations, mut evaluations, mut converged) = (0, 0, false);
    let finite = |p: &Pose2| p.x.is_finite() && p.y.is_finite() && p.theta.is_finite();
    if finite(&initial) {
        for k in (0..levels).rev() {
            let level = pyramid.level(k);
            let thin = if params.thin_coarse_levels { 1 << k } else { 1 };
            let scale = (1u64 << k) as f64;
            let (min_xy, min_th) = (params.min_step_xy * scale, params.min_step_theta * scale);
            let max_xy = params.max_step_cells * level.resolution;
            let mut cur = problem.evaluate(level, thin, pose);
            evaluations += 1;
            let mut mu = TAU * lambda_ref(&cur.h, l2);
            converged = false;
            let mut budget = params.iterations_per_level;
            while budget > 0 {
                let floor = TAU * lambda_ref(&cur.h, l2);
                mu = mu.max(floor);
                let Some(l) = cholesky(&damped(&cur.h, mu, l2)) else {
                    // H is zero (no point near anything, no prior): nothing to match on
                    break;
                };
                let mut d = cholesky_solve(&l, cur.b);
                let t = d[0].hypot(d[1]);
                let shrink = (max_xy / t)
                    .min(params.max_step_theta / d[2].abs())
                    .min(1.0);
                d = d.map(|v| v * shrink);
                if d[0].hypot(d[1]) < min_xy && d[2].abs() < min_th {
                    converged = true;
                    break;
                }
                let cand = Pose2::new(pose.x + d[0], pose.y + d[1], pose.theta + d[2]);
                let next = problem.evaluate(level, thin, cand);
                evaluations += 1;
                budget -= 1;
                if next.f <= cur.f {
                    pose = cand;
                    cur = next;
                    iterations += 1;
                    mu = (mu / 10.0).max(floor);
                } else {
                    mu *= 10.0;
                }
            }
        }
    }
    let fine = problem.evaluate(pyramid.level(0), 1, pose);
    let eps = 1e-12 * lambda_ref(&fine.h, l2) + 1e-9;
    let covariance = cholesky(&damped(&fine.h, eps, l2))
        .map(|l| {
            let cols =
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| cholesky_solve(&l, e));
            [0, 1, 2].map(|i| [0, 1, 2].map(|j| 0.5 * (cols[j][i] + cols[i][j])))
        })
        .unwrap_or([
            [1.0 / eps, 0.0, 0.0],
            [0.0, 1.0 / eps, 0.0],
            [0.0, 0.0, 1.0 / (eps * l2)],
        ]);
    GnResult {
        pose,
        covariance,
        score: if fine.n > 0 {
            fine.m_sum / fine.n as f64
        } else {
            0.0
        },
        iterations,
        evaluations,
        converged,
    }
}

#[cfg(test)]
mod tests;
