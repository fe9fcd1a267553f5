//! Graph SLAM in the spirit of Cartographer (W. Hess, D. Kohler, H. Rapp, D. Andor, "Real-Time
//! Loop Closure in 2D LIDAR SLAM", ICRA 2016 ([Hess 2016]); [SLAM thesis §4.3.3], which finds
//! its loop closure the most accurate of the three systems it compares on large data).
//!
//! * Local SLAM (§IV): every scan is tracked by the scan-to-map step of
//!   [`super::scan_to_map`] (odometry prediction, Gauss-Newton against a pyramid, odometry
//!   prior) — but against the older of two active [`submap::Submaps`] rather than one map of
//!   everything. A scan becomes a node of the pose graph once the robot moved
//!   `map_update_min_d` / turned `map_update_min_a` since the last node; nodes are inserted into
//!   the active submaps.
//! * Constraints (§V): consecutive nodes are joined by the local SLAM's relative pose, with a
//!   spread growing with the motion between them; every `every_n_nodes`-th node is searched for in
//!   each finished submap it is near by branch-and-bound and refined by Gauss-Newton
//!   ([`loop_closure`]); a match becomes an edge from the submap's anchor node. Matches against
//!   the submap just finished are local constraints; against older ones, loop closures.
//! * Global SLAM (§III, "sparse pose adjustment"): whenever new constraints exist and
//!   `optimize_every_n_nodes` nodes were added since the last optimization, the graph is
//!   optimized ([`super::pose_graph::optimize`], Levenberg-Marquardt with a Huber kernel on the
//!   constraints); constraints still far off afterwards (whitened error above `outlier_chi2`)
//!   are removed as false matches and the graph optimized again. The local SLAM keeps running in
//!   its own frame; published poses are its poses carried into the global frame through the
//!   latest node.
//! * The map (`map()`) is rebuilt from every node's scan at its optimized pose (`global_map`).

mod global_map;
pub mod loop_closure;
pub mod submap;
#[cfg(test)]
mod tests;

use super::matched_map::base_points;
use super::pose_graph::{
    Edge, EdgeKind, OptimizeParams, PoseGraph, edge_error, information_from_sigmas, optimize,
};
use super::scan_to_map::{OdometryPriorModel, ScanToMapConfig, insertion_due, track};
use crate::core::Pose2;
use crate::localization::{GraphEdgeKind, GraphEdgeView, GraphView, PoseEstimate, ScanEstimator};
use crate::matching::ProbGrid;
use crate::sensors::LaserScan;
use global_map::CachedMap;
use loop_closure::{LoopClosureConfig, search};
use std::any::Any;
use submap::Submaps;

#[derive(Clone, Debug, PartialEq)]
pub struct GraphSlamConfig {
    /// The local SLAM: resolution, pyramid levels, occupancy model, matcher, node thresholds
    /// (`map_update_min_d`, `map_update_min_a`), beam stride, odometry prior, start pose.
    pub local: ScanToMapConfig,
    /// Nodes per submap (Cartographer's num_range_data).
    pub submap_scans: usize,
    pub loop_closure: LoopClosureConfig,
    /// Spread of the constraint between consecutive nodes: σ at zero motion and its growth per
    /// metre and per radian of motion between them.
    pub sequential: OdometryPriorModel,
    /// Optimize at most once per this many new nodes (and only with new constraints).
    pub optimize_every_n_nodes: usize,
    pub optimizer: OptimizeParams,
    /// A constraint whose whitened squared error eᵀΩe is above this after optimization is
    /// removed as a false match.
    pub outlier_chi2: f64,
}

impl Default for GraphSlamConfig {
    fn default() -> Self {
        GraphSlamConfig {
            local: ScanToMapConfig::default(),
            submap_scans: 120,
            loop_closure: LoopClosureConfig::default(),
            sequential: OdometryPriorModel {
                base_std: [0.005, 0.005, 0.002],
                per_metre: 0.02,
                per_radian: 0.02,
            },
            optimize_every_n_nodes: 20,
            optimizer: OptimizeParams::default(),
            outlier_chi2: 25.0,
        }
    }
}

#[derive(Clone, Debug)]
struct Node {
    /// Pose in the local SLAM frame.
    local: Pose2,
    mount: Pose2,
    scan: LaserScan,
    /// End points in the base frame for the loop-closure search.
    points: Vec<[f32; 2]>,
}

/// Counters for summaries and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GraphStats {
    pub nodes: usize,
    pub submaps: usize,
    pub searches: usize,
    pub local_constraints: usize,
    pub loop_closures: usize,
    pub rejected: usize,
    pub optimizations: usize,
}

