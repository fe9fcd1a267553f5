//! Matcher tests on realistic scans: 1081-beam SICK LMS100 scans (270°, 0.25°, 0.5–20 m,
//! 12 mm range noise) ray-cast on the hospital map.

use super::*;
use crate::core::{Pose2, SimRng, stream_rng};
use crate::raycast::RayMap;
use crate::world::{Cell, OccupancyGrid, load_map};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::PI;
use std::sync::OnceLock;

pub(super) struct Hospital {
    pub grid: OccupancyGrid,
    pub map: RayMap,
}

pub(super) fn hospital() -> &'static Hospital {
    static H: OnceLock<Hospital> = OnceLock::new();
    H.get_or_init(|| {
        let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
        let grid = load_map(&path).expect("the hospital map loads");
        let map = RayMap::new(
            grid.width,
            grid.height,
            grid.resolution as f32,
            [grid.origin[0] as f32, grid.origin[1] as f32],
            &grid.obstacles(),
        );
        Hospital { grid, map }
    })
}

const BEAMS: usize = 1081;
const RANGE_MIN: f32 = 0.5;
const RANGE_MAX: f32 = 20.0;

fn increment() -> f32 {
    0.25f32.to_radians()
}

fn angle_min() -> f32 {
    -135f32.to_radians()
}

/// A SICK LMS100 scan at `pose` (sensor frame points), with 12 mm range noise if `rng` is given.
pub(super) fn scan_at(pose: Pose2, rng: Option<&mut SimRng>) -> Vec<[f32; 2]> {
    let h = hospital();
    let mut ranges = vec![0f32; BEAMS];
    h.map.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + angle_min(),
        increment(),
        RANGE_MAX,
        &mut ranges,
    );
    if let Some(rng) = rng {
        for r in ranges.iter_mut().filter(|r| r.is_finite()) {
            let n: f64 = rng.sample(StandardNormal);
            *r += (0.012 * n) as f32;
        }
    }
    scan_to_points(angle_min(), increment(), &ranges, RANGE_MIN, RANGE_MAX)
}

/// A free pose: inside a free cell with 0.3 m clearance.
pub(super) fn is_free(x: f64, y: f64) -> bool {
    let g = &hospital().grid;
    g.cell_of(x, y)
        .is_some_and(|(c, r)| g.get(c, r) == Cell::Free && g.disc_is_clear(x, y, 0.3))
}

/// Whether the straight segment between two positions is free (the robot can drive it).
pub(super) fn line_of_sight(a: Pose2, b: Pose2) -> bool {
    let d = a.distance(&b);
    if d < 1e-6 {
        return true;
    }
    let ang = (b.y - a.y).atan2(b.x - a.x);
    hospital()
        .map
        .cast([a.x as f32, a.y as f32], ang as f32, d as f32 + 0.3)
        > d as f32 + 0.3
}

/// A random (reference pose, true transform) pair: free reference pose, displacement uniform in
/// ±`max_xy` on each axis and ±`max_theta`, current pose free and reachable in a straight line.
pub(super) fn random_pair(rng: &mut SimRng, max_xy: f64, max_theta: f64) -> (Pose2, Pose2) {
    let b = hospital().grid.bounds();
    loop {
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        if !is_free(x, y) {
            continue;
        }
        let reference = Pose2::new(x, y, rng.random_range(-PI..PI));
        let t = Pose2::new(
            rng.random_range(-max_xy..max_xy),
            rng.random_range(-max_xy..max_xy),
            rng.random_range(-max_theta..max_theta),
        );
        let current = reference.compose(&t);
        if is_free(current.x, current.y) && line_of_sight(reference, current) {
            return (reference, t);
        }
    }
}

/// Whether `found` is within `xy` metres (per axis) and `theta` radians of `truth`.
pub(super) fn close(found: &Pose2, truth: &Pose2, xy: f64, theta: f64) -> bool {
    (found.x - truth.x).abs() <= xy
        && (found.y - truth.y).abs() <= xy
        && crate::core::wrap_angle(found.theta - truth.theta).abs() <= theta
}

/// A reference pose in a hospital room from which the thesis's example transform
/// (−911 mm, 2579 mm, −57°, [Hospital thesis §6]) lands on a free, visible pose.
fn thesis_example_pair() -> (Pose2, Pose2) {
    let t = Pose2::new(-0.911, 2.579, (-57f64).to_radians());
    let b = hospital().grid.bounds();
    let mut rng = stream_rng(7, "matching", "thesis-example");
    loop {
        let x = rng.random_range(b[0]..b[2]);
        let y = rng.random_range(b[1]..b[3]);
        if !is_free(x, y) {
            continue;
        }
        let reference = Pose2::new(x, y, rng.random_range(-PI..PI));
        let current = reference.compose(&t);
        if is_free(current.x, current.y) && line_of_sight(reference, current) {
            return (reference, t);
        }
    }
}

