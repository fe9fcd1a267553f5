//! Submaps (Hess et al., "Real-Time Loop Closure in 2D LIDAR SLAM", ICRA 2016, §IV): the local
//! SLAM inserts each node's scan into the two active submaps; the older one, which has seen more,
//! is the one scans are matched against. When it holds `scans` nodes it is finished — never
//! changed again — and gets the precomputed grids the loop-closure search needs; a new submap
//! starts once the newer one is half full, so every scan always has a well-filled submap to
//! match against.
//!
//! Submaps are built in the local SLAM frame (the frame the local poses live in). Each is tied to
//! the pose graph by its anchor, the first node inserted into it: the submap's global pose is
//! G = global(anchor) ⊕ local(anchor)⁻¹, mapping its local coordinates into the global frame.

use crate::core::Pose2;
use crate::mapping::inverse_model::OccupancyParams;
use crate::mapping::matched_map::MatchedMap;
use crate::matching::{PrecomputedGrids, ProbGrid, likelihood_grid};
use crate::sensors::LaserScan;
use crate::world::Cell;

#[derive(Clone, Debug)]
pub struct Submap {
    /// The first node inserted (ties the submap to the pose graph).
    pub anchor: usize,
    /// The anchor's local pose when it was inserted.
    pub anchor_local: Pose2,
    pub map: MatchedMap,
    /// Nodes inserted, in order.
    pub nodes: Vec<usize>,
    /// The branch-and-bound tables, once finished.
    pub search: Option<PrecomputedGrids>,
    /// Bounds [x0, y0, x1, y1] of the finished map in local coordinates.
    pub bounds: [f64; 4],
}

impl Submap {
    fn new(anchor: usize, anchor_local: Pose2, map: MatchedMap) -> Self {
        Submap {
            anchor,
            anchor_local,
            map,
            nodes: Vec::new(),
            search: None,
            bounds: [0.0; 4],
        }
    }

    pub fn finished(&self) -> bool {
        self.search.is_some()
    }

    /// G: the submap's local coordinates → the global frame, given the anchor's global pose.
    pub fn global_transform(&self, anchor_global: &Pose2) -> Pose2 {
        anchor_global.compose(&self.anchor_local.inverse())
    }

    /// Freezes the submap and builds its search tables: the map thresholded (unknown counts as
    /// free, so a scan placed off the surveyed area scores nothing), blurred by `sigma` (Olson
    /// 2009) and precomputed to `depth` levels (Hess §V-C).
    fn finish(&mut self, sigma: f64, depth: usize) {
        let mut occ = self.map.prob().to_occupancy();
        for c in occ.cells.iter_mut() {
            if *c == Cell::Unknown {
                *c = Cell::Free;
            }
        }
        let blurred: ProbGrid = likelihood_grid(&occ, sigma);
        self.bounds = blurred.bounds();
        self.search = Some(PrecomputedGrids::new(&blurred, depth));
    }
}

/// The submaps of a trajectory and the rule that keeps two of them active.
#[derive(Clone, Debug)]
pub struct Submaps {
    pub all: Vec<Submap>,
    /// Indices of the active submaps, oldest first (one or two).
    active: Vec<usize>,
    scans_per_submap: usize,
    resolution: f64,
    levels: usize,
    params: OccupancyParams,
    sigma: f64,
    depth: usize,
}

impl Submaps {
    pub fn new(
        scans_per_submap: usize,
        resolution: f64,
        levels: usize,
        params: OccupancyParams,
        sigma: f64,
        depth: usize,
    ) -> Self {
        Submaps {
            all: Vec::new(),
            active: Vec::new(),
            scans_per_submap: scans_per_submap.max(2),
            resolution,
            levels,
            params,
            sigma,
            depth,
        }
    }

    /// The submap scans are matched against: the oldest active one (None before any insertion).
    pub fn matching(&self) -> Option<&MatchedMap> {
        self.active.first().map(|&i| &self.all[i].map)
    }

    /// Inserts node `node` (at `local`, the robot's local pose; the laser at `sensor`) into the
    /// active submaps, opening and finishing submaps as needed; returns the indices of the
    /// submaps finished by this insertion.
    pub fn insert(
        &mut self,
        node: usize,
        local: &Pose2,
        sensor: &Pose2,
        scan: &LaserScan,
    ) -> Vec<usize> {
        let half = self.scans_per_submap / 2;
        let newest_full = self
            .active
            .last()
            .is_none_or(|&i| self.all[i].nodes.len() >= half);
        if self.active.len() < 2 && newest_full {
            let map = MatchedMap::new(self.resolution, self.params.clone(), self.levels);
            self.all.push(Submap::new(node, *local, map));
            self.active.push(self.all.len() - 1);
        }
        match self.active[..] {
            // the two active submaps share nothing: they take the scan side by side on the pool
            [a, b] if a < b => {
                let (older, newer) = self.all.split_at_mut(b);
                let (older, newer) = (&mut older[a], &mut newer[0]);
                rayon::join(
                    || older.map.insert(sensor, scan),
                    || newer.map.insert(sensor, scan),
                );
                older.nodes.push(node);
                newer.nodes.push(node);
            }
            _ => {
                for &i in &self.active {
                    let s = &mut self.all[i];
                    s.map.insert(sensor, scan);
                    s.nodes.push(node);
                }
            }
        }
        let mut finished = Vec::new();
        while let Some(&i) = self.active.first() {
            if self.all[i].nodes.len() < self.scans_per_submap {
                break;
            }
            self.all[i].finish(self.sigma, self.depth);
            self.active.remove(0);
            finished.push(i);
        }
        finished
    }

    /// Whether submap `i` is still being built.
    pub fn is_active(&self, i: usize) -> bool {
        self.active.contains(&i)
    }
}
