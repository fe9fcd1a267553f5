//! Applying one scan to log-odds cells, the kernel of occupancy grid mapping
//! ([`super::occupancy`]; Thrun et al., *Probabilistic Robotics*, §9.2): the scan's usable beams
//! ([`prepare_beams`]), then every return's end cell as a hit and the cells each beam crossed as
//! misses, each cell at most once per scan ([`apply_beams`]). The cells are anything that
//! implements [`CellStore`]: the contiguous grid of [`super::LogOddsMap`] or the copy-on-write
//! tiles of a particle's map in [`super::rbpf`].

use super::inverse_model::{OccupancyParams, log_odds};
use crate::core::Pose2;
use crate::raycast::traverse_segment;

/// What one scan contributed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InsertStats {
    /// Beams that ended on an obstacle (inside the grid).
    pub hits: usize,
    /// Beams without a return that cleared space.
    pub clears: usize,
    /// Readings not used: NaN, −Inf, below `range_min`.
    pub ignored: usize,
    /// The cells [c0, c1) × [r0, r1) the scan may have changed (the box of the sensor and the
    /// beams' ends with a cell of margin, clipped to the grid), for callers that mirror the map.
    pub window: Option<[usize; 4]>,
}

/// One usable beam of a scan: unit direction in the map frame, length (m), and whether it ends
/// on a return (false: a beam without a return, clearing only).
pub(crate) type Beam = ([f32; 2], f32, bool);

/// The inverse sensor model of [`OccupancyParams`] in log-odds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LogOddsModel {
    pub hit: f32,
    pub miss: f32,
    pub min: f32,
    pub max: f32,
    /// [`OccupancyParams::hit_clear_gap`] (cells).
    pub hit_clear_gap: f32,
}

impl LogOddsModel {
    pub fn new(params: &OccupancyParams) -> Self {
        LogOddsModel {
            hit: log_odds(params.p_hit),
            miss: log_odds(params.p_miss),
            min: log_odds(params.p_min),
            max: log_odds(params.p_max),
            hit_clear_gap: params.hit_clear_gap,
        }
    }
}

/// Where a grid of cells lies: `width` × `height` cells of `resolution`, cell (0, 0)'s lower-left
/// corner at `origin`; cell (c, r) has index `r * width + c`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GridFrame {
    pub width: usize,
    pub height: usize,
    pub resolution: f64,
    pub origin: [f64; 2],
}

/// Log-odds cells a scan is applied to, indexed as in [`GridFrame`]: the contiguous grid of
/// [`LogOddsMap`], or the shared tiles of a particle's map in the RBPF.
pub(crate) trait CellStore {
    /// Adds `delta` to cell `i`, clamped to [lo, hi], unless scan `id` already updated it.
    fn update_once(&mut self, i: usize, id: u32, delta: f32, lo: f32, hi: f32);
}

/// The usable beams of a scan (layout and REP 117 conventions as [`LogOddsMap::insert_ranges`];
/// `angles` = [angle_min, angle_increment]) from `sensor`, into `beams`; counts the ignored
/// readings and the clearing beams into `stats`.
pub(crate) fn prepare_beams(
    params: &OccupancyParams,
    sensor: &Pose2,
    angles: [f32; 2],
    limits: [f32; 2],
    ranges: &[f32],
    beams: &mut Vec<Beam>,
    stats: &mut InsertStats,
) {
    let max_range = limits[1].min(params.max_range);
    let clear = params.clear_range.min(max_range).max(0.0);
    beams.clear();
    for (k, &r) in ranges.iter().enumerate() {
        let (len, hit) = if r.is_nan() || r < limits[0] {
            stats.ignored += 1; // NaN, −Inf and too-close readings
            continue;
        } else if r <= max_range {
            (r, true)
        } else if clear > 0.0 {
            stats.clears += 1;
            (clear, false)
        } else {
            continue;
        };
        // the angle in f64: k · increment summed in f32 loses ~1e-7 rad at k = 1080
        let a = sensor.theta + angles[0] as f64 + k as f64 * angles[1] as f64;
        let (s, c) = a.sin_cos();
        beams.push(([c as f32, s as f32], len, hit));
    }
}

/// Applies `beams` from `sensor` to the cells of `grid` as scan `id`: first every return's end
/// cell (a hit), then the cells each beam crossed (misses; a return's beam stops
/// `hit_clear_gap` cells short of its end). Returns the number of hits inside the grid.
pub(crate) fn apply_beams(
    store: &mut impl CellStore,
    grid: &GridFrame,
    sensor: &Pose2,
    beams: &[Beam],
    model: &LogOddsModel,
    id: u32,
) -> usize {
    let (w, h, res) = (grid.width, grid.height, grid.resolution);
    let o = grid.origin;
    // grid-relative sensor position, in f64 before the f32 kernel
    let pd = [sensor.x - o[0], sensor.y - o[1]];
    let (p, resf) = ([pd[0] as f32, pd[1] as f32], res as f32);
    let mut hits = 0;
    // hits first: they win over misses of other beams in the same scan
    for &(d, len, hit) in beams {
        if !hit {
            continue;
        }
        let ex = ((pd[0] + d[0] as f64 * len as f64) / res).floor();
        let ey = ((pd[1] + d[1] as f64 * len as f64) / res).floor();
        if ex < 0.0 || ey < 0.0 || ex >= w as f64 || ey >= h as f64 {
            continue;
        }
        hits += 1;
        store.update_once(
            ey as usize * w + ex as usize,
            id,
            model.hit,
            model.min,
            model.max,
        );
    }
    let short = model.hit_clear_gap * resf;
    for &(d, len, hit) in beams {
        let len = if hit { (len - short).max(0.0) } else { len };
        traverse_segment(w, h, resf, [0.0, 0.0], p, d, len, |i| {
            store.update_once(i, id, model.miss, model.min, model.max);
        });
    }
    hits
}

/// The bounding box of the sensor at `p` and every beam's end point.
pub(crate) fn beam_box(p: [f64; 2], beams: &[Beam]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = (p, p);
    for &(d, len, _) in beams {
        let e = [p[0] + (d[0] * len) as f64, p[1] + (d[1] * len) as f64];
        lo = [lo[0].min(e[0]), lo[1].min(e[1])];
        hi = [hi[0].max(e[0]), hi[1].max(e[1])];
    }
    (lo, hi)
}
