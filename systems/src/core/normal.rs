//! Standard normal deviates in bulk, as f32, by the ziggurat method of Marsaglia & Tsang
//! ("The Ziggurat Method for Generating Random Variables", J. Statistical Software 5(8), 2000):
//! 128 layers of equal area, so almost every deviate is one table lookup, one comparison and one
//! multiplication. As Doornik recommends ("An Improved Ziggurat Method to Generate Normal Random
//! Samples", 2005), the layer index and the deviate come from disjoint bits of the random word
//! (in Marsaglia & Tsang's code they share the low bits, which correlates them). One 64-bit word
//! gives two deviates (24-bit magnitudes with sign, ample for sensor noise in f32), which halves
//! the generator's share of the cost: laser noise draws one deviate per beam.

use rand::Rng;
use std::sync::OnceLock;

const LAYERS: usize = 128;
/// x-coordinate where the base layer's tail begins.
const R: f64 = 3.442_619_855_899;
/// Area of each layer (including the base layer's tail).
const V: f64 = 9.912_563_035_262_17e-3;
/// Scale of a 24-bit signed deviate (|j| < 2^23).
const M: f64 = (1u32 << 23) as f64;

struct Tables {
    /// Acceptance bounds on |j| per layer (the fast path).
    k: [i32; LAYERS],
    /// Scale from j to x per layer.
    w: [f32; LAYERS],
    /// Density exp(-x²/2) at each layer's edge.
    f: [f32; LAYERS],
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Tables {
            k: [0; LAYERS],
            w: [0.0; LAYERS],
            f: [0.0; LAYERS],
        };
        let density = |x: f64| (-0.5 * x * x).exp();
        let q = V / density(R);
        let (mut d, mut prev) = (R, R);
        t.k[0] = ((R / q) * M) as i32;
        t.k[1] = 0;
        t.w[0] = (q / M) as f32;
        t.w[LAYERS - 1] = (R / M) as f32;
        t.f[0] = 1.0;
        t.f[LAYERS - 1] = density(R) as f32;
        for i in (1..LAYERS - 1).rev() {
            d = (-2.0 * (V / d + density(d)).ln()).sqrt();
            t.k[i + 1] = ((d / prev) * M) as i32;
            prev = d;
            t.f[i] = density(d) as f32;
            t.w[i] = (d / M) as f32;
        }
        t
    })
}

/// A uniform deviate in (0, 1], never 0 (its logarithm is taken).
fn open_uniform<G: Rng + ?Sized>(rng: &mut G) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 1.0) * (1.0 / (1u64 << 53) as f64)
}

/// The slow path for a word that missed its layer's rectangle: the wedge test, the base layer's
/// tail, or a fresh draw.
#[cold]
fn slow<G: Rng + ?Sized>(rng: &mut G, t: &Tables, mut j: i32, mut i: usize) -> f32 {
    loop {
        let x = j as f64 * t.w[i] as f64;
        if i == 0 {
            // the tail beyond R (Marsaglia 1964)
            loop {
                let x = -open_uniform(rng).ln() / R;
                let y = -open_uniform(rng).ln();
                if y + y >= x * x {
                    return (if j > 0 { R + x } else { -R - x }) as f32;
                }
            }
        }
        let (fi, fp) = (t.f[i] as f64, t.f[i - 1] as f64);
        if fi + open_uniform(rng) * (fp - fi) < (-0.5 * x * x).exp() {
            return x as f32;
        }
        let u = rng.next_u64();
        (j, i) = split(u as u32);
        if j.unsigned_abs() < t.k[i] as u32 {
            return j as f32 * t.w[i];
        }
    }
}

/// A 32-bit word as (signed 24-bit deviate, layer): bits 8..32 and bits 0..7.
#[inline]
fn split(word: u32) -> (i32, usize) {
    ((word as i32) >> 8, (word & (LAYERS as u32 - 1)) as usize)
}

