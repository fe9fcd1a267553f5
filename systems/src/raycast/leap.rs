//! One ray's walk on the distance field of [`super::RayMap`]: the state and the move every
//! distance-field kernel uses ([`super::RayMap::cast`] one ray at a time, the ray streams of
//! `batch` several in turn).
//!
//! A cell whose value is k ≥ 2 is the centre of a free square of cells within L∞ distance
//! k − 1 (the Chebyshev distance transform's meaning), so from the point where the ray entered
//! the cell it can advance an L∞ distance of k − 1 cells without meeting an obstacle: a leap
//! across open space, sphere tracing with the L∞ metric. Next to an obstacle (k = 1) it takes
//! the Amanatides & Woo (1987) cell step, the crossing time computed from the ray's origin and
//! the cell indices (never accumulated), so the hit parameter is the boundary crossing into the
//! first occupied cell, as in [`super::cast_dda`].
//!
//! Two moves, one per use. [`Lane::advance`] leaps the inscribed L∞ distance k − 1 from the
//! cell's entry point: few operations, for the streams, whose cost is arithmetic once the loads
//! of several rays overlap. [`Lane::exit_square`] leaves the whole free square (its far boundary
//! on either axis, k − 1 to k cells, into the first cell outside it): more arithmetic but fewer
//! moves, for a single ray, whose cost is the chain of dependent loads (measured on the
//! hospital, random free poses, 20 m: 5.8 moves per ray against 7.8, and 9.6–10.2 against
//! 8.3–9.4 M single rays/s; the streams, the other way round, 16.9 against 11.1 M rays/s). It
//! works in cell units ([`InCells`]), which shortens each move's chain by two multiplications
//! (about 10 % more single rays/s) at the cost of millimetres at grazing incidence. `cast` makes
//! these moves through [`Single`], the same arithmetic arranged without unpredictable branches;
//! `Lane::exit_square` stays for rays along an axis and as the reference of the tests.

use super::dda::{enter_grid, step_sign};

/// A ray in grid-relative metres, and the cell it is in.
#[derive(Clone, Copy, Default)]
pub(super) struct Lane {
    pub gx: f32,
    pub gy: f32,
    pub dx: f32,
    pub dy: f32,
    /// 1/dx, 1/dy (finite: only used when the step sign is non-zero).
    pub idx: f32,
    pub idy: f32,
    /// Cell steps and the offsets (0 or 1) of the next boundary.
    pub sx: i32,
    pub sy: i32,
    pub bx: i32,
    pub by: i32,
    /// Length of one cell of L∞ travel along the ray.
    pub leap: f32,
    pub cx: i32,
    pub cy: i32,
    /// Parameter at which the ray entered the current cell (or landed in it after a leap).
    pub t: f32,
    /// Output slot (for the streams).
    pub id: usize,
}

/// The grid a walk runs on: size in cells and cell size.
#[derive(Clone, Copy)]
pub(super) struct Bounds {
    pub w: i32,
    pub h: i32,
    pub res: f32,
    pub inv_res: f32,
    /// Size in metres.
    pub wf: f32,
    pub hf: f32,
}

impl Bounds {
    pub fn new(w: usize, h: usize, res: f32) -> Bounds {
        Bounds {
            w: w as i32,
            h: h as i32,
            res,
            inv_res: 1.0 / res,
            wf: w as f32 * res,
            hf: h as f32 * res,
        }
    }
}

impl Lane {
    /// The ray from (gx, gy) along the unit direction (dx, dy), at parameter t, which must be a
    /// point inside the grid.
    #[inline(always)]
    pub fn new(gx: f32, gy: f32, dx: f32, dy: f32, t: f32, b: &Bounds) -> Lane {
        let (sx, sy) = (step_sign(dx), step_sign(dy));
        Lane {
            gx,
            gy,
            dx,
            dy,
            idx: if sx != 0 { 1.0 / dx } else { 0.0 },
            idy: if sy != 0 { 1.0 / dy } else { 0.0 },
            sx,
            sy,
            bx: (sx > 0) as i32,
            by: (sy > 0) as i32,
            leap: b.res / dx.abs().max(dy.abs()),
            cx: (((gx + dx * t) * b.inv_res) as i32).clamp(0, b.w - 1),
            cy: (((gy + dy * t) * b.inv_res) as i32).clamp(0, b.h - 1),
            t,
            id: 0,
        }
    }