#[test]
fn thesis_example_transform_is_recovered() {
    let (reference, truth) = thesis_example_pair();
    let mut rng = stream_rng(7, "matching", "thesis-example-noise");
    let a = scan_at(reference, Some(&mut rng));
    let b = scan_at(reference.compose(&truth), Some(&mut rng));
    let improved = match_scans(&a, &b, &MatchConfig::improved()).unwrap();
    assert!(
        close(&improved.transform, &truth, 0.020, 1f64.to_radians()),
        "improved matcher found {:?}, truth {truth:?}",
        improved.transform
    );
    // the thesis's own program (correlation, rand/1, F 0.5) on a budget, with early stop
    let mut de = DeParams::thesis_figure_run();
    de.generations = 1000;
    de.stall = Some(StallStop {
        generations: 200,
        tolerance: 0.0,
    });
    let thesis = MatchConfig::thesis(ThesisFitness::EuclideanField, de);
    let found = match_scans(&a, &b, &thesis).unwrap();
    assert!(
        close(&found.transform, &truth, 0.020, 1f64.to_radians()),
        "thesis DE (Euclidean field) found {:?}, truth {truth:?}",
        found.transform
    );
}

#[test]
fn improved_matcher_aligns_random_pairs() {
    let mut rng = stream_rng(11, "matching", "random-pairs");
    let n = 60;
    let mut right = 0;
    let mut slowest = std::time::Duration::ZERO;
    for i in 0..n {
        let (reference, truth) = random_pair(&mut rng, 2.0, PI);
        let a = scan_at(reference, Some(&mut rng));
        let b = scan_at(reference.compose(&truth), Some(&mut rng));
        let r = match_scans(&a, &b, &MatchConfig::improved().with_seed(i)).unwrap();
        slowest = slowest.max(r.elapsed);
        if close(&r.transform, &truth, 0.1, 2f64.to_radians()) {
            right += 1;
        } else {
            eprintln!("pair {i}: found {:?}, truth {truth:?}", r.transform);
        }
    }
    eprintln!("{right}/{n} right, slowest {slowest:?}");
    // arbitrary headings in look-alike rooms are harder than driving (see `sim experiment
    // de-match` for the thesis protocol); a few symmetric pairs are genuinely ambiguous
    assert!(
        right >= n - 4,
        "{right}/{n} pairs aligned within 0.1 m and 2°"
    );
}

#[test]
fn same_seed_same_answer() {
    let mut rng = stream_rng(3, "matching", "determinism");
    let (reference, truth) = random_pair(&mut rng, 3.0, PI);
    let a = scan_at(reference, Some(&mut rng));
    let b = scan_at(reference.compose(&truth), Some(&mut rng));
    for config in [
        MatchConfig::improved().with_seed(5),
        MatchConfig::thesis(ThesisFitness::Correlation, {
            let mut de = DeParams::thesis_final_experiment();
            de.generations = 200;
            de
        })
        .with_seed(5),
    ] {
        let x = match_scans(&a, &b, &config).unwrap();
        let y = match_scans(&a, &b, &config).unwrap();
        assert_eq!(
            (x.transform, x.fitness, x.evaluations),
            (y.transform, y.fitness, y.evaluations)
        );
    }
}

/// A search window far larger than the scans (up to 10³⁰ m) costs the improved matcher no more
/// than the scans' extent: no panic, no huge allocation, and still the right answer.
#[test]
fn improved_matcher_survives_a_huge_window() {
    let (reference, truth) = thesis_example_pair();
    let a = scan_at(reference, None);
    let b = scan_at(reference.compose(&truth), None);
    for max_xy in [100.0, 1e4, 1e8, 1e9, 1e30] {
        let mut cfg = MatchConfig::improved();
        cfg.window.max_xy = max_xy;
        let r = match_scans(&a, &b, &cfg).unwrap();
        assert!(
            close(&r.transform, &truth, 0.1, 2f64.to_radians()),
            "window ±{max_xy} m: found {:?}, truth {truth:?}",
            r.transform
        );
    }
}