/// Fills `out` with independent standard normal deviates from `rng`.
pub fn fill_standard_normal<G: Rng + ?Sized>(rng: &mut G, out: &mut [f32]) {
    let t = tables();
    let one = |rng: &mut G, word: u32| {
        let (j, i) = split(word);
        if j.unsigned_abs() < t.k[i] as u32 {
            j as f32 * t.w[i]
        } else {
            slow(rng, t, j, i)
        }
    };
    let mut pairs = out.chunks_exact_mut(2);
    for pair in &mut pairs {
        let u = rng.next_u64();
        pair[0] = one(rng, u as u32);
        pair[1] = one(rng, (u >> 32) as u32);
    }
    if let [last] = pairs.into_remainder() {
        let u = rng.next_u64();
        *last = one(rng, u as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;

    /// Φ(x), the standard normal CDF, by erfc's continued-fraction-free rational approximation
    /// (Abramowitz & Stegun 7.1.26, error below 1.5e-7).
    fn phi(x: f64) -> f64 {
        let z = x.abs() / std::f64::consts::SQRT_2;
        let t = 1.0 / (1.0 + 0.327_591_1 * z);
        let poly = t
            * (0.254_829_592
                + t * (-0.284_496_736
                    + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
        let erfc = poly * (-z * z).exp();
        if x >= 0.0 {
            1.0 - 0.5 * erfc
        } else {
            0.5 * erfc
        }
    }

    #[test]
    fn deviates_follow_the_standard_normal_distribution() {
        let mut rng = stream_rng(7, "normal", "test");
        let n = 2_000_001; // odd: the last deviate comes from a word of its own
        let mut xs = vec![0f32; n];
        fill_standard_normal(&mut rng, &mut xs);
        let (mut s1, mut s2, mut s4) = (0.0f64, 0.0f64, 0.0f64);
        for &x in &xs {
            let x = x as f64;
            s1 += x;
            s2 += x * x;
            s4 += x * x * x * x;
        }
        let nf = n as f64;
        let (mean, var, kurt) = (s1 / nf, s2 / nf, s4 / nf);
        // standard errors: 1/√n = 7e-4 for the mean, √(2/n) = 1e-3 for the variance, √(96/n) =
        // 7e-3 for the fourth moment (3 for a normal)
        assert!(mean.abs() < 4e-3, "mean {mean}");
        assert!((var - 1.0).abs() < 6e-3, "variance {var}");
        assert!((kurt - 3.0).abs() < 4e-2, "fourth moment {kurt}");
        // the histogram against Φ in 60 bins over ±3, and both tails beyond: chi-square with 61
        // degrees of freedom has mean 61 and standard deviation 11; 130 is beyond 6 sigma
        let edges: Vec<f64> = (0..=60).map(|k| -3.0 + k as f64 * 0.1).collect();
        let mut counts = vec![0u64; edges.len() + 1];
        for &x in &xs {
            let x = x as f64;
            let bin = edges.partition_point(|&e| e <= x);
            counts[bin] += 1;
        }
        let mut chi2 = 0.0;
        for (b, &c) in counts.iter().enumerate() {
            let lo = if b == 0 { 0.0 } else { phi(edges[b - 1]) };
            let hi = if b == edges.len() { 1.0 } else { phi(edges[b]) };
            let expected = (hi - lo) * nf;
            chi2 += (c as f64 - expected).powi(2) / expected;
        }
        assert!(chi2 < 130.0, "chi-square {chi2}");
        // the base layer's tail (beyond R = 3.44) has its own path: P(|x| > 3.5) = 4.65e-4
        let tail = xs.iter().filter(|x| x.abs() > 3.5).count() as f64 / nf;
        assert!((tail / 4.65e-4 - 1.0).abs() < 0.1, "tail {tail}");
        assert!(xs.iter().all(|x| x.is_finite()));
    }

    #[test]
    fn the_same_stream_gives_the_same_deviates() {
        let draw = |seed| {
            let mut rng = stream_rng(seed, "laser", "noise");
            let mut xs = vec![0f32; 181];
            fill_standard_normal(&mut rng, &mut xs);
            xs
        };
        assert_eq!(draw(3), draw(3));
        assert_ne!(draw(3), draw(4));
    }
}
