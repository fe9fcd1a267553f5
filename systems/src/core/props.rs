//! Property-test support: the configuration every property test of the crate runs with, and
//! generators of the faulty values sensors and drivers can produce (NaN, ±∞, zeros, the sensor's
//! limits, huge and negative numbers).
//!
//! Runs are deterministic: a fixed seed, a modest number of cases, and no failure files written
//! into the source tree. A failure a property finds is kept as a plain regression test beside
//! the code it concerns.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// The configuration of a property test with `cases` cases: seeded, no persistence files, and
/// shrinking bounded so a failure is reported within seconds.
pub fn config(cases: u32) -> Config {
    Config {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x5EED),
        max_shrink_iters: 256,
        ..Config::default()
    }
}

/// A laser range as a faulty scanner may report it: mostly plausible ranges in
/// [0, 1.2 · `range_max`], and NaN, ±∞, exact zeros, the maximum range, negative and huge values.
pub fn range_reading(range_max: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => 0.0f32..range_max * 1.2,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(range_max),
        1 => Just(f32::MAX),
        1 => Just(-f32::MAX),
        1 => Just(f32::MIN_POSITIVE),
        1 => -1e6f32..0.0,
        1 => any::<f32>(),
    ]
}

/// What a faulted laser sends instead of a scan.
#[derive(Clone, Debug)]
pub enum LaserFault {
    /// Every beam NaN (invalid).
    AllNan,
    /// Every beam at the maximum range.
    AllMax,
    /// Every beam 0 m.
    AllZero,
    /// Every beam +∞ (no return).
    AllNoReturn,
    /// Every beam −∞ (below the minimum range).
    AllTooClose,
    /// The last good scan again, whatever the robot does.
    Stuck,
    /// Arbitrary readings, repeated over the scan's beams.
    Garbage(Vec<f32>),
}

impl LaserFault {
    /// Overwrites `ranges` with the fault; `stuck` is the scan a stuck laser repeats.
    pub fn apply(&self, ranges: &mut [f32], range_max: f32, stuck: Option<&[f32]>) {
        let fill = |ranges: &mut [f32], v: f32| ranges.iter_mut().for_each(|r| *r = v);
        match self {
            LaserFault::AllNan => fill(ranges, f32::NAN),
            LaserFault::AllMax => fill(ranges, range_max),
            LaserFault::AllZero => fill(ranges, 0.0),
            LaserFault::AllNoReturn => fill(ranges, f32::INFINITY),
            LaserFault::AllTooClose => fill(ranges, f32::NEG_INFINITY),
            LaserFault::Stuck => {
                if let Some(s) = stuck.filter(|s| s.len() == ranges.len()) {
                    ranges.copy_from_slice(s);
                }
            }
            LaserFault::Garbage(values) if !values.is_empty() => {
                for (r, v) in ranges.iter_mut().zip(values.iter().cycle()) {
                    *r = *v;
                }
            }
            LaserFault::Garbage(_) => {}
        }
    }

    /// Whether the fault leaves no beam with a return in [range_min, range_max).
    pub fn is_unusable(&self) -> bool {
        matches!(
            self,
            LaserFault::AllNan
                | LaserFault::AllMax
                | LaserFault::AllZero
                | LaserFault::AllNoReturn
                | LaserFault::AllTooClose
        )
    }
}

/// A laser fault; garbage scans of up to `len` readings.
pub fn laser_fault(range_max: f32, len: usize) -> impl Strategy<Value = LaserFault> {
    prop_oneof![
        Just(LaserFault::AllNan),
        Just(LaserFault::AllMax),
        Just(LaserFault::AllZero),
        Just(LaserFault::AllNoReturn),
        Just(LaserFault::AllTooClose),
        Just(LaserFault::Stuck),
        proptest::collection::vec(range_reading(range_max), 1..=len.max(1))
            .prop_map(LaserFault::Garbage),
    ]
}

/// A number as a broken driver or sensor may produce it: ordinary values, 0, ±∞, NaN, the
/// extremes of f64 and huge magnitudes.
pub fn extreme_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0f64..10.0,
        1 => Just(0.0f64),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
        1 => Just(f64::MIN),
        1 => Just(f64::MIN_POSITIVE),
        1 => -1e12f64..1e12,
        1 => prop_oneof![Just(1e300f64), Just(-1e300f64)],
    ]
}

/// Whether every value is finite.
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// Whether a 3 × 3 matrix is finite, symmetric and positive semi-definite, up to rounding
/// relative to its scale (leading principal minors and the diagonal non-negative, every 2 × 2
/// minor of a pair of axes non-negative).
pub fn is_covariance(c: &[[f64; 3]; 3]) -> bool {
    if !all_finite(&c.concat()) {
        return false;
    }
    let scale = (0..3)
        .map(|i| c[i][i].abs())
        .fold(f64::MIN_POSITIVE, f64::max);
    let eps = 1e-9 * scale;
    let pairs = (0..3).flat_map(|i| (0..3).map(move |j| (i, j)));
    if (0..3).any(|i| c[i][i] < -eps)
        || pairs
            .into_iter()
            .any(|(i, j)| (c[i][j] - c[j][i]).abs() > eps)
    {
        return false;
    }
    let minor = |i: usize, j: usize| c[i][i] * c[j][j] - c[i][j] * c[j][i];
    let det = c[0][0] * minor(1, 2) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    let eps2 = 1e-9 * scale * scale;
    minor(0, 1) >= -eps2 && minor(0, 2) >= -eps2 && minor(1, 2) >= -eps2 && det >= -eps2 * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covariances_are_told_from_other_matrices() {
        let id = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        assert!(is_covariance(&id));
        assert!(is_covariance(&[[0.0; 3]; 3]));
        let mut asym = id;
        asym[0][1] = 0.5;
        assert!(!is_covariance(&asym));
        let mut indefinite = id;
        indefinite[0][1] = 2.0;
        indefinite[1][0] = 2.0;
        assert!(!is_covariance(&indefinite));
        let mut nan = id;
        nan[2][2] = f64::NAN;
        assert!(!is_covariance(&nan));
    }

    #[test]
    fn faults_overwrite_every_beam() {
        let mut r = vec![1.0f32; 5];
        LaserFault::Garbage(vec![f32::NAN, 2.0]).apply(&mut r, 10.0, None);
        assert!(r[0].is_nan() && r[1] == 2.0 && r[4].is_nan());
        LaserFault::AllMax.apply(&mut r, 10.0, None);
        assert!(r.iter().all(|&v| v == 10.0));
        LaserFault::Stuck.apply(&mut r, 10.0, Some(&[3.0; 5]));
        assert!(r.iter().all(|&v| v == 3.0));
    }
}
