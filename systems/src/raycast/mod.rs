//! Grid ray casting, the simulator's hot path: plain functions and one structure over contiguous
//! slices.
//!
//! - [`cast_dda`]: the reference, a plain Amanatides & Woo (1987) cell walk.
//! - [`RayMap`]: the same exact walk, accelerated with a two-level grid: the fine walk runs only
//!   inside 8 × 8-cell blocks near obstacles, and a coarse Chebyshev distance field (in blocks)
//!   lets a ray leap across open space. Results are identical to [`cast_dda`] (every crossing
//!   time is computed from the ray's origin, never accumulated), edits (doors) only touch block
//!   flags and re-run a small breadth-first pass.
//! - [`overlay_circles`], [`overlay_segments`]: moving obstacles (other robots) drawn into an
//!   already-cast scan, touching only the beams inside each obstacle's angular interval.
//!
//! Conventions: f32 metres and radians; row 0 is the bottom row; outside the grid is free; a ray
//! starting in an occupied cell returns 0; no hit within `max_range` returns `f32::INFINITY`.

mod dda;
mod overlay;
mod raymap;
mod sweep;

pub use dda::cast_dda;
pub use overlay::{overlay_circles, overlay_segments};
pub use raymap::RayMap;

#[cfg(test)]
mod tests;
