//! The accelerated static-map structure: ONE byte per cell, the Chebyshev distance (in cells,
//! capped) from the cell to the nearest occupied cell, 0 meaning occupied. A ray inside a cell
//! whose value is k ≥ 2 can advance an L∞ distance of (k − 1) cells without meeting an obstacle
//! (every cell it can reach is within Chebyshev distance k − 1 of its cell), so it leaps across
//! open space — sphere tracing with a conservative metric — and near obstacles it walks cell by
//! cell exactly like Amanatides & Woo. Crossing times are computed from the ray's origin, so hits
//! agree with [`super::cast_dda`]. The walk itself is `super::leap`.
//!
//! Memory layout: cells are stored in 8 × 8 tiles of 64 bytes (one cache line), so the cells
//! around a ray share few cache lines; measured, memory latency — not arithmetic — dominates
//! random rays on a row-major map.

use super::leap::{Bounds, InCells, Lane, Single};
use super::sweep::{Faces, TILE as FACE_TILE};
use crate::core::cache::{CacheKey, Cached, Decoder, Encoder, Malformed, MapCache};

/// Distances are capped, so an edit only changes the field within this many cells.
const CAP: u8 = 120;
const TILE_SHIFT: usize = 3;
const TILE: usize = 1 << TILE_SHIFT;
/// Bytes after the field's last cell, so a 4-byte gather at any cell stays inside it.
const PAD: usize = 3;

/// Whether streams of rays on a padded field of `len` bytes take the AVX2 kernel.
fn use_avx2(len: usize) -> bool {
    crate::core::cpu::has_avx2() && len <= i32::MAX as usize
}

#[derive(Clone)]
pub struct RayMap {
    w: usize,
    h: usize,
    res: f32,
    origin: [f32; 2],
    /// Tiles per row.
    tw: usize,
    /// The grid for the walks.
    bounds: Bounds,
    /// The field in tiled order, then [`PAD`] bytes.
    dist: Vec<u8>,
    /// Streams of rays use the AVX2 kernel (detected, and the field fits `i32` indices).
    avx2: bool,
    /// Boundary faces per tile, for whole scans.
    faces: Faces,
}

impl RayMap {
    /// The ray map of an occupancy grid's obstacles.
    pub fn from_grid(grid: &crate::world::OccupancyGrid) -> Self {
        RayMap::new(
            grid.width,
            grid.height,
            grid.resolution as f32,
            [grid.origin[0] as f32, grid.origin[1] as f32],
            &grid.obstacles(),
        )
    }

    /// [`RayMap::from_grid`] through `cache`.
    pub fn from_grid_cached(grid: &crate::world::OccupancyGrid, cache: &MapCache) -> Self {
        let key = grid.add_to_key(CacheKey::new::<RayMap>());
        cache.get_or_build(&key, || RayMap::from_grid(grid))
    }

    /// [`RayMap::from_grid_cached`], the copy other worlds of a sharing cache hold if any
    /// ([`MapCache::get_or_build_shared`]).
    pub fn from_grid_shared(
        grid: &crate::world::OccupancyGrid,
        cache: &MapCache,
    ) -> std::sync::Arc<Self> {
        let key = grid.add_to_key(CacheKey::new::<RayMap>());
        cache.get_or_build_shared(&key, || RayMap::from_grid(grid))
    }

    pub fn new(
        width: usize,
        height: usize,
        resolution: f32,
        origin: [f32; 2],
        occupied: &[bool],
    ) -> RayMap {
        assert_eq!(occupied.len(), width * height, "occupancy size");
        let tw = width.div_ceil(TILE).max(1);
        let th = height.div_ceil(TILE).max(1);
        let mut m = RayMap {
            w: width,
            h: height,
            res: resolution,
            origin,
            tw,
            bounds: Bounds::new(width, height, resolution),
            dist: vec![CAP; tw * th * TILE * TILE + PAD],
            avx2: use_avx2(tw * th * TILE * TILE + PAD),
            faces: Faces::new(0, 0, resolution, &|_, _| false),
        };
        for r in 0..height {
            for c in 0..width {
                if occupied[r * width + c] {
                    let i = m.idx(c, r);
                    m.dist[i] = 0;
                }
            }
        }
        m.update(0, 0, width, height);
        m.faces = Faces::new(width, height, resolution, &|c, r| m.occupied_at(c, r));
        m
    }

