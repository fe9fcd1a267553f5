//! Laser measurement models for particle weighting, as ROS AMCL implements them (amcl_laser.cpp):
//!
//! - likelihood field (Probabilistic Robotics §6.4, Table 6.3): each beam endpoint, projected from
//!   the particle's pose, scores pz = z_hit·exp(−d²/2σ_hit²) + z_rand/z_max, d its distance to the
//!   nearest obstacle (precomputed, [`crate::world::DistanceField`]);
//! - beam model (§6.3, Table 6.1): the expected range z* is ray-cast from the particle's sensor
//!   pose and pz mixes z_hit·N(z; z*, σ_hit), z_short·λe^{−λz} (z < z*), z_max·[z = z_max] and
//!   z_rand/z_max.
//!
//! Both combine beams as AMCL does, p = 1 + Σ pz³ (a deliberately flattened product that keeps
//! one bad beam from zeroing a good particle), and the particle's weight is multiplied by p.
//! Kernels are plain functions over particle arrays; particles are weighed in fixed chunks on the
//! rayon pool (each weight depends on its particle only, so results do not depend on threads).

use super::field_kernel::{self, GridPose};
use crate::core::Pose2;
use crate::raycast::RayMap;
use crate::sensors::LaserScan;
use crate::world::DistanceField;
use rayon::prelude::*;

/// Particles per parallel work item.
pub const CHUNK: usize = 256;

/// Parameters shared by both models (AMCL's `laser_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaserModelParams {
    pub z_hit: f64,
    pub z_rand: f64,
    pub sigma_hit: f64,
    /// Beam model only.
    pub z_short: f64,
    pub z_max: f64,
    pub lambda_short: f64,
    /// Likelihood field: distances are truncated here (m).
    pub max_dist: f64,
}

impl Default for LaserModelParams {
    /// AMCL's defaults.
    fn default() -> Self {
        LaserModelParams {
            z_hit: 0.95,
            z_rand: 0.05,
            sigma_hit: 0.2,
            z_short: 0.1,
            z_max: 0.05,
            lambda_short: 0.1,
            max_dist: 2.0,
        }
    }
}

/// The beams a filter update uses: `max_beams` evenly spaced over the scan (AMCL's step
/// (n − 1)/(max_beams − 1)), as (range, bearing in the base frame) and the endpoint in the base
/// frame. A beam with no return (+Inf) is kept as a max-range reading; one below the minimum
/// range (−Inf, or a finite reading under `range_min`, such as the zeros or negative values of
/// a faulty scanner) or NaN is dropped.
#[derive(Clone, Debug, Default)]
pub struct BeamSubset {
    /// Range per beam (m); `range_max` for no return.
    pub ranges: Vec<f32>,
    /// Whether the beam returned nothing (max-range reading).
    pub max_reading: Vec<bool>,
    /// Beam direction in the base frame.
    pub angles: Vec<f32>,
    /// Endpoints in the base frame (meaningful for returns only).
    pub points: Vec<[f32; 2]>,
    pub mount: Pose2,
    pub range_max: f32,
}

impl BeamSubset {
    pub fn from_scan(scan: &LaserScan, mount: &Pose2, max_beams: usize) -> Self {
        let mut s = BeamSubset {
            mount: *mount,
            range_max: scan.range_max,
            ..Default::default()
        };
        for (k, r) in picked(scan, max_beams) {
            let max_reading = r == f32::INFINITY || r >= scan.range_max;
            let r = if max_reading { scan.range_max } else { r };
            let a = scan.angle_min as f64 + k as f64 * scan.angle_increment as f64;
            let p = mount.transform_point([r as f64 * a.cos(), r as f64 * a.sin()]);
            s.ranges.push(r);
            s.max_reading.push(max_reading);
            s.angles.push((mount.theta + a) as f32);
            s.points.push([p[0] as f32, p[1] as f32]);
        }
        s
    }

    /// `BeamSubset::from_scan(scan, _, max_beams).has_returns()` without building the subset:
    /// a scan that does not update a filter is still checked for returns at every scan.
    pub fn scan_has_returns(scan: &LaserScan, max_beams: usize) -> bool {
        picked(scan, max_beams).any(|(_, r)| r != f32::INFINITY && r < scan.range_max)
    }

    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// Endpoints of the beams that returned something (what the likelihood field weighs: AMCL
    /// leaves max-range readings out).
    pub fn returns(&self) -> Vec<[f32; 2]> {
        self.points
            .iter()
            .zip(&self.max_reading)
            .filter(|(_, max)| !**max)
            .map(|(p, _)| *p)
            .collect()
    }

    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// Whether some beam returned something: without one (every reading NaN, zero, below the
    /// minimum or at the maximum range) the scan says nothing about where the robot is.
    pub fn has_returns(&self) -> bool {
        self.max_reading.iter().any(|max| !max)
    }
}

/// The beams of [`BeamSubset::from_scan`]: index and reading of every picked beam that is kept
/// (not NaN, not below the minimum range).
fn picked(scan: &LaserScan, max_beams: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
    let n = scan.ranges.len();
    let picks = if n == 0 { 0 } else { max_beams.min(n) };
    let step = if picks > 1 {
        (n - 1) as f64 / (picks - 1) as f64
    } else {
        0.0
    };
    (0..picks)
        .map(move |j| ((j as f64 * step).round() as usize).min(n - 1))
        .map(|k| (k, scan.ranges[k]))
        .filter(|&(_, r)| !(r.is_nan() || r < scan.range_min.max(0.0)))
}

