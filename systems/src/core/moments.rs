//! The weighted second moment of pose differences, the covariance estimators of the SLAM
//! filters and matchers share (the proposal's Gaussian fit, the RBPF's particle spread, the DE
//! population's spread).

/// Σ wᵢ dᵢ dᵢᵀ / Σ wᵢ of (difference (x, y, θ), weight) pairs, the differences already taken about
/// the centre (and their angles wrapped); zero when the weights sum to zero.
pub fn weighted_scatter(samples: impl IntoIterator<Item = ([f64; 3], f64)>) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    let mut total = 0.0;
    for (d, w) in samples {
        total += w;
        for a in 0..3 {
            for b in 0..3 {
                m[a][b] += w * d[a] * d[b];
            }
        }
    }
    if total > 0.0 {
        m.iter_mut().flatten().for_each(|v| *v /= total);
    }
    m
}

#[cfg(test)]
mod tests {
    #[test]
    fn scatter_of_two_weighted_points() {
        let m = super::weighted_scatter([([1.0, 0.0, 0.5], 3.0), ([-1.0, 2.0, 0.0], 1.0)]);
        assert_eq!(m[0][0], 1.0);
        assert_eq!(m[1][1], 1.0);
        assert_eq!(m[0][1], -0.5);
        assert_eq!(m[2][2], 0.75 * 0.25);
        assert_eq!(
            m,
            [
                [m[0][0], m[1][0], m[2][0]],
                [m[0][1], m[1][1], m[2][1]],
                [m[0][2], m[1][2], m[2][2]]
            ]
        );
        assert_eq!(
            super::weighted_scatter([([1.0, 1.0, 1.0], 0.0)]),
            [[0.0; 3]; 3]
        );
    }
}
