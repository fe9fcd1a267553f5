//! The localizers a robot carries, as one component, and the Estimate-set system that feeds them.
//! A robot may carry several at once (each with its own parameters and random stream), so they are
//! compared on identical sensor data. Inputs are the robot's laser scans and its wheel-odometry
//! estimate at each scan's time; nothing here reads ground truth.

use super::de_filter::DeFilter;
use super::de_mc::DeMc;
use super::de_odometry::DeOdometry;
use super::map::LocalizationMap;
use super::markov_grid::MarkovGrid;
use super::mcl::{BeamSubset, Mcl, PoseEstimate};
use super::odometry::WheelOdometry;
use crate::core::{KernelPool, Pose2};
use crate::sensors::{Laser, LaserScans};
use bevy_ecs::prelude::*;

/// One localization algorithm with its state.
#[derive(Clone, Debug)]
pub enum Filter {
    Mcl(Box<Mcl>),
    MarkovGrid(Box<MarkovGrid>),
    DeFilter(Box<DeFilter>),
    DeMc(Box<DeMc>),
    DeOdometry(Box<DeOdometry>),
}

impl Filter {
    /// The localizer's type name as written in scenario files.
    pub fn kind(&self) -> &'static str {
        match self {
            Filter::Mcl(_) => "mcl",
            Filter::MarkovGrid(_) => "markov_grid",
            Filter::DeFilter(_) => "de_filter",
            Filter::DeMc(_) => "de_mc",
            Filter::DeOdometry(_) => "de_odometry",
        }
    }

    /// Beams of a scan the filter reads.
    pub fn max_beams(&self) -> usize {
        match self {
            Filter::Mcl(m) => m.config.max_beams,
            Filter::MarkovGrid(g) => g.config.max_beams,
            Filter::DeFilter(f) => f.config.max_beams,
            Filter::DeMc(f) => f.config.max_beams,
            Filter::DeOdometry(f) => f.config.max_beams,
        }
    }

    /// The latest estimate.
    pub fn estimate(&self) -> Option<PoseEstimate> {
        match self {
            Filter::Mcl(m) => m.estimate,
            Filter::MarkovGrid(g) => g.estimate,
            Filter::DeFilter(f) => f.estimate(),
            Filter::DeMc(f) => f.estimate(),
            Filter::DeOdometry(f) => f.estimate,
        }
    }
}

/// An estimate published at a scan's time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StampedEstimate {
    pub stamp: f64,
    pub estimate: PoseEstimate,
}

/// A named localizer and what it published.
#[derive(Clone, Debug)]
pub struct Localizer {
    pub name: String,
    pub filter: Filter,
    /// The latest estimate.
    pub latest: Option<StampedEstimate>,
    /// Estimates published during the current tick (cleared at the start of each tick).
    pub fresh: Vec<StampedEstimate>,
}

impl Localizer {
    pub fn new(name: impl Into<String>, filter: Filter) -> Self {
        Localizer {
            name: name.into(),
            filter,
            latest: None,
            fresh: Vec::new(),
        }
    }

    /// Consumes one scan (beams already in the base frame) taken at odometry pose `odom`.
    fn consume(&mut self, map: &LocalizationMap, scan_stamp: f64, scan: &ScanInput, odom: &Pose2) {
        let beams = scan.beams(self.filter.max_beams());
        let updated = match &mut self.filter {
            Filter::Mcl(f) => f.update(map, beams, odom),
            Filter::MarkovGrid(f) => f.update(map, &beams.returns(), beams.range_max, odom),
            Filter::DeFilter(f) => f.update(map, beams, odom),
            Filter::DeMc(f) => f.update(map, beams, odom),
            Filter::DeOdometry(f) => f.update(&beams.returns(), odom),
        };
        if updated && let Some(e) = self.filter.estimate() {
            self.publish(scan_stamp, e);
        }
    }

    fn publish(&mut self, stamp: f64, estimate: PoseEstimate) {
        let s = StampedEstimate { stamp, estimate };
        self.latest = Some(s);
        self.fresh.push(s);
    }
}

/// A scan with its beam subsets, built once per distinct beam count.
struct ScanInput<'a> {
    scan: &'a crate::sensors::LaserScan,
    mount: Pose2,
    subsets: Vec<(usize, BeamSubset)>,
}

impl ScanInput<'_> {
    fn prepare(&mut self, max_beams: usize) {
        if !self.subsets.iter().any(|(m, _)| *m == max_beams) {
            let s = BeamSubset::from_scan(self.scan, &self.mount, max_beams);
            self.subsets.push((max_beams, s));
        }
    }

    fn beams(&self, max_beams: usize) -> &BeamSubset {
        self.subsets
            .iter()
            .find(|(m, _)| *m == max_beams)
            .map(|(_, s)| s)
            .expect("subsets are prepared before use")
    }
}

/// Every localizer of a robot.
#[derive(Component, Clone, Debug, Default)]
pub struct Localizers {
    pub items: Vec<Localizer>,
}

impl Localizers {
    fn beam_counts(&self) -> Vec<usize> {
        self.items.iter().map(|l| l.filter.max_beams()).collect()
    }
}

/// Estimate: every localizer consumes this tick's scans, in time order, with the odometry pose at
/// each scan's time. Kernels inside the filters run on the run's rayon pool.
pub fn run_localizers(
    map: Option<Res<LocalizationMap>>,
    pool: Res<KernelPool>,
    mut robots: Query<(&mut Localizers, &LaserScans, &Laser, &WheelOdometry)>,
) {
    let Some(map) = map else {
        return; // no robot carries a localizer
    };
    let map: &LocalizationMap = &map;
    for (mut locs, scans, laser, odom) in robots.iter_mut() {
        for l in locs.items.iter_mut() {
            l.fresh.clear();
        }
        let counts = locs.beam_counts();
        for scan in &scans.scans {
            let mut input = ScanInput {
                scan,
                mount: laser.spec.mount,
                subsets: Vec::new(),
            };
            for &m in &counts {
                input.prepare(m);
            }
            let at = odom.pose_at(scan.stamp);
            pool.install(|| {
                for l in locs.items.iter_mut() {
                    l.consume(map, scan.stamp, &input, &at);
                }
            });
        }
    }
}
