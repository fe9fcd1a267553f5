//! A growable grid's extent on a fixed cell lattice, and growth by whole blocks. The lattice is
//! fixed by an anchor point and the resolution; the grid covers lattice cells
//! [cell0, cell0 + size), so growing never moves a cell in the world, and the origin is always
//! `anchor + cell0 · resolution` (an exact integer multiple, no accumulated rounding).

use crate::world::grid::place_rows;

/// Where a grid lies on its lattice.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Extent {
    pub resolution: f64,
    /// A lattice point: the lower-left corner of lattice cell (0, 0).
    pub anchor: [f64; 2],
    /// Lattice index of the grid's cell (0, 0).
    pub cell0: [i64; 2],
    pub width: usize,
    pub height: usize,
}

impl Extent {
    /// No cells yet, on the lattice through `anchor`.
    pub fn empty(resolution: f64, anchor: [f64; 2]) -> Self {
        Extent {
            resolution,
            anchor,
            cell0: [0, 0],
            width: 0,
            height: 0,
        }
    }

    /// World position of the lower-left corner of grid cell (0, 0).
    pub fn origin(&self) -> [f64; 2] {
        [
            self.anchor[0] + self.cell0[0] as f64 * self.resolution,
            self.anchor[1] + self.cell0[1] as f64 * self.resolution,
        ]
    }

    /// Grid (column, row) of the cell holding a world point; may lie outside the grid.
    pub fn cell_coords(&self, x: f64, y: f64) -> [i64; 2] {
        let o = self.origin();
        [
            ((x - o[0]) / self.resolution).floor() as i64,
            ((y - o[1]) / self.resolution).floor() as i64,
        ]
    }
}

/// Grows `extent` so it holds the grid cells [c0, c1) × [r0, r1) of `want` (grid coordinates,
/// possibly negative), adding whole blocks of `block` cells on the sides that need them (an empty
/// grid is placed on block boundaries of the lattice). Returns the new extent and the cells
/// copied into it (new cells 0), or None when nothing had to grow.
pub(crate) fn grow_to<A: Copy + Default, B: Copy + Default>(
    extent: &Extent,
    want: [i64; 4],
    block: usize,
    a: &[A],
    b: &[B],
) -> Option<(Extent, Vec<A>, Vec<B>)> {
    let [c0, r0, c1, r1] = want;
    let (w, h) = (extent.width as i64, extent.height as i64);
    let bl = block as i64;
    // new bounds in grid coordinates of the old extent
    let (nc0, nr0, nc1, nr1) = if w == 0 || h == 0 {
        let lattice = |v: i64, cell0: i64| v + cell0;
        let (ac0, ar0) = (lattice(c0, extent.cell0[0]), lattice(r0, extent.cell0[1]));
        let (ac1, ar1) = (lattice(c1, extent.cell0[0]), lattice(r1, extent.cell0[1]));
        (
            ac0.div_euclid(bl) * bl - extent.cell0[0],
            ar0.div_euclid(bl) * bl - extent.cell0[1],
            (ac1 + bl - 1).div_euclid(bl) * bl - extent.cell0[0],
            (ar1 + bl - 1).div_euclid(bl) * bl - extent.cell0[1],
        )
    } else {
        if c0 >= 0 && r0 >= 0 && c1 <= w && r1 <= h {
            return None;
        }
        let below = |v: i64| if v < 0 { (-v + bl - 1) / bl * bl } else { 0 };
        let above = |v: i64, n: i64| if v > n { (v - n + bl - 1) / bl * bl } else { 0 };
        (-below(c0), -below(r0), w + above(c1, w), h + above(r1, h))
    };
    let (nw, nh) = ((nc1 - nc0) as usize, (nr1 - nr0) as usize);
    let mut na = vec![A::default(); nw * nh];
    let mut nb = vec![B::default(); nw * nh];
    // old rows land at column offset −nc0, row offset −nr0
    let (dx, dy) = ((-nc0) as usize, (-nr0) as usize);
    place_rows(a, extent.width, &mut na, nw, [dx, dy]);
    place_rows(b, extent.width, &mut nb, nw, [dx, dy]);
    let grown = Extent {
        resolution: extent.resolution,
        anchor: extent.anchor,
        cell0: [extent.cell0[0] + nc0, extent.cell0[1] + nr0],
        width: nw,
        height: nh,
    };
    Some((grown, na, nb))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_grid_is_placed_on_block_boundaries_of_the_lattice() {
        let e = Extent::empty(0.5, [0.25, 0.0]);
        // cells 13..18 × −3..2 of the lattice
        let (g, a, _) = grow_to::<u8, u8>(&e, [13, -3, 18, 2], 8, &[], &[]).unwrap();
        assert_eq!(g.cell0, [8, -8]);
        assert_eq!((g.width, g.height), (16, 16));
        assert_eq!(a.len(), 256);
        assert_eq!(g.origin(), [0.25 + 8.0 * 0.5, -4.0]);
    }

    #[test]
    fn growing_keeps_cells_in_place_and_adds_whole_blocks() {
        let mut e = Extent::empty(0.1, [0.0, 0.0]);
        e.width = 3;
        e.height = 2;
        let a: Vec<u32> = (0..6).collect();
        let b = vec![1u8; 6];
        assert!(grow_to(&e, [0, 0, 3, 2], 4, &a, &b).is_none());
        // one column to the left and two rows above: a block on each of those sides
        let (g, na, nb) = grow_to(&e, [-1, 0, 3, 4], 4, &a, &b).unwrap();
        assert_eq!((g.width, g.height), (7, 6));
        assert_eq!(g.cell0, [-4, 0]);
        for row in 0..2 {
            for col in 0..3 {
                assert_eq!(na[row * 7 + col + 4], a[row * 3 + col]);
                assert_eq!(nb[row * 7 + col + 4], 1);
            }
        }
        assert_eq!(nb.iter().filter(|&&v| v == 1).count(), 6);
    }
}
