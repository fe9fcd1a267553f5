//! Euclidean distance field of an occupancy grid: for every cell, the distance from its centre to
//! the boundary of occupied space, truncated at `max_dist`. This is the precomputed
//! "likelihood field" of Thrun, Burgard & Fox, Probabilistic Robotics (2005), §6.4, as ROS AMCL
//! builds it (`map_update_cspace`, parameter `laser_likelihood_max_dist`).
//!
//! The exact transform is the separable lower-envelope-of-parabolas algorithm of Felzenszwalb &
//! Huttenlocher, "Distance Transforms of Sampled Functions", Theory of Computing 8 (2012), §2–3:
//! one pass along columns, one along rows, O(cells). Distances are stored quantised to one byte
//! (`max_dist / 254` per step, 255 = at or beyond `max_dist`), so a hospital floor of a million
//! cells costs one megabyte and the measurement kernels read a small lookup table per byte.
//!
//! The boundary, not the nearest occupied cell centre, is what a laser beam ends on: measured to
//! occupied cell centres, every endpoint pushed into a wall would score perfectly and the most
//! likely pose would sit about a cell too close to whatever the robot sees. So a free cell reads
//! (distance to the nearest occupied centre − half a cell), an occupied one (distance to the
//! nearest non-occupied centre − half a cell): the distance from the cell's centre to the surface,
//! half a cell on both sides of it, growing away from it in both directions.
//!
//! Local edits (a door opening) recompute only a window around the edited cells: a cell's
//! truncated distance depends only on obstacles within `max_dist` of it.

use super::grid::OccupancyGrid;
use crate::core::cache::{CacheKey, Cached, Decoder, Encoder, Malformed, MapCache};
use rayon::prelude::*;

/// Byte value meaning "at least `max_dist` from any obstacle" (also used outside the grid).
pub const FAR: u8 = 255;

#[derive(Clone, Debug)]
pub struct DistanceField {
    pub width: usize,
    pub height: usize,
    pub resolution: f64,
    pub origin: [f64; 2],
    pub max_dist: f64,
    /// Metres per quantisation step.
    pub step: f64,
    /// Row-major (row 0 at `origin`), one byte per cell.
    pub cells: Vec<u8>,
}

/// Squared distance "infinity" for the parabola envelope (finite so differences stay defined).
const INF: f64 = 1e20;

/// The 1-D squared Euclidean distance transform of `f` (Felzenszwalb & Huttenlocher 2012,
/// Algorithm DT(f)): `d[q] = min_p (q − p)² + f[p]`. `v` and `z` are scratch of length n and n+1.
fn transform_1d(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    if n == 0 {
        return;
    }
    let mut k = 0usize;
    v[0] = 0;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in 1..n {
        let qf = q as f64;
        loop {
            let p = v[k] as f64;
            let s = ((f[q] + qf * qf) - (f[v[k]] + p * p)) / (2.0 * qf - 2.0 * p);
            if s <= z[k] && k > 0 {
                k -= 1;
                continue;
            }
            if s <= z[k] {
                // k == 0: the new parabola is lower everywhere
                v[0] = q;
                z[0] = f64::NEG_INFINITY;
                z[1] = f64::INFINITY;
                break;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f64::INFINITY;
            break;
        }
    }
    k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        let qf = q as f64;
        while z[k + 1] < qf {
            k += 1;
        }
        let p = v[k] as f64;
        *dq = (qf - p) * (qf - p) + f[v[k]];
    }
}