#[derive(Clone, Debug)]
pub struct GraphSlam {
    pub config: GraphSlamConfig,
    submaps: Submaps,
    nodes: Vec<Node>,
    /// Global node poses and the constraints; `kinds[k]` is how `graph.edges[k]` was made.
    graph: PoseGraph,
    kinds: Vec<GraphEdgeKind>,
    rejected: Vec<(usize, usize)>,
    local_pose: Pose2,
    last_odom: Option<Pose2>,
    /// Every scan: stamp, the latest node then, and the pose relative to it (local frame).
    path: Vec<(f64, usize, Pose2)>,
    estimate: Option<PoseEstimate>,
    nodes_since_optimization: usize,
    constraints_since_optimization: usize,
    pub stats: GraphStats,
    map_cache: CachedMap,
}

impl GraphSlam {
    pub fn new(config: GraphSlamConfig) -> Self {
        let l = &config.local;
        let submaps = Submaps::new(
            config.submap_scans,
            l.resolution,
            l.levels,
            l.occupancy.clone(),
            config.loop_closure.sigma,
            config.loop_closure.depth,
        );
        let map_cache = CachedMap::new(l.resolution, l.occupancy.clone());
        GraphSlam {
            local_pose: l.init_pose,
            submaps,
            nodes: Vec::new(),
            graph: PoseGraph::new(Vec::new()),
            kinds: Vec::new(),
            rejected: Vec::new(),
            last_odom: None,
            path: Vec::new(),
            estimate: None,
            nodes_since_optimization: 0,
            constraints_since_optimization: 0,
            stats: GraphStats::default(),
            map_cache,
            config,
        }
    }

    /// Global poses of the nodes.
    pub fn node_poses(&self) -> &[Pose2] {
        &self.graph.nodes
    }

    /// One scan: track it locally, add a node if the robot moved enough, search constraints,
    /// optimize when due.
    pub fn step(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) {
        let delta = match self.last_odom {
            Some(prev) => prev.between(odom),
            None => Pose2::default(),
        };
        self.last_odom = Some(*odom);
        let points = base_points(scan, mount, self.config.local.beam_stride);
        let mut covariance = [[0.0; 3]; 3];
        self.local_pose = match self.submaps.matching() {
            Some(map) => {
                let t = track(map, &self.config.local, self.local_pose, &delta, &points);
                covariance = t.covariance;
                t.pose
            }
            None => self.local_pose.compose(&delta),
        };
        let last_local = self.nodes.last().map(|n| n.local);
        if insertion_due(last_local, &self.local_pose, &self.config.local) {
            self.add_node(scan, mount);
        }
        let k = self.nodes.len() - 1;
        let rel = self.nodes[k].local.between(&self.local_pose);
        self.path.push((scan.stamp, k, rel));
        self.estimate = Some(PoseEstimate {
            pose: self.graph.nodes[k].compose(&rel),
            covariance,
            weight: 1.0,
        });
    }

    fn add_node(&mut self, scan: &LaserScan, mount: &Pose2) {
        let idx = self.nodes.len();
        let local = self.local_pose;
        let global = match self.nodes.last() {
            None => local,
            Some(prev) => self.graph.nodes[idx - 1].compose(&prev.local.between(&local)),
        };
        self.graph.nodes.push(global);
        if let Some(prev) = self.nodes.last() {
            let z = prev.local.between(&local);
            let std = self.config.sequential.std(&z);
            self.push_edge(Edge {
                from: idx - 1,
                to: idx,
                measurement: z,
                information: information_from_sigmas(std[0], std[1], std[2]),
                kind: EdgeKind::ScanMatch,
                huber: None,
            });
            self.kinds.push(GraphEdgeKind::Sequential);
        }
        self.submaps
            .insert(idx, &local, &local.compose(mount), scan);
        self.nodes.push(Node {
            local,
            mount: *mount,
            scan: scan.clone(),
            points: base_points(scan, mount, self.config.loop_closure.beam_stride),
        });
        self.stats.nodes = self.nodes.len();
        self.stats.submaps = self.submaps.all.len();
        self.nodes_since_optimization += 1;
        if idx.is_multiple_of(self.config.loop_closure.every_n_nodes.max(1)) {
            self.search_constraints(idx);
        }
        if self.constraints_since_optimization > 0
            && self.nodes_since_optimization >= self.config.optimize_every_n_nodes
        {
            self.optimize();
        }
    }

    fn push_edge(&mut self, e: Edge) {
        self.graph.edges.push(e);
    }

