//! The Amanatides & Woo (1987) voxel traversal on an occupancy grid: the reference every faster
//! kernel is checked against, and the baseline of the benchmarks.

/// Entry of a ray into the grid's rectangle [0, w·res] × [0, h·res] (grid-relative coordinates):
/// the parameter t ≥ 0 where it enters, or None if it misses it before `max_range`.
pub(crate) fn enter_grid(
    gx: f32,
    gy: f32,
    dx: f32,
    dy: f32,
    w: f32,
    h: f32,
    max_range: f32,
) -> Option<f32> {
    let mut t0 = 0.0f32;
    let mut t1 = max_range;
    for (p, d, hi) in [(gx, dx, w), (gy, dy, h)] {
        if d.abs() < 1e-12 {
            if p < 0.0 || p >= hi {
                return None;
            }
        } else {
            let a = (0.0 - p) / d;
            let b = (hi - p) / d;
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some(t0)
}

/// State of a cell walk: the current cell and the next crossing times, all relative to the ray
/// origin so no error accumulates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Walk {
    pub cx: i32,
    pub cy: i32,
    pub sx: i32,
    pub sy: i32,
    pub t_max_x: f32,
    pub t_max_y: f32,
    pub t_delta_x: f32,
    pub t_delta_y: f32,
    /// Parameter at which the ray entered the current cell.
    pub t: f32,
}

impl Walk {
    /// Moves into the next cell.
    #[inline(always)]
    pub fn step(&mut self) {
        // `max`: never back along the ray (a boundary a rounding error behind a restarted walk)
        if self.t_max_x < self.t_max_y {
            self.t = self.t_max_x.max(self.t);
            self.cx += self.sx;
            self.t_max_x += self.t_delta_x;
        } else {
            self.t = self.t_max_y.max(self.t);
            self.cy += self.sy;
            self.t_max_y += self.t_delta_y;
        }
    }
}

/// The cell step (−1, 0 or +1) of a direction component; components within 1e-12 of zero never
/// cross a cell boundary.
#[inline]
pub(crate) fn step_sign(d: f32) -> i32 {
    if d > 1e-12 {
        1
    } else if d < -1e-12 {
        -1
    } else {
        0
    }
}

/// A ray's constants for restarting cell walks cheaply after leaps (no division, no floor).
pub(crate) struct Ray {
    gx: f32,
    gy: f32,
    dx: f32,
    dy: f32,
    res: f32,
    inv_res: f32,
    /// 1/dx, 1/dy (or +Inf) and the per-cell crossing periods.
    idx: f32,
    idy: f32,
    sx: i32,
    sy: i32,
    tdx: f32,
    tdy: f32,
}

impl Ray {
    pub(crate) fn new(gx: f32, gy: f32, dx: f32, dy: f32, res: f32) -> Ray {
        let inv = |d: f32| {
            if d.abs() > 1e-12 {
                1.0 / d
            } else {
                f32::INFINITY
            }
        };
        let (idx, idy) = (inv(dx), inv(dy));
        Ray {
            gx,
            gy,
            dx,
            dy,
            res,
            inv_res: 1.0 / res,
            idx,
            idy,
            sx: step_sign(dx),
            sy: step_sign(dy),
            tdx: (res * idx).abs(),
            tdy: (res * idy).abs(),
        }
    }

    /// The walk state at parameter t (a point inside the grid, so coordinates are ≥ 0 and
    /// truncation is floor).
    #[inline(always)]
    pub(crate) fn walk_at(&self, t: f32, w: i32, h: i32) -> Walk {
        let cx = (((self.gx + self.dx * t) * self.inv_res) as i32).clamp(0, w - 1);
        let cy = (((self.gy + self.dy * t) * self.inv_res) as i32).clamp(0, h - 1);
        let next = |g: f32, s: i32, c: i32, inv: f32| match s {
            1 => ((c + 1) as f32 * self.res - g) * inv,
            -1 => (c as f32 * self.res - g) * inv,
            _ => f32::INFINITY,
        };
        Walk {
            cx,
            cy,
            sx: self.sx,
            sy: self.sy,
            t_max_x: next(self.gx, self.sx, cx, self.idx),
            t_max_y: next(self.gy, self.sy, cy, self.idy),
            t_delta_x: self.tdx,
            t_delta_y: self.tdy,
            t,
        }
    }
}

/// One ray by a plain cell walk (see the module conventions).
#[allow(clippy::too_many_arguments)]
pub fn cast_dda(
    width: usize,
    height: usize,
    resolution: f32,
    origin: [f32; 2],
    occupied: &[bool],
    p: [f32; 2],
    angle: f32,
    max_range: f32,
) -> f32 {
    let (dy, dx) = angle.sin_cos();
    let gx = p[0] - origin[0];
    let gy = p[1] - origin[1];
    let Some(t0) = enter_grid(
        gx,
        gy,
        dx,
        dy,
        width as f32 * resolution,
        height as f32 * resolution,
        max_range,
    ) else {
        return f32::INFINITY;
    };
    let mut walk = Ray::new(gx, gy, dx, dy, resolution).walk_at(t0, width as i32, height as i32);
    loop {
        if walk.cx < 0 || walk.cy < 0 || walk.cx >= width as i32 || walk.cy >= height as i32 {
            return f32::INFINITY;
        }
        if occupied[walk.cy as usize * width + walk.cx as usize] {
            return walk.t;
        }
        walk.step();
        if walk.t > max_range {
            return f32::INFINITY;
        }
    }
}

/// The cells a segment crosses, in order from its start (Amanatides & Woo 1987): the segment
/// from `p` along the unit direction `dir` for `len` metres, clipped to the `width` × `height`
/// grid of `resolution` whose cell (0, 0) has its lower-left corner at `origin`. Calls
/// `visit(row * width + col)` for every crossed cell inside the grid BEFORE the one holding the
/// end point, and returns that end cell's index, or None when the end point is outside the grid
/// (the segment's cells inside the grid have then all been visited). The occupancy mapper walks
/// its beams with it: the visited cells are the free space a beam has passed, the end cell is
/// where it ended.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn traverse_segment(
    width: usize,
    height: usize,
    resolution: f32,
    origin: [f32; 2],
    p: [f32; 2],
    dir: [f32; 2],
    len: f32,
    mut visit: impl FnMut(usize),
) -> Option<usize> {
    if width == 0 || height == 0 {
        return None;
    }
    let gx = p[0] - origin[0];
    let gy = p[1] - origin[1];
    let [dx, dy] = dir;
    let (wf, hf) = (width as f32 * resolution, height as f32 * resolution);
    let t0 = if gx >= 0.0 && gy >= 0.0 && gx < wf && gy < hf {
        0.0
    } else {
        enter_grid(gx, gy, dx, dy, wf, hf, len)?
    };
    let (w, h) = (width as i32, height as i32);
    let mut walk = Ray::new(gx, gy, dx, dy, resolution).walk_at(t0, w, h);
    loop {
        let i = walk.cy as usize * width + walk.cx as usize;
        // the next boundary lies beyond the end point: this cell holds it
        if walk.t_max_x.min(walk.t_max_y) >= len {
            return Some(i);
        }
        visit(i);
        walk.step();
        if walk.cx < 0 || walk.cy < 0 || walk.cx >= w || walk.cy >= h {
            return None;
        }
    }
}