    /// The ray from grid-relative (gx, gy) along the unit direction (dx, dy), placed where it
    /// enters the grid; or, when there is nothing to walk, its answer: NaN for an undefined ray
    /// (a NaN or infinite pose), ∞ for one that misses the grid within `max_range`.
    #[inline(always)]
    pub fn start(
        gx: f32,
        gy: f32,
        dx: f32,
        dy: f32,
        b: &Bounds,
        max_range: f32,
    ) -> Result<Lane, f32> {
        if !(gx.is_finite() && gy.is_finite() && dx.is_finite() && dy.is_finite()) {
            return Err(f32::NAN);
        }
        let t = if gx >= 0.0 && gy >= 0.0 && gx < b.wf && gy < b.hf {
            0.0
        } else {
            enter_grid(gx, gy, dx, dy, b.wf, b.hf, max_range).ok_or(f32::INFINITY)?
        };
        Ok(Lane::new(gx, gy, dx, dy, t, b))
    }

    /// One move from the current cell, whose distance value is `k` ≥ 1: a leap of k − 1 cells
    /// of L∞ travel or a cell step (see the module doc).
    /// Returns false when the ray leaves the grid or passes `max_range` (no hit).
    #[inline(always)]
    pub fn advance(&mut self, k: u8, b: &Bounds, max_range: f32) -> bool {
        if k >= 2 {
            let t = self.t + (k - 1) as f32 * self.leap;
            let (px, py) = (self.gx + self.dx * t, self.gy + self.dy * t);
            if t > max_range || px < 0.0 || py < 0.0 || px >= b.wf || py >= b.hf {
                return false;
            }
            self.t = t;
            self.cx = ((px * b.inv_res) as i32).min(b.w - 1);
            self.cy = ((py * b.inv_res) as i32).min(b.h - 1);
            return true;
        }
        let tx = if self.sx != 0 {
            ((self.cx + self.bx) as f32 * b.res - self.gx) * self.idx
        } else {
            f32::INFINITY
        };
        let ty = if self.sy != 0 {
            ((self.cy + self.by) as f32 * b.res - self.gy) * self.idy
        } else {
            f32::INFINITY
        };
        // never back along the ray: a ray running along a cell boundary can find the boundary
        // it crosses a rounding error behind it, and leaping on from there could cycle between
        // two cells for ever
        if tx < ty {
            self.t = tx.max(self.t);
            self.cx += self.sx;
        } else {
            self.t = ty.max(self.t);
            self.cy += self.sy;
        }
        !(self.t > max_range || self.cx < 0 || self.cy < 0 || self.cx >= b.w || self.cy >= b.h)
    }

    /// One move out of the free square around the current cell, whose distance value is `k` ≥ 1
    /// (with k = 1 the square is the cell, and this is the cell step), with the ray in cell
    /// units `u` (see [`InCells`]). Returns false when the ray leaves the grid or passes
    /// `max_range`. Cell indices never move backwards, so a walk always ends.
    #[inline(always)]
    pub fn exit_square(&mut self, k: u8, u: &InCells, b: &Bounds, max_range: f32) -> bool {
        let k = k as i32;
        let m = k - 1;
        // the boundary's index + 1, against the origin + 1 cell (see `InCells`)
        let tx = if self.sx != 0 {
            ((self.cx + self.bx + self.sx * m + 1) as f32 - u.gx1) * u.idx
        } else {
            f32::INFINITY
        };
        let ty = if self.sy != 0 {
            ((self.cy + self.by + self.sy * m + 1) as f32 - u.gy1) * u.idy
        } else {
            f32::INFINITY
        };
        // `max`: never back along the ray, as in `advance`
        if tx < ty {
            self.t = tx.max(self.t);
            self.cx += self.sx * k;
            self.cy = across(u.gy1, u.dy, self.t, self.cy, self.sy * m);
        } else {
            self.t = ty.max(self.t);
            self.cy += self.sy * k;
            self.cx = across(u.gx1, u.dx, self.t, self.cx, self.sx * m);
        }
        !(self.t > max_range || self.cx < 0 || self.cy < 0 || self.cx >= b.w || self.cy >= b.h)
    }
}

