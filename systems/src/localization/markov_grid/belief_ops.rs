//! Passes over the whole belief (about a million cells at the default 0.25 m × 10° on a
//! 64 × 32 m floor), run at every update, written so that they vectorise: each keeps
//! [`LANES`] independent partial results instead of one chain of dependent operations, which a
//! compiler may not reorder for floating point. The tests hold each to the plain computation
//! (`sum_plain`, `peak_plain`, `runs_at_or_above_plain`, the scalings written out).

/// Independent partial results per pass.
pub const LANES: usize = 8;

/// The sum (f64) and the largest value (and 0, NaN ignored) of the values a pass has written,
/// in [`LANES`] partial results: a pass that writes the belief tallies it on the way, so the
/// normalisation and the selective update's threshold need no pass of their own.
#[derive(Clone, Copy, Debug)]
pub struct Tally {
    sum: [f64; LANES],
    max: [f32; LANES],
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            sum: [0.0; LANES],
            max: [0.0; LANES],
        }
    }
}

impl Tally {
    /// Adds a block of at most [`LANES`] values.
    #[inline(always)]
    fn block(&mut self, b: &[f32]) {
        for (lane, &x) in b.iter().enumerate() {
            self.lane(lane, x);
        }
    }

    /// Adds `x` to lane `lane`.
    #[inline(always)]
    fn lane(&mut self, lane: usize, x: f32) {
        self.sum[lane] += x as f64;
        self.max[lane] = if x > self.max[lane] {
            x
        } else {
            self.max[lane]
        };
    }

    pub fn add(&mut self, v: &[f32]) {
        let (blocks, rest) = v.as_chunks::<LANES>();
        for b in blocks {
            self.block(b);
        }
        self.block(rest);
    }

    /// The partial sums added pairwise: equal to the plain sum up to rounding (a relative 1e-12
    /// on a million non-negative cells).
    pub fn sum(&self) -> f64 {
        let mut acc = self.sum;
        let mut w = LANES;
        while w > 1 {
            w /= 2;
            for i in 0..w {
                acc[i] += acc[i + w];
            }
        }
        acc[0]
    }

    /// The largest value: exactly the plain one.
    pub fn peak(&self) -> f32 {
        self.max
            .iter()
            .fold(0.0f32, |a, &x| if x > a { x } else { a })
    }
}

/// The sum in f64 of `v`, tallied.
pub fn sum(v: &[f32]) -> f64 {
    let mut t = Tally::default();
    t.add(v);
    t.sum()
}

/// The sum in f64 of `v`, element after element.
pub fn sum_plain(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum()
}

/// The largest value of `v` and 0, NaN ignored, tallied: exactly [`peak_plain`].
pub fn peak(v: &[f32]) -> f32 {
    let mut t = Tally::default();
    t.add(v);
    t.peak()
}

/// The largest value of `v` and 0, NaN ignored, element after element.
pub fn peak_plain(v: &[f32]) -> f32 {
    v.iter().copied().fold(0.0f32, f32::max)
}

/// Cells [`runs_at_or_above`] tests at once.
pub const RUN_BLOCK: usize = 32;

/// Calls `emit(start, len)` for every maximal run of `row` at or above `threshold`, in order:
/// exactly [`runs_at_or_above_plain`]. Blocks of [`RUN_BLOCK`] wholly below or wholly above the
/// threshold (nearly all of them once the belief has converged) are passed in one test.
pub fn runs_at_or_above(row: &[f32], threshold: f32, mut emit: impl FnMut(usize, usize)) {
    let mut start: Option<usize> = None;
    for (b, block) in row.chunks(RUN_BLOCK).enumerate() {
        let above = block
            .iter()
            .fold(0usize, |n, &x| n + usize::from(x >= threshold));
        runs_in_block(
            block,
            b * RUN_BLOCK,
            above,
            threshold,
            &mut start,
            &mut emit,
        );
    }
    if let Some(s) = start {
        emit(s, row.len() - s);
    }
}

/// The runs of one block of a row, which starts at `at` and has `above` values at or above
/// `threshold`, `start` being where the run still open began: whole blocks below or above in one
/// step, the others value by value.
#[inline(always)]
fn runs_in_block(
    block: &[f32],
    at: usize,
    above: usize,
    threshold: f32,
    start: &mut Option<usize>,
    emit: &mut impl FnMut(usize, usize),
) {
    if above == 0 {
        if let Some(s) = start.take() {
            emit(s, at - s);
        }
    } else if above == block.len() {
        start.get_or_insert(at);
    } else {
        for (i, &x) in block.iter().enumerate() {
            match (x >= threshold, *start) {
                (true, None) => *start = Some(at + i),
                (false, Some(s)) => {
                    emit(s, at + i - s);
                    *start = None;
                }
                _ => {}
            }
        }
    }
}

