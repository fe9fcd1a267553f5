//! The localizers a robot carries, as one component, and the Estimate-set system that feeds them.
//! A robot may carry several at once (each with its own parameters and random stream), so they are
//! compared on identical sensor data. Inputs are the robot's laser scans and its wheel-odometry
//! estimate at each scan's time; nothing here reads ground truth.

use super::map::LocalizationMap;
use super::map_localizer::MapLocalizer;
use super::mcl::{BeamSubset, PoseEstimate};
use super::odometry::WheelOdometry;
use super::scan_estimator::ScanEstimator;
use crate::core::{KernelPool, Pose2};
use crate::sensors::{Laser, LaserScans};
use bevy_ecs::prelude::*;

/// One localization algorithm with its state.
#[derive(Clone, Debug)]
pub enum Filter {
    /// A localizer on the map (ours or a user's), fed in the Estimate set.
    Map(Box<dyn MapLocalizer>),
    /// A SLAM system (or another estimator of a higher layer), fed in the Map set.
    Scan(Box<dyn ScanEstimator>),
}

impl Filter {
    /// The localizer's type name as written in scenario files.
    pub fn kind(&self) -> &'static str {
        match self {
            Filter::Map(f) => f.kind(),
            Filter::Scan(f) => f.kind(),
        }
    }

    /// Beams of a scan the filter reads.
    pub fn max_beams(&self) -> usize {
        match self {
            Filter::Map(f) => f.max_beams(),
            Filter::Scan(_) => 0, // reads the whole scan
        }
    }

    /// The latest estimate.
    pub fn estimate(&self) -> Option<PoseEstimate> {
        match self {
            Filter::Map(f) => f.estimate(),
            Filter::Scan(f) => f.estimate(),
        }
    }

    /// True for estimators fed in the Map set (SLAM).
    pub fn is_scan(&self) -> bool {
        matches!(self, Filter::Scan(_))
    }

    /// The map localizer, if this is one.
    pub fn as_map(&self) -> Option<&dyn MapLocalizer> {
        match self {
            Filter::Map(f) => Some(f.as_ref()),
            Filter::Scan(_) => None,
        }
    }

    /// The map localizer as a concrete type (`Mcl`, `MarkovGrid`, .. or a user's own), if it is
    /// one.
    pub fn downcast_ref<T: MapLocalizer + 'static>(&self) -> Option<&T> {
        self.as_map()?.downcast_ref()
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
    fn consume(
        &mut self,
        map: Option<&LocalizationMap>,
        scan_stamp: f64,
        scan: &ScanInput,
        odom: &Pose2,
    ) {
        if let Filter::Scan(f) = &mut self.filter {
            if f.update(scan.scan, &scan.mount, odom)
                && let Some(e) = f.estimate()
            {
                self.publish(scan_stamp, e);
            }
            return;
        }
        let Some(map) = map else {
            return; // map-based filters only run where the map exists
        };
        let Filter::Map(f) = &mut self.filter else {
            return;
        };
        let beams = scan.beams(f.max_beams());
        if f.predict(odom)
            && f.correct(map, beams)
            && let Some(e) = f.estimate()
        {
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
    /// Feeds this tick's scans, in time order with the odometry pose at each scan's time, to the
    /// localizers `select` picks (their fresh estimates cleared first). Kernels inside the
    /// filters run on the run's rayon pool.
    pub fn feed(
        &mut self,
        map: Option<&LocalizationMap>,
        pool: &KernelPool,
        scans: &LaserScans,
        mount: Pose2,
        odom: &WheelOdometry,
        select: impl Fn(&Filter) -> bool,
    ) {
        let chosen: Vec<usize> = (0..self.items.len())
            .filter(|&i| select(&self.items[i].filter))
            .collect();
        if chosen.is_empty() {
            return;
        }
        for &i in &chosen {
            self.items[i].fresh.clear();
        }
        for scan in &scans.scans {
            let mut input = ScanInput {
                scan,
                mount,
                subsets: Vec::new(),
            };
            for &i in &chosen {
                if !self.items[i].filter.is_scan() {
                    input.prepare(self.items[i].filter.max_beams());
                }
            }
            let at = odom.pose_at(scan.stamp);
            pool.install(|| {
                for &i in &chosen {
                    self.items[i].consume(map, scan.stamp, &input, &at);
                }
            });
        }
    }
}

/// Estimate: every localizer (not the SLAM systems, fed in the Map set) consumes this tick's
/// scans.
pub fn run_localizers(
    map: Option<Res<LocalizationMap>>,
    pool: Res<KernelPool>,
    mut robots: Query<(&mut Localizers, &LaserScans, &Laser, &WheelOdometry)>,
) {
    let Some(map) = map else {
        return; // no robot carries a localizer
    };
    for (mut locs, scans, laser, odom) in robots.iter_mut() {
        locs.feed(Some(&map), &pool, scans, laser.spec.mount, odom, |f| {
            !f.is_scan()
        });
    }
}
