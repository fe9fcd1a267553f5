//! Resampling with an adaptive particle count.
//!
//! - Low-variance (systematic) resampling, Probabilistic Robotics Table 4.4: one random offset u
//!   and a comb of evenly spaced pointers into the cumulative weights.
//! - KLD-sampling (Fox, "Adapting the Sample Size in Particle Filters Through KLD-Sampling",
//!   IJRR 22(12), 2003, eq. 8; Probabilistic Robotics Table 8.4): draw until the count reaches
//!   n = (k−1)/(2ε)·(1 − 2/(9(k−1)) + √(2/(9(k−1)))·z_{1−δ})³, k the number of histogram bins the
//!   new particles occupy. Because the count is not known in advance, the comb's teeth are taken
//!   in van der Corput (bit-reversed) order: every prefix of the sequence is itself an evenly
//!   spread comb, so stopping early still gives a low-variance sample.
//! - Random-particle injection of Augmented MCL (Probabilistic Robotics Table 8.3): each new
//!   particle is drawn uniformly over free space with probability max(0, 1 − w_fast/w_slow).

use rand::Rng;
use rand::RngExt;
use rustc_hash::FxHashSet;

/// The i-th element of the base-2 van der Corput sequence in [0, 1).
fn van_der_corput(i: u32) -> f64 {
    i.reverse_bits() as f64 / 4_294_967_296.0
}

/// The standard normal quantile Φ⁻¹(p), p ∈ (0, 1) (Acklam's rational approximation, relative
/// error below 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// Fox's bound on the particle count for `k` occupied bins, error `epsilon` and normal quantile
/// `z` = Φ⁻¹(1 − δ).
pub fn kld_bound(k: usize, epsilon: f64, z: f64) -> usize {
    if k <= 1 {
        return 1;
    }
    let km1 = (k - 1) as f64;
    let a = 2.0 / (9.0 * km1);
    let b = 1.0 - a + a.sqrt() * z;
    (km1 / (2.0 * epsilon) * b * b * b).ceil() as usize
}

/// Histogram bin of a pose for KLD-sampling and clustering (AMCL: 0.5 m, 0.5 m, 10°).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinSize {
    pub xy: f64,
    pub theta: f64,
}

impl Default for BinSize {
    fn default() -> Self {
        BinSize {
            xy: 0.5,
            theta: 10f64.to_radians(),
        }
    }
}

impl BinSize {
    pub fn key(&self, x: f64, y: f64, th: f64) -> (i32, i32, i32) {
        (
            (x / self.xy).floor() as i32,
            (y / self.xy).floor() as i32,
            (th / self.theta).floor() as i32,
        )
    }
}

/// Low-variance (systematic) resampling, Probabilistic Robotics Table 4.4: the indices of `n`
/// particles drawn from the (not necessarily normalised) weights `w` by a comb of `n` evenly
/// spaced pointers starting at `u · total / n`, `u` ∈ [0, 1). Every particle of weight at least
/// total/n is drawn at least once.
pub fn low_variance_indices(w: &[f64], n: usize, u: f64) -> Vec<usize> {
    if w.is_empty() {
        return Vec::new();
    }
    let total: f64 = w.iter().sum();
    let step = total.max(f64::MIN_POSITIVE) / n.max(1) as f64;
    let mut out = Vec::with_capacity(n);
    let (mut j, mut acc) = (0, w[0]);
    for i in 0..n {
        let pos = (u + i as f64) * step;
        while pos > acc && j + 1 < w.len() {
            j += 1;
            acc += w[j];
        }
        out.push(j);
    }
    out
}

/// `s mod 1` for s ∈ [0, 2), the sum of two numbers in [0, 1): s − 1 is exact there (Sterbenz),
/// and needs no `fmod` call.
#[inline]
fn unit_wrap(s: f64) -> f64 {
    if s >= 1.0 { s - 1.0 } else { s }
}

