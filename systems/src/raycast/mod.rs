//! Grid ray casting, the simulator's hot path: plain functions and one structure over contiguous
//! slices.
//!
//! - [`cast_dda`]: the reference, a plain Amanatides & Woo (1987) cell walk.
//! - [`traverse_segment`]: the same walk visiting every cell a segment crosses (the occupancy
//!   mapper's beam traversal).
//! - [`RayMap`]: the static map as a one-byte Chebyshev distance field (rays leap across open
//!   space and walk cell by cell only next to obstacles) plus the boundary faces of occupied
//!   cells per tile. `cast` is one ray, `cast_many` many independent rays advanced in turn so
//!   their memory loads overlap (with AVX2, 32 rays in four vectors: `batch_avx2`), and
//!   `cast_scan` a whole scan by an angular sweep over the faces (front to back, skipping
//!   hidden tiles). Results agree with [`cast_dda`] (single rays to
//!   millimetres where they graze a wall, see `leap`); edits (doors) refresh the field and the
//!   faces locally.
//! - [`overlay_circles`], [`overlay_segments`]: moving obstacles (other robots) drawn into an
//!   already-cast scan, touching only the beams inside each obstacle's angular interval.
//! - [`StaticWorld`]: the static world resource, an occupancy grid with its ray map and the
//!   collider tiles physics rebuilds, kept in step by every edit; [`Doors`] edit it at run time.
//!   They live here, not in `world`, because they own a [`RayMap`] and `world` is below
//!   `raycast`.
//!
//! Conventions: f32 metres and radians; row 0 is the bottom row; outside the grid is free; a ray
//! starting in an occupied cell returns 0; no hit within `max_range` returns `f32::INFINITY`.

mod batch;
#[cfg(target_arch = "x86_64")]
mod batch_avx2;
mod dda;
pub mod doors;
mod fan;
mod feed;
mod leap;
mod overlay;
mod raymap;
pub mod static_world;
pub mod sweep;

pub use dda::{cast_dda, traverse_segment};
pub use doors::{Door, Doors};
pub use overlay::{overlay_circles, overlay_segments};
pub use raymap::RayMap;
pub use static_world::{COLLIDER_TILE, StaticWorld};

#[cfg(test)]
mod tests;
