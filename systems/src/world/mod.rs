//! The static environment: the occupancy grid (from ROS map_server files and/or vector shapes),
//! its ray-casting structure and the tiles its physics colliders are built from. Local edits
//! (doors) change the grid, the ray map and the affected collider tiles only. The Euclidean
//! distance field localization weighs scans on lives here too, and the outdoor road networks
//! (OSM XML and GPX) with their road surface, and the zones that degrade GPS and compass.

pub mod distance_field;
pub mod doors;
pub mod grid;
pub mod map_file;
pub mod rects;
pub mod roads;
pub mod shapes;
pub mod static_world;
pub mod zones;

pub use distance_field::DistanceField;
pub use doors::{Door, Doors};
pub use grid::{Cell, OccupancyGrid};
pub use map_file::{MapError, load_map};
pub use shapes::Shape;
pub use static_world::{COLLIDER_TILE, StaticWorld};
pub use zones::{Zone, ZoneKind, ZoneShape, Zones};