/// The particle tooth `i` of the comb picks: the first whose cumulative weight exceeds the
/// tooth's position ((u + vdc(i)) mod 1) · total, at most the last.
fn comb_index(cdf: &[f64], total: f64, u: f64, i: usize) -> usize {
    let pos = unit_wrap(u + van_der_corput(i as u32)) * total;
    cdf.partition_point(|&c| c <= pos).min(cdf.len() - 1)
}

/// [`comb_index`] of every tooth i < n at once, by one merge of the teeth in increasing
/// position with `cdf`; None (the caller searches tooth by tooth) unless `cdf` is finite and
/// non-decreasing, where the merge and the binary search agree.
///
/// For i < n ≤ 2^m, vdc(i) = rev_m(i) / 2^m, so running k over 0..2^m and taking i = rev_m(k)
/// visits the teeth in increasing vdc(i); u + vdc(i) rounds monotonically, and the teeth whose
/// sum reaches 1 (a suffix of k) wrap below the others.
fn comb_indices(cdf: &[f64], total: f64, u: f64, n: usize) -> Option<Vec<u32>> {
    let len = cdf.len();
    if len == 0 || len > u32::MAX as usize || n > 1 << 31 {
        return None;
    }
    if !(cdf.iter().all(|c| c.is_finite()) && cdf.windows(2).all(|p| p[0] <= p[1])) {
        return None;
    }
    let m = n.max(1).next_power_of_two().trailing_zeros();
    let tooth = |k: u32| -> u32 {
        if m == 0 {
            0
        } else {
            k.reverse_bits() >> (32 - m)
        }
    };
    let size = 1u32 << m;
    // the first k whose sum u + vdc reaches 1: those from it on come first once wrapped
    let wraps = (0..size)
        .find(|&k| u + van_der_corput(tooth(k)) >= 1.0)
        .unwrap_or(size);
    let mut out = vec![0u32; n];
    let mut j = 0;
    for k in (wraps..size).chain(0..wraps) {
        let i = tooth(k) as usize;
        if i >= n {
            continue;
        }
        let pos = unit_wrap(u + van_der_corput(i as u32)) * total;
        while j < len && cdf[j] <= pos {
            j += 1;
        }
        out[i] = j.min(len - 1) as u32;
    }
    Some(out)
}

/// How many particles to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CountLimits {
    pub min: usize,
    pub max: usize,
    /// KLD-sampling on; off: exactly `max`.
    pub kld: bool,
    pub epsilon: f64,
    /// Φ⁻¹(1 − δ).
    pub z: f64,
}

