//! Reactive obstacle avoidance on a laser scan, in the spirit of the vector field histogram
//! (Borenstein & Koren 1991): the scan is reduced to the minimum range per angular sector around
//! the robot; a candidate heading is blocked at the nearest sector reading whose lateral offset
//! from that heading is within the robot's half width; the behaviour then takes the free heading
//! closest to the one it wants. O(beams + sectors × candidates) per scan; the points are kept as
//! coordinate columns padded to whole lanes so the candidate test runs vectorized.

use crate::core::Pose2;
use crate::sensors::LaserScan;
use std::f64::consts::PI;

pub const SECTORS: usize = 180;
const SECTOR_WIDTH: f64 = 2.0 * PI / SECTORS as f64;
/// Points tested side by side (the padding of the coordinate columns).
const LANES: usize = 8;

/// The nearest scan point of each 2° sector around the robot that saw something, in its base
/// frame (a compact list: headings are tested against the points only).
#[derive(Clone, Debug, Default)]
pub struct SectorRanges {
    /// x and y of the points, in sector order, padded with NaN to a multiple of [`LANES`] (a NaN
    /// point never blocks a heading).
    xs: Vec<f32>,
    ys: Vec<f32>,
    len: usize,
}

impl SectorRanges {
    pub fn from_scan(scan: &LaserScan, mount: &Pose2) -> Self {
        let mut best = [f32::INFINITY; SECTORS];
        let mut nearest = [(0f32, 0f32); SECTORS];
        // beam directions by rotation (no trigonometry per beam); points are binned by beam
        // angle, while the free-distance test uses their exact coordinates
        let a0 = scan.angle_min as f64 + mount.theta;
        let inc = scan.angle_increment as f64;
        let (si, ci) = inc.sin_cos();
        let (mut s, mut c) = a0.sin_cos();
        // the sector index as a running value in [0, SECTORS): no division per beam
        let n = SECTORS as f64;
        let mut q = ((a0 / SECTOR_WIDTH) % n + n) % n;
        let dq = inc / SECTOR_WIDTH;
        for &r in &scan.ranges {
            let (sk, ck) = (s, c);
            (s, c) = (s * ci + c * si, c * ci - s * si);
            let idx = (q as usize).min(SECTORS - 1);
            q += dq;
            if q >= n {
                q -= n;
            } else if q < 0.0 {
                q += n;
            }
            // a reading below range_min (-Inf) means something very close: treat it as range_min
            let r = if r == f32::NEG_INFINITY {
                scan.range_min
            } else {
                r
            };
            if !r.is_finite() {
                continue;
            }
            let px = (mount.x + ck * r as f64) as f32;
            let py = (mount.y + sk * r as f64) as f32;
            let d2 = px * px + py * py;
            if d2 < best[idx] {
                best[idx] = d2;
                nearest[idx] = (px, py);
            }
        }
        let mut xs = Vec::with_capacity(SECTORS + LANES);
        let mut ys = Vec::with_capacity(SECTORS + LANES);
        for i in (0..SECTORS).filter(|&i| best[i].is_finite()) {
            xs.push(nearest[i].0);
            ys.push(nearest[i].1);
        }
        let len = xs.len();
        xs.resize(len.next_multiple_of(LANES), f32::NAN);
        ys.resize(len.next_multiple_of(LANES), f32::NAN);
        SectorRanges { xs, ys, len }
    }

    /// The seen points (base frame), in sector order.
    pub fn points(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        self.xs[..self.len]
            .iter()
            .copied()
            .zip(self.ys[..self.len].iter().copied())
    }

    /// Free distance along `heading` (base frame) for a body of half width `half_width`: the
    /// nearest seen point within the swept band.
    pub fn free_distance(&self, heading: f64, half_width: f64) -> f64 {
        let (uy, ux) = heading.sin_cos();
        let (ux, uy, hw) = (ux as f32, uy as f32, half_width as f32);
        // one running minimum per lane (the minimum of a set does not depend on the order)
        let mut free = [f32::INFINITY; LANES];
        for (xs, ys) in self.xs.chunks_exact(LANES).zip(self.ys.chunks_exact(LANES)) {
            for l in 0..LANES {
                let (x, y) = (xs[l], ys[l]);
                let along = x * ux + y * uy;
                // branch-free, so the lanes run as one vector operation
                let blocks = (along > 0.0) & ((x * uy - y * ux).abs() < hw);
                let d = if blocks { along } else { f32::INFINITY };
                free[l] = if d < free[l] { d } else { free[l] };
            }
        }
        free.into_iter().fold(f32::INFINITY, f32::min) as f64
    }

    /// Among headings within ±`max_dev` of `wanted` (steps of 5°), the one closest to `wanted`
    /// whose free distance is at least `needed`; otherwise the one with the most room.
    pub fn choose_heading(
        &self,
        wanted: f64,
        half_width: f64,
        needed: f64,
        max_dev: f64,
    ) -> (f64, f64) {
        let step = 5f64.to_radians();
        let n = (max_dev / step).floor() as i32;
        let mut best_open = (wanted, self.free_distance(wanted, half_width));
        if best_open.1 >= needed {
            return best_open;
        }
        for k in 1..=n {
            for sign in [1.0, -1.0] {
                let h = wanted + sign * k as f64 * step;
                let f = self.free_distance(h, half_width);
                if f >= needed {
                    return (h, f);
                }
                if f > best_open.1 {
                    best_open = (h, f);
                }
            }
        }
        best_open
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall_scan(dist: f32) -> LaserScan {
        // a wall across the front at x = dist, 360° scan, nothing elsewhere
        let n = 720;
        let inc = (2.0 * PI / n as f64) as f32;
        let ranges = (0..n)
            .map(|k| {
                let a = -PI as f32 + k as f32 * inc;
                if a.cos() > 0.1 {
                    dist / a.cos()
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        LaserScan {
            stamp: 0.0,
            angle_min: -PI as f32,
            angle_increment: inc,
            range_min: 0.05,
            range_max: 30.0,
            ranges,
        }
    }

    #[test]
    fn a_wall_ahead_blocks_forward_but_not_sideways() {
        let s = SectorRanges::from_scan(&wall_scan(2.0), &Pose2::IDENTITY);
        let ahead = s.free_distance(0.0, 0.3);
        assert!((ahead - 2.0).abs() < 0.05, "{ahead}");
        assert!(s.free_distance(PI / 2.0, 0.3) > 10.0);
        let (h, f) = s.choose_heading(0.0, 0.3, 3.0, PI);
        assert!(h.abs() > 0.5 && f >= 3.0, "{h} {f}");
    }
}