    /// Searches node `idx` in every finished submap near its estimate.
    fn search_constraints(&mut self, idx: usize) {
        let lc = &self.config.loop_closure;
        let node_global = self.graph.nodes[idx];
        let mut found = Vec::new();
        for s in self.submaps.all.iter().filter(|s| s.finished()) {
            let nearest = s.nodes.iter().copied().min_by(|&a, &b| {
                let (da, db) = (self.graph.nodes[a], self.graph.nodes[b]);
                da.distance(&node_global)
                    .total_cmp(&db.distance(&node_global))
            });
            let Some(m) =
                nearest.filter(|&m| self.graph.nodes[m].distance(&node_global) <= lc.max_distance)
            else {
                continue;
            };
            let reference = self.nodes[m].local;
            let guess = reference.compose(&self.graph.nodes[m].between(&node_global));
            self.stats.searches += 1;
            let refine = &self.config.local.matcher;
            let last = s.nodes.last().copied().unwrap_or(s.anchor);
            let local = idx.saturating_sub(last) <= self.config.submap_scans;
            let points = &self.nodes[idx].points;
            if let Some(f) = search(s, &reference, guess, points, local, lc, refine) {
                found.push((m, f, local));
            }
        }
        for (m, f, local) in found {
            self.push_edge(Edge {
                from: m,
                to: idx,
                measurement: f.measurement,
                information: f.information,
                kind: EdgeKind::LoopClosure,
                huber: Some(self.config.loop_closure.huber),
            });
            if local {
                self.stats.local_constraints += 1;
                self.kinds.push(GraphEdgeKind::Local);
            } else {
                self.stats.loop_closures += 1;
                self.kinds.push(GraphEdgeKind::LoopClosure);
            }
            self.constraints_since_optimization += 1;
        }
    }

    /// Optimizes the graph, drops constraints that stay far off, and optimizes again if any
    /// were dropped.
    fn optimize(&mut self) {
        optimize(&mut self.graph, &self.config.optimizer);
        self.stats.optimizations += 1;
        let mut keep = Vec::with_capacity(self.graph.edges.len());
        let mut dropped = false;
        for (e, k) in self.graph.edges.iter().zip(&self.kinds) {
            let bad =
                e.huber.is_some() && whitened_chi2(&self.graph.nodes, e) > self.config.outlier_chi2;
            if bad {
                self.rejected.push((e.from, e.to));
                self.stats.rejected += 1;
                match k {
                    GraphEdgeKind::LoopClosure => self.stats.loop_closures -= 1,
                    _ => self.stats.local_constraints -= 1,
                }
                dropped = true;
            }
            keep.push(!bad);
        }
        if dropped {
            let mut it = keep.iter();
            self.graph.edges.retain(|_| *it.next().unwrap_or(&true));
            let mut it = keep.iter();
            self.kinds.retain(|_| *it.next().unwrap_or(&true));
            optimize(&mut self.graph, &self.config.optimizer);
            self.stats.optimizations += 1;
        }
        self.nodes_since_optimization = 0;
        self.constraints_since_optimization = 0;
    }

    /// Runs the last optimization with the constraints found since the previous one
    /// (Cartographer's final optimization when a trajectory ends).
    pub fn finish(&mut self) {
        if self.constraints_since_optimization > 0 {
            self.optimize();
        }
    }
}

/// eᵀΩe of an edge at the given poses.
fn whitened_chi2(nodes: &[Pose2], e: &Edge) -> f64 {
    let r = edge_error(&nodes[e.from], &nodes[e.to], &e.measurement);
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += r[i] * e.information[i][j] * r[j];
        }
    }
    s
}

impl ScanEstimator for GraphSlam {
    fn kind(&self) -> &'static str {
        "graph"
    }

    fn update(&mut self, scan: &LaserScan, mount: &Pose2, odom: &Pose2) -> bool {
        self.step(scan, mount, odom);
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn finish(&mut self) {
        GraphSlam::finish(self);
    }

    fn map(&self) -> Option<ProbGrid> {
        if self.nodes.is_empty() {
            return None;
        }
        let scans = self
            .nodes
            .iter()
            .zip(&self.graph.nodes)
            .map(|(n, g)| (g.compose(&n.mount), &n.scan));
        Some(self.map_cache.get(scans))
    }

    fn trajectory(&self) -> Vec<(f64, Pose2)> {
        self.path
            .iter()
            .map(|&(t, k, rel)| (t, self.graph.nodes[k].compose(&rel)))
            .collect()
    }

    fn graph(&self) -> Option<GraphView> {
        let mut edges: Vec<GraphEdgeView> = self
            .graph
            .edges
            .iter()
            .zip(&self.kinds)
            .map(|(e, &kind)| GraphEdgeView {
                from: e.from,
                to: e.to,
                kind,
            })
            .collect();
        edges.extend(self.rejected.iter().map(|&(from, to)| GraphEdgeView {
            from,
            to,
            kind: GraphEdgeKind::Rejected,
        }));
        Some(GraphView {
            nodes: self.graph.nodes.clone(),
            edges,
        })
    }

    fn box_clone(&self) -> Box<dyn ScanEstimator> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