/// Squared distances (in cells², centre to centre) of a `w` × `h` window to the nearest `true`
/// cell of `occ`; cells with no `true` cell anywhere read about 1e20. Shared with the navigation
/// costmap, which inflates obstacles by the same exact transform.
///
/// The columns' pass needs no parabolas for a binary image (two sweeps per column) and
/// writes each column contiguously, a blocked transpose turns the result into rows, and the
/// rows' pass runs in place; both passes spread their lines over rayon's threads. Every finite
/// value is identical to the bit to [`squared_distances_plain`]'s; where that one reads "no
/// `true` cell" (about 1e20), so does this one.
pub fn squared_distances(
    w: usize,
    h: usize,
    occ: impl Fn(usize, usize) -> bool + Sync,
) -> Vec<f64> {
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let scratch =
        |n: usize| move || -> RowScratch { (vec![0.0; n], vec![0; n], vec![(0, 1); n + 1]) };
    let mut columns = vec![0.0; w * h];
    columns
        .par_chunks_mut(h)
        .enumerate()
        .for_each(|(x, column)| nearest_along_column(column, |y| occ(x, y)));
    let mut g = vec![0.0; w * h];
    // rows in bands of TRANSPOSE_BLOCK, each band read from the columns block by block
    g.par_chunks_mut(w * TRANSPOSE_BLOCK)
        .enumerate()
        .for_each(|(band, rows)| {
            let y0 = band * TRANSPOSE_BLOCK;
            let band_h = rows.len() / w;
            for x0 in (0..w).step_by(TRANSPOSE_BLOCK) {
                for x in x0..(x0 + TRANSPOSE_BLOCK).min(w) {
                    let column = &columns[x * h + y0..x * h + y0 + band_h];
                    for (dy, &value) in column.iter().enumerate() {
                        rows[dy * w + x] = value;
                    }
                }
            }
        });
    drop(columns);
    g.par_chunks_mut(w)
        .for_each_init(scratch(w), |(f, v, z), row| {
            f.copy_from_slice(row);
            envelope_of_whole_numbers(f, row, v, z);
        });
    g
}

/// Scratch of the rows' pass: the input row, the envelope's parabolas and their boundaries
/// (numerator, denominator).
type RowScratch = (Vec<f64>, Vec<usize>, Vec<(i64, i64)>);

/// [`transform_1d`] for inputs that are squares of whole numbers (or ∞): the parabolas'
/// intersections are kept as exact fractions and compared by cross-multiplying, with no
/// division. Parabolas of ∞ are left out; they never win against a finite one, and a row of
/// nothing but ∞ reads ∞. Two different fractions with denominators below 2·width are at least
/// 1/(2·width)² apart, more than a double's rounding of the intersections of rows up to about
/// 4 000 cells long, so there the envelope, and every output, is the one the floating-point
/// version finds; on longer rows this one is exact where that one may round.
fn envelope_of_whole_numbers(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [(i64, i64)]) {
    let key = |p: usize| f[p] as i64 + (p * p) as i64;
    let mut k = usize::MAX; // the envelope's last parabola; MAX while it is empty
    for (q, &fq) in f.iter().enumerate() {
        if fq >= INF * 0.5 {
            continue;
        }
        if k == usize::MAX {
            k = 0;
            v[0] = q;
            continue;
        }
        let kq = key(q);
        loop {
            let p = v[k];
            let (num, den) = (kq - key(p), 2 * (q - p) as i64);
            // s <= z[k] for s = num / den, z[k] = zn / zd (both denominators positive)
            if k > 0 && num * z[k].1 <= z[k].0 * den {
                k -= 1;
                continue;
            }
            k += 1;
            v[k] = q;
            z[k] = (num, den);
            break;
        }
    }
    if k == usize::MAX {
        d.fill(INF);
        return;
    }
    let last = k;
    k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        // the next boundary z[k + 1] < q
        while k < last && z[k + 1].0 < q as i64 * z[k + 1].1 {
            k += 1;
        }
        let p = v[k];
        let dp = q.abs_diff(p) as f64;
        *dq = dp * dp + f[p];
    }
}

/// The columns' pass of a binary image: the squared distance to the nearest `true` cell along
/// the column, from one sweep down and one up. With every input 0 or ∞, this is what the lower
/// envelope of parabolas computes (the same squares of whole numbers, exactly); a column with
/// no `true` cell reads ∞ (the envelope's reads ∞ plus rounding), which stays beyond every
/// finite distance in the rows' pass.
fn nearest_along_column(column: &mut [f64], occ: impl Fn(usize) -> bool) {
    let mut last: Option<usize> = None;
    for (y, d) in column.iter_mut().enumerate() {
        if occ(y) {
            last = Some(y);
        }
        *d = last.map_or(INF, |p| ((y - p) * (y - p)) as f64);
    }
    let mut next: Option<usize> = None;
    for (y, d) in column.iter_mut().enumerate().rev() {
        if *d == 0.0 {
            next = Some(y);
        } else if let Some(n) = next {
            *d = d.min(((n - y) * (n - y)) as f64);
        }
    }
}

