//! Estimators defined in higher layers (the SLAM systems of `crate::mapping`) that consume the
//! same laser scans and wheel odometry as the localizers, through one interface. They sit in a
//! robot's [`super::Localizers`] as [`super::Filter::Scan`], so their estimates are published,
//! evaluated (ATE/RPE), summarised and recorded exactly like a localizer's; their scans are fed
//! in the Map set of the tick, after the localizers (systems/ARCHITECTURE.md, "One tick").

use super::mcl::PoseEstimate;
use crate::core::Pose2;
use crate::matching::ProbGrid;
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
    /// The run is over: a smoother runs its final optimization here (call once, before reading
    /// [`ScanEstimator::trajectory`] and [`ScanEstimator::map`] for the results).
    fn finish(&mut self) {}
    /// The map built so far, P(occupied) per cell in the map frame (0.5 unknown); None before
    /// the first scan or for estimators without a map.
    fn map(&self) -> Option<ProbGrid> {
        None
    }
    /// The estimator's best trajectory of the whole run so far, one pose per consumed scan
    /// (stamp, base pose in the map frame). For a smoother (graph SLAM) this is the optimized
    /// trajectory, which revises the poses published online; for a filter, the pose published
    /// at each scan (RBPF: the best particle's path).
    fn trajectory(&self) -> Vec<(f64, Pose2)>;
    /// The pose graph, for estimators that keep one.
    fn graph(&self) -> Option<GraphView> {
        None
    }
    fn box_clone(&self) -> Box<dyn ScanEstimator>;
    /// For the recorder and the experiments, which know the concrete types.
    fn as_any(&self) -> &dyn Any;
}

impl Clone for Box<dyn ScanEstimator> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}

/// A pose graph as the recorder draws it: node poses in the map frame and the constraints
/// between them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GraphView {
    pub nodes: Vec<Pose2>,
    pub edges: Vec<GraphEdgeView>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GraphEdgeView {
    pub from: usize,
    pub to: usize,
    pub kind: GraphEdgeKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GraphEdgeKind {
    /// Consecutive nodes (odometry / local matching).
    Sequential,
    /// A node matched into a submap of its own recent past.
    Local,
    /// A loop closure that was accepted into the graph.
    LoopClosure,
    /// A loop closure candidate that was matched but rejected (kept for inspection).
    Rejected,
}
