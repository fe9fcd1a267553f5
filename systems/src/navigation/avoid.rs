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

/// Length of the coordinate columns: every sector, padded to whole lanes.
const PADDED: usize = SECTORS.next_multiple_of(LANES);

/// The nearest scan point of each 2° sector around the robot that saw something, in its base
/// frame (a compact list: headings are tested against the points only). The columns are kept
/// inline, not on the heap: a behaviour reads them every tick, and its robots' components lie one
/// after the other in memory, which the processor's prefetcher follows (separate heap
/// allocations it cannot guess).
#[derive(Clone, Debug)]
pub struct SectorRanges {
    /// x and y of the points, in sector order, padded with NaN to a multiple of [`LANES`] (a NaN
    /// point never blocks a heading).
    xs: [f32; PADDED],
    ys: [f32; PADDED],
    len: usize,
    /// The last answers of [`Self::choose_heading_remembered`] and
    /// [`Self::free_distance_remembered`], forgotten at every [`Self::update`].
    memo: Memo,
}

impl Default for SectorRanges {
    fn default() -> Self {
        SectorRanges {
            xs: [f32::NAN; PADDED],
            ys: [f32::NAN; PADDED],
            len: 0,
            memo: Memo::default(),
        }
    }
}

/// One remembered question and answer of each kind, keyed by the arguments' bits.
#[derive(Clone, Debug, Default)]
struct Memo {
    /// (wanted, half width, needed, max deviation) → (heading, free distance).
    choice: Option<([u64; 4], (f64, f64))>,
    /// (heading, half width) → free distance.
    free: Option<([u64; 2], f64)>,
}

/// A scan's beams in the robot's base frame: each beam's direction, and the runs of beams that
/// fall in the same sector. It depends only on the laser's angles and mount, so it is built once
/// and reused for every scan of the same geometry.
#[derive(Default)]
struct BeamSectors {
    /// angle_min, angle_increment, beam count, mount (x, y, θ) as bits: what the table is for.
    key: (u32, u32, usize, [u64; 3]),
    /// cos and sin of each beam's angle in the base frame, as columns.
    cos: Vec<f32>,
    sin: Vec<f32>,
    /// (sector, first beam, end beam) of each run of consecutive beams in one sector, in beam
    /// order (a fan crossing 2π visits a sector in two runs).
    runs: Vec<(u32, u32, u32)>,
    /// The runs in sector order, when no sector is seen in two runs (a fan that does not cross
    /// 2π into its own start): then each run is one point of the list, written in order.
    by_sector: Option<Vec<u32>>,
    /// Scratch: each beam's squared distance from the robot's centre in the current scan.
    d2: Vec<f32>,
}

/// The nearest beam of the run [start, end) without a branch on the readings (whether a beam is
/// lost or nearer than the one before is a coin toss in a real scan): its squared distance
/// (+Inf when the run saw nothing) and its index (on a tie the first beam).
#[inline(always)]
fn nearest_in_run(d2: &[f32], start: u32, end: u32) -> (f32, usize) {
    let (start, end) = (start as usize, end as usize);
    let (mut bd, mut bk) = (f32::INFINITY, start);
    for (k, &d) in d2[start..end].iter().enumerate() {
        let k = start + k;
        let nearer = d < bd;
        bd = if nearer { d } else { bd };
        bk = if nearer { k } else { bk };
    }
    (bd, bk)
}

impl BeamSectors {
    fn key(scan: &LaserScan, mount: &Pose2) -> (u32, u32, usize, [u64; 3]) {
        (
            scan.angle_min.to_bits(),
            scan.angle_increment.to_bits(),
            scan.ranges.len(),
            [mount.x.to_bits(), mount.y.to_bits(), mount.theta.to_bits()],
        )
    }

