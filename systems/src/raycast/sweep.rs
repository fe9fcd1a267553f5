//! Whole scans by angular rasterisation ("z-buffering" in polar coordinates). The boundary faces
//! of occupied cells are precomputed per 64 × 64-cell tile, merged along straight runs, grouped by
//! the side they face and sorted by position. A scan visits the tiles within range front to back
//! and skips those that the beams already hitting nearer cannot see past (tested against per-block
//! maxima of the ranges so far, 16 beams a block). In a visited tile the faces turned towards the
//! sensor are a prefix or suffix of each group; they are gathered and mapped to the beam indices
//! they subtend four at a time (branch-free, so the arctangents vectorise; the tiles' bounding
//! corners likewise), and every beam keeps the nearest exact ray–face intersection. The first
//! occupied cell a ray enters is entered through such a face, so results agree with the cell walk
//! of [`super::cast_dda`]. Cost grows with the faces actually visible, not with the length of the
//! rays.

use super::fan::{Fan, MARGIN, atan2_approx};
use crate::core::cache::{Decoder, Encoder, Malformed};
use std::f32::consts::TAU;

/// Cells per side of a tile. Faces are merged along straight runs within a tile, and a tile is
/// the unit of the occlusion test: measured on the hospital (random poses, 20 m), 64 beat 32 and
/// 128 for 180- and 1081-beam scans, and a second level of 16-cell tiles inside did not pay for
/// its occlusion tests.
pub(crate) const TILE: usize = 64;
/// Offsets are tabulated to this many tiles (64 × 64 cells, 205 m at 5 cm).
const RADIUS: i32 = 64;

/// Beam k's direction (dx, dy) and the reciprocals (1/dx, 1/dy) into `dirs[k]`, for beams at
/// `start + k·inc`: four interleaved rotation recurrences (by 4·inc, so they do not wait on each
/// other), re-anchored on sin/cos every 64 beams.
fn beam_dirs(start: f32, inc: f32, dirs: &mut [[f32; 4]]) {
    let (si, ci) = inc.sin_cos();
    let (s4, c4) = (4.0 * inc).sin_cos();
    for (c, chunk) in dirs.chunks_mut(64).enumerate() {
        let (mut xs, mut ys) = ([0.0f32; 4], [0.0f32; 4]);
        (ys[0], xs[0]) = (start + (c * 64) as f32 * inc).sin_cos();
        for i in 1..4 {
            xs[i] = xs[i - 1] * ci - ys[i - 1] * si;
            ys[i] = xs[i - 1] * si + ys[i - 1] * ci;
        }
        for quad in chunk.chunks_mut(4) {
            for ((d, &dx), &dy) in quad.iter_mut().zip(&xs).zip(&ys) {
                // one division for both reciprocals, unless a component is (nearly) zero;
                // both ways computed and one selected, so the four beams vectorise
                let p = dx * dy;
                let r = 1.0 / p;
                let recip = |v: f32| {
                    if v.abs() < 1e-12 {
                        f32::INFINITY
                    } else {
                        1.0 / v
                    }
                };
                let (rx, ry) = (recip(dx), recip(dy));
                let shared = p.abs() > 1e-12;
                *d = [
                    dx,
                    dy,
                    if shared { dy * r } else { rx },
                    if shared { dx * r } else { ry },
                ];
            }
            for i in 0..4 {
                let nx = xs[i] * c4 - ys[i] * s4;
                ys[i] = xs[i] * s4 + ys[i] * c4;
                xs[i] = nx;
            }
        }
    }
}

/// Beams per block of the occlusion maxima.
const BLOCK: usize = 16;

/// Per-thread scratch of a scan: beam directions with their reciprocals and, per block of
/// `BLOCK` beams, an upper bound of their ranges (exact after a refresh, stale-high in between:
/// never too low).
#[derive(Default)]
struct Scratch {
    dirs: Vec<[f32; 4]>,
    bmax: Vec<f32>,
    front: Front,
}

