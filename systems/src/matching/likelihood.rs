//! A blurred occupancy map to match scans against: the rasterized lookup table of E. Olson,
//! "Real-time correlative scan matching", ICRA 2009, §III, where each cell holds how likely a
//! scan point is to fall there — the obstacles blurred by a Gaussian of the expected point error.
//!
//! Why blur a ground-truth map: its walls end exactly on cell boundaries, so a surface point lies
//! on the boundary between an occupied and a free cell, and the candidate poses of a discretized
//! search are up to half a cell and half an angular step from the truth; reading the bare 0/1
//! map, about half the points of a face then land in the free cell (scores near 0.5–0.8 at the
//! true pose). With σ of one to two cells every point near a surface keeps most of its weight,
//! and the score still peaks where the surfaces align.

use super::ProbGrid;
use crate::world::{Cell, OccupancyGrid};

/// P = exp(−d²/(2σ²)) with d the distance (cell centre to cell centre) to the nearest occupied
/// cell, cut at 3σ; unknown cells keep 0.5 where the blur is lower. `sigma` in metres.
pub fn likelihood_grid(grid: &OccupancyGrid, sigma: f64) -> ProbGrid {
    let (w, h) = (grid.width as i64, grid.height as i64);
    let mut p: Vec<f32> = grid
        .cells
        .iter()
        .map(|c| if *c == Cell::Unknown { 0.5 } else { 0.0 })
        .collect();
    let s = (sigma / grid.resolution).max(1e-6);
    let reach = (3.0 * s).ceil() as i64;
    // the kernel once: weights by offset
    let side = (2 * reach + 1) as usize;
    let kernel: Vec<f32> = (0..side * side)
        .map(|i| {
            let (dx, dy) = ((i % side) as i64 - reach, (i / side) as i64 - reach);
            let d2 = (dx * dx + dy * dy) as f64;
            if d2 > (3.0 * s) * (3.0 * s) {
                0.0
            } else {
                (-d2 / (2.0 * s * s)).exp() as f32
            }
        })
        .collect();
    for r in 0..h {
        for c in 0..w {
            if grid.cells[(r * w + c) as usize] != Cell::Occupied {
                continue;
            }
            for dy in -reach..=reach {
                let rr = r + dy;
                if rr < 0 || rr >= h {
                    continue;
                }
                for dx in -reach..=reach {
                    let cc = c + dx;
                    if cc < 0 || cc >= w {
                        continue;
                    }
                    let k = kernel[((dy + reach) as usize) * side + (dx + reach) as usize];
                    let cell = &mut p[(rr * w + cc) as usize];
                    *cell = cell.max(k);
                }
            }
        }
    }
    ProbGrid {
        width: grid.width,
        height: grid.height,
        resolution: grid.resolution,
        origin: grid.origin,
        p,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blurs_obstacles_and_keeps_unknown() {
        let mut g = OccupancyGrid::new(9, 5, 0.1, [0.0, 0.0], Cell::Free);
        g.set(4, 2, Cell::Occupied);
        g.set(0, 0, Cell::Unknown);
        let p = likelihood_grid(&g, 0.1);
        assert_eq!(p.get(4, 2), 1.0);
        assert!((p.get(5, 2) - (-0.5f32).exp()).abs() < 1e-6);
        assert!((p.get(5, 3) - (-1.0f32).exp()).abs() < 1e-6);
        // beyond 3σ
        assert_eq!(p.get(8, 2), 0.0);
        assert_eq!(p.get(0, 0), 0.5);
    }
}
