//! The DE localizers on the hospital map: from global initialisation they converge on the
//! corridor drive and then track.

use super::de_filter::{DeFilter, DeFilterConfig};
use super::de_mc::{DeMc, DeMcConfig};
use super::mcl::BeamSubset;
use super::mcl::PoseEstimate;
use super::test_drive::{CORRIDOR, drive, error, hospital};
use crate::core::{Pose2, stream_rng};

fn motion() -> super::OdometryMotionModel {
    super::OdometryMotionModel {
        alpha1: 0.05,
        alpha2: 0.05,
        alpha3: 0.05,
        alpha4: 0.05,
    }
}

/// (first update from which five in a row are within 0.2 m / 5°, share right after it, count).
fn convergence(errors: &[(f64, f64)]) -> (Option<usize>, f64, usize) {
    let ok = |e: &(f64, f64)| e.0 < 0.2 && e.1 < 5f64.to_radians();
    let since = (0..errors.len().saturating_sub(5)).find(|&i| errors[i..i + 5].iter().all(ok));
    let tracked = since.map_or(0.0, |s| {
        errors[s..].iter().filter(|e| ok(e)).count() as f64 / (errors.len() - s) as f64
    });
    (since, tracked, errors.len())
}

fn run(mut step: impl FnMut(&BeamSubset, &Pose2) -> Option<PoseEstimate>) -> Vec<(f64, f64)> {
    let map = hospital();
    let mut errors = Vec::new();
    drive(&map, &CORRIDOR, 0.0, 4, |truth, odom, scan| {
        let beams = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60);
        if let Some(e) = step(&beams, odom) {
            errors.push(error(&e, truth));
        }
    });
    errors
}

#[test]
fn de_filter_converges_from_global_initialisation() {
    let map = hospital();
    let mut f = DeFilter::new(
        DeFilterConfig {
            motion: motion(),
            ..DeFilterConfig::default()
        },
        &map,
        stream_rng(4, "test", "de"),
    );
    let errors = run(|beams, odom| f.update(&map, beams, odom).then(|| f.estimate().unwrap()));
    let (since, tracked, n) = convergence(&errors);
    let since = since.unwrap_or_else(|| panic!("never converged in {n} updates"));
    assert!(since < 40 && tracked > 0.9, "{since} {tracked}");
    let t = &f.tracker;
    assert!(t.converged && t.population.len() == f.config.min_population);
    assert!(t.evaluations < 2_000_000, "{}", t.evaluations);
}

#[test]
fn de_mc_converges_from_global_initialisation() {
    let map = hospital();
    let mut f = DeMc::new(
        DeMcConfig {
            motion: motion(),
            ..DeMcConfig::default()
        },
        &map,
        stream_rng(4, "test", "demc"),
    );
    let errors = run(|beams, odom| f.update(&map, beams, odom).then(|| f.estimate().unwrap()));
    let (since, tracked, n) = convergence(&errors);
    let since = since.unwrap_or_else(|| panic!("never converged in {n} updates"));
    assert!(since < 40 && tracked > 0.9, "{since} {tracked}");
}
