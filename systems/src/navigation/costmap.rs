//! Navigation costmap of the static map: one cost byte per occupancy-grid cell, in the classes
//! and with the inflation formula of the ROS `costmap_2d` inflation layer
//! (`costmap_2d/plugins/inflation_layer.cpp`, `InflationLayer::computeCost`, ROS wiki
//! "costmap_2d: Inflation"):
//!
//! - [`LETHAL`] (254): an occupied cell, and an unknown one unless configured otherwise;
//! - [`INSCRIBED`] (253): the centre is within the robot radius of a lethal cell's centre, so a
//!   robot centred there touches an obstacle;
//! - 252 · exp(−k · (d − r_inscribed)) for distances d up to the inflation radius, truncated to
//!   a byte as ROS does, so planners can prefer to keep away from walls;
//! - [`FREE`] (0) beyond the inflation radius.
//!
//! Distances are centre to centre (as in ROS), from the exact Euclidean distance transform of
//! Felzenszwalb & Huttenlocher (2012) that the localization distance field uses too
//! (`squared_distances`), so inflation is isotropic rather than the chamfer approximation of
//! a breadth-first wave. Cells outside the grid are not obstacles.

use crate::core::cache::{CacheKey, Cached, Decoder, Encoder, Malformed, MapCache};
use crate::world::distance_field::squared_distances;
use crate::world::{Cell, OccupancyGrid};

/// Cost of an obstacle cell.
pub const LETHAL: u8 = 254;
/// Cost of a cell within the robot radius of an obstacle: impassable for the robot's centre.
pub const INSCRIBED: u8 = 253;
/// Cost of a cell beyond the inflation radius.
pub const FREE: u8 = 0;

/// How obstacles are inflated. Lengths in metres, `cost_scaling_factor` in 1/m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostmapParams {
    /// Radius of the robot's inscribed circle (m): cells this close to an obstacle are
    /// [`INSCRIBED`].
    pub robot_radius: f64,
    /// Distance (m) out to which costs decay; cells beyond it are [`FREE`].
    pub inflation_radius: f64,
    /// Decay rate k (1/m) of the cost gradient beyond the robot radius (ROS
    /// `cost_scaling_factor`, default 10 there; 5 here for a gentler, wider gradient).
    pub cost_scaling_factor: f64,
    /// Unknown cells are lethal (and inflated) when true, free space when false.
    pub unknown_is_lethal: bool,
}

impl Default for CostmapParams {
    fn default() -> Self {
        CostmapParams {
            robot_radius: 0.3,
            inflation_radius: 1.0,
            cost_scaling_factor: 5.0,
            unknown_is_lethal: true,
        }
    }
}

impl CostmapParams {
    /// The cost of a non-lethal cell whose centre is `d` metres from the nearest lethal cell
    /// centre (`d` = 0 means the cell itself is lethal).
    pub fn cost_at_distance(&self, d: f64) -> u8 {
        // a nanometre of slack, so 3 cells × 0.1 m reads as 0.3 m despite rounding
        const EPS: f64 = 1e-9;
        let r = self.robot_radius.max(0.0);
        if d <= 0.0 {
            LETHAL
        } else if d <= r + EPS {
            INSCRIBED
        } else if d <= self.inflation_radius + EPS {
            let factor = (-self.cost_scaling_factor.max(0.0) * (d - r).max(0.0)).exp();
            // truncation, as ROS casts to unsigned char
            ((INSCRIBED - 1) as f64 * factor).clamp(0.0, (INSCRIBED - 1) as f64) as u8
        } else {
            FREE
        }
    }
}

/// A costmap: plain data, row-major with row 0 at `origin` like [`OccupancyGrid`].
#[derive(Clone, Debug, PartialEq)]
pub struct Costmap {
    pub width: usize,
    pub height: usize,
    /// Metres per cell.
    pub resolution: f64,
    /// World position of the lower-left corner of cell (0, 0).
    pub origin: [f64; 2],
    pub costs: Vec<u8>,
}