    /// Occupancy with signed indices; outside the grid is free.
    fn occupied_at(&self, c: i64, r: i64) -> bool {
        c >= 0
            && r >= 0
            && (c as usize) < self.w
            && (r as usize) < self.h
            && self.dist[self.idx(c as usize, r as usize)] == 0
    }

    #[inline(always)]
    pub(super) fn idx(&self, c: usize, r: usize) -> usize {
        (((r >> TILE_SHIFT) * self.tw + (c >> TILE_SHIFT)) << (2 * TILE_SHIFT))
            + ((r & (TILE - 1)) << TILE_SHIFT)
            + (c & (TILE - 1))
    }

    /// The distance field in tiled order (see [`RayMap::idx`]).
    pub(super) fn dist(&self) -> &[u8] {
        &self.dist[..self.dist.len() - PAD]
    }

    /// The field and its padding, for gathers.
    pub(super) fn dist_padded(&self) -> &[u8] {
        &self.dist
    }

    pub(super) fn tiles_per_row(&self) -> usize {
        self.tw
    }

    /// Whether streams of rays use the AVX2 kernel.
    pub(super) fn stream_avx2(&self) -> bool {
        self.avx2
    }

    /// The same map with streams on the scalar kernel (to compare the two).
    #[cfg(test)]
    pub(super) fn without_avx2(mut self) -> Self {
        self.avx2 = false;
        self
    }

    pub fn width(&self) -> usize {
        self.w
    }
    pub fn height(&self) -> usize {
        self.h
    }
    pub fn resolution(&self) -> f32 {
        self.res
    }
    pub fn origin(&self) -> [f32; 2] {
        self.origin
    }

    pub fn is_occupied(&self, col: usize, row: usize) -> bool {
        self.dist[self.idx(col, row)] == 0
    }

    /// Bytes used by the structure.
    pub fn memory_bytes(&self) -> usize {
        self.dist.len() + self.faces.memory_bytes()
    }

    /// Local edit: sets cells and refreshes the distance field around them only.
    pub fn set_cells(&mut self, cells: &[(usize, usize, bool)]) {
        let (mut c0, mut r0, mut c1, mut r1) = (usize::MAX, usize::MAX, 0, 0);
        for &(c, r, o) in cells {
            if c >= self.w || r >= self.h || self.is_occupied(c, r) == o {
                continue;
            }
            let i = self.idx(c, r);
            self.dist[i] = if o { 0 } else { CAP };
            c0 = c0.min(c);
            r0 = r0.min(r);
            c1 = c1.max(c + 1);
            r1 = r1.max(r + 1);
        }
        if c0 < c1 {
            // faces: the edited cells' tiles and their neighbours (a cell's faces look into them)
            let (ftw, fth) = self.faces.tile_counts();
            let tx0 = c0.saturating_sub(1) / FACE_TILE;
            let ty0 = r0.saturating_sub(1) / FACE_TILE;
            let tx1 = (c1 / FACE_TILE + 1).min(ftw);
            let ty1 = (r1 / FACE_TILE + 1).min(fth);
            let mut faces =
                std::mem::replace(&mut self.faces, Faces::new(0, 0, self.res, &|_, _| false));
            for ty in ty0..ty1 {
                for tx in tx0..tx1 {
                    faces.rebuild_tile(tx, ty, self.w, self.h, &|c, r| self.occupied_at(c, r));
                }
            }
            self.faces = faces;
            let cap = CAP as usize;
            self.update(
                c0.saturating_sub(cap),
                r0.saturating_sub(cap),
                (c1 + cap).min(self.w),
                (r1 + cap).min(self.h),
            );
        }
    }

