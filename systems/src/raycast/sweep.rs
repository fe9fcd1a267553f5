//! Whole scans by angular rasterisation ("z-buffering" in polar coordinates): the boundary faces
//! of occupied cells are precomputed per 16 × 16-cell tile (merged along straight runs); a scan
//! visits 4 × 4 groups of tiles (super tiles) within range front to back, skips groups and then
//! tiles that the beams already hitting nearer cannot see past (tested against per-block maxima
//! of the ranges so far, 16 beams a block), culls back faces, maps each face to the beam indices
//! it subtends and keeps, per beam, the nearest exact ray–face intersection. The first occupied cell a ray enters
//! is entered through such a face, so results agree with the cell walk of [`super::cast_dda`].
//! Cost grows with the faces actually visible, not with the length of the rays.

use super::fan::Fan;

pub(crate) const TILE: usize = 16;
/// Tiles per side of a super tile: empty or hidden regions are skipped 4 × 4 tiles at a time.
const SUPER: usize = 4;
/// Offsets are tabulated to this many super tiles (64 × 16 × SUPER cells, 205 m at 5 cm).
const SUPER_RADIUS: i32 = 64;

/// atan2 by a minimax polynomial (max error about 1e-5 rad): beam ranges are taken with a 1e-4
/// rad margin and every hit is then computed exactly, so the approximation never changes a range.
#[inline]
fn fast_atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (mn, mx) = if ax < ay { (ax, ay) } else { (ay, ax) };
    if mx == 0.0 {
        return 0.0;
    }
    let a = mn / mx;
    let s = a * a;
    let mut r =
        a * (0.999_866 + s * (-0.330_299_5 + s * (0.180_141 + s * (-0.085_133 + s * 0.020_835_1))));
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 { -r } else { r }
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

/// Occlusion test of a square region (centre offset (cx, cy) from the sensor, half diagonal
/// `half_diag`): false if its nearest possible point lies beyond `horizon` (the longest range
/// any beam still has) or if every beam that can cross it already hit something nearer. The
/// sensor's own neighbourhood is always visible.
#[allow(clippy::too_many_arguments)]
#[inline]
fn visible(
    fan: &Fan,
    out: &[f32],
    bmax: &[f32],
    cx: f32,
    cy: f32,
    half_diag: f32,
    inc: f32,
    horizon: f32,
) -> bool {
    let dist = (cx * cx + cy * cy).sqrt();
    let near = dist - half_diag;
    if near > horizon {
        return false;
    }
    if dist <= half_diag * 1.05 {
        return true;
    }
    // asin(x) ≤ x·π/2 on [0, 1]: a slightly wide, never narrow, interval
    let half = (half_diag / dist).min(1.0) * std::f32::consts::FRAC_PI_2 + inc;
    let lo = fast_atan2(cy, cx) - half;
    any_beyond(fan, out, bmax, lo, 2.0 * half, near)
}

/// An axis-aligned face in grid-relative metres: the line `axis = at` between `lo` and `hi`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Face {
    at: f32,
    lo: f32,
    hi: f32,
    /// 0: x = at, facing +x; 1: facing −x; 2: y = at, facing +y; 3: facing −y.
    kind: u8,
}

/// Tiles in a super tile.
const SUPER_TILES: usize = SUPER * SUPER;

/// The faces of the SUPER × SUPER tiles of one super tile in one array, tile after tile (row
/// major), so a scan reading a super tile touches one allocation: on a large map, chasing a
/// separate allocation per tile cost cache misses on most visited tiles.
#[derive(Clone, Default)]
struct SuperTile {
    faces: Vec<Face>,
    /// Faces of local tile l are `faces[starts[l]..starts[l + 1]]` (a 64 × 64-cell super tile
    /// has at most 4 · 64 · 64 faces).
    starts: [u16; SUPER_TILES + 1],
}

impl SuperTile {
    #[inline]
    fn tile(&self, l: usize) -> &[Face] {
        &self.faces[self.starts[l] as usize..self.starts[l + 1] as usize]
    }
}

pub(crate) struct Faces {
    tw: usize,
    th: usize,
    res: f32,
    /// Super tiles per row and column, and their faces.
    sw: usize,
    sh: usize,
    supers: Vec<SuperTile>,
    /// Super-tile offsets sorted by distance (for front-to-back visits).
    offsets: Vec<(i16, i16, f32)>,
}

