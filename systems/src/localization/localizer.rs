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
use std::sync::OnceLock;

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

    /// Whether a scan at odometry pose `odom` would be corrected with (see
    /// [`MapLocalizer::due`]); a SLAM system takes every scan.
    pub fn due(&self, odom: &Pose2) -> bool {
        match self {
            Filter::Map(f) => f.due(odom),
            Filter::Scan(_) => true,
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
    /// Carried forward by the odometry alone while the laser is faulted or its scans have no
    /// usable beam (see [`Localizer::degraded`]), not the filter's own.
    pub degraded: bool,
}

/// Growth of a degraded estimate's standard deviations: position per metre driven, heading
/// per radian turned and per metre. Odometry's error grows with the path; a few percent per
/// metre is what real wheels do on real floors [Thrun 2005, §5.4].
const DEGRADED_SD_PER_M: f64 = 0.05;
const DEGRADED_SD_RAD_PER_RAD: f64 = 0.05;
const DEGRADED_SD_RAD_PER_M: f64 = 0.02;

/// Where a degraded estimate is carried from: the filter's last estimate and the odometry pose
/// of its scan, and the path driven since.
#[derive(Clone, Copy, Debug)]
struct Anchor {
    estimate: PoseEstimate,
    odom: Pose2,
    last_odom: Pose2,
    travelled_m: f64,
    turned_rad: f64,
}

impl Anchor {
    fn new(estimate: PoseEstimate, odom: Pose2) -> Self {
        Anchor {
            estimate,
            odom,
            last_odom: odom,
            travelled_m: 0.0,
            turned_rad: 0.0,
        }
    }

    /// The estimate carried to odometry pose `odom`, its covariance grown with the path.
    fn carry(&mut self, odom: Pose2) -> PoseEstimate {
        self.travelled_m += self.last_odom.distance(&odom);
        self.turned_rad += crate::core::wrap_angle(odom.theta - self.last_odom.theta).abs();
        self.last_odom = odom;
        let pose = self.estimate.pose.compose(&self.odom.between(&odom));
        let sd = DEGRADED_SD_PER_M * self.travelled_m;
        let sd_theta =
            DEGRADED_SD_RAD_PER_RAD * self.turned_rad + DEGRADED_SD_RAD_PER_M * self.travelled_m;
        let mut covariance = self.estimate.covariance;
        covariance[0][0] += sd * sd;
        covariance[1][1] += sd * sd;
        covariance[2][2] += sd_theta * sd_theta;
        PoseEstimate {
            pose,
            covariance,
            weight: self.estimate.weight,
        }
    }
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
    /// Wall-clock cost of its updates: a measurement of the machine, not of the run, so it is
    /// kept out of everything determinism covers.
    pub cost: UpdateCost,
    /// True while the robot's laser is faulted, or its scans have no usable beam (every one
    /// NaN, zero, below the minimum or at the maximum range): a map localizer then cannot
    /// correct, so it publishes its last estimate carried forward by the odometry, with a
    /// covariance that grows with the path, until a scan with returns comes and the filter
    /// resumes.
    pub degraded: bool,
    anchor: Option<Anchor>,
}

/// The weight of the newest scan in [`UpdateCost::due_s`]: the cost follows a filter from its
/// global start (dear) into tracking (cheap) within a few updates.
const DUE_COST_WEIGHT: f64 = 0.3;

/// What a localizer's updates cost in wall-clock time (one update = one scan consumed).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UpdateCost {
    /// Scans consumed.
    pub updates: u64,
    /// Their total (s).
    pub total_s: f64,
    /// The dearest one (s).
    pub max_s: f64,
    /// What a scan the filter corrects with costs (s), a moving average over those scans: the
    /// others (not moved enough since the last update) cost next to nothing. The hint that
    /// hands a tick's dearest localizers out first.
    pub due_s: f64,
}