    /// Recomputes distances on cells [c0, c1) × [r0, r1): a two-pass Chebyshev distance
    /// transform over the window grown by CAP + 1 (every obstacle that can matter lies in it).
    fn update(&mut self, c0: usize, r0: usize, c1: usize, r1: usize) {
        let g = CAP as usize + 1;
        let (ec0, er0) = (c0.saturating_sub(g), r0.saturating_sub(g));
        let (ec1, er1) = ((c1 + g).min(self.w), (r1 + g).min(self.h));
        let (ew, eh) = (ec1 - ec0, er1 - er0);
        let mut d = vec![CAP; ew * eh];
        for y in 0..eh {
            for x in 0..ew {
                if self.dist[self.idx(x + ec0, y + er0)] == 0 {
                    d[y * ew + x] = 0;
                }
            }
        }
        for y in 0..eh {
            for x in 0..ew {
                let mut v = d[y * ew + x];
                if x > 0 {
                    v = v.min(d[y * ew + x - 1] + 1);
                }
                if y > 0 {
                    let r = (y - 1) * ew;
                    v = v.min(d[r + x] + 1);
                    if x > 0 {
                        v = v.min(d[r + x - 1] + 1);
                    }
                    if x + 1 < ew {
                        v = v.min(d[r + x + 1] + 1);
                    }
                }
                d[y * ew + x] = v.min(CAP);
            }
        }
        for y in (0..eh).rev() {
            for x in (0..ew).rev() {
                let mut v = d[y * ew + x];
                if x + 1 < ew {
                    v = v.min(d[y * ew + x + 1] + 1);
                }
                if y + 1 < eh {
                    let r = (y + 1) * ew;
                    v = v.min(d[r + x] + 1);
                    if x > 0 {
                        v = v.min(d[r + x - 1] + 1);
                    }
                    if x + 1 < ew {
                        v = v.min(d[r + x + 1] + 1);
                    }
                }
                d[y * ew + x] = v.min(CAP);
            }
        }
        for y in r0..r1 {
            for x in c0..c1 {
                let i = self.idx(x, y);
                self.dist[i] = d[(y - er0) * ew + x - ec0];
            }
        }
    }

    /// One ray (random access). Its walk is a chain of dependent loads; with many rays at hand,
    /// [`RayMap::cast_many`] overlaps their walks and is several times faster per ray.
    #[inline]
    pub fn cast(&self, p: [f32; 2], angle: f32, max_range: f32) -> f32 {
        let b = self.bounds;
        let (gx, gy) = (p[0] - self.origin[0], p[1] - self.origin[1]);
        // from inside the grid the first cell needs no direction (it is `Lane::new`'s at t = 0),
        // so its load overlaps sin_cos
        let inside = gx >= 0.0 && gy >= 0.0 && gx < b.wf && gy < b.hf;
        let cx = ((gx * b.inv_res) as i32).clamp(0, b.w - 1);
        let cy = ((gy * b.inv_res) as i32).clamp(0, b.h - 1);
        let (dy, dx) = angle.sin_cos();
        if inside && let Some(ray) = Single::new(gx, gy, dx, dy, &b) {
            return self.walk(&ray, cx, cy, 0.0, &b, max_range);
        }
        self.cast_dir(p, dx, dy, max_range)
    }

    fn cast_dir(&self, p: [f32; 2], dx: f32, dy: f32, max_range: f32) -> f32 {
        let b = self.bounds;
        let (gx, gy) = (p[0] - self.origin[0], p[1] - self.origin[1]);
        let lane = match Lane::start(gx, gy, dx, dy, &b, max_range) {
            Ok(lane) => lane,
            Err(answer) => return answer,
        };
        match Single::new(gx, gy, dx, dy, &b) {
            Some(ray) => self.walk(&ray, lane.cx, lane.cy, lane.t, &b, max_range),
            None => self.walk_plain(lane, &b, max_range),
        }
    }

    /// The walk of [`Single`] from cell (cx, cy), entered at `t`.
    #[inline(always)]
    fn walk(
        &self,
        ray: &Single,
        mut cx: i32,
        mut cy: i32,
        mut t: f32,
        b: &Bounds,
        max_range: f32,
    ) -> f32 {
        loop {
            let k = self.dist[self.idx(cx as usize, cy as usize)];
            if k == 0 {
                return t;
            }
            // a branch on purpose: predicted, the cell step next to a wall starts before the load
            // is back
            (cx, cy, t) = if k == 1 {
                ray.step(cx, cy, t)
            } else {
                ray.exit_square(k as i32, cx, cy, t)
            };
            if t > max_range || cx as u32 >= b.w as u32 || cy as u32 >= b.h as u32 {
                return f32::INFINITY;
            }
        }
    }

