//! Files other tools read and write, each with its reader and writer together: CARMEN logs
//! ([`carmen`]), SCANS files of scans with true poses ([`scans`]), TUM trajectories ([`tum`]) and
//! ROS map_server maps ([`maps`]).

pub mod carmen;
pub mod maps;
pub mod scans;
pub mod tum;
