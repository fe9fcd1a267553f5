//! The hot kernels of the road localizers, plain functions over slices: the grid's motion
//! (a Gaussian integrated over 2 m cells), its Bayes correction and acceptance test
//! ([Park thesis §5.3.2, §5.5]), and the MCL's effective sample size and
//! low-variance resampling (Probabilistic Robotics Table 4.4).

/// Standard normal CDF Φ(x), by the complementary error function of Numerical Recipes
/// (`erfcc`, fractional error below 1.2e-7).
pub fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let erfc = t * poly.exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// Adds `mass` distributed as N(t, σ²) to the cells of length `h` (integrated over each cell);
/// returns the mass falling before the first and after the last cell.
pub fn spread_gaussian(cells: &mut [f64], h: f64, t: f64, sigma: f64, mass: f64) -> (f64, f64) {
    let sigma = sigma.max(1e-9);
    let len = h * cells.len() as f64;
    let below = mass * normal_cdf(-t / sigma);
    let above = mass * (1.0 - normal_cdf((len - t) / sigma));
    if h > 0.0 {
        let lo = ((t - 6.0 * sigma) / h).floor().max(0.0) as usize;
        let hi = (((t + 6.0 * sigma) / h).ceil().max(0.0) as usize).min(cells.len());
        let mut prev = normal_cdf((lo as f64 * h - t) / sigma);
        for (j, c) in cells.iter_mut().enumerate().take(hi).skip(lo) {
            let next = normal_cdf(((j + 1) as f64 * h - t) / sigma);
            *c += mass * (next - prev);
            prev = next;
        }
    }
    (below, above)
}

/// Bayes correction: `p[i] *= exp(ll[i])`, normalized (shifted by the largest `ll` of a cell
/// with mass, so nothing underflows). False if no mass is left.
pub fn apply_log_likelihood(p: &mut [f64], ll: &[f64]) -> bool {
    let top = p
        .iter()
        .zip(ll)
        .filter(|(p, _)| **p > 0.0)
        .map(|(_, l)| *l)
        .fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return false;
    }
    let mut sum = 0.0;
    for (p, l) in p.iter_mut().zip(ll) {
        *p *= (l - top).exp();
        sum += *p;
    }
    if !(sum > 0.0 && sum.is_finite()) {
        return false;
    }
    p.iter_mut().for_each(|p| *p /= sum);
    true
}

/// The thesis's acceptance test (§5.5): the index of the strict global maximum of `p` if it
/// exceeds `ratio` × the `percentile` (nearest rank) of the other cells.
pub fn accept_cell(
    p: &[f64],
    ratio: f64,
    percentile: f64,
    scratch: &mut Vec<f64>,
) -> Option<usize> {
    let (best, top) =
        p.iter()
            .enumerate()
            .fold(None, |b: Option<(usize, f64)>, (i, &v)| match b {
                Some((_, bv)) if bv >= v => b,
                _ => Some((i, v)),
            })?;
    scratch.clear();
    scratch.extend(
        p.iter()
            .enumerate()
            .filter(|&(i, _)| i != best)
            .map(|(_, &v)| v),
    );
    if scratch.is_empty() {
        return Some(best);
    }
    if scratch.iter().any(|&v| v >= top) {
        return None;
    }
    let m = scratch.len();
    let k = ((percentile * m as f64).ceil() as usize).clamp(1, m) - 1;
    let q = *scratch.select_nth_unstable_by(k, f64::total_cmp).1;
    (top > ratio * q).then_some(best)
}

/// N_eff = 1 / Σw² of normalized weights.
pub fn effective_sample_size(weights: &[f64]) -> f64 {
    1.0 / weights
        .iter()
        .map(|w| w * w)
        .sum::<f64>()
        .max(f64::MIN_POSITIVE)
}

/// Low-variance resampling (Probabilistic Robotics Table 4.4): the indices picked by a comb of
/// `weights.len()` teeth offset by `u` ∈ [0, 1), from normalized weights.
pub fn low_variance_indices(weights: &[f64], u: f64, out: &mut Vec<usize>) {
    out.clear();
    let n = weights.len();
    let (mut i, mut c) = (0, weights.first().copied().unwrap_or(0.0));
    for m in 0..n {
        let target = (u + m as f64) / n as f64;
        while target > c && i + 1 < n {
            i += 1;
            c += weights[i];
        }
        out.push(i);
    }
}