impl Faces {
    pub fn new(w: usize, h: usize, res: f32, occ: &dyn Fn(i64, i64) -> bool) -> Faces {
        let tw = w.div_ceil(TILE).max(1);
        let th = h.div_ceil(TILE).max(1);
        let (sw, sh) = (tw.div_ceil(SUPER), th.div_ceil(SUPER));
        let mut f = Faces {
            tw,
            th,
            res,
            sw,
            sh,
            supers: vec![SuperTile::default(); sw * sh],
            offsets: Vec::new(),
        };
        for ty in 0..th {
            for tx in 0..tw {
                f.rebuild_tile(tx, ty, w, h, occ);
            }
        }
        let r = SUPER_RADIUS;
        let size = (SUPER * TILE) as f32 * res;
        for dy in -r..=r {
            for dx in -r..=r {
                let d = ((dx * dx + dy * dy) as f32).sqrt() * size;
                f.offsets.push((dx as i16, dy as i16, d));
            }
        }
        f.offsets.sort_by(|a, b| a.2.total_cmp(&b.2));
        f
    }

    /// The longest range a sweep handles: every super tile that can hold a point within it
    /// (centre up to range + one super-tile diagonal away) must be in the offset table.
    pub fn reach(&self) -> f32 {
        (SUPER_RADIUS - 2) as f32 * (SUPER * TILE) as f32 * self.res
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
        let mut faces = Vec::new();
        // vertical faces: for each column boundary side, runs along y
        for c in c0..c1 {
            for (kind, nc) in [(0u8, c + 1), (1u8, c - 1)] {
                let mut run: Option<i64> = None;
                for r in r0..=r1 {
                    let on = r < r1 && occ(c, r) && !occ(nc, r);
                    match (on, run) {
                        (true, None) => run = Some(r),
                        (false, Some(s)) => {
                            let x = if kind == 0 { c + 1 } else { c } as f32 * res;
                            faces.push(Face {
                                at: x,
                                lo: s as f32 * res,
                                hi: r as f32 * res,
                                kind,
                            });
                            run = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        for r in r0..r1 {
            for (kind, nr) in [(2u8, r + 1), (3u8, r - 1)] {
                let mut run: Option<i64> = None;
                for c in c0..=c1 {
                    let on = c < c1 && occ(c, r) && !occ(c, nr);
                    match (on, run) {
                        (true, None) => run = Some(c),
                        (false, Some(s)) => {
                            let y = if kind == 2 { r + 1 } else { r } as f32 * res;
                            faces.push(Face {
                                at: y,
                                lo: s as f32 * res,
                                hi: c as f32 * res,
                                kind,
                            });
                            run = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        let st = &mut self.supers[(ty / SUPER) * self.sw + tx / SUPER];
        let l = (ty % SUPER) * SUPER + tx % SUPER;
        let (a, b) = (st.starts[l] as usize, st.starts[l + 1] as usize);
        let added = faces.len();
        st.faces.splice(a..b, faces);
        for s in &mut st.starts[l + 1..] {
            *s = (*s as usize + added - (b - a)) as u16;
        }
        debug_assert!(st.faces.len() <= u16::MAX as usize);
    }

    pub fn tile_counts(&self) -> (usize, usize) {
        (self.tw, self.th)
    }

    pub fn memory_bytes(&self) -> usize {
        self.supers
            .iter()
            .map(|t| t.faces.capacity() * std::mem::size_of::<Face>())
            .sum::<usize>()
            + self.supers.len() * std::mem::size_of::<SuperTile>()
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
        let Scratch { dirs, bmax } = scratch;
        bmax.clear();
        bmax.resize(n.div_ceil(BLOCK), f32::INFINITY);
        // beam directions by rotation, re-anchored every 64 beams
        dirs.clear();
        let (si, ci) = inc.sin_cos();
        let (mut dy, mut dx) = (0.0f32, 1.0f32);
        let recip = |d: f32| {
            if d.abs() < 1e-12 {
                f32::INFINITY
            } else {
                1.0 / d
            }
        };
        for k in 0..n {
            if k % 64 == 0 {
                (dy, dx) = (start + k as f32 * inc).sin_cos();
            }
            dirs.push([dx, dy, recip(dx), recip(dy)]);
            let nx = dx * ci - dy * si;
            dy = dx * si + dy * ci;
            dx = nx;
        }
        let tsize = TILE as f32 * self.res;
        let ssize = SUPER as f32 * tsize;
        let half_diag = tsize * std::f32::consts::FRAC_1_SQRT_2;
        let super_half_diag = ssize * std::f32::consts::FRAC_1_SQRT_2;
        let (psx, psy) = ((gx / ssize) as i32, (gy / ssize) as i32);
        // a scan of at most 180° sees nothing wholly behind the line through the sensor across
        // its central direction
        let (my, mx) = (start + fan.span() / 2.0).sin_cos();
        let half_plane = fan.span() <= std::f32::consts::PI + 1e-6;
        let behind = |cx: f32, cy: f32, hd: f32| half_plane && cx * mx + cy * my < -hd;
        // super tiles are visited front to back: once every beam has hit something nearer than
        // the next ones, the scan is complete
        let mut horizon = max_range;
        for &(ox, oy, d) in &self.offsets {
            if d - 2.0 * super_half_diag > horizon {
                break;
            }
            let (sx, sy) = (psx + ox as i32, psy + oy as i32);
            if sx < 0 || sy < 0 || sx >= self.sw as i32 || sy >= self.sh as i32 {
                continue;
            }
            let st = &self.supers[sy as usize * self.sw + sx as usize];
            if st.faces.is_empty() {
                continue;
            }
            let cx = (sx as f32 + 0.5) * ssize - gx;
            let cy = (sy as f32 + 0.5) * ssize - gy;
            if behind(cx, cy, super_half_diag) {
                continue;
            }
            if !visible(&fan, out, bmax, cx, cy, super_half_diag, inc, horizon) {
                continue;
            }
            // its tiles, nearest corner first (the order only makes occlusion more effective)
            let (x0, y0) = (sx as usize * SUPER, sy as usize * SUPER);
            for j in 0..SUPER {
                let ty = if cy >= 0.0 {
                    y0 + j
                } else {
                    y0 + SUPER - 1 - j
                };
                if ty >= self.th {
                    continue;
                }
                for i in 0..SUPER {
                    let tx = if cx >= 0.0 {
                        x0 + i
                    } else {
                        x0 + SUPER - 1 - i
                    };
                    if tx >= self.tw {
                        continue;
                    }
                    let faces = st.tile((ty - y0) * SUPER + tx - x0);
                    if faces.is_empty() {
                        continue;
                    }
                    let tcx = (tx as f32 + 0.5) * tsize - gx;
                    let tcy = (ty as f32 + 0.5) * tsize - gy;
                    if behind(tcx, tcy, half_diag) {
                        continue;
                    }
                    if !visible(&fan, out, bmax, tcx, tcy, half_diag, inc, horizon) {
                        continue;
                    }
                    let (mut k0, mut k1) = (usize::MAX, 0);
                    for f in faces {
                        self.draw_face(f, gx, gy, &fan, dirs, out, &mut k0, &mut k1);
                    }
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
        }
        for o in out.iter_mut() {
            if *o > max_range {
                *o = f32::INFINITY;
            }
        }
    }

    /// Intersects one face with the beams it subtends, keeping the nearest hit per beam; the
    /// indices of beams it shortened widen [k0, k1].
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn draw_face(
        &self,
        f: &Face,
        gx: f32,
        gy: f32,
        fan: &Fan,
        dirs: &[[f32; 4]],
        out: &mut [f32],
        k0: &mut usize,
        k1: &mut usize,
    ) {
        let vertical = f.kind < 2;
        // back-face culling: the sensor must be on the face's free side
        let rel = if vertical { gx - f.at } else { gy - f.at };
        let facing_pos = f.kind == 0 || f.kind == 2;
        if (facing_pos && rel <= 0.0) || (!facing_pos && rel >= 0.0) {
            return;
        }
        let (ax, ay, bx, by) = if vertical {
            (f.at - gx, f.lo - gy, f.at - gx, f.hi - gy)
        } else {
            (f.lo - gx, f.at - gy, f.hi - gx, f.at - gy)
        };
        let a0 = fast_atan2(ay, ax);
        let a1 = fast_atan2(by, bx);
        let mut diff = a1 - a0;
        if diff > std::f32::consts::PI {
            diff -= std::f32::consts::TAU;
        } else if diff < -std::f32::consts::PI {
            diff += std::f32::consts::TAU;
        }
        let (lo, width) = if diff >= 0.0 { (a0, diff) } else { (a1, -diff) };
        let (p_at, p_lo, p_hi) = if vertical { (ax, ay, by) } else { (ay, ax, bx) };
        // the perpendicular component and its reciprocal, the parallel one
        let (ia, ib) = if vertical { (2, 1) } else { (3, 0) };
        fan.for_each_in(lo - 1e-4, width + 2e-4, |k| {
            let d = &dirs[k];
            let t = p_at * d[ia];
            if !(t >= 0.0 && t < out[k]) {
                return;
            }
            let s = t * d[ib];
            if s >= p_lo && s <= p_hi {
                out[k] = t;
                *k0 = (*k0).min(k);
                *k1 = (*k1).max(k);
            }
        });
    }
}