    fn build(&mut self, scan: &LaserScan, mount: &Pose2) {
        self.key = Self::key(scan, mount);
        let a0 = scan.angle_min as f64 + mount.theta;
        let inc = scan.angle_increment as f64;
        let n = scan.ranges.len();
        (self.cos, self.sin) = (Vec::with_capacity(n), Vec::with_capacity(n));
        self.runs.clear();
        for k in 0..n {
            let a = a0 + k as f64 * inc;
            let (s, c) = a.sin_cos();
            let sector = ((a.rem_euclid(2.0 * PI) / SECTOR_WIDTH) as usize).min(SECTORS - 1);
            self.cos.push(c as f32);
            self.sin.push(s as f32);
            match self.runs.last_mut() {
                Some((last, _, end)) if *last == sector as u32 => *end = k as u32 + 1,
                _ => self.runs.push((sector as u32, k as u32, k as u32 + 1)),
            }
        }
        let mut order: Vec<u32> = (0..self.runs.len() as u32).collect();
        order.sort_by_key(|&i| self.runs[i as usize].0);
        let distinct = order
            .windows(2)
            .all(|w| self.runs[w[0] as usize].0 != self.runs[w[1] as usize].0);
        self.by_sector = distinct.then_some(order);
        self.d2 = vec![0.0; n];
    }
}

thread_local! {
    /// The beam table of the last scan geometry reduced on this thread (robots with the same
    /// laser share it).
    static BEAM_SECTORS: std::cell::RefCell<BeamSectors> =
        std::cell::RefCell::new(BeamSectors::default());
}

impl SectorRanges {
    pub fn from_scan(scan: &LaserScan, mount: &Pose2) -> Self {
        let mut s = SectorRanges::default();
        s.update(scan, mount);
        s
    }

    /// Reduces `scan` (from a laser at `mount` on the robot) to its nearest point per sector,
    /// reusing this value's storage.
    pub fn update(&mut self, scan: &LaserScan, mount: &Pose2) {
        BEAM_SECTORS.with_borrow_mut(|table| {
            if table.key != BeamSectors::key(scan, mount) {
                table.build(scan, mount);
            }
            self.reduce(scan, mount, table);
        });
    }

    fn reduce(&mut self, scan: &LaserScan, mount: &Pose2, table: &mut BeamSectors) {
        self.memo = Memo::default();
        let (mx, my) = (mount.x as f32, mount.y as f32);
        // a reading below range_min (-Inf) means something very close: taken as range_min
        let reading = |r: f32| {
            if r == f32::NEG_INFINITY {
                scan.range_min
            } else {
                r
            }
        };
        // every beam's squared distance from the centre, as one vectorized pass; a lost beam
        // (+Inf, NaN) gives +Inf or NaN, which never compares below anything
        let BeamSectors {
            cos,
            sin,
            runs,
            by_sector,
            d2,
            ..
        } = table;
        for (((d, &r), &c), &s) in d2.iter_mut().zip(&scan.ranges).zip(&*cos).zip(&*sin) {
            let r = reading(r);
            let (x, y) = (mx + c * r, my + s * r);
            *d = x * x + y * y;
        }
        let (d2, cos, sin) = (&d2[..], &cos[..], &sin[..]);
        let nearest_of = |start: u32, end: u32| {
            let (bd, bk) = nearest_in_run(d2, start, end);
            let r = reading(scan.ranges[bk]);
            (bd, mx + cos[bk] * r, my + sin[bk] * r)
        };
        let mut len = 0;
        if let Some(order) = by_sector {
            // one run per sector: the runs' points in sector order, each written at the end of
            // the list, which only grows past a run that saw something
            for &i in order.iter() {
                let (_, start, end) = runs[i as usize];
                let (d, x, y) = nearest_of(start, end);
                self.xs[len] = x;
                self.ys[len] = y;
                len += d.is_finite() as usize;
            }
        } else {
            // a sector seen in two runs (the fan crosses 2π) keeps the nearer, on a tie the
            // earlier: the runs go into per-sector slots, with one slot more than there are
            // sectors for a run that is not nearer than its sector's best
            const DISCARD: usize = SECTORS;
            let mut best = [f32::INFINITY; SECTORS + 1];
            let mut nearest = [(0f32, 0f32); SECTORS + 1];
            for &(sector, start, end) in runs.iter() {
                let (bd, x, y) = nearest_of(start, end);
                let i = sector as usize;
                let slot = if bd < best[i] { i } else { DISCARD };
                best[slot] = bd;
                nearest[slot] = (x, y);
            }
            // the sectors that saw something, compacted without a branch either
            for (&d, &(x, y)) in best[..SECTORS].iter().zip(&nearest[..SECTORS]) {
                self.xs[len] = x;
                self.ys[len] = y;
                len += d.is_finite() as usize;
            }
        }
        self.len = len;
        let end = len.next_multiple_of(LANES);
        self.xs[len..end].fill(f32::NAN);
        self.ys[len..end].fill(f32::NAN);
    }

