//! Path shortening by line of sight ("string pulling"): of a grid path, keep only the waypoints
//! needed so that every straight segment crosses cells of acceptable cost. A greedy forward pass
//! as in Botea, Müller & Schaeffer, "Near Optimal Hierarchical Path-Finding" (2004, path
//! smoothing): from the last kept waypoint, skip ahead while the next point is still in sight.
//!
//! "In sight" is decided on every cell a segment touches (the supercover of the segment), walked
//! with the voxel traversal of Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
//! Tracing" (Eurographics 1987). Where a segment passes exactly through a cell corner, both cells
//! beside the corner are checked too, so a shortcut never squeezes diagonally between two
//! blocked cells (the same rule as A*'s no-corner-cutting).

use super::costmap::{Costmap, INSCRIBED};

/// Calls `visit(col, row)` for every cell the segment from `a` to `b` (in cell units, i.e.
/// world coordinates relative to the origin divided by the resolution) touches, in order, until
/// `visit` returns false. Returns false if it was stopped. Both ends must be finite.
pub fn walk_segment(a: [f64; 2], b: [f64; 2], mut visit: impl FnMut(i64, i64) -> bool) -> bool {
    let (mut cx, mut cy) = (a[0].floor() as i64, a[1].floor() as i64);
    let (tx, ty) = (b[0].floor() as i64, b[1].floor() as i64);
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let sx = if dx > 0.0 { 1 } else { -1 };
    let sy = if dy > 0.0 { 1 } else { -1 };
    // ray parameter t ∈ [0, 1] at which the next vertical / horizontal cell border is crossed
    let (mut tmx, tdx) = if dx != 0.0 {
        let border = if dx > 0.0 { cx as f64 + 1.0 } else { cx as f64 };
        ((border - a[0]) / dx, 1.0 / dx.abs())
    } else {
        (f64::INFINITY, f64::INFINITY)
    };
    let (mut tmy, tdy) = if dy != 0.0 {
        let border = if dy > 0.0 { cy as f64 + 1.0 } else { cy as f64 };
        ((border - a[1]) / dy, 1.0 / dy.abs())
    } else {
        (f64::INFINITY, f64::INFINITY)
    };
    if !visit(cx, cy) {
        return false;
    }
    let mut steps = (tx - cx).abs() + (ty - cy).abs();
    while steps > 0 {
        if (tmx - tmy).abs() <= 1e-9 && steps >= 2 {
            // through a corner: the two cells beside it, then the diagonal one
            if !visit(cx + sx, cy) || !visit(cx, cy + sy) {
                return false;
            }
            cx += sx;
            cy += sy;
            tmx += tdx;
            tmy += tdy;
            steps -= 2;
        } else if tmx < tmy {
            cx += sx;
            tmx += tdx;
            steps -= 1;
        } else {
            cy += sy;
            tmy += tdy;
            steps -= 1;
        }
        if !visit(cx, cy) {
            return false;
        }
    }
    true
}

/// True if every cell the segment between world points `a` and `b` touches is inside the map
/// and costs at most `max_cost`.
pub fn segment_clear(map: &Costmap, a: [f64; 2], b: [f64; 2], max_cost: u8) -> bool {
    let to_cells = |p: [f64; 2]| {
        [
            (p[0] - map.origin[0]) / map.resolution,
            (p[1] - map.origin[1]) / map.resolution,
        ]
    };
    let (w, h) = (map.width as i64, map.height as i64);
    walk_segment(to_cells(a), to_cells(b), |c, r| {
        c >= 0 && r >= 0 && c < w && r < h && map.costs[(r * w + c) as usize] <= max_cost
    })
}

/// Indices of the points of a grid path to keep. `points` are the path's world points (cell
/// centres, or the exact start and goal at the ends), `cells` their costmap indices. A segment
/// replacing a stretch of the path is accepted if every cell it touches costs at most the larger
/// of `max_cost` and the highest cost on that stretch, and below [`INSCRIBED`] in any case:
/// shortcuts never pass closer to walls than the grid path they replace already did (unless
/// `max_cost` allows it), and never through cells where the robot would touch an obstacle.
pub fn shorten(map: &Costmap, points: &[[f64; 2]], cells: &[usize], max_cost: u8) -> Vec<usize> {
    let n = points.len();
    let mut keep = Vec::new();
    if n == 0 {
        return keep;
    }
    keep.push(0);
    let mut anchor = 0;
    let mut stretch_max = cells.first().map_or(0, |&i| map.costs[i]);
    for i in 1..n.saturating_sub(1) {
        stretch_max = stretch_max
            .max(map.costs[cells[i]])
            .max(map.costs[cells[i + 1]]);
        let limit = max_cost.max(stretch_max).min(INSCRIBED - 1);
        // anchor ≤ i − 1 here; if the point after i is out of sight, i is kept, and the move
        // from i to i + 1 is the A* move itself
        if !segment_clear(map, points[anchor], points[i + 1], limit) {
            keep.push(i);
            anchor = i;
            stretch_max = map.costs[cells[i]];
        }
    }
    if n > 1 {
        keep.push(n - 1);
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells_of(a: [f64; 2], b: [f64; 2]) -> Vec<(i64, i64)> {
        let mut v = Vec::new();
        walk_segment(a, b, |c, r| {
            v.push((c, r));
            true
        });
        v
    }

    #[test]
    fn supercover_of_segments() {
        assert_eq!(
            cells_of([0.5, 0.5], [3.5, 0.5]),
            [(0, 0), (1, 0), (2, 0), (3, 0)]
        );
        assert_eq!(cells_of([0.5, 2.5], [0.5, 0.5]), [(0, 2), (0, 1), (0, 0)]);
        // exact diagonal through corners: both side cells of each corner
        assert_eq!(
            cells_of([0.5, 0.5], [2.5, 2.5]),
            [(0, 0), (1, 0), (0, 1), (1, 1), (2, 1), (1, 2), (2, 2)]
        );
        // a shallow line: every touched cell, 4-connected
        let v = cells_of([0.2, 0.3], [5.7, 2.1]);
        assert_eq!(v.first(), Some(&(0, 0)));
        assert_eq!(v.last(), Some(&(5, 2)));
        assert_eq!(v.len(), 8);
        assert!(
            v.windows(2)
                .all(|w| (w[0].0 - w[1].0).abs() + (w[0].1 - w[1].1).abs() == 1)
        );
        assert_eq!(cells_of([1.5, 1.5], [1.7, 1.2]), [(1, 1)]);
    }
}