/// Side of the square blocks [`squared_distances`] transposes in (64 × 64 values, 32 KB).
const TRANSPOSE_BLOCK: usize = 64;

/// [`squared_distances`] as first written: one line at a time on one thread, the columns' pass
/// writing straight into the row-major result. The plain version the tests compare with.
pub fn squared_distances_plain(w: usize, h: usize, occ: impl Fn(usize, usize) -> bool) -> Vec<f64> {
    let mut g = vec![0.0; w * h];
    let n = w.max(h);
    let (mut f, mut d) = (vec![0.0; n], vec![0.0; n]);
    let (mut v, mut z) = (vec![0usize; n], vec![0.0; n + 1]);
    for x in 0..w {
        for (y, fy) in f[..h].iter_mut().enumerate() {
            *fy = if occ(x, y) { 0.0 } else { INF };
        }
        transform_1d(&f[..h], &mut d[..h], &mut v, &mut z);
        for y in 0..h {
            g[y * w + x] = d[y];
        }
    }
    for y in 0..h {
        f[..w].copy_from_slice(&g[y * w..(y + 1) * w]);
        transform_1d(&f[..w], &mut d[..w], &mut v, &mut z);
        g[y * w..(y + 1) * w].copy_from_slice(&d[..w]);
    }
    g
}

impl DistanceField {
    /// The field of `grid`'s obstacles, truncated at `max_dist` (m, > 0).
    pub fn new(grid: &OccupancyGrid, max_dist: f64) -> Self {
        let max_dist = max_dist.max(grid.resolution);
        let mut f = DistanceField {
            width: grid.width,
            height: grid.height,
            resolution: grid.resolution,
            origin: grid.origin,
            max_dist,
            step: max_dist / 254.0,
            cells: vec![FAR; grid.width * grid.height],
        };
        f.recompute(grid, 0, 0, grid.width, grid.height);
        f
    }

    /// [`DistanceField::new`] through `cache`.
    pub fn new_cached(grid: &OccupancyGrid, max_dist: f64, cache: &MapCache) -> Self {
        let key = grid
            .add_to_key(CacheKey::new::<DistanceField>())
            .f64(max_dist);
        cache.get_or_build(&key, || DistanceField::new(grid, max_dist))
    }

    /// Margin of cells whose obstacles can influence a cell's truncated distance.
    fn margin(&self) -> usize {
        (self.max_dist / self.resolution).ceil() as usize + 1
    }

    /// The byte of a cell whose centre is `d_cells_sq` (cells²) from the nearest centre of the
    /// other kind: the boundary lies half a cell before that centre.
    fn quantise(&self, d_cells_sq: f64) -> u8 {
        let d = ((d_cells_sq.sqrt() - 0.5) * self.resolution).max(0.0);
        if d >= self.max_dist {
            FAR
        } else {
            ((d / self.step).round() as u32).min(254) as u8
        }
    }

    /// Recomputes cells [c0, c1) × [r0, r1) from `grid`.
    fn recompute(&mut self, grid: &OccupancyGrid, c0: usize, r0: usize, c1: usize, r1: usize) {
        let m = self.margin();
        let (ec0, er0) = (c0.saturating_sub(m), r0.saturating_sub(m));
        let (ec1, er1) = ((c1 + m).min(self.width), (r1 + m).min(self.height));
        let ew = ec1 - ec0;
        let eh = er1 - er0;
        let to_occ = squared_distances(ew, eh, |x, y| grid.is_obstacle(ec0 + x, er0 + y));
        let to_free = squared_distances(ew, eh, |x, y| !grid.is_obstacle(ec0 + x, er0 + y));
        for r in r0..r1 {
            for c in c0..c1 {
                let k = (r - er0) * ew + c - ec0;
                let sq = if grid.is_obstacle(c, r) {
                    to_free[k]
                } else {
                    to_occ[k]
                };
                self.cells[r * self.width + c] = self.quantise(sq);
            }
        }
    }