    /// The points nearer than `sqrt(limit2)` (a copy, compacted without a branch).
    fn within(&self, limit2: f32) -> SectorRanges {
        let mut near = SectorRanges::default();
        let mut len = 0;
        for (&x, &y) in self.xs[..self.len].iter().zip(&self.ys[..self.len]) {
            near.xs[len] = x;
            near.ys[len] = y;
            len += (x * x + y * y < limit2) as usize;
        }
        near.len = len;
        let end = len.next_multiple_of(LANES);
        near.xs[len..end].fill(f32::NAN);
        near.ys[len..end].fill(f32::NAN);
        near
    }

    /// The squared distance of the nearest seen point from the robot's centre (+∞ for none).
    pub fn nearest_squared(&self) -> f32 {
        let end = self.len.next_multiple_of(LANES);
        let mut best = [f32::INFINITY; LANES];
        for (xs, ys) in self.xs[..end]
            .chunks_exact(LANES)
            .zip(self.ys[..end].chunks_exact(LANES))
        {
            for l in 0..LANES {
                let d = xs[l] * xs[l] + ys[l] * ys[l];
                // NaN padding never compares below
                best[l] = if d < best[l] { d } else { best[l] };
            }
        }
        best.into_iter().fold(f32::INFINITY, f32::min)
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
        self.free_along(ux, uy, half_width as f32) as f64
    }

    /// [`Self::free_distance`], answered from memory when asked the same as last time since the
    /// last [`Self::update`] (a behaviour asks the same between two scans while its wanted
    /// heading stays put, e.g. a wandering robot; the answer is the same to the bit).
    pub fn free_distance_remembered(&mut self, heading: f64, half_width: f64) -> f64 {
        let key = [heading.to_bits(), half_width.to_bits()];
        match self.memo.free {
            Some((k, f)) if k == key => f,
            _ => {
                let f = self.free_distance(heading, half_width);
                self.memo.free = Some((key, f));
                f
            }
        }
    }

    /// [`Self::choose_heading`], answered from memory like [`Self::free_distance_remembered`].
    pub fn choose_heading_remembered(
        &mut self,
        wanted: f64,
        half_width: f64,
        needed: f64,
        max_dev: f64,
    ) -> (f64, f64) {
        let key = [wanted, half_width, needed, max_dev].map(f64::to_bits);
        match self.memo.choice {
            Some((k, answer)) if k == key => answer,
            _ => {
                let answer = self.choose_heading(wanted, half_width, needed, max_dev);
                self.memo.choice = Some((key, answer));
                answer
            }
        }
    }

    /// [`Self::free_distance`] along the unit vector (ux, uy).
    fn free_along(&self, ux: f64, uy: f64, hw: f32) -> f32 {
        let (ux, uy) = (ux as f32, uy as f32);
        // one running minimum per lane (the minimum of a set does not depend on the order)
        let mut free = [f32::INFINITY; LANES];
        let end = self.len.next_multiple_of(LANES);
        let (xs, ys) = (&self.xs[..end], &self.ys[..end]);
        for (xs, ys) in xs.chunks_exact(LANES).zip(ys.chunks_exact(LANES)) {
            for l in 0..LANES {
                let (x, y) = (xs[l], ys[l]);
                let along = x * ux + y * uy;
                // branch-free, so the lanes run as one vector operation
                let blocks = (along > 0.0) & ((x * uy - y * ux).abs() < hw);
                let d = if blocks { along } else { f32::INFINITY };
                free[l] = if d < free[l] { d } else { free[l] };
            }
        }
        free.into_iter().fold(f32::INFINITY, f32::min)
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
        let hw = half_width as f32;
        let (uy, ux) = wanted.sin_cos();
        let ahead = self.free_along(ux, uy, hw) as f64;
        if ahead >= needed || !needed.is_finite() {
            return (wanted, ahead);
        }
        // a point blocks a heading at its distance along it, and its distance across is under
        // the half width: so only points nearer than √(needed² + hw²) can block one short of
        // `needed` (with a margin far above rounding). The candidates are tested on those
        // alone: a shorter free distance found there is the free distance, to the bit, and the
        // heading that is free enough gets its distance over all points
        let reach2 = (needed as f32 * 1.001 + 0.01).powi(2) + (hw + 0.01).powi(2);
        let near = self.within(reach2);
        choose_among(
            wanted,
            ahead,
            needed,
            max_dev,
            |dx, dy| near.free_along(dx, dy, hw) as f64,
            |dx, dy| self.free_along(dx, dy, hw) as f64,
        )
    }
}