/// A reference scan with a point 10⁸ m away would need grids of petabytes: every matcher
/// refuses it with an error instead of aborting on the allocation.
#[test]
fn an_absurdly_wide_reference_is_an_error() {
    let (reference, truth) = thesis_example_pair();
    let mut a = scan_at(reference, None);
    let b = scan_at(reference.compose(&truth), None);
    a.push([1e8, 0.0]);
    for cfg in [
        MatchConfig::improved(),
        MatchConfig::thesis_final_experiment(ThesisFitness::EuclideanField),
    ] {
        let e = match_scans(&a, &b, &cfg).expect_err("a 10⁸ m wide reference");
        assert!(
            matches!(
                e,
                MatchError::ReferenceTooWide { .. } | MatchError::InvalidParameter { .. }
            ),
            "{e}"
        );
    }
}

#[test]
fn empty_or_invalid_scans_are_errors() {
    let pts = vec![[1.0f32, 0.0], [0.0, 1.0]];
    let nan = vec![[f32::NAN, 0.0]];
    let cfg = MatchConfig::improved();
    assert!(matches!(
        match_scans(&[], &pts, &cfg),
        Err(MatchError::EmptyReference)
    ));
    assert!(matches!(
        match_scans(&pts, &nan, &cfg),
        Err(MatchError::EmptyCurrent)
    ));
    let mut bad = cfg.clone();
    bad.window.max_xy = f64::NAN;
    assert!(match_scans(&pts, &pts, &bad).is_err());
}

/// `scan` (sensor frame) with a person — a 0.25 m disc at `person` (sensor frame) — in front of
/// whatever the beams hit behind it.
fn with_person(scan: &[[f32; 2]], person: [f32; 2]) -> Vec<[f32; 2]> {
    const R: f32 = 0.25;
    scan.iter()
        .map(|p| {
            let r = p[0].hypot(p[1]);
            let u = [p[0] / r, p[1] / r];
            // nearest intersection of the ray t·u with the disc
            let along = u[0] * person[0] + u[1] * person[1];
            let d2 = person[0] * person[0] + person[1] * person[1] - along * along;
            if along > 0.0 && d2 < R * R {
                let t = along - (R * R - d2).sqrt();
                if t < r {
                    return [t * u[0], t * u[1]];
                }
            }
            *p
        })
        .collect()
}

#[test]
fn people_walking_between_the_scans_do_not_turn_the_answer_around() {
    // driving 0.3–0.5 m straight on while a person walks about ahead: in the right alignment
    // the person of each scan stands in space the other scan saw free. Counted beam by beam,
    // those violations (≈ 10 points of each scan) made a 180° flip in a symmetric corridor win
    // in `sim experiment de-match`; counted as one object each, they must not
    let mut rng = stream_rng(21, "matching", "people");
    let (n, mut right, mut right_per_point) = (30, 0, 0);
    let per_point = ImprovedConfig {
        blob_extent: 0.0,
        ..ImprovedConfig::default()
    };
    for i in 0..n {
        // along a corridor: at least 10 m free ahead
        let (reference, truth) = loop {
            let (reference, _) = random_pair(&mut rng, 0.1, 0.1);
            let ahead = hospital().map.cast(
                [reference.x as f32, reference.y as f32],
                reference.theta as f32,
                20.0,
            );
            if ahead < 10.0 {
                continue;
            }
            let step = rng.random_range(0.3..0.5);
            let truth = Pose2::new(step, 0.0, 0.0);
            let current = reference.compose(&truth);
            if is_free(current.x, current.y) && line_of_sight(reference, current) {
                break (reference, truth);
            }
        };
        // two people 3–8 m ahead who have moved by the current scan
        let at = |rng: &mut SimRng| {
            let d = rng.random_range(3.0f32..8.0);
            let a = rng.random_range(-0.2f32..0.2);
            [d * a.cos(), d * a.sin()]
        };
        let a = scan_at(reference, Some(&mut rng));
        let b = scan_at(reference.compose(&truth), Some(&mut rng));
        let (a, b) = (with_person(&a, at(&mut rng)), with_person(&b, at(&mut rng)));
        let (a, b) = (with_person(&a, at(&mut rng)), with_person(&b, at(&mut rng)));
        let mut cfg = MatchConfig::improved().with_seed(i);
        let r = match_scans(&a, &b, &cfg).unwrap();
        if close(&r.transform, &truth, 0.1, 2f64.to_radians()) {
            right += 1;
        } else {
            eprintln!("pair {i}: found {:?}, truth {truth:?}", r.transform);
        }
        cfg.method = Method::Improved(per_point.clone());
        let r = match_scans(&a, &b, &cfg).unwrap();
        right_per_point += close(&r.transform, &truth, 0.1, 2f64.to_radians()) as usize;
    }
    eprintln!("{right}/{n} right; counting every violating point: {right_per_point}/{n}");
    assert!(
        right >= n - 1,
        "{right}/{n} pairs aligned within 0.1 m and 2°"
    );
}
