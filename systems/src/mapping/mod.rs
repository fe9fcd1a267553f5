//! Mapping and SLAM (001_6ab7973871dfdca6.txt).
//!
//! * [`pose_graph`] — sparse pose adjustment on SE(2) with a Huber kernel, the back end of
//!   graph-based SLAM.

pub mod pose_graph;
