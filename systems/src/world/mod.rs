//! The static environment: the occupancy grid (from ROS map_server files and/or vector shapes)
//! and the rectangles its physics colliders are built from. The Euclidean distance field
//! localization weighs scans on lives here too, and the outdoor road networks (OSM XML and GPX)
//! with their road surface, and the zones that degrade GPS and compass. The run-time resource
//! that keeps the grid, its ray map and its collider tiles in step, and the doors that edit it,
//! are in [`crate::raycast`]: the ray map is built on the grid, so it sits above this layer.

pub mod distance_field;
pub mod grid;
pub mod map_file;
pub mod rects;
pub mod roads;
pub mod shapes;
pub mod zones;

pub use distance_field::DistanceField;
pub use grid::{Cell, OccupancyGrid};
pub use map_file::{MapError, load_map};
pub use shapes::Shape;
pub use zones::{Zone, ZoneKind, ZoneShape, Zones};