/// [`runs_at_or_above`], element after element.
pub fn runs_at_or_above_plain(row: &[f32], threshold: f32, mut emit: impl FnMut(usize, usize)) {
    let mut start: Option<usize> = None;
    for (i, &x) in row.iter().enumerate() {
        match (x >= threshold, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                emit(s, i - s);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        emit(s, row.len() - s);
    }
}

/// Each value `x` of `v` becomes `f(x)`, tallied: blocks of [`LANES`], one value per lane.
#[inline(always)]
fn map_tallied(v: &mut [f32], t: &mut Tally, f: impl Fn(f32) -> f32) {
    let (blocks, rest) = v.as_chunks_mut::<LANES>();
    for b in blocks {
        for (lane, x) in b.iter_mut().enumerate() {
            let y = f(*x);
            *x = y;
            t.lane(lane, y);
        }
    }
    for (lane, x) in rest.iter_mut().enumerate() {
        let y = f(*x);
        *x = y;
        t.lane(lane, y);
    }
}

/// Multiplies every value of `v` by `factor`, tallying the results.
pub fn scale(v: &mut [f32], factor: f32, t: &mut Tally) {
    map_tallied(v, t, |x| x * factor);
}

/// Each value `x` of `v` becomes `keep · (x · factor) + add`, tallied: a normalisation and a
/// uniform mix in one pass, rounded as the two passes one after the other would be.
pub fn scale_and_mix(v: &mut [f32], factor: f32, keep: f32, add: f32, t: &mut Tally) {
    map_tallied(v, t, |x| keep * (x * factor) + add);
}

/// The selective update's last pass: each value `x` of `v` at or above `threshold` (a cell it
/// scored) becomes its weighed value, `scored`'s at the same place, each below it `x · floor`;
/// then `keep · (y · factor) + add` with `[factor, keep, add]` = `scale`, tallied: rounded as
/// the weighing then [`scale_and_mix`] one after the other would be.
pub fn weigh_and_mix(
    v: &mut [f32],
    scored: &[f32],
    threshold: f32,
    floor: f32,
    scale: [f32; 3],
    t: &mut Tally,
) {
    let [factor, keep, add] = scale;
    let f = |x: f32, w: f32| {
        let y = if x >= threshold { w } else { x * floor };
        keep * (y * factor) + add
    };
    let (wb, wr) = scored[..v.len()].as_chunks::<LANES>();
    let (blocks, rest) = v.as_chunks_mut::<LANES>();
    for (b, w) in blocks.iter_mut().zip(wb) {
        for (lane, (x, &w)) in b.iter_mut().zip(w).enumerate() {
            let y = f(*x, w);
            *x = y;
            t.lane(lane, y);
        }
    }
    for (lane, (x, &w)) in rest.iter_mut().zip(wr).enumerate() {
        let y = f(*x, w);
        *x = y;
        t.lane(lane, y);
    }
}

/// [`f32::total_cmp`]'s order as integers.
fn order_key(x: f32) -> i32 {
    let b = x.to_bits() as i32;
    b ^ (((b >> 31) as u32) >> 1) as i32
}

/// The first place of `value` in `v` (bit for bit), if any: a block of [`LANES`] at a time.
pub fn find(v: &[f32], value: f32) -> Option<usize> {
    let bits = value.to_bits();
    let b = v
        .chunks(LANES)
        .position(|c| c.iter().fold(false, |f, &x| f | (x.to_bits() == bits)))?;
    Some(b * LANES + v[b * LANES..].iter().position(|&x| x.to_bits() == bits)?)
}

/// The index and value of the largest value of `v` by [`f32::total_cmp`], the first of equals:
/// the largest key (vectorised), then the first block and the first cell holding it (held to
/// `max_by` with `total_cmp` in the Markov grid's tests).
pub fn argmax(v: &[f32]) -> Option<(usize, f32)> {
    let top = v.iter().map(|&x| order_key(x)).max()?;
    let b = v
        .chunks(LANES)
        .position(|c| c.iter().fold(false, |f, &x| f | (order_key(x) == top)))?;
    let i = b * LANES + v[b * LANES..].iter().position(|&x| order_key(x) == top)?;
    Some((i, v[i]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use rand::RngExt;

    /// A belief-like vector: mostly tiny values, a few large ones, runs of zeros (walls),
    /// and a length that is not a multiple of the lanes.
    fn belief(seed: u64, n: usize) -> Vec<f32> {
        let mut rng = stream_rng(seed, "test", "belief-ops");
        (0..n)
            .map(|i| match rng.random_range(0..10) {
                0 => 0.0,
                1 => rng.random_range(0.0..1.0),
                _ if (i / 40) % 7 == 3 => rng.random_range(0.5..1.0),
                _ => rng.random_range(0.0..1e-9),
            })
            .collect()
    }

    #[test]
    fn the_vectorised_passes_equal_the_plain_ones() {
        for (seed, n) in [
            (1, 0),
            (2, 1),
            (3, 15),
            (4, 16),
            (5, 17),
            (6, 1000),
            (7, 100_003),
        ] {
            let v = belief(seed, n);
            let (a, b) = (sum(&v), sum_plain(&v));
            assert!((a - b).abs() <= 1e-12 * b.abs(), "sum {a} against {b}");
            assert_eq!(peak(&v).to_bits(), peak_plain(&v).to_bits());
            for threshold in [1e-10, 0.4, 0.75, 2.0] {
                let (mut fast, mut plain) = (Vec::new(), Vec::new());
                runs_at_or_above(&v, threshold, |s, l| fast.push((s, l)));
                runs_at_or_above_plain(&v, threshold, |s, l| plain.push((s, l)));
                assert_eq!(fast, plain, "n {n}, threshold {threshold}");
            }
        }
    }

    #[test]
    fn argmax_finds_the_first_of_equal_maxima_across_blocks() {
        let mut v = vec![0.25f32; 100];
        v[37] = 0.5;
        v[90] = 0.5;
        assert_eq!(argmax(&v), Some((37, 0.5)));
        assert_eq!(argmax(&[]), None);
        // a NaN orders above every number under total_cmp
        v[50] = f32::NAN;
        assert_eq!(argmax(&v).map(|p| p.0), Some(50));
    }

    #[test]
    fn runs_cover_a_whole_row_and_none() {
        let v = vec![1.0f32; 40];
        let mut r = Vec::new();
        runs_at_or_above(&v, 0.5, |s, l| r.push((s, l)));
        assert_eq!(r, vec![(0, 40)]);
        r.clear();
        runs_at_or_above(&v, 2.0, |s, l| r.push((s, l)));
        assert!(r.is_empty());
    }

    #[test]
    fn weigh_and_mix_takes_the_scored_cells_and_keeps_nan() {
        let mut v = vec![0.0, 1e-9, 0.5, 1.0, f32::NAN];
        let scored = [9.0, 9.0, 0.125, 0.75, 9.0];
        let mut t = Tally::default();
        weigh_and_mix(&mut v, &scored, 0.5, 0.25, [2.0, 1.0, 0.0], &mut t);
        assert_eq!(&v[..4], &[0.0, 0.5e-9, 0.25, 1.5]);
        assert!(v[4].is_nan());
        assert_eq!(t.peak(), 1.5);
    }

    /// The fused passes write what the plain passes do and tally what they wrote.
    #[test]
    fn the_fused_passes_write_and_tally_as_the_plain_ones() {
        let v = belief(9, 1003);
        let (f, keep, add) = (1.7f32, 1.0 - 1e-6, 3e-12);
        let tallied = |t: &Tally, w: &[f32]| {
            assert!((t.sum() - sum_plain(w)).abs() <= 1e-12 * sum_plain(w));
            assert_eq!(t.peak().to_bits(), peak_plain(w).to_bits());
        };
        let mut one = v.clone();
        let mut t = Tally::default();
        scale_and_mix(&mut one[..500], f, keep, add, &mut t);
        scale_and_mix(&mut one[500..], f, keep, add, &mut t);
        let mut two: Vec<f32> = v.iter().map(|x| x * f).collect();
        two.iter_mut().for_each(|x| *x = keep * *x + add);
        assert_eq!(one, two);
        tallied(&t, &two);
        let mut t = Tally::default();
        let mut scaled = v.clone();
        scale(&mut scaled, f, &mut t);
        tallied(&t, &scaled);
        // the selective update's last pass against the weighing, then the normalisation and mix
        let scored: Vec<f32> = v.iter().map(|x| x * 0.3).collect();
        let mut t = Tally::default();
        let mut fused = v.clone();
        weigh_and_mix(
            &mut fused[..501],
            &scored[..501],
            0.5,
            f,
            [1.3, keep, add],
            &mut t,
        );
        weigh_and_mix(
            &mut fused[501..],
            &scored[501..],
            0.5,
            f,
            [1.3, keep, add],
            &mut t,
        );
        let plain: Vec<f32> = v
            .iter()
            .zip(&scored)
            .map(|(&x, &w)| if x >= 0.5 { w } else { x * f })
            .map(|y| keep * (y * 1.3) + add)
            .collect();
        assert_eq!(fused, plain);
        tallied(&t, &fused);
        let mut t = Tally::default();
        t.add(&v[..10]);
        t.add(&v[10..]);
        tallied(&t, &v);
        let top = peak_plain(&v);
        assert_eq!(find(&v, top), v.iter().position(|&x| x == top));
        assert_eq!(find(&v, 2.0), None);
    }
}
