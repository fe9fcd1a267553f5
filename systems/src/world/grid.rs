//! Occupancy grid in the world frame. Row 0 is the BOTTOM row (the map_server image's last row),
//! so cell (col, row) covers [ox + col·res, ox + (col+1)·res) × [oy + row·res, oy + (row+1)·res).

use crate::core::cache::CacheKey;

/// A cell's state, with the ROS `nav_msgs/OccupancyGrid` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Cell {
    Free = 0,
    Occupied = 100,
    Unknown = 255,
}

#[derive(Clone, Debug, PartialEq)]
pub struct OccupancyGrid {
    pub width: usize,
    pub height: usize,
    /// Metres per cell.
    pub resolution: f64,
    /// World position of the lower-left corner of cell (0, 0).
    pub origin: [f64; 2],
    pub cells: Vec<Cell>,
}

impl OccupancyGrid {
    pub fn new(width: usize, height: usize, resolution: f64, origin: [f64; 2], fill: Cell) -> Self {
        OccupancyGrid {
            width,
            height,
            resolution,
            origin,
            cells: vec![fill; width * height],
        }
    }

    /// `key` fed with every field: size, resolution, origin and cells (the on-disk cache's key
    /// of a structure computed from the grid).
    pub fn add_to_key(&self, key: CacheKey) -> CacheKey {
        let cells: Vec<u8> = self.cells.iter().map(|&c| c as u8).collect();
        key.u64(self.width as u64)
            .u64(self.height as u64)
            .f64(self.resolution)
            .f64(self.origin[0])
            .f64(self.origin[1])
            .bytes(&cells)
    }

    pub fn index(&self, col: usize, row: usize) -> usize {
        row * self.width + col
    }

    pub fn get(&self, col: usize, row: usize) -> Cell {
        self.cells[self.index(col, row)]
    }

    pub fn set(&mut self, col: usize, row: usize, cell: Cell) {
        let i = self.index(col, row);
        self.cells[i] = cell;
    }

    /// Obstacles for physics and sensors: only occupied cells (unknown space is not solid, as in
    /// Stage; maps enclose their free space with walls).
    pub fn is_obstacle(&self, col: usize, row: usize) -> bool {
        self.get(col, row) == Cell::Occupied
    }

    pub fn obstacles(&self) -> Vec<bool> {
        self.cells.iter().map(|c| *c == Cell::Occupied).collect()
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

    /// The cell containing a world point, if inside the grid.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let c = ((x - self.origin[0]) / self.resolution).floor();
        let r = ((y - self.origin[1]) / self.resolution).floor();
        if c < 0.0 || r < 0.0 || c >= self.width as f64 || r >= self.height as f64 {
            return None;
        }
        Some((c as usize, r as usize))
    }

    /// World coordinates of a cell centre.
    pub fn cell_center(&self, col: usize, row: usize) -> [f64; 2] {
        [
            self.origin[0] + (col as f64 + 0.5) * self.resolution,
            self.origin[1] + (row as f64 + 0.5) * self.resolution,
        ]
    }

    /// True if every cell overlapping the disc of `radius` around (x, y) is free of obstacles
    /// (cells outside the grid count as free).
    pub fn disc_is_clear(&self, x: f64, y: f64, radius: f64) -> bool {
        let res = self.resolution;
        let c0 = ((x - radius - self.origin[0]) / res).floor().max(0.0) as usize;
        let r0 = ((y - radius - self.origin[1]) / res).floor().max(0.0) as usize;
        let c1 = ((x + radius - self.origin[0]) / res).floor();
        let r1 = ((y + radius - self.origin[1]) / res).floor();
        if c1 < 0.0 || r1 < 0.0 {
            return true;
        }
        let c1 = (c1 as usize).min(self.width.saturating_sub(1));
        let r1 = (r1 as usize).min(self.height.saturating_sub(1));
        for row in r0..=r1 {
            for col in c0..=c1 {
                if !self.is_obstacle(col, row) {
                    continue;
                }
                // distance from the point to the cell's square
                let cx0 = self.origin[0] + col as f64 * res;
                let cy0 = self.origin[1] + row as f64 * res;
                let dx = (cx0 - x).max(0.0).max(x - (cx0 + res));
                let dy = (cy0 - y).max(0.0).max(y - (cy0 + res));
                if dx * dx + dy * dy < radius * radius {
                    return false;
                }
            }
        }
        true
    }