impl UpdateCost {
    /// One scan consumed in `seconds`; `due`: one the filter corrected with.
    fn add(&mut self, seconds: f64, due: bool) {
        self.updates += 1;
        self.total_s += seconds;
        self.max_s = self.max_s.max(seconds);
        if due {
            self.due_s += DUE_COST_WEIGHT * (seconds - self.due_s);
        }
    }

    /// Mean cost of an update (s); 0 before the first.
    pub fn mean_s(&self) -> f64 {
        if self.updates == 0 {
            0.0
        } else {
            self.total_s / self.updates as f64
        }
    }
}

impl Localizer {
    pub fn new(name: impl Into<String>, filter: Filter) -> Self {
        Localizer {
            name: name.into(),
            filter,
            latest: None,
            fresh: Vec::new(),
            cost: UpdateCost::default(),
            degraded: false,
            anchor: None,
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
        let due = self.filter.due(odom);
        let started = std::time::Instant::now();
        if self.update(map, scan_stamp, scan, odom) {
            self.cost.add(started.elapsed().as_secs_f64(), due);
        }
    }

    /// False when the filter could not run (a map localizer without a map).
    fn update(
        &mut self,
        map: Option<&LocalizationMap>,
        scan_stamp: f64,
        scan: &ScanInput,
        odom: &Pose2,
    ) -> bool {
        if let Filter::Scan(f) = &mut self.filter {
            if f.update(scan.scan, &scan.mount, odom)
                && let Some(e) = f.estimate()
            {
                self.publish(scan_stamp, e);
            }
            return true;
        }
        let Some(map) = map else {
            return false; // map-based filters only run where the map exists
        };
        let Filter::Map(f) = &mut self.filter else {
            return false;
        };
        let max_beams = f.max_beams();
        if !scan.has_returns(max_beams) {
            // no usable beam (a laser sending NaN, zeros or nothing but its maximum range):
            // degraded as while the laser is faulted, rather than a confident estimate the
            // scan never confirmed
            self.dead_reckon(scan_stamp, *odom);
            return true;
        }
        self.degraded = false;
        if f.predict(odom)
            && f.correct(map, scan.beams(max_beams))
            && let Some(e) = f.estimate()
        {
            self.anchor = Some(Anchor::new(e, *odom));
            self.publish(scan_stamp, e);
        }
        true
    }

    /// Without a laser: a map localizer's last estimate carried to odometry pose `odom` (none
    /// before its first estimate). SLAM systems wait for scans.
    fn dead_reckon(&mut self, stamp: f64, odom: Pose2) {
        if self.filter.is_scan() {
            return;
        }
        self.degraded = true;
        if let Some(e) = self.anchor.as_mut().map(|a| a.carry(odom)) {
            self.publish(stamp, e);
        }
    }

    fn publish(&mut self, stamp: f64, estimate: PoseEstimate) {
        let s = StampedEstimate {
            stamp,
            estimate,
            degraded: self.degraded,
        };
        self.latest = Some(s);
        self.fresh.push(s);
    }
}

/// A scan with its beam subsets per distinct beam count: whether each has returns, checked for
/// every scan, and the subset itself, built once by the first filter that updates on it (most
/// scans update none: the filters wait for enough motion).
struct ScanInput<'a> {
    scan: &'a crate::sensors::LaserScan,
    mount: Pose2,
    subsets: Vec<Subset>,
}

struct Subset {
    max_beams: usize,
    has_returns: bool,
    beams: OnceLock<BeamSubset>,
}

impl ScanInput<'_> {
    fn prepare(&mut self, max_beams: usize) {
        if !self.subsets.iter().any(|s| s.max_beams == max_beams) {
            self.subsets.push(Subset {
                max_beams,
                has_returns: BeamSubset::scan_has_returns(self.scan, max_beams),
                beams: OnceLock::new(),
            });
        }
    }

    fn subset(&self, max_beams: usize) -> &Subset {
        self.subsets
            .iter()
            .find(|s| s.max_beams == max_beams)
            .expect("subsets are prepared before use")
    }

    fn has_returns(&self, max_beams: usize) -> bool {
        self.subset(max_beams).has_returns
    }

    fn beams(&self, max_beams: usize) -> &BeamSubset {
        self.subset(max_beams)
            .beams
            .get_or_init(|| BeamSubset::from_scan(self.scan, &self.mount, max_beams))
    }
}