impl Costmap {
    /// The costmap of `grid`'s static obstacles.
    pub fn from_grid(grid: &OccupancyGrid, params: &CostmapParams) -> Self {
        let lethal = |c: Cell| match c {
            Cell::Occupied => true,
            Cell::Unknown => params.unknown_is_lethal,
            Cell::Free => false,
        };
        let (w, h) = (grid.width, grid.height);
        let sq = squared_distances(w, h, |x, y| lethal(grid.cells[y * w + x]));
        let res = grid.resolution;
        // beyond this many cells² every cost is FREE; skips the exp for most of the map
        let reach = params.inflation_radius.max(params.robot_radius) / res;
        let reach_sq = reach * reach + 1e-6;
        let costs = sq
            .iter()
            .map(|&s| {
                if s > reach_sq {
                    FREE
                } else {
                    params.cost_at_distance(s.sqrt() * res)
                }
            })
            .collect();
        Costmap {
            width: w,
            height: h,
            resolution: res,
            origin: grid.origin,
            costs,
        }
    }

    /// [`Costmap::from_grid`] through `cache`.
    pub fn from_grid_cached(
        grid: &OccupancyGrid,
        params: &CostmapParams,
        cache: &MapCache,
    ) -> Self {
        let key = grid
            .add_to_key(CacheKey::new::<Costmap>())
            .f64(params.robot_radius)
            .f64(params.inflation_radius)
            .f64(params.cost_scaling_factor)
            .u64(params.unknown_is_lethal.into());
        cache.get_or_build(&key, || Costmap::from_grid(grid, params))
    }

    pub fn index(&self, col: usize, row: usize) -> usize {
        row * self.width + col
    }

    pub fn cost(&self, col: usize, row: usize) -> u8 {
        self.costs[self.index(col, row)]
    }

    /// The cell containing a world point, if the point is finite and inside the map.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let c = ((x - self.origin[0]) / self.resolution).floor();
        let r = ((y - self.origin[1]) / self.resolution).floor();
        let inside = c >= 0.0 && r >= 0.0 && c < self.width as f64 && r < self.height as f64;
        // NaN fails every comparison above
        inside.then_some((c as usize, r as usize))
    }

    /// World coordinates of a cell centre.
    pub fn cell_center(&self, col: usize, row: usize) -> [f64; 2] {
        [
            self.origin[0] + (col as f64 + 0.5) * self.resolution,
            self.origin[1] + (row as f64 + 0.5) * self.resolution,
        ]
    }
}

/// Every field.
impl Cached for Costmap {
    const KIND: &'static str = "costmap";
    const FORMAT: u32 = 1;

