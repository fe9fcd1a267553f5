//! What a localizer believes, turned into drawable geometry for the recording (plain data, no
//! Rerun types, so it is unit-tested on its own):
//!
//! - particle sets: MCL particles coloured by weight normalised to the heaviest (w / w_max),
//!   DE populations coloured by cost rank (best first), Markov grid cells whose belief,
//!   marginalised over θ, is at least [`GRID_MASS_FLOOR`] of the most probable cell's, coloured by
//!   mass on a log scale, a user's localizer's belief points coloured by their weight; all on one
//!   dark-blue → yellow colormap (viridis), yellow = most likely;
//! - the 2-σ ellipse of an estimate's (x, y) covariance and the ±2σ wedge of its heading.
//!
//! Sets larger than the cap are subsampled evenly (every k-th member in storage order, or in
//! cost-rank order for DE populations), so the picture keeps its spatial extent and the data
//! stay small whatever the particle count.

use systems::localization::Filter;
use systems::localization::de_filter::DeFilter;
use systems::localization::de_mc::DeMc;
use systems::localization::de_odometry::DeOdometry;
use systems::localization::markov_grid::MarkovGrid;
use systems::localization::mcl::Mcl;

/// Markov grid cells drawn: marginal mass ≥ this share of the most probable cell's.
pub const GRID_MASS_FLOOR: f64 = 1e-3;

/// Anchors of the viridis colormap (matplotlib), evenly spaced on [0, 1].
const VIRIDIS: [[f32; 3]; 5] = [
    [68.0, 1.0, 84.0],
    [59.0, 82.0, 139.0],
    [33.0, 145.0, 140.0],
    [94.0, 201.0, 98.0],
    [253.0, 231.0, 37.0],
];

/// Dark blue (0) → yellow (1); NaN reads as 0.
pub fn colormap(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } as f32;
    let x = t * (VIRIDIS.len() - 1) as f32;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f32;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    std::array::from_fn(|c| (a[c] + f * (b[c] - a[c])).round() as u8)
}

/// A coloured point set on the floor (z = 0).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cloud {
    pub points: Vec<[f32; 3]>,
    pub colors: Vec<[u8; 3]>,
    /// Point radius (UI points: visible at every zoom).
    pub radius: f32,
}

/// `cap` indices spread evenly over 0..n (all of them when n ≤ cap).
pub fn even_subset(n: usize, cap: usize) -> Vec<usize> {
    if n <= cap {
        (0..n).collect()
    } else {
        (0..cap).map(|k| k * n / cap).collect()
    }
}

/// MCL particles, coloured by w / w_max.
pub fn mcl_cloud(m: &Mcl, cap: usize) -> Cloud {
    let w_max = m.w.iter().copied().fold(0.0f64, f64::max);
    let idx = even_subset(m.len(), cap);
    Cloud {
        points: idx
            .iter()
            .map(|&i| [m.xs[i] as f32, m.ys[i] as f32, 0.0])
            .collect(),
        colors: idx
            .iter()
            .map(|&i| colormap(if w_max > 0.0 { m.w[i] / w_max } else { 0.0 }))
            .collect(),
        radius: 1.5,
    }
}

/// A DE population, coloured by cost rank: the best member yellow, the worst dark blue.
pub fn population_cloud(poses: &[[f64; 3]], costs: &[f64], cap: usize) -> Cloud {
    let n = poses.len().min(costs.len());
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]).then(a.cmp(&b)));
    let ranks = even_subset(n, cap);
    let last = (n.max(2) - 1) as f64;
    Cloud {
        points: ranks
            .iter()
            .map(|&r| {
                let p = poses[order[r]];
                [p[0] as f32, p[1] as f32, 0.0]
            })
            .collect(),
        colors: ranks
            .iter()
            .map(|&r| colormap(1.0 - r as f64 / last))
            .collect(),
        radius: 2.0,
    }
}

