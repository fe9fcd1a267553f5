//! A Z-order (Morton) key of a position, for visiting many robots in an order that keeps
//! neighbours together: two scans cast one after the other from nearby poses read the same map
//! tiles, which then come from the core's cache instead of memory. Only the visiting order
//! changes, never a result (every job writes its own outputs).

use bevy_ecs::prelude::Entity;

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

/// A Morton visiting order kept from call to call. Robots move a few centimetres a tick, so the
/// order is sorted again only every [`SpatialOrder::REFRESH_CALLS`] calls, or at once when the
/// items are other entities than last time; in between, reading every robot's pose on the
/// calling thread (just written by the workers, so a cache miss each) to sort them cost more
/// than the order saved.
#[derive(Default)]
pub struct SpatialOrder {
    /// The items' entities, in the order they came in at the last sort.
    entities: Vec<Entity>,
    /// Each of those items' place in the visiting order.
    rank: Vec<u32>,
    /// Calls since the last sort.
    age: u32,
    /// Scratch of the sort and of the moves, kept so that a call allocates nothing.
    keyed: Vec<(u64, u32)>,
    place: Vec<u32>,
}

impl SpatialOrder {
    pub const REFRESH_CALLS: u32 = 20;

    /// `items` in the Morton order of the positions they had at the last sort (each item's
    /// entity by `entity`, its position by `position`).
    pub fn arrange<T>(
        &mut self,
        items: Vec<T>,
        entity: impl Fn(&T) -> Entity,
        position: impl Fn(&T) -> (f64, f64),
    ) -> Vec<T> {
        let n = items.len();
        let same = self.entities.len() == n
            && items
                .iter()
                .zip(&self.entities)
                .all(|(t, &e)| entity(t) == e);
        if !same || self.age >= Self::REFRESH_CALLS {
            self.keyed.clear();
            self.keyed.extend(items.iter().enumerate().map(|(i, t)| {
                let (x, y) = position(t);
                (morton_key(x, y), i as u32)
            }));
            self.keyed.sort_unstable();
            self.rank.resize(n, 0);
            for (r, &(_, i)) in self.keyed.iter().enumerate() {
                self.rank[i as usize] = r as u32;
            }
            self.entities.clear();
            self.entities.extend(items.iter().map(&entity));
            self.age = 0;
        }
        self.age += 1;
        // in place: the item at i goes to place[i], and whatever was there comes to i
        let (mut items, place) = (items, &mut self.place);
        place.clear();
        place.extend_from_slice(&self.rank);
        for i in 0..n {
            while place[i] as usize != i {
                let j = place[i] as usize;
                items.swap(i, j);
                place.swap(i, j);
            }
        }
        items
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_ecs::prelude::World;

    /// The order is the Morton order at the last sort: kept while the robots move, sorted
    /// again after [`SpatialOrder::REFRESH_CALLS`] calls, and at once for other entities.
    #[test]
    fn the_order_is_kept_a_while_and_follows_other_entities_at_once() {
        let mut world = World::new();
        let entities: Vec<Entity> = (0..50).map(|_| world.spawn_empty().id()).collect();
        let mut places: Vec<(f64, f64)> = (0..50)
            .map(|i| (((i * 37) % 50) as f64 * 2.9, ((i * 11) % 50) as f64 * 1.7))
            .collect();
        let sorted = |items: &[(Entity, (f64, f64))]| {
            let mut v = items.to_vec();
            v.sort_by_key(|&(e, (x, y))| (morton_key(x, y), e.index()));
            v.iter().map(|x| x.0).collect::<Vec<_>>()
        };
        let items = |places: &[(f64, f64)]| -> Vec<(Entity, (f64, f64))> {
            entities
                .iter()
                .copied()
                .zip(places.iter().copied())
                .collect()
        };
        let mut order = SpatialOrder::default();
        let arrange = |order: &mut SpatialOrder, items: Vec<(Entity, (f64, f64))>| {
            let got = order.arrange(items, |t| t.0, |t| t.1);
            got.iter().map(|t| t.0).collect::<Vec<_>>()
        };
        let first = arrange(&mut order, items(&places));
        assert_eq!(first, sorted(&items(&places)));
        // everyone moves far: the old order stands until the refresh
        places.reverse();
        for call in 1..SpatialOrder::REFRESH_CALLS {
            assert_eq!(arrange(&mut order, items(&places)), first, "call {call}");
        }
        let refreshed = arrange(&mut order, items(&places));
        assert_eq!(refreshed, sorted(&items(&places)));
        assert_ne!(refreshed, first);
        // one entity fewer: sorted at once, and nothing is lost
        let fewer: Vec<_> = items(&places).into_iter().skip(1).collect();
        let got = arrange(&mut order, fewer.clone());
        assert_eq!(got, sorted(&fewer));
    }

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