    fn encode(&self, out: &mut Encoder) {
        out.grid_frame(self.width, self.height, self.resolution, self.origin);
        out.bytes(&self.costs);
    }

    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed> {
        let (width, height, resolution, origin) = input.grid_frame()?;
        let m = Costmap {
            width,
            height,
            resolution,
            origin,
            costs: input.bytes()?.to_vec(),
        };
        if Some(m.costs.len()) != m.width.checked_mul(m.height) {
            return Err(Malformed("costmap: cell count"));
        }
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 31 × 21 cells of 0.1 m, one occupied cell at (10, 10), one unknown at (25, 10).
    fn fixture() -> OccupancyGrid {
        let mut g = OccupancyGrid::new(31, 21, 0.1, [1.0, -2.0], Cell::Free);
        g.set(10, 10, Cell::Occupied);
        g.set(25, 10, Cell::Unknown);
        g
    }

    #[test]
    fn costs_at_known_distances() {
        let p = CostmapParams {
            robot_radius: 0.3,
            inflation_radius: 1.0,
            cost_scaling_factor: 5.0,
            unknown_is_lethal: false,
        };
        let m = Costmap::from_grid(&fixture(), &p);
        assert_eq!(m.cost(10, 10), LETHAL);
        for (dc, dr) in [(1, 0), (3, 0), (0, -3), (2, 2)] {
            assert_eq!(
                m.cost(10 + dc, (10 + dr) as usize),
                INSCRIBED,
                "({dc},{dr})"
            );
        }
        // 252·exp(−5·(d − 0.3)), truncated
        let want = |d: f64| (252.0 * (-5.0 * (d - 0.3)).exp()) as u8;
        assert_eq!(m.cost(14, 10), want(0.4));
        assert_eq!(m.cost(14, 10), 152);
        assert_eq!(m.cost(13, 13), want(0.3 * 2f64.sqrt()));
        assert_eq!(m.cost(10, 20), want(1.0));
        assert_eq!(m.cost(10, 20), 7);
        assert_eq!(m.cost(21, 10), FREE);
        assert_eq!(m.cost(10, 0), want(1.0)); // the other way, same distance
        assert_eq!(m.cost(0, 0), FREE); // d ≈ 1.41 m
        // the unknown cell is free space here
        assert_eq!(m.cost(25, 10), FREE);
    }

    #[test]
    fn cost_decays_monotonically_with_distance() {
        let p = CostmapParams::default();
        let m = Costmap::from_grid(&fixture(), &p);
        // along the column above the occupied cell (the unknown one is 15 cells to the right)
        let col: Vec<u8> = (10..21).map(|r| m.cost(10, r)).collect();
        assert!(col.windows(2).all(|w| w[0] >= w[1]), "{col:?}");
        assert!(
            col.windows(2).filter(|w| w[0] > w[1]).count() >= 7,
            "{col:?}"
        );
        // and the formula itself, on a fine sweep
        let mut last = LETHAL;
        for i in 0..=1200 {
            let c = p.cost_at_distance(i as f64 * 0.001);
            assert!(c <= last, "at {} mm", i);
            last = c;
        }
        assert_eq!(last, FREE);
    }

    #[test]
    fn lethal_and_inscribed_classes() {
        let p = CostmapParams::default();
        let g = fixture();
        let m = Costmap::from_grid(&g, &p);
        assert_eq!(m.cost(25, 10), LETHAL); // unknown is lethal by default
        assert_eq!(m.cost(22, 10), INSCRIBED);
        for r in 0..g.height {
            for c in 0..g.width {
                let cost = m.cost(c, r);
                let d = [(10, 10), (25, 10)]
                    .iter()
                    .map(|&(oc, or)| (c as f64 - oc as f64).hypot(r as f64 - or as f64) * 0.1)
                    .fold(f64::INFINITY, f64::min);
                let class = if d == 0.0 {
                    LETHAL
                } else if d <= 0.3 + 1e-9 {
                    INSCRIBED
                } else {
                    cost.min(INSCRIBED - 1)
                };
                assert_eq!(cost, class, "({c},{r}) d = {d}");
            }
        }
        // an all-unknown map is lethal everywhere; an empty one free everywhere
        let u = OccupancyGrid::new(4, 3, 0.05, [0.0, 0.0], Cell::Unknown);
        assert!(
            Costmap::from_grid(&u, &p)
                .costs
                .iter()
                .all(|&c| c == LETHAL)
        );
        let f = OccupancyGrid::new(4, 3, 0.05, [0.0, 0.0], Cell::Free);
        assert!(Costmap::from_grid(&f, &p).costs.iter().all(|&c| c == FREE));
    }

    #[test]
    fn world_lookup() {
        let m = Costmap::from_grid(&fixture(), &CostmapParams::default());
        assert_eq!(m.cell_of(1.0, -2.0), Some((0, 0)));
        assert_eq!(m.cell_of(1.05 + 1.0, -2.0 + 1.05), Some((10, 10)));
        assert_eq!(m.cell_of(0.99, 0.0), None);
        assert_eq!(m.cell_of(f64::NAN, 0.0), None);
        let [x, y] = m.cell_center(10, 10);
        assert!((x - 2.05).abs() < 1e-12 && (y + 0.95).abs() < 1e-12);
    }
}