/// The Markov grid's belief marginalised over θ: the cells at or above [`GRID_MASS_FLOOR`] of
/// the peak, coloured by mass on a log scale from that floor to the peak.
pub fn grid_cloud(g: &MarkovGrid, cap: usize) -> Cloud {
    let l = &g.layout;
    let layer = l.layer();
    let mut marginal = vec![0.0f64; layer];
    for k in 0..l.n_theta {
        let b = &g.belief[k * layer..(k + 1) * layer];
        for (m, &v) in marginal.iter_mut().zip(b) {
            *m += v as f64;
        }
    }
    let peak = marginal.iter().copied().fold(0.0f64, f64::max);
    if peak <= 0.0 {
        return Cloud::default();
    }
    let floor = peak * GRID_MASS_FLOOR;
    let cells: Vec<usize> = (0..layer).filter(|&c| marginal[c] >= floor).collect();
    let span = (peak / floor).ln();
    let idx = even_subset(cells.len(), cap);
    Cloud {
        points: idx
            .iter()
            .map(|&k| {
                let c = cells[k];
                let (x, y) = l.centre(c % l.nx, c / l.nx);
                [x as f32, y as f32, 0.0]
            })
            .collect(),
        colors: idx
            .iter()
            .map(|&k| colormap((marginal[cells[k]] / floor).ln() / span))
            .collect(),
        radius: 2.5,
    }
}

/// The particle set of a filter: ours drawn from their own state; any other map localizer (a
/// user's) from its [`systems::localization::MapLocalizer::belief_points`]. None for those
/// without one (DE odometry, SLAM systems).
pub fn filter_cloud(f: &Filter, cap: usize) -> Option<Cloud> {
    // SLAM systems record their map and graph under robots/<name>/slam
    let f = f.as_map()?;
    if let Some(m) = f.downcast_ref::<Mcl>() {
        Some(mcl_cloud(m, cap))
    } else if let Some(g) = f.downcast_ref::<MarkovGrid>() {
        Some(grid_cloud(g, cap))
    } else if let Some(d) = f.downcast_ref::<DeFilter>() {
        Some(population_cloud(
            &d.tracker.population.poses,
            &d.tracker.population.costs,
            cap,
        ))
    } else if let Some(d) = f.downcast_ref::<DeMc>() {
        Some(population_cloud(
            &d.tracker.population.poses,
            &d.tracker.population.costs,
            cap,
        ))
    } else if f.downcast_ref::<DeOdometry>().is_some() {
        None
    } else {
        f.belief_points().map(|p| points_cloud(&p, cap))
    }
}

/// Weighted poses (the most likely weighing 1), coloured by weight.
pub fn points_cloud(points: &[([f64; 2], f64)], cap: usize) -> Cloud {
    let idx = even_subset(points.len(), cap);
    Cloud {
        points: idx
            .iter()
            .map(|&i| [points[i].0[0] as f32, points[i].0[1] as f32, 0.0])
            .collect(),
        colors: idx.iter().map(|&i| colormap(points[i].1)).collect(),
        radius: 1.5,
    }
}

/// Points of the closed 2-σ ellipse of the (x, y) block of `cov` around (x, y): `segments`
/// segments, the first point repeated at the end. None if the block is not a finite covariance.
pub fn ellipse_2sigma(
    x: f64,
    y: f64,
    cov: &[[f64; 3]; 3],
    segments: usize,
) -> Option<Vec<[f32; 3]>> {
    let (a, b, c) = (cov[0][0], 0.5 * (cov[0][1] + cov[1][0]), cov[1][1]);
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    // eigen-decomposition of [[a, b], [b, c]]
    let mid = 0.5 * (a + c);
    let rad = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = ((mid + rad).max(0.0), (mid - rad).max(0.0));
    let phi = 0.5 * (2.0 * b).atan2(a - c);
    let (r1, r2) = (2.0 * l1.sqrt(), 2.0 * l2.sqrt());
    let (s, co) = phi.sin_cos();
    let n = segments.max(3);
    Some(
        (0..=n)
            .map(|k| {
                let t = std::f64::consts::TAU * (k % n) as f64 / n as f64;
                let (u, v) = (r1 * t.cos(), r2 * t.sin());
                [
                    (x + co * u - s * v) as f32,
                    (y + s * u + co * v) as f32,
                    0.0,
                ]
            })
            .collect(),
    )
}