/// A ray in cell units for [`Lane::exit_square`] and [`Single`]: its origin in cells plus one (so
/// truncation floors every point above −1 cell), the cells it crosses per metre of travel on each
/// axis, and the travel per cell. Each move of a single ray is a chain of dependent operations, and
/// these factors take two multiplications out of it (10 % more single rays per second). The price
/// is rounding: the origin is rounded in cells rather than each boundary in metres, so a ray
/// meeting a wall at a grazing angle (a few hundredths of a degree, where a micrometre across the
/// ray is a millimetre along it) can end a few millimetres from [`super::cast_dda`]'s answer on a
/// large map; on the hospital doubled (2560 × 640 cells, 2 M random rays) 5 rays differed by more
/// than 1 mm, at most 4 mm, and the exact answers lay 0.6–3 mm from ours, 0.2–1.1 mm from the cell
/// walk's.
pub(super) struct InCells {
    gx1: f32,
    gy1: f32,
    dx: f32,
    dy: f32,
    idx: f32,
    idy: f32,
}

impl InCells {
    #[inline(always)]
    pub fn new(l: &Lane, b: &Bounds) -> InCells {
        InCells {
            gx1: l.gx * b.inv_res + 1.0,
            gy1: l.gy * b.inv_res + 1.0,
            dx: l.dx * b.inv_res,
            dy: l.dy * b.inv_res,
            idx: l.idx * b.res,
            idy: l.idy * b.res,
        }
    }
}

/// A single ray whose direction has no zero component ([`step_sign`] ±1 on both axes), for
/// [`super::RayMap::cast`]: the moves of [`Lane::exit_square`], to the bit, arranged for a short
/// chain of dependent operations from one distance value to the next cell's address. Both exits
/// are computed and the earlier one picked without a branch (which axis comes first is hard to
/// predict), and `exit_square`'s guards (the `max` with the previous parameter, the clamp into
/// the square) leave the chain for a predicted branch, since they almost never act.
pub(super) struct Single {
    u: InCells,
    sx: i32,
    sy: i32,
    /// The boundary index + 1 of `exit_square` is `c + s·k + o` on each axis.
    ox: i32,
    oy: i32,
}

impl Single {
    /// The ray from grid-relative (gx, gy) along (dx, dy); None when a component is within 1e-12
    /// of zero (or not a number).
    #[inline(always)]
    pub fn new(gx: f32, gy: f32, dx: f32, dy: f32, b: &Bounds) -> Option<Single> {
        let (sx, sy) = (step_sign(dx), step_sign(dy));
        if sx == 0 || sy == 0 {
            return None;
        }
        // what `Lane::new` and `InCells::new` compute for this ray
        let l = Lane {
            gx,
            gy,
            dx,
            dy,
            idx: 1.0 / dx,
            idy: 1.0 / dy,
            ..Lane::default()
        };
        Some(Single {
            u: InCells::new(&l, b),
            sx,
            sy,
            ox: (sx > 0) as i32 - sx + 1,
            oy: (sy > 0) as i32 - sy + 1,
        })
    }

