//! Pose estimate of a particle set from its dominant cluster, as ROS AMCL does (pf.c,
//! `pf_cluster_stats`): particles are binned on a (0.5 m, 0.5 m, 10°) histogram, bins that touch
//! (26-neighbourhood, heading wrapping around) form clusters, and the estimate is the weighted
//! mean of the heaviest cluster with its covariance (x–y block from the particles, heading
//! variance −2 ln R̄ from the mean resultant length of the headings).

use super::resample::BinSize;
use crate::core::Pose2;
use rustc_hash::FxHashMap;

/// A weighted pose estimate with its 3 × 3 covariance (x, y, θ; row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseEstimate {
    pub pose: Pose2,
    pub covariance: [[f64; 3]; 3],
    /// Share of the total weight in the cluster the estimate comes from.
    pub weight: f64,
}

impl PoseEstimate {
    /// √(σ²ₓ + σ²ᵧ) (m): how far the estimator thinks it may be off; 0 for a covariance that is
    /// not finite or not positive.
    pub fn position_spread(&self) -> f64 {
        let v = self.covariance[0][0] + self.covariance[1][1];
        if v.is_finite() && v > 0.0 {
            v.sqrt()
        } else {
            0.0
        }
    }
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of bins `a` and `b`, the smaller root under the larger: the plain version,
/// whose roots are each set's smallest bin number whatever order bins are joined in.
fn union_min(parent: &mut [usize], a: usize, b: usize) {
    let (a, b) = (find(parent, a), find(parent, b));
    if a != b {
        parent[a.max(b)] = a.min(b);
    }
}

/// Disjoint sets joined by size (shallow trees: the plain rule chains bins numbered in
/// random spatial order into long paths), labelled at the end with each set's smallest
/// member, the same roots as [`union_min`] gives.
struct SizedSets {
    parent: Vec<usize>,
    size: Vec<u32>,
}

impl SizedSets {
    fn new(n: usize) -> Self {
        SizedSets {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (find(&mut self.parent, a), find(&mut self.parent, b));
        if a == b {
            return;
        }
        let (big, small) = if self.size[a] >= self.size[b] {
            (a, b)
        } else {
            (b, a)
        };
        self.parent[small] = big;
        self.size[big] += self.size[small];
    }

    /// Each member's set, named by the set's smallest member.
    fn smallest_members(mut self) -> Vec<usize> {
        let n = self.parent.len();
        let mut smallest = vec![usize::MAX; n];
        let mut roots = Vec::with_capacity(n);
        for i in 0..n {
            let r = find(&mut self.parent, i);
            if smallest[r] == usize::MAX {
                // members are visited in increasing order: the first one seen is the smallest
                smallest[r] = i;
            }
            roots.push(smallest[r]);
        }
        roots
    }
}

/// Bins numbered in the order particles first fall into them: each particle's bin number and
/// each bin's key (heading bin wrapped into `0..theta_bins`).
struct Bins {
    of_particle: Vec<usize>,
    keys: Vec<(i32, i32, i32)>,
}

/// The half of the 26 neighbour offsets that is lexicographically after (0, 0, 0): every pair
/// of touching bins is one bin plus one of these.
const FORWARD: [(i32, i32, i32); 13] = [
    (0, 0, 1),
    (0, 1, -1),
    (0, 1, 0),
    (0, 1, 1),
    (1, -1, -1),
    (1, -1, 0),
    (1, -1, 1),
    (1, 0, -1),
    (1, 0, 0),
    (1, 0, 1),
    (1, 1, -1),
    (1, 1, 0),
    (1, 1, 1),
];

/// Cells a dense histogram may have per particle before the hash map is used instead: a
/// global filter covers the map's box densely, a tracking one a few bins around the robot.
const DENSE_CELLS_PER_PARTICLE: usize = 64;
const DENSE_CELLS_MIN: usize = 1 << 16;

/// A histogram over the bounding box of the keys, padded by one bin in x and y so that
/// neighbours need no bounds checks; headings wrap. None when the box is too sparse.
struct DenseBins {
    cells: Vec<u32>,
    x0: i32,
    y0: i32,
    row: usize,
    theta_bins: usize,
}

impl DenseBins {
    fn new(keys: &[(i32, i32, i32)], theta_bins: i32) -> Option<Self> {
        let (mut x0, mut x1, mut y0, mut y1) = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
        for &(kx, ky, _) in keys {
            (x0, x1, y0, y1) = (x0.min(kx), x1.max(kx), y0.min(ky), y1.max(ky));
        }
        let width = (x1 as i64 - x0 as i64 + 3) as usize;
        let height = (y1 as i64 - y0 as i64 + 3) as usize;
        let theta_bins = theta_bins as usize;
        let limit = (keys.len() * DENSE_CELLS_PER_PARTICLE).max(DENSE_CELLS_MIN);
        let cells = width.checked_mul(height)?.checked_mul(theta_bins)?;
        (cells <= limit).then(|| DenseBins {
            cells: vec![u32::MAX; cells],
            x0: x0 - 1,
            y0: y0 - 1,
            row: width,
            theta_bins,
        })
    }