/// The ±2σ heading wedge: two rays of length `len` from (x, y) at θ ± 2σθ (at most ±π).
pub fn heading_wedge(
    x: f64,
    y: f64,
    theta: f64,
    var_theta: f64,
    len: f64,
) -> Option<Vec<[f32; 3]>> {
    if !(var_theta.is_finite() && var_theta >= 0.0) {
        return None;
    }
    let half = (2.0 * var_theta.sqrt()).min(std::f64::consts::PI);
    let tip = |a: f64| [(x + len * a.cos()) as f32, (y + len * a.sin()) as f32, 0.0];
    Some(vec![
        tip(theta - half),
        [x as f32, y as f32, 0.0],
        tip(theta + half),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use systems::core::Pose2;
    use systems::localization::{BeamSubset, LocalizationMap, MapLocalizer, PoseEstimate};

    #[test]
    fn colormap_runs_from_dark_blue_to_yellow() {
        assert_eq!(colormap(0.0), [68, 1, 84]);
        assert_eq!(colormap(1.0), [253, 231, 37]);
        assert_eq!(colormap(f64::NAN), colormap(0.0));
        assert_eq!(colormap(7.0), colormap(1.0));
    }

    #[test]
    fn even_subset_keeps_the_spread() {
        assert_eq!(even_subset(3, 10), vec![0, 1, 2]);
        let s = even_subset(100_000, 1000);
        assert_eq!(s.len(), 1000);
        assert_eq!(s[0], 0);
        assert!(*s.last().unwrap() >= 99_000);
    }

    #[test]
    fn population_colours_follow_cost_rank() {
        let poses = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let c = population_cloud(&poses, &[5.0, 1.0, 3.0], 10);
        // best (cost 1, x = 1) first and yellow, worst (x = 0) last and dark blue
        assert_eq!(c.points[0][0], 1.0);
        assert_eq!(c.colors[0], colormap(1.0));
        assert_eq!(c.points[2][0], 0.0);
        assert_eq!(c.colors[2], colormap(0.0));
    }

    #[test]
    fn ellipse_has_the_two_sigma_axes() {
        // σx = 0.5, σy = 0.1, rotated by 90° through the off-diagonal: check the extent only
        let cov = [[0.25, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.0]];
        let e = ellipse_2sigma(1.0, 2.0, &cov, 36).unwrap();
        assert_eq!(e.len(), 37);
        assert_eq!(e[0], e[36]);
        let max_x = e.iter().map(|p| p[0]).fold(f32::MIN, f32::max);
        let max_y = e.iter().map(|p| p[1]).fold(f32::MIN, f32::max);
        assert!((max_x - 2.0).abs() < 1e-5, "{max_x}");
        assert!((max_y - 2.2).abs() < 1e-3, "{max_y}");
        assert!(ellipse_2sigma(0.0, 0.0, &[[f64::NAN; 3]; 3], 8).is_none());
        let w = heading_wedge(0.0, 0.0, 0.0, 0.01, 1.0).unwrap();
        assert!((w[2][1] - 0.2f64.sin() as f32).abs() < 1e-6);
    }

    /// A user's localizer with its own belief points.
    #[derive(Clone, Debug)]
    struct Points(Vec<([f64; 2], f64)>);

    impl MapLocalizer for Points {
        fn kind(&self) -> &'static str {
            "points"
        }
        fn max_beams(&self) -> usize {
            0
        }
        fn predict(&mut self, _: &Pose2) -> bool {
            false
        }
        fn correct(&mut self, _: &LocalizationMap, _: &BeamSubset) -> bool {
            false
        }
        fn estimate(&self) -> Option<PoseEstimate> {
            None
        }
        fn belief_points(&self) -> Option<Vec<([f64; 2], f64)>> {
            (!self.0.is_empty()).then(|| self.0.clone())
        }
        fn box_clone(&self) -> Box<dyn MapLocalizer> {
            Box::new(self.clone())
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
    }

    #[test]
    fn a_user_localizers_belief_points_become_a_cloud() {
        let pts = vec![([1.0, 2.0], 1.0), ([3.0, 4.0], 0.0), ([5.0, 6.0], 0.5)];
        let c = filter_cloud(&Filter::Map(Box::new(Points(pts))), 10).unwrap();
        assert_eq!(
            c.points,
            vec![[1.0, 2.0, 0.0], [3.0, 4.0, 0.0], [5.0, 6.0, 0.0]]
        );
        assert_eq!(c.colors, vec![colormap(1.0), colormap(0.0), colormap(0.5)]);
        let many: Vec<_> = (0..100).map(|k| ([k as f64, 0.0], 1.0)).collect();
        let c = filter_cloud(&Filter::Map(Box::new(Points(many))), 10).unwrap();
        assert_eq!(c.points.len(), 10);
        // none drawn for a localizer without belief points
        assert!(filter_cloud(&Filter::Map(Box::new(Points(Vec::new()))), 10).is_none());
    }
}
