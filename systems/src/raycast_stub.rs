//! TEMPORARY stand-in with the agreed API (plain DDA) until the real kernel lands.
#![allow(clippy::too_many_arguments)]

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
    let (dx, dy) = (angle.cos(), angle.sin());
    let mut t = 0.0f32;
    let step = resolution * 0.25;
    while t <= max_range {
        let x = p[0] + dx * t;
        let y = p[1] + dy * t;
        let c = ((x - origin[0]) / resolution).floor();
        let r = ((y - origin[1]) / resolution).floor();
        if c >= 0.0
            && r >= 0.0
            && (c as usize) < width
            && (r as usize) < height
            && occupied[r as usize * width + c as usize]
        {
            return t;
        }
        t += step;
    }
    f32::INFINITY
}

pub struct RayMap {
    w: usize,
    h: usize,
    res: f32,
    origin: [f32; 2],
    occ: Vec<bool>,
}
impl RayMap {
    pub fn new(
        width: usize,
        height: usize,
        resolution: f32,
        origin: [f32; 2],
        occupied: &[bool],
    ) -> RayMap {
        RayMap {
            w: width,
            h: height,
            res: resolution,
            origin,
            occ: occupied.to_vec(),
        }
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
        self.occ[row * self.w + col]
    }
    pub fn set_cells(&mut self, cells: &[(usize, usize, bool)]) {
        for &(c, r, o) in cells {
            self.occ[r * self.w + c] = o;
        }
    }
    pub fn cast(&self, p: [f32; 2], angle: f32, max_range: f32) -> f32 {
        cast_dda(
            self.w,
            self.h,
            self.res,
            self.origin,
            &self.occ,
            p,
            angle,
            max_range,
        )
    }
    pub fn cast_scan(
        &self,
        p: [f32; 2],
        start: f32,
        increment: f32,
        max_range: f32,
        out: &mut [f32],
    ) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.cast(p, start + k as f32 * increment, max_range);
        }
    }
}
pub fn overlay_circles(
    _p: [f32; 2],
    _start: f32,
    _increment: f32,
    _out: &mut [f32],
    _circles: &[[f32; 3]],
) {
}
pub fn overlay_segments(
    _p: [f32; 2],
    _start: f32,
    _increment: f32,
    _out: &mut [f32],
    _segments: &[[f32; 4]],
) {
}