    fn index(&self, (kx, ky, kt): (i32, i32, i32)) -> usize {
        let (x, y) = ((kx - self.x0) as usize, (ky - self.y0) as usize);
        (y * self.row + x) * self.theta_bins + kt as usize
    }
}

fn bin_particles(keys: &[(i32, i32, i32)], dense: Option<&mut DenseBins>) -> Bins {
    let mut bins = Bins {
        of_particle: Vec::with_capacity(keys.len()),
        keys: Vec::new(),
    };
    match dense {
        Some(grid) => {
            for &key in keys {
                let cell = grid.index(key);
                if grid.cells[cell] == u32::MAX {
                    grid.cells[cell] = bins.keys.len() as u32;
                    bins.keys.push(key);
                }
                bins.of_particle.push(grid.cells[cell] as usize);
            }
        }
        None => {
            let mut ids: FxHashMap<(i32, i32, i32), usize> = FxHashMap::default();
            for &key in keys {
                let id = *ids.entry(key).or_insert_with(|| {
                    bins.keys.push(key);
                    bins.keys.len() - 1
                });
                bins.of_particle.push(id);
            }
        }
    }
    bins
}

/// Each bin's cluster root (the smallest bin number of its cluster), neighbours looked up in
/// `dense`, the histogram `bin_particles` filled, or else in a hash map.
fn cluster_roots(
    bin_keys: &[(i32, i32, i32)],
    theta_bins: i32,
    dense: Option<&DenseBins>,
) -> Vec<usize> {
    let mut sets = SizedSets::new(bin_keys.len());
    match dense {
        Some(grid) => return dense_cluster_roots(grid, bin_keys.len()),
        None => {
            let ids = bin_ids(bin_keys);
            for (id, &key) in bin_keys.iter().enumerate() {
                for offset in FORWARD {
                    if let Some(&other) = ids.get(&neighbour(key, offset, theta_bins)) {
                        sets.union(id, other);
                    }
                }
            }
        }
    }
    sets.smallest_members()
}

/// [`cluster_roots`] over the dense histogram. The bins are joined in the histogram's memory
/// order under labels given in that order, so neighbouring bins have nearby labels and the
/// sets' arrays are read almost in sequence (bin numbers, given in particle order, are
/// scattered over the floor).
fn dense_cluster_roots(grid: &DenseBins, bins: usize) -> Vec<usize> {
    let mut label_of_bin = vec![0u32; bins];
    let mut labels = vec![u32::MAX; grid.cells.len()];
    let mut next = 0;
    for (cell, &id) in grid.cells.iter().enumerate() {
        if id != u32::MAX {
            label_of_bin[id as usize] = next;
            labels[cell] = next;
            next += 1;
        }
    }
    let t_bins = grid.theta_bins;
    let mut sets = SizedSets::new(bins);
    // each forward offset as a shift of the (x, y) column in the histogram, and the heading step
    let shifts = FORWARD.map(|(dx, dy, dt)| {
        let columns = dy as isize * grid.row as isize + dx as isize;
        (columns * t_bins as isize, dt)
    });
    for (column, cells) in labels.chunks_exact(t_bins).enumerate() {
        let start = (column * t_bins) as isize;
        for (t, &label) in cells.iter().enumerate() {
            if label == u32::MAX {
                continue;
            }
            for (shift, dt) in shifts {
                // the heading wraps: one step below 0 is the last bin, one above it the first
                let tt = match t as isize + dt as isize {
                    -1 => t_bins - 1,
                    tt if tt as usize == t_bins => 0,
                    tt => tt as usize,
                };
                let other = labels[(start + shift) as usize + tt];
                if other != u32::MAX {
                    sets.union(label as usize, other as usize);
                }
            }
        }
    }
    // each bin's set, named by the set's smallest bin number (bins visited in increasing order)
    let mut smallest = vec![usize::MAX; bins];
    (0..bins)
        .map(|id| {
            let r = find(&mut sets.parent, label_of_bin[id] as usize);
            if smallest[r] == usize::MAX {
                smallest[r] = id;
            }
            smallest[r]
        })
        .collect()
}

/// The plain version of [`cluster_roots`]: every one of the 26 neighbours looked up in a hash
/// map, sets joined under their smallest root.
fn cluster_roots_plain(bin_keys: &[(i32, i32, i32)], theta_bins: i32) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..bin_keys.len()).collect();
    let ids = bin_ids(bin_keys);
    for (id, &key) in bin_keys.iter().enumerate() {
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dt in -1..=1 {
                    if let Some(&other) = ids.get(&neighbour(key, (dx, dy, dt), theta_bins)) {
                        union_min(&mut parent, id, other);
                    }
                }
            }
        }
    }
    (0..bin_keys.len()).map(|i| find(&mut parent, i)).collect()
}

