//! Mapping: building maps from sensor data, and judging them against ground truth.
//!
//! * [`occupancy`] — occupancy grid mapping with known poses (Thrun et al., *Probabilistic
//!   Robotics*, §9.2): the log-odds map scans are inserted into, growing by blocks, exported as a
//!   [`crate::matching::ProbGrid`] or a map_server map;
//! * [`quality`] — map quality against a true map: precision (estimated walls on true walls)
//!   and recall (observable true walls covered), after aligning the frames;
//! * [`align`] — that alignment: from the robot's true start pose, optionally refined by chamfer
//!   matching;
//! * `grow` — a grid's extent on a fixed cell lattice and growth by whole blocks (private).

pub mod align;
mod grow;
pub mod occupancy;
pub mod quality;

#[cfg(test)]
mod tests;

pub use align::{refine_alignment, start_pose_alignment};
pub use occupancy::{InsertStats, LogOddsMap, OccupancyParams};
pub use quality::{MapQuality, map_quality, quality_with_start_pose};