    /// Local edit: `grid` has changed at `cells` (col, row); refreshes the affected window.
    pub fn update(&mut self, grid: &OccupancyGrid, cells: &[(usize, usize)]) {
        let Some(c0) = cells.iter().map(|c| c.0).min() else {
            return;
        };
        let c1 = cells.iter().map(|c| c.0).max().unwrap_or(c0) + 1;
        let r0 = cells.iter().map(|c| c.1).min().unwrap_or(0);
        let r1 = cells.iter().map(|c| c.1).max().unwrap_or(r0) + 1;
        let m = self.margin();
        self.recompute(
            grid,
            c0.saturating_sub(m),
            r0.saturating_sub(m),
            (c1 + m).min(self.width),
            (r1 + m).min(self.height),
        );
    }

    /// Distance (m) from world point (x, y) to the nearest boundary of occupied space (at cell
    /// precision), capped at `max_dist` (`max_dist` outside the grid).
    pub fn distance(&self, x: f64, y: f64) -> f64 {
        let c = ((x - self.origin[0]) / self.resolution).floor();
        let r = ((y - self.origin[1]) / self.resolution).floor();
        if c < 0.0 || r < 0.0 || c >= self.width as f64 || r >= self.height as f64 {
            return self.max_dist;
        }
        self.value(self.cells[r as usize * self.width + c as usize])
    }

    /// The distance (m) a stored byte stands for.
    pub fn value(&self, q: u8) -> f64 {
        if q == FAR {
            self.max_dist
        } else {
            q as f64 * self.step
        }
    }

    /// A lookup table from stored byte to `f(distance)`, for the measurement kernels.
    pub fn table(&self, f: impl Fn(f64) -> f32) -> [f32; 256] {
        std::array::from_fn(|q| f(self.value(q as u8)))
    }

    pub fn memory_bytes(&self) -> usize {
        self.cells.len()
    }
}

/// Every field.
impl Cached for DistanceField {
    const KIND: &'static str = "distance_field";
    const FORMAT: u32 = 1;

