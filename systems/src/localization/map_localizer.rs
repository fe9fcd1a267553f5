//! The interface every map localizer implements, ours (MCL, Markov grid, DE filter, DE-MC, DE
//! odometry) and a user's own alike. A robot's [`super::Localizers`] holds them as
//! [`super::Filter::Map`]; the Estimate set feeds each one every scan through the same path
//! (predict with the odometry at the scan's time, then correct with the scan), and what it
//! publishes is evaluated (ATE/RPE, convergence, tracking), recorded and exported under the name
//! it was given, exactly like ours.
//!
//! Inputs: the wheel-odometry pose ([`Pose2`], odometry frame) and the scan as a [`BeamSubset`]:
//! the scan subsampled evenly to [`MapLocalizer::max_beams`] beams, each with its range
//! (`ranges`, `range_max` where nothing returned, flagged in `max_reading`), its bearing in the
//! base frame (`angles`, measured from the laser at `mount`) and its endpoint in the base frame
//! (`points`; `returns()` keeps the endpoints of beams that hit something). The map is the
//! [`LocalizationMap`]: the occupancy grid, its distance field and ray map, its free cells.

use super::map::LocalizationMap;
use super::mcl::cluster::PoseEstimate;
use super::mcl::sensor_model::BeamSubset;
use crate::core::Pose2;
use std::any::Any;
use std::fmt::Debug;

/// A localizer on the map: a Bayes filter fed the odometry and the laser scans.
pub trait MapLocalizer: Send + Sync + Debug {
    /// The type name (scenario files' `type`, e.g. `mcl`); a user's localizer returns its own.
    fn kind(&self) -> &'static str;
    /// Beams of each scan it reads (the scan is subsampled evenly to this many).
    fn max_beams(&self) -> usize;
    /// Motion update with the wheel-odometry pose at the time of the scan about to be corrected
    /// with. False: skip this scan (e.g. not moved enough since the last update); then
    /// [`MapLocalizer::correct`] is not called for it.
    fn predict(&mut self, odom: &Pose2) -> bool;
    /// What [`MapLocalizer::predict`] would answer for a scan at odometry pose `odom`, without
    /// changing anything: whether the scan would be corrected with. Only a hint, for handing a
    /// tick's localizers to the workers the dearest first (a skipped scan costs next to
    /// nothing); true by default.
    fn due(&self, odom: &Pose2) -> bool {
        let _ = odom;
        true
    }
    /// Measurement update with the scan's beams on the map, after a `predict` that returned
    /// true. True if the filter updated: its [`MapLocalizer::estimate`] (if any) is then
    /// published at the scan's time.
    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool;
    /// The latest estimate (pose in the map frame, covariance, weight).
    fn estimate(&self) -> Option<PoseEstimate>;
    /// The belief as weighted poses `([x, y], weight)`, the weight scaled so the most likely is
    /// 1, for the recording's particle view; None (nothing drawn) by default.
    fn belief_points(&self) -> Option<Vec<([f64; 2], f64)>> {
        None
    }
    /// Whether its estimates are poses in the map (true by default): its error is then judged
    /// in the map frame. False for one that integrates motion from its start pose and reads
    /// the map not at all (scan-to-scan odometry), judged aligned at its first pose.
    fn localizes_in_map(&self) -> bool {
        true
    }
    fn box_clone(&self) -> Box<dyn MapLocalizer>;
    /// For the recorder and the experiments, which know our concrete types.
    fn as_any(&self) -> &dyn Any;
}

impl Clone for Box<dyn MapLocalizer> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}

impl dyn MapLocalizer + '_ {
    /// The localizer as a concrete type, if it is one.
    pub fn downcast_ref<T: MapLocalizer + 'static>(&self) -> Option<&T> {
        self.as_any().downcast_ref()
    }
}

#[cfg(test)]
mod tests;
