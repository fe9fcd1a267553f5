//! The inverse sensor model of occupancy grid mapping (see [`super::occupancy`]): its
//! parameters and the log-odds ↔ probability conversions. A leaf of its own because the scan
//! inserting kernel (`insert`), the grid it fills ([`super::occupancy`]) and the particle
//! maps of [`super::rbpf`] all read it.

/// The inverse sensor model and how readings are used.
#[derive(Clone, Debug, PartialEq)]
pub struct OccupancyParams {
    /// P(occupied) the end cell of a return is given.
    pub p_hit: f32,
    /// P(occupied) the cells a beam crosses are given.
    pub p_miss: f32,
    /// Clamping limits of P(occupied).
    pub p_min: f32,
    pub p_max: f32,
    /// Returns farther than this (or the scan's `range_max`, whichever is shorter) count as no
    /// return. Finite: it bounds how far one scan can grow the map.
    pub max_range: f32,
    /// How far a beam without a return clears free space (capped at the usable maximum range;
    /// 0 disables clearing by such beams).
    pub clear_range: f32,
    /// A beam with a return clears free space only up to this many cells short of it. With
    /// 0, the cell in front of a surface — which holds the returns that fall short of it under
    /// range noise — is cleared by every beam that ends just behind it, so the wall's ridge
    /// moves half a cell into the wall and scan matching against the map is biased by up to
    /// half a cell (hospital_loop scan-to-map: a constant (+2.5, +2.5) cm offset at 5 cm cells).
    pub hit_clear_gap: f32,
}

impl OccupancyParams {
    /// The inverse sensor model of the SLAM maps: Cartographer's (hit 0.55, miss 0.49, clamped
    /// to 0.1…0.9; `cartographer/configuration_files/trajectory_builder_2d.lua`), where a cell
    /// needs about five crossing beams to undo one return. With OctoMap's 0.7 / 0.4 a wall
    /// lying across cells is eroded by the beams that graze it on their way along a corridor,
    /// differently from each viewpoint, and scan-to-map matching drifts: hospital_loop ATE
    /// 0.70 m with 4 cm cells and 1.21 m with 4.5 cm (0.039 m with 5 cm, where the walls
    /// happen to lie on cell faces), against 0.026, 0.030 and 0.036 m with these.
    pub fn slam() -> Self {
        OccupancyParams {
            p_hit: 0.55,
            p_miss: 0.49,
            p_min: 0.1,
            p_max: 0.9,
            hit_clear_gap: 1.0,
            ..OccupancyParams::default()
        }
    }
}

impl Default for OccupancyParams {
    fn default() -> Self {
        OccupancyParams {
            p_hit: 0.7,
            p_miss: 0.4,
            p_min: 0.1192,
            p_max: 0.971,
            max_range: 80.0,
            clear_range: 5.0,
            hit_clear_gap: 0.0,
        }
    }
}

/// log(p / (1 − p)).
pub fn log_odds(p: f32) -> f32 {
    (p / (1.0 - p)).ln()
}

/// P(occupied) of a log-odds value.
pub fn probability(l: f32) -> f32 {
    1.0 - 1.0 / (1.0 + l.exp())
}