    /// Tiles the grid `nx` × `ny` times (for large benchmark worlds).
    pub fn tiled(&self, nx: usize, ny: usize) -> OccupancyGrid {
        let mut out = OccupancyGrid::new(
            self.width * nx,
            self.height * ny,
            self.resolution,
            self.origin,
            Cell::Unknown,
        );
        for ty in 0..ny {
            for row in 0..self.height {
                let dst_row = ty * self.height + row;
                for tx in 0..nx {
                    let src = &self.cells[row * self.width..(row + 1) * self.width];
                    let start = dst_row * out.width + tx * self.width;
                    out.cells[start..start + self.width].copy_from_slice(src);
                }
            }
        }
        out
    }
}

/// Copies the row-major `src`, `width` cells wide, into the row-major `dst`, `dst_width` cells
/// wide, with `src`'s cell (0, 0) landing on `dst`'s cell `at`: how a grid grown by whole cells
/// keeps its old cells where they were. `src`'s rows must fit inside `dst`.
pub fn place_rows<T: Copy>(
    src: &[T],
    width: usize,
    dst: &mut [T],
    dst_width: usize,
    at: [usize; 2],
) {
    if width == 0 {
        return;
    }
    for (r, row) in src.chunks_exact(width).enumerate() {
        let start = (r + at[1]) * dst_width + at[0];
        dst[start..start + width].copy_from_slice(row);
    }
}

#[cfg(test)]
mod tests {
    use super::place_rows;

    #[test]
    fn placed_rows_keep_their_cells_and_leave_the_rest() {
        // a 3 × 2 block into a 5 × 4 grid at column 1, row 2
        let src = [1, 2, 3, 4, 5, 6];
        let mut dst = [0; 20];
        place_rows(&src, 3, &mut dst, 5, [1, 2]);
        assert_eq!(dst[10..20], [0, 1, 2, 3, 0, 0, 4, 5, 6, 0]);
        assert!(dst[..10].iter().all(|&v| v == 0));
    }

    use super::*;

    #[test]
    fn cell_lookup_and_centres() {
        let g = OccupancyGrid::new(10, 5, 0.5, [-1.0, 2.0], Cell::Free);
        assert_eq!(g.cell_of(-1.0, 2.0), Some((0, 0)));
        assert_eq!(g.cell_of(3.99, 4.49), Some((9, 4)));
        assert_eq!(g.cell_of(4.0, 3.0), None);
        assert_eq!(g.cell_of(-1.01, 3.0), None);
        assert_eq!(g.cell_center(1, 1), [-0.25, 2.75]);
    }

    #[test]
    fn disc_clearance() {
        let mut g = OccupancyGrid::new(20, 20, 0.1, [0.0, 0.0], Cell::Free);
        g.set(10, 10, Cell::Occupied); // covers [1.0,1.1]²
        assert!(!g.disc_is_clear(1.05, 1.05, 0.01));
        assert!(!g.disc_is_clear(1.3, 1.05, 0.21));
        assert!(g.disc_is_clear(1.3, 1.05, 0.19));
        assert!(g.disc_is_clear(-5.0, -5.0, 1.0));
    }

    #[test]
    fn tiling_repeats_the_map() {
        let mut g = OccupancyGrid::new(3, 2, 1.0, [0.0, 0.0], Cell::Free);
        g.set(2, 1, Cell::Occupied);
        let t = g.tiled(2, 3);
        assert_eq!((t.width, t.height), (6, 6));
        for ty in 0..3 {
            for tx in 0..2 {
                assert!(t.is_obstacle(tx * 3 + 2, ty * 2 + 1));
                assert!(!t.is_obstacle(tx * 3, ty * 2));
            }
        }
    }
}
