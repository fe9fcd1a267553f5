//! Estimators defined in higher layers (the SLAM systems of `crate::mapping`) that consume the
//! same laser scans and wheel odometry as the localizers, through one interface. They sit in a
//! robot's [`super::Localizers`] as [`super::Filter::Scan`], so their estimates are published,
//! evaluated (ATE/RPE), summarised and recorded exactly like a localizer's; their scans are fed
//! in the Map set of the tick, after the localizers (DESIGN.md, tick order).

use super::mcl::PoseEstimate;
use crate::core::Pose2;
use crate::sensors::LaserScan;
use std::any::Any;
use std::fmt::Debug;

pub trait ScanEstimator: Send + Sync + Debug {
    /// The type name as written in scenario files (e.g. `scan_to_map`).
    fn kind(&self) -> &'static str;
    /// Consumes one scan (as the laser published it, from `mount`, its pose in the base frame)
    /// taken at odometry pose `odom`; true if it published a new estimate.
    fn update(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) -> bool;
    /// The latest estimate.
    fn estimate(&self) -> Option<PoseEstimate>;
    fn box_clone(&self) -> Box<dyn ScanEstimator>;
    /// For the recorder and the experiments, which know the concrete types.
    fn as_any(&self) -> &dyn Any;
}

impl Clone for Box<dyn ScanEstimator> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}