/// Every localizer of a robot.
#[derive(Component, Clone, Debug, Default)]
pub struct Localizers {
    pub items: Vec<Localizer>,
}

impl Localizers {
    /// Feeds this tick's scans, in time order with the odometry pose at each scan's time, to the
    /// localizers `select` picks (their fresh estimates cleared first); see [`feed_robots`].
    pub fn feed(
        &mut self,
        map: Option<&LocalizationMap>,
        pool: &KernelPool,
        scans: &LaserScans,
        mount: Pose2,
        odom: &WheelOdometry,
        select: impl Fn(&Filter) -> bool + Sync,
    ) {
        let robot = RobotFeed {
            localizers: self,
            scans,
            mount,
            odom,
            laser_works: true,
        };
        feed_robots(map, pool, &mut [robot], select);
    }
}

/// One robot's localizers with what feeds them this tick.
pub struct RobotFeed<'a> {
    pub localizers: &'a mut Localizers,
    pub scans: &'a LaserScans,
    /// The laser's mount on the robot.
    pub mount: Pose2,
    pub odom: &'a WheelOdometry,
    /// False while the laser is faulted: the map localizers are then degraded.
    pub laser_works: bool,
}

/// Feeds every robot's scans of this tick, in time order with the odometry pose at each scan's
/// time, to the localizers `select` picks (their fresh estimates cleared first). Each scan's
/// beam subsets are built once per robot and distinct beam count. The localizers run side by
/// side on the run's pool, each through its own scans in order (each owns its state and random
/// stream, so the results do not depend on the threads); kernels inside a filter share the pool.
/// A robot whose laser is faulted has its map localizers degraded (see [`Localizer::degraded`]).
pub fn feed_robots(
    map: Option<&LocalizationMap>,
    pool: &KernelPool,
    robots: &mut [RobotFeed],
    select: impl Fn(&Filter) -> bool + Sync,
) {
    let inputs: Vec<Vec<(ScanInput, Pose2)>> = robots
        .iter()
        .map(|r| {
            let beams: Vec<usize> = r
                .localizers
                .items
                .iter()
                .filter(|l| select(&l.filter) && !l.filter.is_scan())
                .map(|l| l.filter.max_beams())
                .collect();
            r.scans
                .scans
                .iter()
                .map(|scan| {
                    let mut input = ScanInput {
                        scan,
                        mount: r.mount,
                        subsets: Vec::new(),
                    };
                    for &b in &beams {
                        input.prepare(b);
                    }
                    (input, r.odom.pose_at(scan.stamp))
                })
                .collect()
        })
        .collect();
    for r in robots.iter_mut().filter(|r| !r.laser_works) {
        let (stamp, pose) = (r.odom.stamp, r.odom.pose);
        for l in r.localizers.items.iter_mut().filter(|l| select(&l.filter)) {
            l.fresh.clear();
            l.dead_reckon(stamp, pose);
        }
    }
    let mut jobs: Vec<(&mut Localizer, &[(ScanInput, Pose2)])> = robots
        .iter_mut()
        .zip(&inputs)
        .filter(|(r, _)| r.laser_works)
        .flat_map(|(r, input)| {
            r.localizers
                .items
                .iter_mut()
                .filter(|l| select(&l.filter))
                .map(move |l| (l, &input[..]))
        })
        .collect();
    // a localizer with no scan this tick only forgets its last estimates: no hand-over to the
    // pool for it (half the ticks of a 10 Hz laser at 20 Hz physics)
    jobs.retain_mut(|(loc, input)| {
        if input.is_empty() {
            loc.fresh.clear();
        }
        !input.is_empty()
    });
    let run = |(loc, input): &mut (&mut Localizer, &[(ScanInput, Pose2)])| {
        loc.fresh.clear();
        for (scan, at) in input.iter() {
            loc.consume(map, scan.scan.stamp, scan, at);
        }
    };
    // only a scan the filter corrects with costs something, about what the last ones did; the
    // few centimetres of a tick's scans bring at most one by the filters' update thresholds
    let expected = |(loc, input): &(&mut Localizer, &[(ScanInput, Pose2)])| {
        if input.iter().any(|(_, at)| loc.filter.due(at)) {
            loc.cost.due_s
        } else {
            0.0
        }
    };
    if !jobs.is_empty() {
        pool.for_each_dearest_first(&mut jobs, expected, run);
    }
}

