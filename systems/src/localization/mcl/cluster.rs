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

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The dominant cluster's estimate; None for an empty set.
pub fn dominant_cluster(
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    w: &[f64],
    bins: &BinSize,
) -> Option<PoseEstimate> {
    if w.is_empty() {
        return None;
    }
    let theta_bins = ((std::f64::consts::TAU / bins.theta).round() as i32).max(1);
    let mut ids: FxHashMap<(i32, i32, i32), usize> = FxHashMap::default();
    let mut keys = Vec::new();
    let mut particle_bin = Vec::with_capacity(w.len());
    for i in 0..w.len() {
        let (kx, ky, kt) = bins.key(xs[i], ys[i], ths[i]);
        let key = (kx, ky, kt.rem_euclid(theta_bins));
        let id = *ids.entry(key).or_insert_with(|| {
            keys.push(key);
            keys.len() - 1
        });
        particle_bin.push(id);
    }
    let mut parent: Vec<usize> = (0..keys.len()).collect();
    for (id, &(kx, ky, kt)) in keys.iter().enumerate() {
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dt in -1..=1 {
                    let nk = (kx + dx, ky + dy, (kt + dt).rem_euclid(theta_bins));
                    if let Some(&other) = ids.get(&nk) {
                        let (a, b) = (find(&mut parent, id), find(&mut parent, other));
                        if a != b {
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
            }
        }
    }
    let roots: Vec<usize> = (0..keys.len()).map(|i| find(&mut parent, i)).collect();
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
            sc += w[i] * ths[i].cos();
            ss += w[i] * ths[i].sin();
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
}
