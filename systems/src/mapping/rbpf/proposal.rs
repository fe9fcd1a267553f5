//! GMapping's improved proposal (Grisetti, Stachniss & Burgard, IEEE T-RO 23(1), 2007, §IV):
//! the optimal proposal p(x | m, z, x', u) is peaked around the scan-matched pose x*, so it is
//! approximated by a Gaussian fitted to K points x_j sampled around x* — a grid of ±llsamplerange
//! in x and y at llsamplestep and ±lasamplerange in θ at lasamplestep (the paper's and GMapping's
//! parameter names) — each weighted by τ(x_j) = p(z | m, x_j) · p(x_j | x', u):
//! μ = Σ x_j τ_j / η, Σ = Σ τ_j (x_j − μ)(x_j − μ)ᵀ / η, η = Σ τ_j; the particle's new pose is
//! drawn from N(μ, Σ) and its weight multiplied by η.

use crate::core::moments::weighted_scatter;
use crate::core::{Pose2, wrap_angle};
use crate::matching::gauss_newton::cholesky;

/// The sampling grid around the matched pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleGrid {
    pub llsamplerange: f64,
    pub llsamplestep: f64,
    pub lasamplerange: f64,
    pub lasamplestep: f64,
}

impl SampleGrid {
    /// The offsets (dx, dy, dθ) of the grid's points.
    fn offsets(&self) -> Vec<[f64; 3]> {
        let axis = |range: f64, step: f64| -> Vec<f64> {
            let n = if step > 0.0 {
                (range / step + 1e-9).floor() as i64
            } else {
                0
            };
            (-n..=n).map(|k| k as f64 * step).collect()
        };
        let (lin, ang) = (
            axis(self.llsamplerange, self.llsamplestep),
            axis(self.lasamplerange, self.lasamplestep),
        );
        let mut out = Vec::with_capacity(lin.len() * lin.len() * ang.len());
        for &dx in &lin {
            for &dy in &lin {
                for &dt in &ang {
                    out.push([dx, dy, dt]);
                }
            }
        }
        out
    }
}

/// The fitted Gaussian and the weight factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proposal {
    pub mean: Pose2,
    pub covariance: [[f64; 3]; 3],
    /// log η.
    pub log_eta: f64,
}

/// Fits the proposal around `best` with `log_tau(x)` = log τ(x) (any common constant drops out
/// of the Gaussian and shifts every particle's log η alike).
pub fn fit(best: &Pose2, grid: &SampleGrid, mut log_tau: impl FnMut(&Pose2) -> f64) -> Proposal {
    let offsets = grid.offsets();
    let logs: Vec<f64> = offsets
        .iter()
        .map(|o| {
            log_tau(&Pose2::new(
                best.x + o[0],
                best.y + o[1],
                wrap_angle(best.theta + o[2]),
            ))
        })
        .collect();
    let top = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return Proposal {
            mean: *best,
            covariance: [[0.0; 3]; 3],
            log_eta: f64::NEG_INFINITY,
        };
    }
    let w: Vec<f64> = logs.iter().map(|l| (l - top).exp()).collect();
    let eta: f64 = w.iter().sum();
    let mut mu = [0.0; 3];
    for (o, wi) in offsets.iter().zip(&w) {
        for k in 0..3 {
            mu[k] += o[k] * wi / eta;
        }
    }
    let cov = weighted_scatter(
        offsets
            .iter()
            .zip(&w)
            .map(|(o, &wi)| ([o[0] - mu[0], o[1] - mu[1], o[2] - mu[2]], wi)),
    );
    Proposal {
        mean: Pose2::new(
            best.x + mu[0],
            best.y + mu[1],
            wrap_angle(best.theta + mu[2]),
        ),
        covariance: cov,
        log_eta: top + eta.ln(),
    }
}

impl Proposal {
    /// A draw from N(mean, covariance) given three standard normal numbers `z` (through the
    /// Cholesky factor; directions of zero spread stay at the mean).
    pub fn sample(&self, z: [f64; 3]) -> Pose2 {
        let c = &self.covariance;
        // a direction without spread (a sampling grid of one point along it): per-axis spreads
        let l = cholesky(c).unwrap_or([
            [c[0][0].max(0.0).sqrt(), 0.0, 0.0],
            [0.0, c[1][1].max(0.0).sqrt(), 0.0],
            [0.0, 0.0, c[2][2].max(0.0).sqrt()],
        ]);
        let d = [
            l[0][0] * z[0],
            l[1][0] * z[0] + l[1][1] * z[1],
            l[2][0] * z[0] + l[2][1] * z[1] + l[2][2] * z[2],
        ];
        Pose2::new(
            self.mean.x + d[0],
            self.mean.y + d[1],
            wrap_angle(self.mean.theta + d[2]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRID: SampleGrid = SampleGrid {
        llsamplerange: 0.01,
        llsamplestep: 0.01,
        lasamplerange: 0.005,
        lasamplestep: 0.005,
    };

    #[test]
    fn the_grid_of_the_seed_parameters_has_27_points() {
        assert_eq!(GRID.offsets().len(), 27);
    }

    #[test]
    fn fitted_gaussian_recovers_a_gaussian_likelihood() {
        // τ a Gaussian centred off the matched pose: the fit moves the mean towards it
        let centre = [0.004, -0.003, 0.001];
        let sd = [0.01, 0.01, 0.005];
        let best = Pose2::new(1.0, 2.0, 0.5);
        let p = fit(&best, &GRID, |x| {
            let d = [
                x.x - 1.0 - centre[0],
                x.y - 2.0 - centre[1],
                x.theta - 0.5 - centre[2],
            ];
            -(0..3).map(|k| (d[k] / sd[k]).powi(2)).sum::<f64>() / 2.0
        });
        assert!((p.mean.x - 1.0 - centre[0]).abs() < 0.003, "{p:?}");
        assert!((p.mean.y - 2.0 - centre[1]).abs() < 0.003, "{p:?}");
        assert!(p.mean.x > 1.0 && p.mean.y < 2.0);
        for k in 0..3 {
            assert!(p.covariance[k][k] > 0.0);
        }
        // a draw at z = 0 is the mean; spreads follow the covariance
        assert_eq!(p.sample([0.0; 3]), p.mean);
        let s = p.sample([1.0, 0.0, 0.0]);
        assert!((s.x - p.mean.x - p.covariance[0][0].sqrt()).abs() < 1e-12);
    }

    #[test]
    fn eta_grows_with_the_likelihood_and_impossible_poses_give_minus_infinity() {
        let best = Pose2::default();
        let good = fit(&best, &GRID, |_| -1.0);
        let bad = fit(&best, &GRID, |_| -5.0);
        assert!((good.log_eta - bad.log_eta - 4.0).abs() < 1e-9);
        assert!((good.log_eta - (-1.0 + 27f64.ln())).abs() < 1e-9);
        let none = fit(&best, &GRID, |_| f64::NEG_INFINITY);
        assert_eq!(none.log_eta, f64::NEG_INFINITY);
        assert_eq!(none.sample([1.0, 1.0, 1.0]), best);
    }
}