    fn encode(&self, out: &mut Encoder) {
        out.grid_frame(self.width, self.height, self.resolution, self.origin);
        out.f64(self.max_dist);
        out.f64(self.step);
        out.bytes(&self.cells);
    }

    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed> {
        let (width, height, resolution, origin) = input.grid_frame()?;
        let f = DistanceField {
            width,
            height,
            resolution,
            origin,
            max_dist: input.f64()?,
            step: input.f64()?,
            cells: input.bytes()?.to_vec(),
        };
        if Some(f.cells.len()) != f.width.checked_mul(f.height) {
            return Err(Malformed("distance field: cell count"));
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Cell;

    fn brute(grid: &OccupancyGrid, c: usize, r: usize) -> f64 {
        let inside = grid.is_obstacle(c, r);
        let mut best = f64::INFINITY;
        for y in 0..grid.height {
            for x in 0..grid.width {
                if grid.is_obstacle(x, y) != inside {
                    let d = ((x as f64 - c as f64).powi(2) + (y as f64 - r as f64).powi(2)).sqrt();
                    best = best.min(d);
                }
            }
        }
        ((best - 0.5) * grid.resolution).max(0.0)
    }

    fn fixture() -> OccupancyGrid {
        let mut g = OccupancyGrid::new(37, 23, 0.1, [-1.0, 2.0], Cell::Free);
        for c in 3..30 {
            g.set(c, 4, Cell::Occupied);
        }
        for r in 8..20 {
            g.set(25, r, Cell::Occupied);
        }
        g.set(8, 15, Cell::Occupied);
        g
    }

    #[test]
    fn matches_brute_force_within_one_step() {
        let g = fixture();
        let f = DistanceField::new(&g, 1.2);
        for r in 0..g.height {
            for c in 0..g.width {
                let want = brute(&g, c, r).min(f.max_dist);
                let got = f.value(f.cells[r * g.width + c]);
                assert!(
                    (got - want).abs() <= f.step * 0.51,
                    "({c},{r}) {got} vs {want}"
                );
            }
        }
        // world lookups: the cells on both sides of a surface read half a cell, distances grow
        // away from it; the outside reads max_dist
        for (c, r) in [(8, 15), (8, 16), (25, 12), (26, 12)] {
            let [x, y] = g.cell_center(c, r);
            assert!((f.distance(x, y) - 0.05).abs() <= f.step, "({c},{r})");
        }
        let [x, y] = g.cell_center(8, 18);
        assert!((f.distance(x, y) - 0.25).abs() <= f.step);
        assert_eq!(f.distance(-5.0, 0.0), 1.2);
    }

    #[test]
    fn local_edit_equals_rebuild() {
        let mut g = fixture();
        let mut f = DistanceField::new(&g, 0.8);
        // open a gap in the long wall and add a pillar
        let mut edits = Vec::new();
        for c in 10..14 {
            g.set(c, 4, Cell::Free);
            edits.push((c, 4));
        }
        g.set(18, 12, Cell::Occupied);
        edits.push((18, 12));
        f.update(&g, &edits);
        let fresh = DistanceField::new(&g, 0.8);
        assert_eq!(f.cells, fresh.cells);
    }

    #[test]
    fn empty_grid_is_far_everywhere() {
        let g = OccupancyGrid::new(5, 4, 0.05, [0.0, 0.0], Cell::Free);
        let f = DistanceField::new(&g, 2.0);
        assert!(f.cells.iter().all(|&q| q == FAR));
        // and a solid grid is far inside (no boundary anywhere)
        let g = OccupancyGrid::new(5, 4, 0.05, [0.0, 0.0], Cell::Occupied);
        assert!(DistanceField::new(&g, 2.0).cells.iter().all(|&q| q == FAR));
    }

    /// The parallel, transposing transform equals the plain one to the bit, on the hospital
    /// floor and on shapes whose sides are not multiples of the transpose block.
    #[test]
    fn the_fast_transform_equals_the_plain_one() {
        // found at run time (core::source): a test binary from a shared build cache may have
        // been compiled in another clone
        let hospital = crate::world::map_file::load_map(&crate::core::source::source_path(
            "assets/maps/hospital/hospital.yaml",
        ))
        .unwrap();
        let occ = |x: usize, y: usize| hospital.is_obstacle(x, y);
        let (w, h) = (hospital.width, hospital.height);
        // finite values to the bit; "nothing there" (about 1e20) where the plain one says so
        let same = |fast: &[f64], plain: &[f64]| {
            fast.len() == plain.len()
                && fast.iter().zip(plain).all(|(&a, &b)| {
                    a.to_bits() == b.to_bits() || (a >= INF * 0.5 && b >= INF * 0.5)
                })
        };
        let fast = squared_distances(w, h, occ);
        let plain = squared_distances_plain(w, h, occ);
        assert!(same(&fast, &plain));
        assert!(plain.iter().any(|&d| d > 100.0) && plain.contains(&0.0));
        for (w, h) in [(1, 1), (1, 70), (70, 1), (65, 129), (130, 63)] {
            // sparse points, then only a few columns with any (the others read 1e20 after the
            // columns' pass), then nothing at all
            let points = |x: usize, y: usize| (x * 7 + y * 13).is_multiple_of(29);
            let few_columns = |x: usize, y: usize| x % 17 == 3 && y % 5 == 1;
            let nothing = |_: usize, _: usize| false;
            assert!(same(
                &squared_distances(w, h, points),
                &squared_distances_plain(w, h, points)
            ));
            assert!(same(
                &squared_distances(w, h, few_columns),
                &squared_distances_plain(w, h, few_columns)
            ));
            assert!(same(
                &squared_distances(w, h, nothing),
                &squared_distances_plain(w, h, nothing)
            ));
        }
        assert!(squared_distances(0, 5, |_, _| true).is_empty());
    }
}
