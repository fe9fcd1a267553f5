//! Fixtures shared by the localizers' tests and the benchmarks (`benches/localization.rs`,
//! `sim bench mcl`, `sim bench markov-grid`): the hospital map, SICK LMS100-like scans ray-cast
//! from a true pose, and a drive along a route with noisy odometry. Deterministic for a seed.

use super::map::LocalizationMap;
use crate::core::{Pose2, SimRng, stream_rng, wrap_angle};
use crate::sensors::LaserScan;
use crate::world::MapError;
use crate::world::load_map;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;

/// The first leg of the hospital's corridors: west wing → main corridor → north corridor.
pub const CORRIDOR: [[f64; 2]; 4] = [[2.2, 16.0], [21.25, 16.0], [21.25, 24.75], [40.0, 24.75]];

/// The bundled hospital map of this source tree, with distances up to 2 m.
pub fn hospital() -> LocalizationMap {
    let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
    map_from(&path).unwrap()
}

/// A map file (YAML) as localizers see it, with distances up to 2 m.
pub fn map_from(yaml: &Path) -> Result<LocalizationMap, MapError> {
    Ok(LocalizationMap::new(load_map(yaml)?, 2.0))
}

/// Beams of a [`scan_at`] scan.
pub const SCAN_BEAMS: usize = 1081;

/// A SICK LMS100-like scan (270°, 0.25°, 20 m) from `pose` with 1 cm noise.
pub fn scan_at(map: &LocalizationMap, pose: &Pose2, rng: &mut SimRng) -> LaserScan {
    let n = SCAN_BEAMS;
    let inc = 0.25f32.to_radians();
    let start = -135f32.to_radians();
    let mut ranges = vec![0.0f32; n];
    map.rays.cast_scan(
        [pose.x as f32, pose.y as f32],
        pose.theta as f32 + start,
        inc,
        20.0,
        &mut ranges,
    );
    for r in ranges.iter_mut() {
        if r.is_finite() {
            let e: f64 = StandardNormal.sample(rng);
            *r += 0.01 * e as f32;
        }
    }
    LaserScan {
        stamp: 0.0,
        angle_min: start,
        angle_increment: inc,
        range_min: 0.5,
        range_max: 20.0,
        ranges,
    }
}

/// Drives along `route` in 0.1 m steps; odometry has 1 % translation and 2 % rotation error
/// plus jitter. Calls `f(truth, odom, scan)` every step.
pub fn drive(
    map: &LocalizationMap,
    route: &[[f64; 2]],
    start_heading: f64,
    seed: u64,
    mut f: impl FnMut(&Pose2, &Pose2, &LaserScan),
) {
    let mut rng = stream_rng(seed, "test", "drive");
    let mut truth = Pose2::new(route[0][0], route[0][1], start_heading);
    let mut odom = Pose2::new(0.0, 0.0, 0.0);
    for goal in &route[1..] {
        loop {
            let (dx, dy) = (goal[0] - truth.x, goal[1] - truth.y);
            let dist = dx.hypot(dy);
            if dist < 0.05 {
                break;
            }
            let turn = wrap_angle(dy.atan2(dx) - truth.theta);
            let step = if turn.abs() > 0.3 {
                Pose2::new(0.0, 0.0, turn.clamp(-0.3, 0.3))
            } else {
                Pose2::new(dist.min(0.1), 0.0, turn)
            };
            truth = truth.compose(&step);
            let g = |r: &mut SimRng| -> f64 { StandardNormal.sample(r) };
            let noisy = Pose2::new(
                step.x * 1.01 + 0.002 * g(&mut rng),
                0.002 * g(&mut rng),
                step.theta * 1.02 + 0.003 * g(&mut rng),
            );
            odom = odom.compose(&noisy);
            let scan = scan_at(map, &truth, &mut rng);
            f(&truth, &odom, &scan);
        }
    }
}

/// One step of a recorded drive: true pose, odometry reading and the scan taken there.
#[derive(Clone, Debug)]
pub struct DriveStep {
    pub truth: Pose2,
    pub odom: Pose2,
    pub scan: LaserScan,
}

/// [`drive`] along `route`, kept (a few hundred 1081-beam scans for [`CORRIDOR`]).
pub fn recorded_drive(
    map: &LocalizationMap,
    route: &[[f64; 2]],
    start_heading: f64,
    seed: u64,
) -> Vec<DriveStep> {
    let mut steps = Vec::new();
    drive(map, route, start_heading, seed, |truth, odom, scan| {
        steps.push(DriveStep {
            truth: *truth,
            odom: *odom,
            scan: scan.clone(),
        })
    });
    steps
}

/// The MCL of the benchmarks: `particles` particles, KLD off (always that many), the likelihood
/// field with `beams` beams, no recovery injection and no scan-proposal challenges (their cost
/// comes every `challenge_every` updates), an update at every scan (no motion gate),
/// started as a Gaussian (0.3 m, 0.1 rad) around `start`.
pub fn bench_mcl(
    map: &LocalizationMap,
    particles: usize,
    beams: usize,
    start: &Pose2,
) -> super::Mcl {
    use super::mcl::{InitialBelief, LaserModel, MclConfig};
    let config = MclConfig {
        min_particles: particles,
        max_particles: particles,
        kld: false,
        max_beams: beams,
        model: LaserModel::LikelihoodField,
        update_min_d: 0.0,
        update_min_a: 0.0,
        recovery_alpha_slow: 0.0,
        recovery_alpha_fast: 0.0,
        challenge_every: 0,
        init: InitialBelief::Gaussian {
            pose: *start,
            sd: [0.3, 0.3, 0.1],
        },
        ..MclConfig::default()
    };
    super::Mcl::new(config, map, stream_rng(0, "bench", "mcl"))
}

/// The Markov grid of the benchmarks: defaults (0.25 m × 10°, 60 beams), global start, an
/// update at every scan; `selective_threshold` 0 scores every cell at every update.
pub fn bench_markov_grid(map: &LocalizationMap, selective_threshold: f64) -> super::MarkovGrid {
    let config = super::MarkovGridConfig {
        update_min_d: 0.0,
        update_min_a: 0.0,
        selective_threshold,
        ..super::MarkovGridConfig::default()
    };
    super::MarkovGrid::new(config, map)
}