fn bin_ids(bin_keys: &[(i32, i32, i32)]) -> FxHashMap<(i32, i32, i32), usize> {
    bin_keys
        .iter()
        .enumerate()
        .map(|(id, &key)| (key, id))
        .collect()
}

fn neighbour(
    (kx, ky, kt): (i32, i32, i32),
    (dx, dy, dt): (i32, i32, i32),
    theta_bins: i32,
) -> (i32, i32, i32) {
    (kx + dx, ky + dy, (kt + dt).rem_euclid(theta_bins))
}

/// The dominant cluster's estimate; None for an empty set.
pub fn dominant_cluster(
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    w: &[f64],
    bins: &BinSize,
) -> Option<PoseEstimate> {
    dominant_cluster_with(xs, ys, ths, &[], w, bins, true)
}

/// [`dominant_cluster`] with the headings' sines and cosines taken from `trig` where its
/// entry holds the particle's heading to the bit (`[θ, sin θ, cos θ]`, as the weighing keeps
/// them), computed otherwise: the same estimate.
pub fn dominant_cluster_with_trig(
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    trig: &[[f64; 3]],
    w: &[f64],
    bins: &BinSize,
) -> Option<PoseEstimate> {
    dominant_cluster_with(xs, ys, ths, trig, w, bins, true)
}

/// [`dominant_cluster`] as first written: bins and all 26 neighbours looked up in a hash map,
/// sets joined under their smallest root. The plain version the tests and the `cluster`
/// benchmark compare the fast one with.
pub fn dominant_cluster_plain(
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    w: &[f64],
    bins: &BinSize,
) -> Option<PoseEstimate> {
    dominant_cluster_with(xs, ys, ths, &[], w, bins, false)
}