/// The likelihood-field score table: pz³ per stored distance byte.
pub fn likelihood_table(field: &DistanceField, p: &LaserModelParams, range_max: f64) -> [f32; 256] {
    let denom = 2.0 * p.sigma_hit * p.sigma_hit;
    let rand = p.z_rand / range_max.max(1e-6);
    field.table(|d| {
        // one field serves every localizer: distances beyond this model's cap read as the cap
        let d = d.min(p.max_dist);
        let pz = p.z_hit * (-d * d / denom).exp() + rand;
        (pz * pz * pz) as f32
    })
}

/// Likelihood-field kernel: multiplies `w[i]` by 1 + Σ_beams table[field(endpoint of particle
/// i)] for the beam endpoints `points` (base frame; max-range readings must be left out, as AMCL
/// does). Endpoints outside the map read the table's last entry (distance `max_dist`). The sums
/// come from [`field_kernel`] (vectorised where the CPU allows, identical results either way).
pub fn weigh_likelihood_field(
    field: &DistanceField,
    table: &[f32; 256],
    points: &[[f32; 2]],
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    w: &mut [f64],
) {
    weigh_field(field, table, points, [xs, ys, ths], w, None);
}

/// [`weigh_likelihood_field`] that also keeps, per particle, its heading with the sine and
/// cosine the weighing computed of it (`trig`, one entry per particle), for the cluster to
/// reuse.
pub fn weigh_likelihood_field_keeping_trig(
    field: &DistanceField,
    table: &[f32; 256],
    points: &[[f32; 2]],
    [xs, ys, ths]: [&[f64]; 3],
    w: &mut [f64],
    trig: &mut [[f64; 3]],
) {
    weigh_field(field, table, points, [xs, ys, ths], w, Some(trig));
}

fn weigh_field(
    field: &DistanceField,
    table: &[f32; 256],
    points: &[[f32; 2]],
    [xs, ys, ths]: [&[f64]; 3],
    w: &mut [f64],
    trig: Option<&mut [[f64; 3]]>,
) {
    let far = table[crate::world::distance_field::FAR as usize];
    let weigh = |base: usize, wc: &mut [f64], mut tc: Option<&mut [[f64; 3]]>| {
        let poses: Vec<GridPose> = (base..base + wc.len())
            .map(|i| {
                let (s, c) = ths[i].sin_cos();
                if let Some(t) = tc.as_deref_mut() {
                    t[i - base] = [ths[i], s, c];
                }
                GridPose::with_sin_cos(field, xs[i], ys[i], s, c)
            })
            .collect();
        let mut p = vec![0.0f32; wc.len()];
        field_kernel::score_all(field, table, far, points, &poses, &mut p);
        for (wi, p) in wc.iter_mut().zip(p) {
            *wi *= p as f64;
        }
    };
    match trig {
        Some(t) if t.len() == w.len() => w
            .par_chunks_mut(CHUNK)
            .zip(t.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (wc, tc))| weigh(c * CHUNK, wc, Some(tc))),
        _ => w
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, wc)| weigh(c * CHUNK, wc, None)),
    }
}

/// Beam-model kernel: multiplies `w[i]` by 1 + Σ pz³, the expected ranges ray-cast on `rays`
/// from each particle's sensor pose (several rays at a time, [`RayMap::cast_many`]).
#[allow(clippy::too_many_arguments)]
pub fn weigh_beam_model(
    rays: &RayMap,
    params: &LaserModelParams,
    beams: &BeamSubset,
    xs: &[f64],
    ys: &[f64],
    ths: &[f64],
    w: &mut [f64],
) {
    let m = beams.len();
    if m == 0 {
        return;
    }
    let range_max = beams.range_max;
    let p = *params;
    let denom = 2.0 * p.sigma_hit * p.sigma_hit;
    let norm = 1.0 / (p.sigma_hit * (2.0 * std::f64::consts::PI).sqrt());
    let rand = p.z_rand / range_max as f64;
    w.par_chunks_mut(CHUNK).enumerate().for_each(|(c, wc)| {
        let base = c * CHUNK;
        // the chunk's beams in one stream, so the caster keeps its lanes full
        let batch: Vec<([f32; 2], f32)> = (base..base + wc.len())
            .flat_map(|i| {
                let sensor = Pose2::new(xs[i], ys[i], ths[i]).compose(&beams.mount);
                let origin = [sensor.x as f32, sensor.y as f32];
                let th = ths[i] as f32;
                beams.angles.iter().map(move |&a| (origin, th + a))
            })
            .collect();
        let mut all = vec![0.0f32; batch.len()];
        rays.cast_many(&batch, range_max, &mut all);
        for (wi, expected) in wc.iter_mut().zip(all.chunks_exact(m)) {
            let mut total = 1.0f64;
            for (k, &zs) in expected.iter().enumerate() {
                let z = beams.ranges[k] as f64;
                let zs = zs.min(range_max) as f64;
                let mut pz = 0.0;
                if !beams.max_reading[k] {
                    pz += p.z_hit * norm * (-(z - zs).powi(2) / denom).exp();
                    if z < zs {
                        pz += p.z_short * p.lambda_short * (-p.lambda_short * z).exp();
                    }
                } else {
                    pz += p.z_max;
                }
                if z < range_max as f64 {
                    pz += rand;
                }
                total += pz * pz * pz;
            }
            *wi *= total;
        }
    });
}