/// Resamples (xs, ys, ths) with normalised weights `w` into new arrays (weights reset to 1/n).
/// `random_pose` draws an injected particle; `p_inject` is the injection probability. `trig`,
/// the weighing's `[θ, sin θ, cos θ]` per particle, follows the particles when it has one
/// entry per particle (an injected particle's entry is marked stale), else it is emptied.
#[allow(clippy::too_many_arguments)]
pub fn resample(
    xs: &mut Vec<f64>,
    ys: &mut Vec<f64>,
    ths: &mut Vec<f64>,
    trig: &mut Vec<[f64; 3]>,
    w: &mut Vec<f64>,
    limits: &CountLimits,
    bins: &BinSize,
    p_inject: f64,
    rng: &mut impl Rng,
    mut random_pose: impl FnMut(&mut dyn FnMut() -> f64) -> (f64, f64, f64),
) {
    let n_old = w.len();
    if n_old == 0 {
        return;
    }
    let mut cdf = Vec::with_capacity(n_old);
    let mut acc = 0.0;
    for &wi in w.iter() {
        acc += wi;
        cdf.push(acc);
    }
    let total = acc.max(f64::MIN_POSITIVE);
    let u: f64 = rng.random::<f64>();
    let (mut nx, mut ny, mut nt) = (
        Vec::with_capacity(limits.max),
        Vec::with_capacity(limits.max),
        Vec::with_capacity(limits.max),
    );
    let mut occupied = FxHashSet::default();
    let max = limits.max.max(1);
    let min = limits.min.clamp(1, max);
    // every tooth's particle in one merge when the draw will likely take most of the teeth (the
    // cloud was large), else a binary search per tooth drawn: the same indices either way
    let merged = (n_old.saturating_mul(4) >= max)
        .then(|| comb_indices(&cdf, total, u, max))
        .flatten();
    let mut bound = (0, 1);
    let follow = trig.len() == n_old;
    let mut new_trig = Vec::with_capacity(if follow { limits.max } else { 0 });
    for i in 0..max {
        let (x, y, th) = if p_inject > 0.0 && rng.random::<f64>() < p_inject {
            let mut uniform = || rng.random::<f64>();
            if follow {
                new_trig.push([f64::NAN; 3]);
            }
            random_pose(&mut uniform)
        } else {
            let j = match &merged {
                Some(m) => m[i] as usize,
                None => comb_index(&cdf, total, u, i),
            };
            if follow {
                new_trig.push(trig[j]);
            }
            (xs[j], ys[j], ths[j])
        };
        nx.push(x);
        ny.push(y);
        nt.push(th);
        if limits.kld {
            occupied.insert(bins.key(x, y, th));
            if bound.0 != occupied.len() {
                bound = (
                    occupied.len(),
                    kld_bound(occupied.len(), limits.epsilon, limits.z),
                );
            }
            let count = i + 1;
            if count >= min && count >= bound.1 {
                break;
            }
        }
    }
    let n = nx.len();
    *trig = new_trig;
    *xs = nx;
    *ys = ny;
    *ths = nt;
    *w = vec![1.0 / n as f64; n];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;

    #[test]
    fn low_variance_draws_in_proportion_to_weight() {
        // weights 1 : 3 : 0 : 4 of 8 draws: exactly 1, 3, 0 and 4 copies whatever the offset
        for u in [0.001, 0.3, 0.999] {
            let idx = low_variance_indices(&[1.0, 3.0, 0.0, 4.0], 8, u);
            let count = |k| idx.iter().filter(|&&i| i == k).count();
            assert_eq!(
                [count(0), count(1), count(2), count(3)],
                [1, 3, 0, 4],
                "u = {u}"
            );
            assert!(idx.windows(2).all(|p| p[0] <= p[1]));
        }
        assert!(low_variance_indices(&[], 4, 0.5).is_empty());
    }

    /// The one-merge draw picks, for every tooth, the particle the binary search picks: over
    /// weights with runs of zeros, counts that are and are not powers of two, and offsets at
    /// both ends of [0, 1), where the teeth wrap.
    #[test]
    fn merged_comb_picks_what_the_search_picks() {
        let mut rng = stream_rng(7, "t", "comb");
        for len in [1usize, 2, 7, 100, 5000] {
            let w: Vec<f64> = (0..len)
                .map(|k| {
                    if k % 5 == 3 {
                        0.0
                    } else {
                        rng.random::<f64>().powi(4)
                    }
                })
                .collect();
            let cdf: Vec<f64> = w
                .iter()
                .scan(0.0, |acc, wi| {
                    *acc += wi;
                    Some(*acc)
                })
                .collect();
            let total = cdf[len - 1].max(f64::MIN_POSITIVE);
            for n in [1usize, 2, 3, 64, 1000, 4096, 5000, 5001] {
                for u in [
                    0.0,
                    1e-300,
                    0.25,
                    0.5,
                    0.999_999,
                    1.0 - f64::EPSILON / 2.0,
                    rng.random(),
                ] {
                    let merged = comb_indices(&cdf, total, u, n).expect("a finite cdf");
                    for (i, &j) in merged.iter().enumerate() {
                        assert_eq!(
                            j as usize,
                            comb_index(&cdf, total, u, i),
                            "len {len} n {n} u {u} i {i}"
                        );
                    }
                }
            }
        }
        // the wrap is `% 1.0` to the bit over [0, 2)
        for _ in 0..100_000 {
            let x = rng.random::<f64>() + rng.random::<f64>();
            assert_eq!(unit_wrap(x).to_bits(), (x % 1.0).to_bits(), "{x}");
        }
        for x in [0.0, 1.0, 1.0 - f64::EPSILON / 2.0, 2.0 - f64::EPSILON] {
            assert_eq!(unit_wrap(x).to_bits(), (x % 1.0).to_bits(), "{x}");
        }
        // a cdf that is not non-decreasing is left to the search
        assert!(comb_indices(&[1.0, f64::NAN, 2.0], 2.0, 0.5, 4).is_none());
        assert!(comb_indices(&[], 1.0, 0.5, 4).is_none());
    }

    #[test]
    fn quantile_matches_tables() {
        assert!((normal_quantile(0.99) - 2.326_347_874).abs() < 1e-8);
        assert!((normal_quantile(0.5)).abs() < 1e-12);
        assert!((normal_quantile(0.01) + 2.326_347_874).abs() < 1e-8);
    }

    #[test]
    fn kld_bound_grows_with_bins() {
        let z = normal_quantile(0.99);
        // eq. 8 by hand: k = 10 → 9/0.02·(1 − 2/81 + √(2/81)·2.326)³ ≈ 1086; k = 100 → ≈ 6735
        let b10 = kld_bound(10, 0.01, z);
        let b100 = kld_bound(100, 0.01, z);
        assert!(b10 < b100 && (1080..1095).contains(&b10) && (6700..6770).contains(&b100));
        assert_eq!(kld_bound(1, 0.01, z), 1);
    }

    #[test]
    fn resampling_follows_the_weights_with_low_variance() {
        let mut rng = stream_rng(3, "t", "r");
        let mut xs: Vec<f64> = (0..4).map(|i| i as f64 * 10.0).collect();
        let mut ys = vec![0.0; 4];
        let mut ths = vec![0.0; 4];
        let mut w = vec![0.1, 0.2, 0.3, 0.4];
        let limits = CountLimits {
            min: 100,
            max: 1000,
            kld: false,
            epsilon: 0.01,
            z: 2.33,
        };
        resample(
            &mut xs,
            &mut ys,
            &mut ths,
            &mut Vec::new(),
            &mut w,
            &limits,
            &BinSize::default(),
            0.0,
            &mut rng,
            |_| unreachable!(),
        );
        assert_eq!(xs.len(), 1000);
        // a comb of 1000 teeth: each count is within one of its expectation
        for (k, share) in [0.1, 0.2, 0.3, 0.4].iter().enumerate() {
            let c = xs.iter().filter(|&&x| x == k as f64 * 10.0).count() as f64;
            assert!((c - share * 1000.0).abs() <= 1.0, "{k}: {c}");
        }
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn kld_keeps_few_particles_when_concentrated_and_injection_spreads() {
        let mut rng = stream_rng(4, "t", "r");
        let n = 5000;
        let mut xs = vec![1.1; n];
        let mut ys = vec![2.2; n];
        let mut ths = vec![0.05; n];
        let mut w = vec![1.0 / n as f64; n];
        let limits = CountLimits {
            min: 300,
            max: 5000,
            kld: true,
            epsilon: 0.01,
            z: normal_quantile(0.99),
        };
        resample(
            &mut xs,
            &mut ys,
            &mut ths,
            &mut Vec::new(),
            &mut w,
            &limits,
            &BinSize::default(),
            0.0,
            &mut rng,
            |_| unreachable!(),
        );
        assert_eq!(xs.len(), 300, "one bin: the minimum");
        // half of the draws injected uniformly over a 100 m square: many bins, many particles
        resample(
            &mut xs,
            &mut ys,
            &mut ths,
            &mut Vec::new(),
            &mut w,
            &limits,
            &BinSize::default(),
            0.5,
            &mut rng,
            |u| (u() * 100.0, u() * 100.0, u() * 6.0 - 3.0),
        );
        assert!(xs.len() > 2000, "{}", xs.len());
    }
}