/// The front faces of one tile, gathered from the four facings: both ends relative to the sensor
/// in counter-clockwise order (structure of arrays in chunks of four, for the arctangents), and
/// per face its facing and its line.
#[derive(Default)]
struct Front {
    ends: Vec<[[f32; 4]; 4]>,
    faces: Vec<(bool, f32, f32, f32)>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Whether any beam in the arc [lo, lo + width] has a range beyond `near`: blocks whose bound is
/// not beyond are skipped whole, the others are checked beam by beam.
fn any_beyond(fan: &Fan, out: &[f32], bmax: &[f32], lo: f32, width: f32, near: f32) -> bool {
    fan.ranges(lo, width).into_iter().flatten().any(|(k0, k1)| {
        (k0 / BLOCK..=k1 / BLOCK).any(|b| {
            bmax[b] > near
                && out[(b * BLOCK).max(k0)..=(b * BLOCK + BLOCK - 1).min(k1)]
                    .iter()
                    .any(|&x| x > near)
        })
    })
}

/// A tile that may be visible: its index, its centre's offset from the sensor's tile centre
/// (`d`, for the early end), the distance from the sensor to its nearest point, and the two
/// corners that bound it as seen from the sensor (counter-clockwise: start x, y, end x, y);
/// `inside` when the sensor is in it.
#[derive(Clone, Copy, Default)]
struct Candidate {
    tile: usize,
    d: f32,
    near: f32,
    ends: [f32; 4],
    inside: bool,
}

/// The nearest distance and bounding corners of the tile centred at (cx, cy) from the sensor,
/// half side `h`.
#[inline]
fn candidate(tile: usize, d: f32, cx: f32, cy: f32, h: f32) -> Candidate {
    let (qx, qy) = (cx.abs() - h, cy.abs() - h);
    let inside = qx <= 0.0 && qy <= 0.0;
    let near = (qx.max(0.0).powi(2) + qy.max(0.0).powi(2)).sqrt();
    let (x0, x1, y0, y1) = (cx - h, cx + h, cy - h, cy + h);
    // the corner the arc starts from (counter-clockwise) and the one it ends at
    let ((sx, sy), (ex, ey)) = if x0 > 0.0 {
        if y0 >= 0.0 {
            ((x1, y0), (x0, y1))
        } else if y1 <= 0.0 {
            ((x0, y0), (x1, y1))
        } else {
            ((x0, y0), (x0, y1))
        }
    } else if x1 < 0.0 {
        if y0 >= 0.0 {
            ((x1, y1), (x0, y0))
        } else if y1 <= 0.0 {
            ((x0, y1), (x1, y0))
        } else {
            ((x1, y1), (x1, y0))
        }
    } else if y0 > 0.0 {
        ((x1, y0), (x0, y0))
    } else {
        ((x0, y1), (x1, y1))
    };
    Candidate {
        tile,
        d,
        near,
        ends: [sx, sy, ex, ey],
        inside,
    }
}

/// An axis-aligned face in grid-relative metres: the line `axis = at` between `lo` and `hi`
/// (the axis and the side it faces are those of the group it is stored in, see [`Tile`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Face {
    at: f32,
    lo: f32,
    hi: f32,
}

/// The four facings: 0: x = at, facing +x; 1: facing −x; 2: y = at, facing +y; 3: facing −y.
const FACINGS: usize = 4;

/// The faces of one tile, grouped by facing and sorted by `at` within a group, so the faces that
/// face the sensor are a prefix (facing +) or suffix (facing −) of their group: back faces cost
/// nothing and the loops have no unpredictable branch.
#[derive(Clone, Default)]
struct Tile {
    faces: Vec<Face>,
    /// Faces of facing j are `faces[groups[j]..groups[j + 1]]`.
    groups: [u32; FACINGS + 1],
}

#[derive(Clone)]
pub(crate) struct Faces {
    tw: usize,
    th: usize,
    res: f32,
    tiles: Vec<Tile>,
    /// Tile offsets sorted by distance (for front-to-back visits).
    offsets: Vec<(i16, i16, f32)>,
}

