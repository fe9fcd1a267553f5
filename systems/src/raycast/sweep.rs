//! Whole scans by angular rasterisation ("z-buffering" in polar coordinates): the boundary faces
//! of occupied cells are precomputed per 16 × 16-cell tile (merged along straight runs); a scan
//! visits the tiles within range front to back, skips tiles that the beams already hitting
//! nearer cannot see past, culls back faces, maps each face to the beam indices it subtends and
//! keeps, per beam, the nearest exact ray–face intersection. The first occupied cell a ray enters
//! is entered through such a face, so results agree with the cell walk of [`super::cast_dda`].
//! Cost grows with the faces actually visible, not with the length of the rays.

use super::overlay::{arc_beams, beams_in_arc};

pub(crate) const TILE: usize = 16;

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

/// Wraps an angle to [0, 2π) (arguments are within a few turns: no libm fmod).
#[inline]
pub(crate) fn wrap_tau(mut a: f32) -> f32 {
    use std::f32::consts::TAU;
    while a < 0.0 {
        a += TAU;
    }
    while a >= TAU {
        a -= TAU;
    }
    a
}

/// Whether any beam in the arc [lo, lo + width] has a range beyond `near`.
fn any_beyond(start: f32, inc: f32, out: &[f32], lo: f32, width: f32, near: f32) -> bool {
    arc_beams(start, inc, out.len(), lo, width)
        .into_iter()
        .flatten()
        .any(|r| out[r].iter().any(|&x| x > near))
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

pub(crate) struct Faces {
    tw: usize,
    th: usize,
    res: f32,
    tiles: Vec<Vec<Face>>,
    /// Tile offsets sorted by distance (for front-to-back visits).
    offsets: Vec<(i32, i32, f32)>,
}

impl Faces {
    pub fn new(w: usize, h: usize, res: f32, occ: &dyn Fn(i64, i64) -> bool) -> Faces {
        let tw = w.div_ceil(TILE).max(1);
        let th = h.div_ceil(TILE).max(1);
        let mut f = Faces {
            tw,
            th,
            res,
            tiles: vec![Vec::new(); tw * th],
            offsets: Vec::new(),
        };
        for ty in 0..th {
            for tx in 0..tw {
                f.rebuild_tile(tx, ty, w, h, occ);
            }
        }
        let r = 80i32;
        for dy in -r..=r {
            for dx in -r..=r {
                let d = ((dx * dx + dy * dy) as f32).sqrt() * TILE as f32 * res;
                f.offsets.push((dx, dy, d));
            }
        }
        f.offsets.sort_by(|a, b| a.2.total_cmp(&b.2));
        f
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
        self.tiles[ty * self.tw + tx] = faces;
    }

    pub fn tile_counts(&self) -> (usize, usize) {
        (self.tw, self.th)
    }

    pub fn memory_bytes(&self) -> usize {
        self.tiles
            .iter()
            .map(|t| t.capacity() * std::mem::size_of::<Face>() + 24)
            .sum::<usize>()
            + self.offsets.len() * 12
    }

    /// The scan from grid-relative (gx, gy), origin known to be in a free cell: `out[k]` = range
    /// of beam k, +Inf beyond `max_range`.
    pub fn scan(&self, gx: f32, gy: f32, start: f32, inc: f32, max_range: f32, out: &mut [f32]) {
        let n = out.len();
        out.iter_mut().for_each(|o| *o = f32::INFINITY);
        // beam directions by rotation, re-anchored every 64 beams
        let mut dirs = Vec::with_capacity(n);
        let (si, ci) = inc.sin_cos();
        let (mut dy, mut dx) = (0.0f32, 1.0f32);
        for k in 0..n {
            if k % 64 == 0 {
                (dy, dx) = (start + k as f32 * inc).sin_cos();
            }
            dirs.push((dx, dy));
            let nx = dx * ci - dy * si;
            dy = dx * si + dy * ci;
            dx = nx;
        }
        let tsize = TILE as f32 * self.res;
        let half_diag = tsize * std::f32::consts::FRAC_1_SQRT_2;
        let (ptx, pty) = ((gx / tsize).floor() as i32, (gy / tsize).floor() as i32);
        // tiles are visited front to back: once every beam has hit something nearer than the
        // next tiles, the scan is complete
        let mut horizon = max_range;
        let mut visited = 0u32;
        // a scan of at most 180° sees nothing wholly behind the line through the sensor across
        // its central direction
        let span = n.saturating_sub(1) as f32 * inc;
        let (my, mx) = (start + span / 2.0).sin_cos();
        let half_plane = span <= std::f32::consts::PI + 1e-6;
        for &(ox, oy, d) in &self.offsets {
            if d - 2.0 * half_diag > horizon {
                break;
            }
            let (tx, ty) = (ptx + ox, pty + oy);
            if tx < 0 || ty < 0 || tx >= self.tw as i32 || ty >= self.th as i32 {
                continue;
            }
            let faces = &self.tiles[ty as usize * self.tw + tx as usize];
            if faces.is_empty() {
                continue;
            }
            // occlusion: skip the tile if every beam crossing it already hit something nearer
            let cx = (tx as f32 + 0.5) * tsize - gx;
            let cy = (ty as f32 + 0.5) * tsize - gy;
            if half_plane && cx * mx + cy * my < -half_diag {
                continue;
            }
            let dist = (cx * cx + cy * cy).sqrt();
            let near = dist - half_diag;
            if near > max_range {
                continue;
            }
            if dist > half_diag * 1.05 {
                // asin(x) ≤ x·π/2 on [0, 1]: a slightly wide, never narrow, interval
                let half = (half_diag / dist).min(1.0) * std::f32::consts::FRAC_PI_2 + inc;
                if !any_beyond(start, inc, out, fast_atan2(cy, cx) - half, 2.0 * half, near) {
                    continue;
                }
            }
            for f in faces {
                self.draw_face(f, gx, gy, start, inc, &dirs, out);
            }
            visited += 1;
            if visited.is_multiple_of(32) {
                horizon = out.iter().fold(0.0f32, |m, &r| m.max(r)).min(max_range);
            }
        }
        for o in out.iter_mut() {
            if *o > max_range {
                *o = f32::INFINITY;
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn draw_face(
        &self,
        f: &Face,
        gx: f32,
        gy: f32,
        start: f32,
        inc: f32,
        dirs: &[(f32, f32)],
        out: &mut [f32],
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
        let n = out.len();
        let (p_at, p_lo, p_hi) = if vertical { (ax, ay, by) } else { (ay, ax, bx) };
        beams_in_arc(start, inc, n, lo - 1e-4, width + 2e-4, |k| {
            let (dx, dy) = dirs[k];
            let (da, db) = if vertical { (dx, dy) } else { (dy, dx) };
            if da.abs() < 1e-12 {
                return;
            }
            let t = p_at / da;
            if t < 0.0 || t >= out[k] {
                return;
            }
            let s = t * db;
            if s >= p_lo && s <= p_hi {
                out[k] = t;
            }
        });
    }
}
