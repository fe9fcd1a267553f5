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
    /// Starts a walk at parameter `t` (grid-relative origin gx, gy, cell size `res`).
    pub fn start(gx: f32, gy: f32, dx: f32, dy: f32, res: f32, t: f32, w: usize, h: usize) -> Walk {
        let px = gx + dx * t;
        let py = gy + dy * t;
        let cx = ((px / res).floor() as i32).clamp(0, w as i32 - 1);
        let cy = ((py / res).floor() as i32).clamp(0, h as i32 - 1);
        Walk::at_cell(gx, gy, dx, dy, res, t, cx, cy)
    }

    #[allow(clippy::too_many_arguments)]
    pub fn at_cell(gx: f32, gy: f32, dx: f32, dy: f32, res: f32, t: f32, cx: i32, cy: i32) -> Walk {
        let (sx, t_max_x, t_delta_x) = axis(gx, dx, res, cx);
        let (sy, t_max_y, t_delta_y) = axis(gy, dy, res, cy);
        Walk {
            cx,
            cy,
            sx,
            sy,
            t_max_x,
            t_max_y,
            t_delta_x,
            t_delta_y,
            t,
        }
    }

    /// Moves into the next cell.
    #[inline(always)]
    pub fn step(&mut self) {
        if self.t_max_x < self.t_max_y {
            self.t = self.t_max_x;
            self.cx += self.sx;
            self.t_max_x += self.t_delta_x;
        } else {
            self.t = self.t_max_y;
            self.cy += self.sy;
            self.t_max_y += self.t_delta_y;
        }
    }
}

/// (step, first crossing time, crossing period) along one axis.
fn axis(g: f32, d: f32, res: f32, c: i32) -> (i32, f32, f32) {
    if d > 1e-12 {
        (1, ((c + 1) as f32 * res - g) / d, res / d)
    } else if d < -1e-12 {
        (-1, (c as f32 * res - g) / d, -res / d)
    } else {
        (0, f32::INFINITY, f32::INFINITY)
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
    let mut walk = Walk::start(gx, gy, dx, dy, resolution, t0, width, height);
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
