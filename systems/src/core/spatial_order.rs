//! A Z-order (Morton) key of a position, for visiting many robots in an order that keeps
//! neighbours together: two scans cast one after the other from nearby poses read the same map
//! tiles, which then come from the core's cache instead of memory. Only the visiting order
//! changes, never a result (every job writes its own outputs).

/// Side of the square cells the key orders (m): about one tile of the scan sweep (64 cells of
/// 5 cm), so the robots of one cell share their nearest tiles.
pub const CELL: f64 = 3.2;

/// The Z-order key of the cell of side [`CELL`] holding (x, y): cells are numbered by
/// interleaving the bits of their column and row (within ±2³¹ cells of the origin; positions
/// beyond, and NaN, are clamped to the border), so cells near each other mostly get keys near
/// each other.
pub fn morton_key(x: f64, y: f64) -> u64 {
    // NaN becomes 0 (the cast saturates), which is as good a place as any for a bad pose
    let cell = |v: f64| ((v / CELL).floor() as i64).clamp(-(1 << 31), (1 << 31) - 1) + (1 << 31);
    spread(cell(x) as u64) | (spread(cell(y) as u64) << 1)
}

/// The low 32 bits of `v` moved to the even bit positions.
fn spread(mut v: u64) -> u64 {
    v &= 0xffff_ffff;
    v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
    v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
    v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
    v = (v | (v << 2)) & 0x3333_3333_3333_3333;
    (v | (v << 1)) & 0x5555_5555_5555_5555
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_shares_one_key_and_its_quadrants_follow_z_order() {
        assert_eq!(morton_key(0.1, 0.1), morton_key(3.1, 3.1));
        let k = |c: f64, r: f64| morton_key(c * CELL + 0.5, r * CELL + 0.5);
        // the four cells of a 2 × 2 block: (0,0) < (1,0) < (0,1) < (1,1), then the next block
        assert!(k(0.0, 0.0) < k(1.0, 0.0));
        assert!(k(1.0, 0.0) < k(0.0, 1.0));
        assert!(k(0.0, 1.0) < k(1.0, 1.0));
        assert!(k(1.0, 1.0) < k(2.0, 0.0));
        // negative positions order below positive ones
        assert!(k(-1.0, -1.0) < k(0.0, 0.0));
    }

    #[test]
    fn far_and_bad_positions_are_clamped_not_wrapped() {
        assert_eq!(morton_key(1e300, 0.0), morton_key(f64::INFINITY, 0.0));
        assert_eq!(morton_key(-1e300, -1e300), 0);
        assert_eq!(morton_key(f64::NAN, f64::NAN), morton_key(0.0, 0.0));
    }

    #[test]
    fn sorting_by_key_groups_the_robots_of_a_block() {
        // one robot in each cell of an 8 × 8 block, given in scattered order
        let mut cells: Vec<(i32, i32)> = (0..64)
            .map(|i| {
                let j = (i * 37) % 64;
                (j % 8, j / 8)
            })
            .collect();
        cells.sort_by_key(|&(c, r)| morton_key(c as f64 * CELL + 1.0, r as f64 * CELL + 1.0));
        // each run of 16 lies within one 4 × 4 quarter
        for quarter in cells.chunks(16) {
            let (c0, r0) = (quarter[0].0 / 4, quarter[0].1 / 4);
            assert!(quarter.iter().all(|&(c, r)| c / 4 == c0 && r / 4 == r0));
        }
    }
}