/// The candidate search of [`SectorRanges::choose_heading`] once the wanted heading (free for
/// `ahead`) fell short: `test` gives a candidate's free distance when it is short of `needed`
/// (anything at least `needed` otherwise), `exact` its free distance.
fn choose_among(
    wanted: f64,
    ahead: f64,
    needed: f64,
    max_dev: f64,
    test: impl Fn(f64, f64) -> f64,
    exact: impl Fn(f64, f64) -> f64,
) -> (f64, f64) {
    let step = 5f64.to_radians();
    let n = (max_dev / step).floor() as i32;
    let (uy, ux) = wanted.sin_cos();
    let mut best_open = (wanted, ahead);
    // the candidates' directions by rotating the wanted one 5° at a time each way (no
    // trigonometry per candidate; the rounding after 36 steps is far below a microradian)
    let (ss, cs) = step.sin_cos();
    let (mut left, mut right) = ((ux, uy), (ux, uy));
    for k in 1..=n {
        left = (left.0 * cs - left.1 * ss, left.0 * ss + left.1 * cs);
        right = (right.0 * cs + right.1 * ss, -right.0 * ss + right.1 * cs);
        for (sign, (dx, dy)) in [(1.0, left), (-1.0, right)] {
            let h = wanted + sign * k as f64 * step;
            let f = test(dx, dy);
            if f >= needed {
                return (h, exact(dx, dy));
            }
            if f > best_open.1 {
                best_open = (h, f);
            }
        }
    }
    best_open
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A 360° scan from the centre of a wall across the front at x = `dist`.
    pub(crate) fn wall_scan(dist: f32) -> LaserScan {
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
    fn candidate_headings_see_what_free_distance_sees() {
        // a dead end: every heading within ±100° of ahead is blocked, so the choice steps
        // through many candidates; the distance it reports must be the one measured directly
        // walls as (unit normal towards the robot's outside, distance): ahead, left, right
        let walls = [([1.0, 0.0], 1.0), ([0.0, 1.0], 1.0), ([0.0, -1.0], 1.0)];
        let ranges = (0..360)
            .map(|k| {
                let (s, c) = (-180.0 + k as f64).to_radians().sin_cos();
                walls
                    .iter()
                    .filter_map(|&([nx, ny], d)| {
                        let towards = c * nx + s * ny;
                        (towards > 1e-9).then(|| d / towards)
                    })
                    .fold(30.0f64, f64::min) as f32
            })
            .collect();
        let scan = LaserScan {
            stamp: 0.0,
            angle_min: -PI as f32,
            angle_increment: 1f32.to_radians(),
            range_min: 0.05,
            range_max: 30.0,
            ranges,
        };
        let s = SectorRanges::from_scan(&scan, &Pose2::IDENTITY);
        for wanted in [0.0, 0.3, -1.0, 2.5] {
            let (h, f) = s.choose_heading(wanted, 0.3, 5.0, PI * 0.8);
            let direct = s.free_distance(h, 0.3);
            assert!((f - direct).abs() < 1e-4, "{wanted}: {h} {f} {direct}");
        }
        // the way out of the dead end (behind) is beyond reach: the most open heading wins
        let (h, f) = s.choose_heading(0.0, 0.3, 50.0, PI * 0.8);
        let most = (-28..=28)
            .map(|k| s.free_distance((k as f64 * 5.0).to_radians(), 0.3))
            .fold(0.0, f64::max);
        assert!(h.abs() > 2.0 && (f - most).abs() < 1e-4, "{h} {f} {most}");
    }

    /// A scan of 180 beams over the half turn ahead, 8 m range.
    fn half_turn_scan(ranges: Vec<f32>) -> LaserScan {
        LaserScan {
            stamp: 0.0,
            angle_min: -PI as f32 / 2.0,
            angle_increment: (PI / 179.0) as f32,
            range_min: 0.05,
            range_max: 8.0,
            ranges,
        }
    }

    /// The choice as its doc reads: every candidate's free distance over all the points.
    fn choose_by_definition(
        s: &SectorRanges,
        wanted: f64,
        hw: f64,
        needed: f64,
        max_dev: f64,
    ) -> (f64, f64) {
        let (uy, ux) = wanted.sin_cos();
        let ahead = s.free_along(ux, uy, hw as f32) as f64;
        if ahead >= needed {
            return (wanted, ahead);
        }
        let all = |dx, dy| s.free_along(dx, dy, hw as f32) as f64;
        choose_among(wanted, ahead, needed, max_dev, all, all)
    }

    /// Testing the candidates on the near points only picks the same heading with the same
    /// free distance, to the bit, as testing them on all points.
    #[test]
    fn the_choice_on_near_points_is_the_choice_on_all() {
        let mut rng = crate::core::stream_rng(7, "avoid", "choice");
        let mut next = || rand::RngExt::random::<f64>(&mut rng);
        let mut differing_paths = 0;
        for case in 0..400 {
            let n = 180;
            let ranges = (0..n)
                .map(|_| match (next() * 10.0) as u32 {
                    0 => f32::INFINITY,
                    1 => f32::NEG_INFINITY,
                    _ => (0.2 + next() * 4.0) as f32,
                })
                .collect();
            let scan = half_turn_scan(ranges);
            let s = SectorRanges::from_scan(&scan, &Pose2::new(0.1, 0.0, 0.0));
            let wanted = (next() - 0.5) * 2.0;
            let needed = 0.5 + next() * 5.0;
            let hw = 0.2 + next() * 0.3;
            let got = s.choose_heading(wanted, hw, needed, PI * 0.8);
            let want = choose_by_definition(&s, wanted, hw, needed, PI * 0.8);
            assert_eq!(
                (got.0.to_bits(), got.1.to_bits()),
                (want.0.to_bits(), want.1.to_bits()),
                "case {case}"
            );
            differing_paths += usize::from(got.1 < needed);
        }
        // both outcomes occur: a heading free enough, and the most open one
        assert!(
            differing_paths > 10 && differing_paths < 390,
            "{differing_paths}"
        );
    }

    /// The remembered answers are the answers: asked again with the same arguments they repeat
    /// them, asked anything else or after a new scan they are computed afresh.
    #[test]
    fn remembered_answers_are_forgotten_at_every_scan() {
        let mut rng = crate::core::stream_rng(11, "avoid", "memo");
        let mut next = || rand::RngExt::random::<f64>(&mut rng);
        let mut s = SectorRanges::default();
        let mut changed = 0;
        let mut previous = None;
        for case in 0..200 {
            let ranges = (0..180)
                .map(|_| (0.2 + next() * 4.0) as f32)
                .collect::<Vec<_>>();
            let scan = half_turn_scan(ranges);
            s.update(&scan, &Pose2::IDENTITY);
            // the same question as before the new scan, then a few others
            let mut questions = vec![(0.1, 0.3, 2.0)];
            for _ in 0..3 {
                questions.push(((next() - 0.5) * 2.0, 0.2 + next() * 0.3, 0.5 + next() * 5.0));
            }
            for (wanted, hw, needed) in questions {
                for _ in 0..2 {
                    let fresh = SectorRanges::from_scan(&scan, &Pose2::IDENTITY);
                    let want = fresh.choose_heading(wanted, hw, needed, PI * 0.8);
                    let got = s.choose_heading_remembered(wanted, hw, needed, PI * 0.8);
                    assert_eq!(got, want, "case {case}");
                    let got = s.free_distance_remembered(wanted, hw);
                    assert_eq!(got, fresh.free_distance(wanted, hw), "case {case}");
                }
            }
            let answer = s.choose_heading_remembered(0.1, 0.3, 2.0, PI * 0.8);
            changed += usize::from(previous.is_some_and(|p| p != answer));
            previous = Some(answer);
        }
        // the scans differ enough that the first question's answer changes with them
        assert!(changed > 50, "{changed}");
    }

    /// The reduction beam by beam into the sectors' slots, as the definition reads.
    fn reduce_by_definition(scan: &LaserScan, mount: &Pose2) -> Vec<(f32, f32)> {
        let mut best = [(f32::INFINITY, 0f32, 0f32); SECTORS];
        for (k, &r) in scan.ranges.iter().enumerate() {
            let r = if r == f32::NEG_INFINITY {
                scan.range_min
            } else {
                r
            };
            if !r.is_finite() {
                continue;
            }
            let a = scan.angle_min as f64 + mount.theta + k as f64 * scan.angle_increment as f64;
            let (s, c) = a.sin_cos();
            let (px, py) = (mount.x as f32 + c as f32 * r, mount.y as f32 + s as f32 * r);
            let sector = ((a.rem_euclid(2.0 * PI) / SECTOR_WIDTH) as usize).min(SECTORS - 1);
            let d2 = px * px + py * py;
            if d2 < best[sector].0 {
                best[sector] = (d2, px, py);
            }
        }
        best.iter()
            .filter(|b| b.0.is_finite())
            .map(|b| (b.1, b.2))
            .collect()
    }

    #[test]
    fn runs_of_a_sector_reduce_as_beam_by_beam() {
        // fans that cross 2π (so one sector's beams come in two runs), lost beams (+Inf, NaN),
        // readings below range_min (-Inf), equal ranges (the first beam wins a tie)
        for (n, fov, first, mount) in [
            (180, PI, -PI / 2.0, Pose2::IDENTITY),
            (
                1081,
                1.5 * PI,
                100f64.to_radians(),
                Pose2::new(0.2, -0.1, 0.3),
            ),
            (720, 2.0 * PI - 0.01, -PI, Pose2::new(-0.3, 0.0, PI)),
            // from 1° round to 0.5°: sector 0's beams at both ends
            (
                720,
                359.5f64.to_radians(),
                1f64.to_radians(),
                Pose2::IDENTITY,
            ),
            (7, 0.3, 6.2, Pose2::IDENTITY),
        ] {
            let ranges: Vec<f32> = (0..n)
                .map(|k| match (k * 7919) % 23 {
                    0 => f32::INFINITY,
                    1 => f32::NAN,
                    2 => f32::NEG_INFINITY,
                    3 | 4 => 2.0,
                    h => 0.5 + h as f32 * 0.37 + (k % 5) as f32 * 0.01,
                })
                .collect();
            let scan = LaserScan {
                stamp: 0.0,
                angle_min: first as f32,
                angle_increment: (fov / (n - 1).max(1) as f64) as f32,
                range_min: 0.1,
                range_max: 20.0,
                ranges,
            };
            let got: Vec<_> = SectorRanges::from_scan(&scan, &mount).points().collect();
            assert_eq!(got, reduce_by_definition(&scan, &mount), "{n} beams");
            // a scan without beams leaves nothing seen
            let mut reused = SectorRanges::from_scan(&scan, &mount);
            let empty = LaserScan {
                ranges: Vec::new(),
                ..scan
            };
            reused.update(&empty, &mount);
            assert_eq!(reused.points().count(), 0, "{n} beams, then none");
            assert!(reused.free_distance(0.0, 0.3).is_infinite());
        }
    }

    #[test]
    fn reused_storage_gives_the_same_reduction() {
        let first = wall_scan(2.0);
        let second = wall_scan(3.5);
        let mut reused = SectorRanges::from_scan(&first, &Pose2::IDENTITY);
        reused.update(&second, &Pose2::IDENTITY);
        let fresh = SectorRanges::from_scan(&second, &Pose2::IDENTITY);
        assert_eq!(
            reused.points().collect::<Vec<_>>(),
            fresh.points().collect::<Vec<_>>()
        );
        // a mounted laser: the points move with the mount
        let mount = Pose2::new(0.2, 0.0, 0.0);
        reused.update(&second, &mount);
        let ahead = reused.free_distance(0.0, 0.3);
        assert!((ahead - 3.7).abs() < 0.05, "{ahead}");
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