/// Estimate: every localizer (not the SLAM systems, fed in the Map set) consumes this tick's
/// scans.
pub fn run_localizers(
    map: Option<Res<LocalizationMap>>,
    pool: Res<KernelPool>,
    mut robots: FeedQuery,
) {
    let Some(map) = map else {
        return; // no robot carries a localizer
    };
    feed_query(Some(&map), &pool, &mut robots, true, |f| !f.is_scan());
}

/// The robots a localizing system queries: their localizers, scans, laser and odometry.
pub type FeedQuery<'w, 's> = Query<
    'w,
    's,
    (
        &'static mut Localizers,
        &'static LaserScans,
        &'static Laser,
        &'static WheelOdometry,
    ),
>;

/// [`feed_robots`] over a system's query, every robot in one parallel section. `faults`: a
/// faulted laser leaves the map localizers degraded; without it the robot is fed as if its
/// laser worked (the SLAM systems, whose scans simply stop coming).
pub fn feed_query(
    map: Option<&LocalizationMap>,
    pool: &KernelPool,
    robots: &mut FeedQuery,
    faults: bool,
    select: impl Fn(&Filter) -> bool + Sync,
) {
    let mut feeds: Vec<RobotFeed> = robots
        .iter_mut()
        .map(|(locs, scans, laser, odom)| RobotFeed {
            localizers: locs.into_inner(),
            scans,
            mount: laser.spec.mount,
            odom,
            laser_works: laser.enabled || !faults,
        })
        .collect();
    feed_robots(map, pool, &mut feeds, select);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::stream_rng;
    use crate::localization::Mcl;
    use crate::localization::mcl::{InitialBelief, MclConfig};
    use crate::localization::odometry::OdometryModel;
    use crate::localization::props::{estimate_fault, room, room_scan};
    use crate::sensors::LaserScan;

    /// A scan with no usable beam (all NaN, zero, negative, below the minimum or at the
    /// maximum range) leaves a map localizer degraded, publishing its last estimate carried by
    /// the odometry, as a faulted laser does; the next scan with returns ends it.
    /// Every map localizer takes a scan exactly when the odometry has moved its update
    /// threshold (9 cm or 0.2 rad here) since the last scan it took, and `due` says so before
    /// `predict`: at 2 cm and 1° a scan, every fifth.
    #[test]
    fn map_localizers_take_the_scans_due_by_their_thresholds() {
        use crate::localization::de_filter::{DeFilter, DeFilterConfig};
        use crate::localization::de_mc::{DeMc, DeMcConfig};
        use crate::localization::de_odometry::{DeOdometry, DeOdometryConfig};
        use crate::localization::{MapLocalizer, MarkovGrid, MarkovGridConfig};
        let map = room();
        let rng = |name: &str| stream_rng(1, "test", name);
        let (d, a) = (0.09, 0.2);
        let filters: Vec<Box<dyn MapLocalizer>> = vec![
            Box::new(Mcl::new(
                MclConfig {
                    min_particles: 100,
                    max_particles: 300,
                    update_min_d: d,
                    update_min_a: a,
                    ..MclConfig::default()
                },
                &map,
                rng("mcl"),
            )),
            Box::new(MarkovGrid::new(
                MarkovGridConfig {
                    update_min_d: d,
                    update_min_a: a,
                    ..MarkovGridConfig::default()
                },
                &map,
            )),
            Box::new(DeFilter::new(
                DeFilterConfig {
                    population: 60,
                    min_population: 20,
                    update_min_d: d,
                    update_min_a: a,
                    ..DeFilterConfig::default()
                },
                &map,
                rng("de"),
            )),
            Box::new(DeMc::new(
                DeMcConfig {
                    population: 60,
                    update_min_d: d,
                    update_min_a: a,
                    ..DeMcConfig::default()
                },
                &map,
                rng("de_mc"),
            )),
            Box::new(DeOdometry::new(
                DeOdometryConfig {
                    update_min_d: d,
                    update_min_a: a,
                    ..DeOdometryConfig::default()
                },
                rng("de_odo"),
            )),
        ];
        for mut f in filters {
            let mut taken: Vec<usize> = Vec::new();
            for k in 0..40 {
                let odom = Pose2::new(5.0 + 0.02 * k as f64, 4.0, 0.3 + 0.0175 * k as f64);
                let due = f.due(&odom);
                assert_eq!(due, f.predict(&odom), "{} at scan {k}", f.kind());
                if due {
                    let scan = room_scan(&map, &odom, 90);
                    f.correct(&map, &BeamSubset::from_scan(&scan, &Pose2::IDENTITY, 60));
                    taken.push(k);
                }
            }
            let every_fifth: Vec<usize> = (0..40).step_by(5).collect();
            assert_eq!(taken, every_fifth, "{}", f.kind());
        }
    }

    #[test]
    fn scans_without_a_usable_beam_leave_the_localizer_degraded() {
        let map = room();
        let start = Pose2::new(6.0, 4.0, 0.3);
        let config = MclConfig {
            min_particles: 100,
            max_particles: 300,
            injection_candidates: 0,
            challenge_every: 0,
            update_min_d: 0.0,
            update_min_a: 0.0,
            init: InitialBelief::Gaussian {
                pose: start,
                sd: [0.2, 0.2, 0.1],
            },
            ..MclConfig::default()
        };
        let mcl = Mcl::new(config, &map, stream_rng(1, "test", "mcl"));
        let mut locs = Localizers {
            items: vec![Localizer::new("mcl", Filter::Map(Box::new(mcl)))],
        };
        let pool = KernelPool::new(1).unwrap();
        let model = OdometryModel::DiffDrive {
            left_radius: 0.1,
            right_radius: 0.1,
            wheel_base: 0.5,
        };
        let odom = WheelOdometry::new(model, 4096, Pose2::IDENTITY);
        let mut scans = LaserScans::default();
        let good = room_scan(&map, &start, 90);
        let mut feed = |locs: &mut Localizers, scan: LaserScan| {
            scans.scans = vec![scan];
            locs.feed(Some(&map), &pool, &scans, Pose2::IDENTITY, &odom, |f| {
                !f.is_scan()
            });
        };
        feed(&mut locs, good.clone());
        let l = &locs.items[0];
        assert!(!l.degraded && l.latest.is_some_and(|e| !e.degraded));
        for (k, fill) in [
            f32::NAN,
            0.0,
            -1.0,
            0.05,
            10.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ]
        .into_iter()
        .enumerate()
        {
            let mut bad = good.clone();
            bad.ranges.fill(fill);
            bad.stamp = 0.1 * (k + 1) as f64;
            feed(&mut locs, bad);
            let l = &locs.items[0];
            assert!(l.degraded, "{fill}");
            let e = l.latest.expect("the last estimate, carried");
            assert!(
                e.degraded && e.stamp == 0.1 * (k + 1) as f64,
                "{fill}: {e:?}"
            );
            assert_eq!(estimate_fault(&e.estimate), None);
        }
        let mut back = good.clone();
        back.stamp = 1.0;
        feed(&mut locs, back);
        let l = &locs.items[0];
        assert!(!l.degraded && l.latest.is_some_and(|e| !e.degraded && e.stamp == 1.0));
    }
}
