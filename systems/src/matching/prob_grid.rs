//! A probability occupancy grid: what scan-to-map matchers match against and what the SLAM maps
//! export. Cells hold P(occupied) in [0, 1] (0.5 = unknown, the convention of occupancy-grid
//! mapping, Thrun et al., *Probabilistic Robotics*, §9.2), row-major with row 0 at the BOTTOM,
//! the layout of [`crate::world::OccupancyGrid`]: cell (col, row) covers
//! [ox + col·res, ox + (col+1)·res) × [oy + row·res, oy + (row+1)·res).

use crate::world::{Cell, OccupancyGrid};

#[derive(Clone, Debug, PartialEq)]
pub struct ProbGrid {
    pub width: usize,
    pub height: usize,
    /// Metres per cell.
    pub resolution: f64,
    /// World position of the lower-left corner of cell (0, 0).
    pub origin: [f64; 2],
    /// P(occupied) per cell, `row * width + col`.
    pub p: Vec<f32>,
}

impl ProbGrid {
    /// A grid of `fill` probability.
    pub fn new(width: usize, height: usize, resolution: f64, origin: [f64; 2], fill: f32) -> Self {
        ProbGrid {
            width,
            height,
            resolution,
            origin,
            p: vec![fill; width * height],
        }
    }

    /// Occupied cells 1, free 0, unknown 0.5.
    pub fn from_occupancy(grid: &OccupancyGrid) -> Self {
        let p = grid
            .cells
            .iter()
            .map(|c| match c {
                Cell::Occupied => 1.0,
                Cell::Free => 0.0,
                Cell::Unknown => 0.5,
            })
            .collect();
        ProbGrid {
            width: grid.width,
            height: grid.height,
            resolution: grid.resolution,
            origin: grid.origin,
            p,
        }
    }

    /// Thresholded as map_server does with its default thresholds: P ≥ 0.65 occupied, P ≤ 0.196
    /// free, unknown between.
    pub fn to_occupancy(&self) -> OccupancyGrid {
        let cells = self
            .p
            .iter()
            .map(|&p| {
                if p >= 0.65 {
                    Cell::Occupied
                } else if p <= 0.196 {
                    Cell::Free
                } else {
                    Cell::Unknown
                }
            })
            .collect();
        OccupancyGrid {
            width: self.width,
            height: self.height,
            resolution: self.resolution,
            origin: self.origin,
            cells,
        }
    }

    pub fn index(&self, col: usize, row: usize) -> usize {
        row * self.width + col
    }

    pub fn get(&self, col: usize, row: usize) -> f32 {
        self.p[self.index(col, row)]
    }

    /// The cell containing a world point, if inside the grid.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let [c, r] = self.to_grid(x, y);
        let (c, r) = (c.floor(), r.floor());
        if c < 0.0 || r < 0.0 || c >= self.width as f64 || r >= self.height as f64 {
            return None;
        }
        Some((c as usize, r as usize))
    }

    /// Continuous grid coordinates of a world point (cell (c, r) spans [c, c+1) × [r, r+1)).
    pub fn to_grid(&self, x: f64, y: f64) -> [f64; 2] {
        [
            (x - self.origin[0]) / self.resolution,
            (y - self.origin[1]) / self.resolution,
        ]
    }

    /// World extent: (min x, min y, max x, max y).
    pub fn bounds(&self) -> [f64; 4] {
        [
            self.origin[0],
            self.origin[1],
            self.origin[0] + self.width as f64 * self.resolution,
            self.origin[1] + self.height as f64 * self.resolution,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_an_occupancy_grid_and_finds_cells_bottom_up() {
        let mut g = OccupancyGrid::new(4, 3, 0.5, [-1.0, 2.0], Cell::Free);
        g.set(3, 0, Cell::Occupied);
        g.set(0, 2, Cell::Unknown);
        let p = ProbGrid::from_occupancy(&g);
        assert_eq!(p.get(3, 0), 1.0);
        assert_eq!(p.get(0, 2), 0.5);
        assert_eq!(p.to_occupancy(), g);
        // (0.9, 2.1) is in column 3, bottom row
        assert_eq!(p.cell_of(0.9, 2.1), Some((3, 0)));
        assert_eq!(p.cell_of(1.0, 2.1), None);
        assert_eq!(p.to_grid(-1.0, 3.5), [0.0, 3.0]);
    }
}