fn dominant_cluster_with(
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    trig: &[[f64; 3]],
    w: &[f64],
    bins: &BinSize,
    fast: bool,
) -> Option<PoseEstimate> {
    if w.is_empty() {
        return None;
    }
    let theta_bins = ((std::f64::consts::TAU / bins.theta).round() as i32).max(1);
    let particle_keys: Vec<(i32, i32, i32)> = (0..w.len())
        .map(|i| {
            let (kx, ky, kt) = bins.key(xs[i], ys[i], ths[i]);
            (kx, ky, kt.rem_euclid(theta_bins))
        })
        .collect();
    let (particle_bin, keys, roots) = if fast {
        let mut dense = DenseBins::new(&particle_keys, theta_bins);
        let bins = bin_particles(&particle_keys, dense.as_mut());
        let roots = cluster_roots(&bins.keys, theta_bins, dense.as_ref());
        (bins.of_particle, bins.keys, roots)
    } else {
        let bins = bin_particles(&particle_keys, None);
        let roots = cluster_roots_plain(&bins.keys, theta_bins);
        (bins.of_particle, bins.keys, roots)
    };
    let mut cluster_weight = vec![0.0; keys.len()];
    let mut total = 0.0;
    for (i, &b) in particle_bin.iter().enumerate() {
        cluster_weight[roots[b]] += w[i];
        total += w[i];
    }
    // heaviest cluster; ties go to the lowest root (stable)
    let best = (0..keys.len()).fold(0, |best, c| {
        if cluster_weight[c] > cluster_weight[best] {
            c
        } else {
            best
        }
    });
    let (mut sw, mut mx, mut my, mut sc, mut ss) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, &b) in particle_bin.iter().enumerate() {
        if roots[b] == best {
            sw += w[i];
            mx += w[i] * xs[i];
            my += w[i] * ys[i];
            let (s, c) = match trig.get(i) {
                Some(&[th, s, c]) if th.to_bits() == ths[i].to_bits() => (s, c),
                _ => ths[i].sin_cos(),
            };
            sc += w[i] * c;
            ss += w[i] * s;
        }
    }
    if sw <= 0.0 {
        return None;
    }
    let (mx, my) = (mx / sw, my / sw);
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    for (i, &b) in particle_bin.iter().enumerate() {
        if roots[b] == best {
            let (dx, dy) = (xs[i] - mx, ys[i] - my);
            cxx += w[i] * dx * dx;
            cxy += w[i] * dx * dy;
            cyy += w[i] * dy * dy;
        }
    }
    let r = (sc * sc + ss * ss).sqrt() / sw;
    let var_th = -2.0 * r.clamp(1e-12, 1.0).ln();
    Some(PoseEstimate {
        pose: Pose2::new(mx, my, ss.atan2(sc)),
        covariance: [
            [cxx / sw, cxy / sw, 0.0],
            [cxy / sw, cyy / sw, 0.0],
            [0.0, 0.0, var_th],
        ],
        weight: if total > 0.0 { sw / total } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heaviest_of_two_clusters_wins_and_headings_wrap() {
        // cluster A near (1, 1) with headings across ±π; cluster B at (10, 10), lighter
        let mut xs = vec![1.0, 1.1, 1.2, 0.9];
        let mut ys = vec![1.0, 1.05, 0.95, 1.0];
        let pi = std::f64::consts::PI;
        let mut ths = vec![pi - 0.02, -pi + 0.02, pi - 0.01, -pi + 0.01];
        let mut w = vec![0.2, 0.2, 0.2, 0.2];
        xs.extend([10.0, 10.1]);
        ys.extend([10.0, 10.0]);
        ths.extend([0.0, 0.0]);
        w.extend([0.1, 0.1]);
        let e = dominant_cluster(&xs, &ys, &ths, &w, &BinSize::default()).unwrap();
        assert!((e.pose.x - 1.05).abs() < 1e-9 && (e.pose.y - 1.0).abs() < 1e-9);
        assert!((e.pose.theta.abs() - pi).abs() < 1e-9, "{}", e.pose.theta);
        assert!((e.weight - 0.8).abs() < 1e-9);
        assert!(e.covariance[0][0] > 0.0 && e.covariance[2][2] < 1e-3);
    }

    /// Sines and cosines kept from the weighing give the estimate computed without them, to
    /// the bit; an entry whose heading is not the particle's (resampled away, injected, moved)
    /// is not used.
    #[test]
    fn kept_sines_and_cosines_give_the_same_estimate() {
        use crate::core::SimRng;
        use rand::{RngExt, SeedableRng};
        let mut rng = SimRng::seed_from_u64(11);
        let n = 5000;
        let xs: Vec<f64> = (0..n).map(|_| 3.0 + rng.random_range(-0.3..0.3)).collect();
        let ys: Vec<f64> = (0..n).map(|_| 7.0 + rng.random_range(-0.3..0.3)).collect();
        let ths: Vec<f64> = (0..n).map(|_| 0.4 + rng.random_range(-0.3..0.3)).collect();
        let w: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let trig: Vec<[f64; 3]> = ths
            .iter()
            .enumerate()
            .map(|(i, &th)| match i % 3 {
                0 => {
                    let (s, c) = th.sin_cos();
                    [th, s, c]
                }
                // another particle's heading and values, and a stale mark
                1 => [th + 1e-12, 0.5, 0.5],
                _ => [f64::NAN; 3],
            })
            .collect();
        let bins = BinSize::default();
        let plain = dominant_cluster(&xs, &ys, &ths, &w, &bins).unwrap();
        for kept in [&trig[..], &trig[..n / 2], &[]] {
            let e = dominant_cluster_with_trig(&xs, &ys, &ths, kept, &w, &bins).unwrap();
            assert_eq!(e.pose.theta.to_bits(), plain.pose.theta.to_bits());
            assert_eq!(e, plain);
        }
        // separate sin and cos calls, as the cluster made them before, give the same sums
        let (mut sc, mut ss) = (0.0f64, 0.0f64);
        let (mut sc2, mut ss2) = (0.0f64, 0.0f64);
        for i in 0..n {
            sc += w[i] * ths[i].cos();
            ss += w[i] * ths[i].sin();
            let (s, c) = ths[i].sin_cos();
            sc2 += w[i] * c;
            ss2 += w[i] * s;
        }
        assert_eq!((sc.to_bits(), ss.to_bits()), (sc2.to_bits(), ss2.to_bits()));
    }

    /// The dense histogram and the sets joined by size find the same clusters, roots and
    /// estimate as the plain hash map and smallest-root rule, to the bit: a filter spread over a hospital-sized floor, a tracking cloud, several blobs across
    /// the heading wrap, and a sparse set too wide for the dense histogram.
    #[test]
    fn the_fast_clustering_finds_exactly_the_plain_clusters() {
        use crate::core::SimRng;
        use rand::{RngExt, SeedableRng};
        let mut rng = SimRng::seed_from_u64(7);
        let pi = std::f64::consts::PI;
        let mut cases: Vec<Vec<(f64, f64, f64)>> = Vec::new();
        cases.push(
            (0..20_000)
                .map(|_| {
                    (
                        rng.random_range(0.0..140.0),
                        rng.random_range(0.0..60.0),
                        rng.random_range(-pi..pi),
                    )
                })
                .collect(),
        );
        cases.push(
            (0..3_000)
                .map(|_| {
                    (
                        4.0 + rng.random_range(-0.6..0.6),
                        -2.0 + rng.random_range(-0.6..0.6),
                        pi + rng.random_range(-0.3..0.3),
                    )
                })
                .collect(),
        );
        cases.push(
            (0..5_000)
                .map(|i| {
                    let c = (i % 5) as f64;
                    (
                        c * 3.0 + rng.random_range(-1.0..1.0),
                        -c * 2.0 + rng.random_range(-1.0..1.0),
                        rng.random_range(-pi..pi) * (c + 1.0) / 5.0,
                    )
                })
                .collect(),
        );
        cases.push(
            (0..50)
                .map(|_| {
                    (
                        rng.random_range(-5000.0..5000.0),
                        rng.random_range(-5000.0..5000.0),
                        rng.random_range(-pi..pi),
                    )
                })
                .collect(),
        );
        let bins = BinSize::default();
        for (n, case) in cases.iter().enumerate() {
            let xs: Vec<f64> = case.iter().map(|p| p.0).collect();
            let ys: Vec<f64> = case.iter().map(|p| p.1).collect();
            let ths: Vec<f64> = case.iter().map(|p| p.2).collect();
            let w: Vec<f64> = (0..case.len()).map(|_| rng.random::<f64>()).collect();
            let theta_bins = 36;
            let keys: Vec<_> = (0..w.len())
                .map(|i| {
                    let (kx, ky, kt) = bins.key(xs[i], ys[i], ths[i]);
                    (kx, ky, kt.rem_euclid(theta_bins))
                })
                .collect();
            let mut grid = DenseBins::new(&keys, theta_bins);
            assert_eq!(grid.is_some(), n < 3, "case {n}");
            let dense = bin_particles(&keys, grid.as_mut());
            let plain = bin_particles(&keys, None);
            assert_eq!(dense.of_particle, plain.of_particle, "case {n}");
            assert_eq!(dense.keys, plain.keys, "case {n}");
            let roots = cluster_roots(&dense.keys, theta_bins, grid.as_ref());
            assert_eq!(
                roots,
                cluster_roots(&plain.keys, theta_bins, None),
                "case {n}"
            );
            assert_eq!(
                roots,
                cluster_roots_plain(&plain.keys, theta_bins),
                "case {n}"
            );
            let clusters = roots.iter().enumerate().filter(|&(i, &r)| i == r).count();
            assert!(clusters >= 1, "case {n}");
            let a = dominant_cluster_with(&xs, &ys, &ths, &[], &w, &bins, true).unwrap();
            let b = dominant_cluster_with(&xs, &ys, &ths, &[], &w, &bins, false).unwrap();
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "case {n}");
        }
    }
}
