use super::*;
use crate::core::{KernelPool, stream_rng, wrap_angle};
use crate::localization::mcl::{InitialBelief, Mcl, MclConfig};
use crate::localization::test_drive::{CORRIDOR, DriveStep, error, hospital, recorded_drive};
use crate::localization::{Filter, Localizer, Localizers, OdometryModel, WheelOdometry};
use crate::sensors::LaserScans;

/// A user's localizer, written against the trait only: dead reckoning from a known start,
/// corrected at each update by the pose near the prediction whose scan endpoints lie closest to
/// the map's obstacles (a small grid search on the distance field).
#[derive(Clone, Debug)]
struct ScanFit {
    pose: Pose2,
    last_odom: Option<Pose2>,
    /// The candidates of the last correction with their scores (mean endpoint distance).
    candidates: Vec<(Pose2, f64)>,
    estimate: Option<PoseEstimate>,
}

impl ScanFit {
    fn new(start: Pose2) -> Self {
        ScanFit {
            pose: start,
            last_odom: None,
            candidates: Vec::new(),
            estimate: None,
        }
    }
}

impl MapLocalizer for ScanFit {
    fn kind(&self) -> &'static str {
        "scan_fit"
    }

    fn max_beams(&self) -> usize {
        30
    }

    fn predict(&mut self, odom: &Pose2) -> bool {
        if let Some(last) = self.last_odom {
            let d = last.inverse().compose(odom);
            if d.x.hypot(d.y) < 0.2 && wrap_angle(d.theta).abs() < 0.2 {
                return false;
            }
            self.pose = self.pose.compose(&d);
        }
        self.last_odom = Some(*odom);
        true
    }

    fn correct(&mut self, map: &LocalizationMap, beams: &BeamSubset) -> bool {
        let points = beams.returns();
        if points.is_empty() {
            return false;
        }
        let score = |p: &Pose2| {
            points
                .iter()
                .map(|q| {
                    let w = p.transform_point([q[0] as f64, q[1] as f64]);
                    map.field.distance(w[0], w[1])
                })
                .sum::<f64>()
                / points.len() as f64
        };
        self.candidates.clear();
        for i in -2..=2 {
            for j in -2..=2 {
                for k in -2..=2 {
                    let step = Pose2::new(0.05 * i as f64, 0.05 * j as f64, 0.02 * k as f64);
                    let p = self.pose.compose(&step);
                    self.candidates.push((p, score(&p)));
                }
            }
        }
        let best = self
            .candidates
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("candidates");
        self.pose = best.0;
        self.estimate = Some(PoseEstimate {
            pose: self.pose,
            covariance: [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.001]],
            weight: 1.0,
        });
        true
    }

    fn estimate(&self) -> Option<PoseEstimate> {
        self.estimate
    }

    fn belief_points(&self) -> Option<Vec<([f64; 2], f64)>> {
        let best = self.candidates.iter().map(|c| c.1).fold(f64::MAX, f64::min);
        Some(
            self.candidates
                .iter()
                .map(|(p, s)| ([p.x, p.y], (-(s - best) / 0.05).exp()))
                .collect(),
        )
    }

    fn box_clone(&self) -> Box<dyn MapLocalizer> {
        Box::new(self.clone())
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

fn mcl(map: &LocalizationMap, start: &Pose2) -> Mcl {
    let config = MclConfig {
        min_particles: 300,
        max_particles: 300,
        kld: false,
        init: InitialBelief::Gaussian {
            pose: *start,
            sd: [0.3, 0.3, 0.1],
        },
        ..MclConfig::default()
    };
    Mcl::new(config, map, stream_rng(2, "test", "mcl"))
}

/// Feeds every step's scan (taken at the step's odometry pose) through `Localizers::feed`, as
/// the Estimate set does; returns each localizer's fresh estimates per step.
fn feed_drive(
    locs: &mut Localizers,
    map: &LocalizationMap,
    steps: &[DriveStep],
) -> Vec<Vec<Vec<PoseEstimate>>> {
    let pool = KernelPool::new(1).unwrap();
    let model = OdometryModel::DiffDrive {
        left_radius: 0.1,
        right_radius: 0.1,
        wheel_base: 0.5,
    };
    let mut odom = WheelOdometry::new(model, 1000, Pose2::IDENTITY);
    let mut published = Vec::new();
    for (k, s) in steps.iter().enumerate() {
        odom.pose = s.odom;
        let mut scan = s.scan.clone();
        scan.stamp = k as f64 * 0.1;
        let mut scans = LaserScans::default();
        scans.scans.push(scan);
        locs.feed(Some(map), &pool, &scans, Pose2::IDENTITY, &odom, |f| {
            !f.is_scan()
        });
        published.push(
            locs.items
                .iter()
                .map(|l| l.fresh.iter().map(|e| e.estimate).collect())
                .collect(),
        );
    }
    published
}

/// A user's localizer goes through the same path as ours: fed in `Localizers::feed` beside an
/// MCL, it publishes under its own name and tracks the drive with the map's help, and the MCL's
/// estimates are exactly those of an MCL fed alone.
#[test]
fn a_user_localizer_runs_beside_ours_through_one_path() {
    let map = hospital();
    let steps = recorded_drive(&map, &CORRIDOR, 0.0, 7);
    let steps = &steps[..steps.len().min(200)];
    let start = steps[0].truth;

    let mut alone = Localizers {
        items: vec![Localizer::new(
            "amcl",
            Filter::Map(Box::new(mcl(&map, &start))),
        )],
    };
    let mut both = Localizers {
        items: vec![
            Localizer::new("mine", Filter::Map(Box::new(ScanFit::new(start)))),
            Localizer::new("amcl", Filter::Map(Box::new(mcl(&map, &start)))),
        ],
    };
    let by_alone = feed_drive(&mut alone, &map, steps);
    let by_both = feed_drive(&mut both, &map, steps);

    // the MCL publishes the same estimates, bit for bit, with or without the user's localizer
    let mcl_alone: Vec<_> = by_alone.iter().map(|s| s[0].clone()).collect();
    let mcl_both: Vec<_> = by_both.iter().map(|s| s[1].clone()).collect();
    assert_eq!(mcl_alone, mcl_both);
    assert!(mcl_alone.iter().flatten().count() > 20);
    let (a, b) = (
        alone.items[0].filter.downcast_ref::<Mcl>().unwrap(),
        both.items[1].filter.downcast_ref::<Mcl>().unwrap(),
    );
    assert_eq!((&a.xs, &a.ys, &a.ths, &a.w), (&b.xs, &b.ys, &b.ths, &b.w));

    // the user's localizer published under its name, on the scans its own gate let through
    let mine = &both.items[0];
    assert_eq!(
        (mine.name.as_str(), mine.filter.kind()),
        ("mine", "scan_fit")
    );
    assert_eq!(mine.filter.max_beams(), 30);
    assert!(mine.filter.downcast_ref::<Mcl>().is_none());
    let user = mine.filter.downcast_ref::<ScanFit>().unwrap();
    let updates = by_both.iter().filter(|s| !s[0].is_empty()).count();
    assert!(updates > 20 && updates < steps.len(), "{updates}");
    let latest = mine.latest.expect("published");
    assert_eq!(Some(latest.estimate), user.estimate);
    assert_eq!(latest.stamp, (steps.len() - 1) as f64 * 0.1);
    let truth = steps.last().unwrap().truth;
    let (d, a) = error(&latest.estimate, &truth);
    assert!(d < 0.2 && a < 3f64.to_radians(), "{d} m {a} rad");
    let cloud = mine.filter.as_map().unwrap().belief_points().unwrap();
    assert_eq!(cloud.len(), 125);
    assert!(cloud.iter().any(|c| c.1 == 1.0));
}