impl Faces {
    pub fn new(w: usize, h: usize, res: f32, occ: &dyn Fn(i64, i64) -> bool) -> Faces {
        let tw = w.div_ceil(TILE).max(1);
        let th = h.div_ceil(TILE).max(1);
        let mut f = Faces {
            tw,
            th,
            res,
            tiles: vec![Tile::default(); tw * th],
            offsets: Vec::new(),
        };
        for ty in 0..th {
            for tx in 0..tw {
                f.rebuild_tile(tx, ty, w, h, occ);
            }
        }
        let r = RADIUS;
        let size = TILE as f32 * res;
        for dy in -r..=r {
            for dx in -r..=r {
                let d = ((dx * dx + dy * dy) as f32).sqrt() * size;
                f.offsets.push((dx as i16, dy as i16, d));
            }
        }
        f.offsets.sort_by(|a, b| a.2.total_cmp(&b.2));
        f
    }

    /// The longest range a sweep handles: every tile that can hold a point within it (centre
    /// up to range + one tile diagonal away) must be in the offset table.
    pub fn reach(&self) -> f32 {
        (RADIUS - 2) as f32 * TILE as f32 * self.res
    }

    /// Re-extracts the faces of the occupied cells of one tile.
    pub fn rebuild_tile(
        &mut self,
        tx: usize,
        ty: usize,
        w: usize,
        h: usize,
        occ: &dyn Fn(i64, i64) -> bool,
    ) {
        let res = self.res;
        let (c0, r0) = ((tx * TILE) as i64, (ty * TILE) as i64);
        let (c1, r1) = (
            ((tx + 1) * TILE).min(w) as i64,
            ((ty + 1) * TILE).min(h) as i64,
        );
        let mut groups: [Vec<Face>; FACINGS] = Default::default();
        // vertical faces: for each column boundary side, runs along y
        for c in c0..c1 {
            for (kind, nc) in [(0usize, c + 1), (1, c - 1)] {
                let mut run: Option<i64> = None;
                for r in r0..=r1 {
                    let on = r < r1 && occ(c, r) && !occ(nc, r);
                    match (on, run) {
                        (true, None) => run = Some(r),
                        (false, Some(s)) => {
                            let x = if kind == 0 { c + 1 } else { c } as f32 * res;
                            groups[kind].push(Face {
                                at: x,
                                lo: s as f32 * res,
                                hi: r as f32 * res,
                            });
                            run = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        for r in r0..r1 {
            for (kind, nr) in [(2usize, r + 1), (3, r - 1)] {
                let mut run: Option<i64> = None;
                for c in c0..=c1 {
                    let on = c < c1 && occ(c, r) && !occ(c, nr);
                    match (on, run) {
                        (true, None) => run = Some(c),
                        (false, Some(s)) => {
                            let y = if kind == 2 { r + 1 } else { r } as f32 * res;
                            groups[kind].push(Face {
                                at: y,
                                lo: s as f32 * res,
                                hi: c as f32 * res,
                            });
                            run = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        let tile = &mut self.tiles[ty * self.tw + tx];
        tile.faces.clear();
        for (j, g) in groups.iter_mut().enumerate() {
            g.sort_by(|a, b| a.at.total_cmp(&b.at));
            tile.groups[j] = tile.faces.len() as u32;
            tile.faces.extend_from_slice(g);
        }
        tile.groups[FACINGS] = tile.faces.len() as u32;
    }

    pub fn tile_counts(&self) -> (usize, usize) {
        (self.tw, self.th)
    }

    /// Every field, for the on-disk cache ([`crate::core::cache`]).
    pub fn encode(&self, out: &mut Encoder) {
        out.usize(self.tw);
        out.usize(self.th);
        out.f32(self.res);
        out.usize(self.tiles.len());
        for t in &self.tiles {
            t.groups.iter().for_each(|&g| out.u32(g));
            let flat: Vec<f32> = t.faces.iter().flat_map(|f| [f.at, f.lo, f.hi]).collect();
            out.f32s(&flat);
        }
        out.usize(self.offsets.len());
        for &(dx, dy, d) in &self.offsets {
            out.u32(dx as u16 as u32 | (dy as u16 as u32) << 16);
            out.f32(d);
        }
    }

    /// What [`Faces::encode`] wrote.
    pub fn decode(input: &mut Decoder<'_>) -> Result<Faces, Malformed> {
        let (tw, th) = (input.usize()?, input.usize()?);
        let res = input.f32()?;
        let n = input.count(4 * (FACINGS + 1) + 8)?;
        if Some(n) != tw.checked_mul(th) {
            return Err(Malformed("faces: tile count"));
        }
        let mut tiles = Vec::with_capacity(n);
        for _ in 0..n {
            let mut groups = [0u32; FACINGS + 1];
            for g in &mut groups {
                *g = input.u32()?;
            }
            let flat = input.f32s()?;
            if flat.len() % 3 != 0 {
                return Err(Malformed("faces: a face's fields"));
            }
            let faces: Vec<Face> = flat
                .chunks_exact(3)
                .map(|f| Face {
                    at: f[0],
                    lo: f[1],
                    hi: f[2],
                })
                .collect();
            let ordered = groups[0] == 0 && groups.windows(2).all(|g| g[0] <= g[1]);
            if !ordered || groups[FACINGS] as usize != faces.len() {
                return Err(Malformed("faces: groups"));
            }
            tiles.push(Tile { faces, groups });
        }
        let m = input.count(8)?;
        let mut offsets = Vec::with_capacity(m);
        for _ in 0..m {
            let packed = input.u32()?;
            let d = input.f32()?;
            offsets.push((packed as u16 as i16, (packed >> 16) as u16 as i16, d));
        }
        Ok(Faces {
            tw,
            th,
            res,
            tiles,
            offsets,
        })
    }

    pub fn memory_bytes(&self) -> usize {
        self.tiles
            .iter()
            .map(|t| t.faces.capacity() * std::mem::size_of::<Face>())
            .sum::<usize>()
            + self.tiles.len() * std::mem::size_of::<Tile>()
            + self.offsets.len() * 8
    }

    /// The scan from grid-relative (gx, gy), origin known to be in a free cell and `max_range`
    /// within [`Faces::reach`]: `out[k]` = range of beam k, +Inf beyond `max_range`.
    pub fn scan(&self, gx: f32, gy: f32, start: f32, inc: f32, max_range: f32, out: &mut [f32]) {
        SCRATCH.with_borrow_mut(|s| self.scan_with(s, gx, gy, start, inc, max_range, out));
    }

    #[allow(clippy::too_many_arguments)]
    fn scan_with(
        &self,
        scratch: &mut Scratch,
        gx: f32,
        gy: f32,
        start: f32,
        inc: f32,
        max_range: f32,
        out: &mut [f32],
    ) {
        let n = out.len();
        out.iter_mut().for_each(|o| *o = f32::INFINITY);
        if n == 0 {
            return;
        }
        let fan = Fan::new(start, inc, n);
        let Scratch { dirs, bmax, front } = scratch;
        bmax.clear();
        bmax.resize(n.div_ceil(BLOCK), f32::INFINITY);
        dirs.resize(n, [0.0; 4]);
        beam_dirs(start, inc, dirs);
        let tsize = TILE as f32 * self.res;
        let half_diag = tsize * std::f32::consts::FRAC_1_SQRT_2;
        let (ptx, pty) = ((gx / tsize) as i32, (gy / tsize) as i32);
        let beams = Beams {
            gx,
            gy,
            start: super::fan::wrap_tau(start),
            inv_inc: 1.0 / inc,
            n,
        };
        // a scan of at most 180° sees nothing wholly behind the line through the sensor across
        // its central direction
        let (my, mx) = (start + fan.span() / 2.0).sin_cos();
        let half_plane = fan.span() <= std::f32::consts::PI + 1e-6;
        // tiles are visited front to back: once every beam has hit something nearer than the
        // next ones, the scan is complete
        let mut horizon = max_range;
        // tiles that pass the cheap tests are taken four at a time, so that the arctangents of
        // their bounding corners are computed together; each is then tested for occlusion and
        // drawn in turn, front to back as before
        let mut offsets = self.offsets.iter();
        let mut batch = [Candidate::default(); 4];
        let mut more = true;
        'scan: while more {
            let mut m = 0;
            while m < 4 {
                let Some(&(ox, oy, d)) = offsets.next() else {
                    more = false;
                    break;
                };
                if d - 2.0 * half_diag > horizon {
                    more = false;
                    break;
                }
                let (tx, ty) = (ptx + ox as i32, pty + oy as i32);
                if tx < 0 || ty < 0 || tx >= self.tw as i32 || ty >= self.th as i32 {
                    continue;
                }
                let t = ty as usize * self.tw + tx as usize;
                if self.tiles[t].faces.is_empty() {
                    continue;
                }
                let cx = (tx as f32 + 0.5) * tsize - gx;
                let cy = (ty as f32 + 0.5) * tsize - gy;
                if half_plane && cx * mx + cy * my < -half_diag {
                    continue;
                }
                let c = candidate(t, d, cx, cy, tsize / 2.0);
                if c.inside || c.near <= horizon {
                    batch[m] = c;
                    m += 1;
                }
            }
            let mut arcs = [[0.0f32; 2]; 4];
            for (a, c) in arcs.iter_mut().zip(&batch) {
                let [sx, sy, ex, ey] = c.ends;
                let first = atan2_approx(sy, sx);
                let mut width = atan2_approx(ey, ex) - first;
                width += if width < 0.0 { TAU } else { 0.0 };
                *a = [first, width];
            }
            for (c, &[first, width]) in batch[..m].iter().zip(&arcs) {
                // a tile whose nearest point lies beyond the longest range any beam still has
                // is hidden, and so is every later one once their centres are that far
                if c.d - 2.0 * half_diag > horizon {
                    break 'scan;
                }
                // a tile is hidden if every beam that can cross it (those between the two
                // corners that bound it) already hit something nearer; the one holding the
                // sensor is always visible
                if !c.inside
                    && (c.near > horizon
                        || !any_beyond(
                            &fan,
                            out,
                            bmax,
                            first - MARGIN,
                            width + 2.0 * MARGIN,
                            c.near,
                        ))
                {
                    continue;
                }
                let tile = &self.tiles[c.tile];
                let (mut k0, mut k1) = (usize::MAX, 0);
                let group =
                    |j: usize| &tile.faces[tile.groups[j] as usize..tile.groups[j + 1] as usize];
                // front faces: x = at facing +x when at < gx, facing −x when at > gx (y alike)
                let f0 = group(0);
                let f1 = group(1);
                let f2 = group(2);
                let f3 = group(3);
                let f0 = &f0[..f0.partition_point(|f| f.at < gx)];
                let f1 = &f1[f1.partition_point(|f| f.at <= gx)..];
                let f2 = &f2[..f2.partition_point(|f| f.at < gy)];
                let f3 = &f3[f3.partition_point(|f| f.at <= gy)..];
                beams.gather(front, [f0, f1, f2, f3]);
                beams.draw(front, dirs, out, &mut k0, &mut k1);
                if k0 <= k1 {
                    // the touched beams' blocks get exact bounds again
                    for b in k0 / BLOCK..=k1 / BLOCK {
                        let end = (b * BLOCK + BLOCK).min(n);
                        bmax[b] = out[b * BLOCK..end].iter().fold(0.0f32, |m, &x| m.max(x));
                    }
                    horizon = bmax.iter().fold(0.0f32, |m, &r| m.max(r)).min(max_range);
                }
            }
        }
        for o in out.iter_mut() {
            *o = if *o > max_range { f32::INFINITY } else { *o };
        }
    }
}

/// What drawing a face needs of the scan: the sensor (grid-relative), the fan's first angle in
/// [0, 2π) and the reciprocal of its increment, the number of beams.
struct Beams {
    gx: f32,
    gy: f32,
    start: f32,
    inv_inc: f32,
    n: usize,
}

impl Beams {
    /// Gathers the front faces of a tile, facing by facing (0: x = at facing +x, 1: facing −x,
    /// 2: y = at facing +y, 3: facing −y), relative to the sensor.
    #[inline]
    fn gather(&self, front: &mut Front, groups: [&[Face]; FACINGS]) {
        front.faces.clear();
        let m: usize = groups.iter().map(|g| g.len()).sum();
        front.ends.clear();
        front
            .ends
            .resize(m.div_ceil(4), [[1.0; 4], [0.0; 4], [1.0; 4], [0.0; 4]]);
        let mut i = 0;
        for (j, faces) in groups.into_iter().enumerate() {
            let vertical = j < 2;
            let (g_at, g_along) = if vertical {
                (self.gx, self.gy)
            } else {
                (self.gy, self.gx)
            };
            for f in faces {
                let (p_at, p_lo, p_hi) = (f.at - g_at, f.lo - g_along, f.hi - g_along);
                // counter-clockwise, the face runs from its lo end to its hi end when it is to
                // the right of the sensor (facing −x) or below it (facing +y), from hi to lo
                // otherwise
                let (a, b) = if j == 1 || j == 2 {
                    (p_lo, p_hi)
                } else {
                    (p_hi, p_lo)
                };
                let ((ax, ay), (bx, by)) = if vertical {
                    ((p_at, a), (p_at, b))
                } else {
                    ((a, p_at), (b, p_at))
                };
                let e = &mut front.ends[i / 4];
                e[0][i % 4] = ax;
                e[1][i % 4] = ay;
                e[2][i % 4] = bx;
                e[3][i % 4] = by;
                front.faces.push((vertical, p_at, p_lo, p_hi));
                i += 1;
            }
        }
    }

    /// Intersects the gathered front faces with the beams they subtend, keeping the nearest hit
    /// per beam; the beams looked at widen [k0, k1]. First every face's interval of beam indices
    /// (branch-free, four faces at a time), then the beams of each.
    #[inline]
    fn draw(
        &self,
        front: &Front,
        dirs: &[[f32; 4]],
        out: &mut [f32],
        k0: &mut usize,
        k1: &mut usize,
    ) {
        let turn = TAU * self.inv_inc;
        let last = self.n as i32 - 1;
        for (c, e) in front.ends.iter().enumerate() {
            let mut spans = [[0i32; 3]; 4];
            for l in 0..4 {
                let first = atan2_approx(e[1][l], e[0][l]);
                let mut width = atan2_approx(e[3][l], e[2][l]) - first;
                width += if width < 0.0 { TAU } else { 0.0 };
                let mut rel = first - MARGIN - self.start;
                rel += if rel < 0.0 { TAU } else { 0.0 };
                rel += if rel < 0.0 { TAU } else { 0.0 };
                // beams ⌈u0⌉ ..= ⌊u1⌋, and 0 ..= ⌊u1 − turn⌋ if the interval crosses 2π back
                // into the fan (u0 ≥ 0, so truncation is floor; ceil by hand: no SSE4.1
                // rounding; bounded, so the conversions cannot overflow however fine the fan)
                let u0 = (rel * self.inv_inc).min(1e9);
                let u1 = ((rel + width + 2.0 * MARGIN) * self.inv_inc).min(1e9);
                let r0 = u0 as i32 + ((u0 as i32 as f32) < u0) as i32;
                let wrapped = if u1 >= turn { (u1 - turn) as i32 } else { -1 };
                spans[l] = [r0, (u1 as i32).min(last), wrapped.min(last)];
            }
            for (&(vertical, p_at, p_lo, p_hi), &[r0, r1, wrapped]) in
                front.faces[c * 4..].iter().zip(&spans)
            {
                let (ia, ib) = if vertical { (2, 1) } else { (3, 0) };
                for (r0, r1) in [(r0, r1), (0, wrapped)] {
                    if r0 > r1 {
                        continue;
                    }
                    let (r0, r1) = (r0 as usize, r1 as usize);
                    // branch-free: whether a beam hits the face nearer than before is
                    // unpredictable
                    for (d, o) in dirs[r0..=r1].iter().zip(&mut out[r0..=r1]) {
                        let t = p_at * d[ia];
                        let s = t * d[ib];
                        let hit = t >= 0.0 && t < *o && s >= p_lo && s <= p_hi;
                        *o = if hit { t } else { *o };
                    }
                    *k0 = (*k0).min(r0);
                    *k1 = (*k1).max(r1);
                }
            }
        }
    }
}
