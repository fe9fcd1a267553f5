//! Decomposes the occupied cells of one square tile of the grid into few axis-aligned rectangles
//! (greedy meshing: grow a run along the row, then extend it over the following rows while the
//! whole run stays occupied). A 1200 × 600 hospital becomes a few thousand boxes instead of
//! hundreds of thousands of cells, and an edit only redoes its own tile.

use super::grid::OccupancyGrid;

/// A rectangle of cells: columns [col0, col1) × rows [row0, row1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellRect {
    pub col0: usize,
    pub row0: usize,
    pub col1: usize,
    pub row1: usize,
}

impl CellRect {
    /// Centre and half extents in world metres.
    pub fn world_box(&self, grid: &OccupancyGrid) -> ([f64; 2], [f64; 2]) {
        let r = grid.resolution;
        let hx = (self.col1 - self.col0) as f64 * r / 2.0;
        let hy = (self.row1 - self.row0) as f64 * r / 2.0;
        (
            [
                grid.origin[0] + self.col0 as f64 * r + hx,
                grid.origin[1] + self.row0 as f64 * r + hy,
            ],
            [hx, hy],
        )
    }
}

/// Rectangles covering exactly the obstacle cells of tile (tx, ty) of size `tile` cells.
pub fn tile_rects(grid: &OccupancyGrid, tx: usize, ty: usize, tile: usize) -> Vec<CellRect> {
    let c0 = tx * tile;
    let r0 = ty * tile;
    let c1 = (c0 + tile).min(grid.width);
    let r1 = (r0 + tile).min(grid.height);
    if c0 >= c1 || r0 >= r1 {
        return Vec::new();
    }
    let w = c1 - c0;
    let mut used = vec![false; w * (r1 - r0)];
    let mut out = Vec::new();
    for row in r0..r1 {
        let mut col = c0;
        while col < c1 {
            let k = (row - r0) * w + (col - c0);
            if used[k] || !grid.is_obstacle(col, row) {
                col += 1;
                continue;
            }
            // grow along the row
            let mut end = col + 1;
            while end < c1 && !used[(row - r0) * w + end - c0] && grid.is_obstacle(end, row) {
                end += 1;
            }
            // extend upwards while the whole run is free to take
            let mut top = row + 1;
            'grow: while top < r1 {
                for c in col..end {
                    if used[(top - r0) * w + c - c0] || !grid.is_obstacle(c, top) {
                        break 'grow;
                    }
                }
                top += 1;
            }
            for r in row..top {
                for c in col..end {
                    used[(r - r0) * w + c - c0] = true;
                }
            }
            out.push(CellRect {
                col0: col,
                row0: row,
                col1: end,
                row1: top,
            });
            col = end;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::grid::Cell;

    #[test]
    fn rects_cover_exactly_the_obstacles() {
        let mut g = OccupancyGrid::new(40, 30, 0.05, [0.0, 0.0], Cell::Free);
        let mut s = 12345u64;
        for i in 0..g.cells.len() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            if s.is_multiple_of(3) {
                g.cells[i] = Cell::Occupied;
            }
        }
        for r in 0..30 {
            g.set(5, r, Cell::Occupied);
        }
        let tile = 16;
        let mut covered = vec![0u8; g.cells.len()];
        for ty in 0..2 {
            for tx in 0..3 {
                for rect in tile_rects(&g, tx, ty, tile) {
                    assert!(rect.col1 <= (tx + 1) * tile && rect.row1 <= (ty + 1) * tile);
                    for r in rect.row0..rect.row1 {
                        for c in rect.col0..rect.col1 {
                            covered[g.index(c, r)] += 1;
                        }
                    }
                }
            }
        }
        for (i, (cell, n)) in g.cells.iter().zip(&covered).enumerate() {
            assert_eq!(*n, (*cell == Cell::Occupied) as u8, "cell {i}");
        }
    }

    #[test]
    fn a_solid_wall_is_one_rect_per_tile() {
        let mut g = OccupancyGrid::new(64, 64, 0.05, [0.0, 0.0], Cell::Free);
        for c in 0..64 {
            for r in 10..13 {
                g.set(c, r, Cell::Occupied);
            }
        }
        assert_eq!(tile_rects(&g, 0, 0, 64).len(), 1);
        assert_eq!(tile_rects(&g, 0, 0, 32).len(), 1);
        assert_eq!(tile_rects(&g, 1, 0, 32).len(), 1);
    }
}
