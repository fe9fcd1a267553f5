//! Surface normals of scan points: principal-component analysis of the few neighbouring beams
//! around each point, kept only where the neighbourhood is a thin line. This is the normal
//! estimate of point-to-line ICP (Censi, "An ICP variant using a point-to-line metric", ICRA 2008)
//! and of the line-based methods surveyed in [Hospital thesis §3.5, §3.7] (CLS, HSM); the
//! improved matcher uses the normals for its rotation pre-search ([`super::orientation`]) and
//! for point-to-line refinement ([`super::refine`]).
//!
//! Neighbours are taken in slice order (beam order, as [`super::scan_points`] produces), and a
//! neighbour counts only if it lies within `gate` of the point, so depth jumps do not mix
//! surfaces. Unordered input yields few normals; the matcher then falls back on its global DE
//! search.

/// Beams on each side of a point used for its normal.
const HALF_WINDOW: usize = 3;
/// Adaptive gate of [`estimate_normals`] in units of the local point spacing.
const SPACING_GATE: f32 = 3.5;
/// Smallest number of points (the centre included) for a normal.
const MIN_POINTS: usize = 4;
/// Largest ratio of the small to the large eigenvalue of the neighbourhood covariance: the
/// neighbourhood must be at least ~3× longer than it is thick.
const MAX_FLATNESS: f32 = 0.1;

/// The unit normal of every point (pointing towards the sensor at the origin), or `None` where
/// the neighbourhood is too small or not line-like. `gate` is the largest neighbour distance (m).
///
/// Where `max_gate` exceeds `gate`, a point's gate widens, up to `max_gate`, to
/// [`SPACING_GATE`] × the point's spacing from its nearer scan neighbour: a wall seen at a
/// grazing angle or far away is sampled sparsely but evenly, a depth jump is a gap much wider
/// than the spacing on its either side.
pub(crate) fn estimate_normals(
    points: &[[f32; 2]],
    gate: f32,
    max_gate: f32,
) -> Vec<Option<[f32; 2]>> {
    let n = points.len();
    let gap2 = |i: usize, j: usize| {
        let (a, b) = (points[i], points[j]);
        (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
    };
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let p = points[k];
        let mut g2 = gate * gate;
        if max_gate > gate {
            let local2 = match (k.checked_sub(1), (k + 1 < n).then_some(k + 1)) {
                (Some(i), Some(j)) => gap2(k, i).min(gap2(k, j)),
                (Some(i), None) | (None, Some(i)) => gap2(k, i),
                (None, None) => 0.0,
            };
            g2 = g2.max((SPACING_GATE * SPACING_GATE * local2).min(max_gate * max_gate));
        }
        let (lo, hi) = (k.saturating_sub(HALF_WINDOW), (k + HALF_WINDOW + 1).min(n));
        let (mut cnt, mut sx, mut sy, mut sxx, mut sxy, mut syy) =
            (0usize, 0f32, 0f32, 0f32, 0f32, 0f32);
        for q in &points[lo..hi] {
            // relative to p, for precision
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            if dx * dx + dy * dy <= g2 {
                cnt += 1;
                sx += dx;
                sy += dy;
                sxx += dx * dx;
                sxy += dx * dy;
                syy += dy * dy;
            }
        }
        if cnt < MIN_POINTS {
            out.push(None);
            continue;
        }
        let inv = 1.0 / cnt as f32;
        let (mx, my) = (sx * inv, sy * inv);
        let a = sxx * inv - mx * mx;
        let b = sxy * inv - mx * my;
        let c = syy * inv - my * my;
        let half_tr = 0.5 * (a + c);
        let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
        let (l_max, l_min) = (half_tr + disc, half_tr - disc);
        if l_max.is_nan() || l_max <= 0.0 || l_min > MAX_FLATNESS * l_max {
            out.push(None);
            continue;
        }
        // the normal is the eigenvector of the small eigenvalue: (b, λ − a) or (λ − c, b),
        // whichever is better conditioned (no trigonometry)
        let (u, v) = ([b, l_min - a], [l_min - c, b]);
        let (nu, nv) = (u[0] * u[0] + u[1] * u[1], v[0] * v[0] + v[1] * v[1]);
        let (e, norm2) = if nu >= nv { (u, nu) } else { (v, nv) };
        if norm2.is_nan() || norm2 <= 0.0 {
            out.push(None);
            continue;
        }
        let inv = 1.0 / norm2.sqrt();
        let mut nrm = [e[0] * inv, e[1] * inv];
        if nrm[0] * p[0] + nrm[1] * p[1] > 0.0 {
            nrm = [-nrm[0], -nrm[1]];
        }
        out.push(Some(nrm));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_normals_face_the_sensor() {
        // a wall x = 2 seen from the origin, and a corner-free wall y = −1
        let wall: Vec<[f32; 2]> = (0..20).map(|k| [2.0, -1.0 + 0.1 * k as f32]).collect();
        let nr = estimate_normals(&wall, 0.5, 0.5);
        for n in nr.iter().flatten() {
            assert!((n[0] + 1.0).abs() < 1e-4 && n[1].abs() < 1e-3, "{n:?}");
        }
        assert!(nr.iter().all(|n| n.is_some()));
        let floor: Vec<[f32; 2]> = (0..20).map(|k| [-1.0 + 0.1 * k as f32, -1.0]).collect();
        for n in estimate_normals(&floor, 0.5, 0.5).iter().flatten() {
            assert!(n[0].abs() < 1e-3 && (n[1] - 1.0).abs() < 1e-4, "{n:?}");
        }
    }

    #[test]
    fn the_gate_widens_with_even_sparse_sampling_but_not_across_a_jump() {
        // a wall sampled every 0.3 m: no normals with a fixed 0.5 m gate, all with the
        // adaptive one
        let wall: Vec<[f32; 2]> = (0..12).map(|k| [-1.5 + 0.3 * k as f32, 4.0]).collect();
        assert!(
            estimate_normals(&wall, 0.5, 0.5)
                .iter()
                .all(|n| n.is_none())
        );
        let adaptive = estimate_normals(&wall, 0.5, 1.5);
        for n in &adaptive {
            let n = n.expect("a normal on every sample");
            assert!(n[0].abs() < 1e-3 && (n[1] + 1.0).abs() < 1e-4, "{n:?}");
        }
        // densely sampled wall, a jump of 1 m, another dense wall further back: the points at
        // the jump keep neighbours of their own wall only (gate 3.5 × 5 cm, not 1 m)
        let mut jump: Vec<[f32; 2]> = (0..10).map(|k| [0.05 * k as f32, 2.0]).collect();
        jump.extend((0..10).map(|k| [1.45 + 0.05 * k as f32, 3.0]));
        for n in estimate_normals(&jump, 0.5, 1.5).iter().flatten() {
            assert!(n[0].abs() < 1e-3, "{n:?}");
        }
    }

    #[test]
    fn isolated_or_scattered_points_have_no_normal() {
        let sparse: Vec<[f32; 2]> = (0..10).map(|k| [k as f32, 1.0]).collect();
        assert!(
            estimate_normals(&sparse, 0.5, 0.5)
                .iter()
                .all(|n| n.is_none())
        );
        // a tight zig-zag is not a line
        let zig: Vec<[f32; 2]> = (0..10)
            .map(|k| [1.0 + 0.05 * k as f32, if k % 2 == 0 { 0.0 } else { 0.1 }])
            .collect();
        assert!(
            estimate_normals(&zig, 0.5, 0.5)[3..7]
                .iter()
                .all(|n| n.is_none())
        );
    }
}