    /// The plain walk ([`Lane::exit_square`]): rays along an axis, and the reference of the tests.
    fn walk_plain(&self, mut lane: Lane, b: &Bounds, max_range: f32) -> f32 {
        let cells = InCells::new(&lane, b);
        loop {
            let k = self.dist[self.idx(lane.cx as usize, lane.cy as usize)];
            if k == 0 {
                return lane.t;
            }
            if !lane.exit_square(k, &cells, b, max_range) {
                return f32::INFINITY;
            }
        }
    }

    /// [`RayMap::cast`] by the plain walk alone.
    #[cfg(test)]
    pub(super) fn cast_plain(&self, p: [f32; 2], angle: f32, max_range: f32) -> f32 {
        let (dy, dx) = angle.sin_cos();
        let b = self.bounds;
        let (gx, gy) = (p[0] - self.origin[0], p[1] - self.origin[1]);
        match Lane::start(gx, gy, dx, dy, &b, max_range) {
            Ok(lane) => self.walk_plain(lane, &b, max_range),
            Err(answer) => answer,
        }
    }

    /// A whole scan from one origin: beam k at `start + k·increment`. From a free cell inside the
    /// grid this is the angular sweep over boundary faces; otherwise ray by ray.
    pub fn cast_scan(
        &self,
        p: [f32; 2],
        start: f32,
        increment: f32,
        max_range: f32,
        out: &mut [f32],
    ) {
        let gx = p[0] - self.origin[0];
        let gy = p[1] - self.origin[1];
        let inside = gx >= 0.0
            && gy >= 0.0
            && gx < self.w as f32 * self.res
            && gy < self.h as f32 * self.res;
        if inside {
            let c = ((gx / self.res) as usize).min(self.w - 1);
            let r = ((gy / self.res) as usize).min(self.h - 1);
            if self.dist[self.idx(c, r)] == 0 {
                out.iter_mut().for_each(|o| *o = 0.0);
                return;
            }
            if max_range <= self.faces.reach() {
                self.faces.scan(gx, gy, start, increment, max_range, out);
                return;
            }
        }
        self.cast_scan_rays(p, start, increment, max_range, out);
    }

    /// A whole scan ray by ray (the distance-field walk for every beam, several at a time).
    pub fn cast_scan_rays(
        &self,
        p: [f32; 2],
        start: f32,
        increment: f32,
        max_range: f32,
        out: &mut [f32],
    ) {
        let n = out.len();
        self.cast_stream(
            n,
            |k| {
                let (dy, dx) = (start + k as f32 * increment).sin_cos();
                (p, dx, dy)
            },
            max_range,
            out,
        );
    }
}

/// The field and faces; the walks' bounds and the kernel choice are derived again when read.
impl Cached for RayMap {
    const KIND: &'static str = "raymap";
    const FORMAT: u32 = 1;

    fn encode(&self, out: &mut Encoder) {
        out.usize(self.w);
        out.usize(self.h);
        out.f32(self.res);
        out.f32(self.origin[0]);
        out.f32(self.origin[1]);
        out.bytes(&self.dist);
        self.faces.encode(out);
    }

    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed> {
        let (w, h) = (input.usize()?, input.usize()?);
        let res = input.f32()?;
        let origin = [input.f32()?, input.f32()?];
        let dist = input.bytes()?.to_vec();
        let faces = Faces::decode(input)?;
        let tw = w.div_ceil(TILE).max(1);
        let th = h.div_ceil(TILE).max(1);
        let len = tw
            .checked_mul(th)
            .and_then(|n| n.checked_mul(TILE * TILE))
            .and_then(|n| n.checked_add(PAD));
        if len != Some(dist.len()) {
            return Err(Malformed("ray map: field size"));
        }
        if faces.tile_counts() != (w.div_ceil(FACE_TILE).max(1), h.div_ceil(FACE_TILE).max(1)) {
            return Err(Malformed("ray map: face tiles"));
        }
        Ok(RayMap {
            w,
            h,
            res,
            origin,
            tw,
            bounds: Bounds::new(w, h, res),
            avx2: use_avx2(dist.len()),
            dist,
            faces,
        })
    }
}