    /// One move out of the free square around cell (cx, cy), whose distance value is `k` ≥ 2,
    /// entered at `t`: [`Lane::exit_square`] without the bounds test.
    #[inline(always)]
    pub fn exit_square(&self, k: i32, cx: i32, cy: i32, t: f32) -> (i32, i32, f32) {
        let u = &self.u;
        let (kx, ky) = (self.sx * k, self.sy * k);
        let tx = ((cx + kx + self.ox) as f32 - u.gx1) * u.idx;
        let ty = ((cy + ky + self.oy) as f32 - u.gy1) * u.idy;
        // the other index after each exit, as `across` has it before its clamp (the later
        // exit's can lie far outside)
        let ay = truncate(u.gy1 + u.dy * tx).wrapping_sub(1);
        let ax = truncate(u.gx1 + u.dx * ty).wrapping_sub(1);
        let xfirst = tx < ty;
        let pick = |a: i32, b: i32| std::hint::select_unpredictable(xfirst, a, b);
        // how far forward that index went: 0..k inside the square, where `across` keeps it
        let ahead = pick(
            ay.wrapping_sub(cy).wrapping_mul(self.sy),
            ax.wrapping_sub(cx).wrapping_mul(self.sx),
        );
        let nt = if xfirst { tx } else { ty };
        if t > nt || ahead as u32 >= k as u32 {
            return self.guarded(k, cx, cy, t);
        }
        (pick(cx + kx, ax), pick(ay, cy + ky), nt)
    }

    /// [`Single::exit_square`] when a guard of [`Lane::exit_square`] acts: the boundary lies a
    /// rounding error behind `t`, or the crossing point a hair outside the square.
    #[cold]
    #[inline(never)]
    fn guarded(&self, k: i32, cx: i32, cy: i32, t: f32) -> (i32, i32, f32) {
        let u = &self.u;
        let (kx, ky) = (self.sx * k, self.sy * k);
        let tx = ((cx + kx + self.ox) as f32 - u.gx1) * u.idx;
        let ty = ((cy + ky + self.oy) as f32 - u.gy1) * u.idy;
        if tx < ty {
            let t = tx.max(t);
            (cx + kx, across(u.gy1, u.dy, t, cy, ky - self.sy), t)
        } else {
            let t = ty.max(t);
            (across(u.gx1, u.dx, t, cx, kx - self.sx), cy + ky, t)
        }
    }

    /// The move from a cell whose value is 1 (next to an obstacle): the cell step of
    /// [`Lane::exit_square`], whose square is the cell, so no crossing point is needed.
    #[inline(always)]
    pub fn step(&self, cx: i32, cy: i32, t: f32) -> (i32, i32, f32) {
        let u = &self.u;
        let tx = ((cx + self.sx + self.ox) as f32 - u.gx1) * u.idx;
        let ty = ((cy + self.sy + self.oy) as f32 - u.gy1) * u.idy;
        let xfirst = tx < ty;
        let pick = |a: i32, b: i32| std::hint::select_unpredictable(xfirst, a, b);
        let nt = if xfirst { tx } else { ty };
        // `nt.max(t)` (neither is NaN) without its NaN test
        (
            pick(cx + self.sx, cx),
            pick(cy, cy + self.sy),
            if t > nt { t } else { nt },
        )
    }
}

/// `x as i32` by the bare x86-64 truncation, without Rust's saturation (NaN and out-of-range
/// values give i32::MIN instead): two instructions fewer in each move. Such values only occur
/// for the exit not taken, or fail the guard of [`Single::exit_square`], whose path saturates.
#[inline(always)]
fn truncate(x: f32) -> i32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvttss_si32, _mm_set_ss};
        // SAFETY: SSE is part of the x86-64 baseline
        unsafe { _mm_cvttss_si32(_mm_set_ss(x)) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        x as i32
    }
}

/// The cell index on the axis the ray did not exit through: where the ray is at `t` (origin
/// `g1` and direction `d` in cells, see [`InCells`]), kept between the current index `c` and the
/// square's side `span` = ±m cells ahead (rounding can put the point a hair outside), never
/// behind `c`.
#[inline(always)]
fn across(g1: f32, d: f32, t: f32, c: i32, span: i32) -> i32 {
    // floor for points above −1 cell (truncation of the point plus one: `floor` is a libm call
    // on the baseline x86-64 target), enough since the result is clamped next to `c` ≥ 0
    let at = (g1 + d * t) as i32 - 1;
    at.clamp(c + span.min(0), c + span.max(0))
}
