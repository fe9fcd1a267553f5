//! Tests of the ray casters against a plain cell walk (`Map::dda`) and closed forms; the
//! fixtures they share.

use super::*;
use std::f32::consts::PI;

mod overlay;
mod scans;
mod single;

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn f(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

struct Map {
    w: usize,
    h: usize,
    res: f32,
    origin: [f32; 2],
    occ: Vec<bool>,
}

impl Map {
    /// The bundled hospital map, tiled `tx` × `ty`.
    fn hospital(tx: usize, ty: usize) -> Map {
        let path = crate::core::source::source_path("assets/maps/hospital/hospital.yaml");
        let grid = crate::world::load_map(&path)
            .expect("the hospital map loads")
            .tiled(tx, ty);
        Map {
            w: grid.width,
            h: grid.height,
            res: grid.resolution as f32,
            origin: [grid.origin[0] as f32, grid.origin[1] as f32],
            occ: grid.obstacles(),
        }
    }
    fn dda(&self, p: [f32; 2], a: f32, max: f32) -> f32 {
        cast_dda(self.w, self.h, self.res, self.origin, &self.occ, p, a, max)
    }
    fn raymap(&self) -> RayMap {
        RayMap::new(self.w, self.h, self.res, self.origin, &self.occ)
    }
    fn set(&mut self, c: usize, r: usize, v: bool) {
        self.occ[r * self.w + c] = v;
    }
}

/// 10 × 10 m room with inner faces at 0.1 and 9.9 (origin -1, -1; 5 cm cells).
fn square_room() -> Map {
    let (w, h) = (240, 240);
    let mut m = Map {
        w,
        h,
        res: 0.05,
        origin: [-1.0, -1.0],
        occ: vec![false; w * h],
    };
    for r in 0..h {
        for c in 0..w {
            let x = -1.0 + (c as f32 + 0.5) * 0.05;
            let y = -1.0 + (r as f32 + 0.5) * 0.05;
            let inside = (0.1..9.9).contains(&x) && (0.1..9.9).contains(&y);
            let wall = (-0.1..10.1).contains(&x) && (-0.1..10.1).contains(&y);
            m.set(c, r, wall && !inside);
        }
    }
    m
}

fn room_range(x: f32, y: f32, a: f32) -> f32 {
    let (dy, dx) = a.sin_cos();
    let mut t = f32::INFINITY;
    if dx > 1e-9 {
        t = t.min((9.9 - x) / dx);
    }
    if dx < -1e-9 {
        t = t.min((0.1 - x) / dx);
    }
    if dy > 1e-9 {
        t = t.min((9.9 - y) / dy);
    }
    if dy < -1e-9 {
        t = t.min((0.1 - y) / dy);
    }
    t
}

fn random_map(seed: u64) -> Map {
    let (w, h) = (400, 300);
    let mut m = Map {
        w,
        h,
        res: 0.05,
        origin: [2.0, -3.0],
        occ: vec![false; w * h],
    };
    let mut rng = XorShift(seed);
    // room walls every ~80 cells with door gaps, plus pillars
    for r in 0..h {
        for c in 0..w {
            let wall_x = c % 80 < 3 && !(r % 60 > 25 && r % 60 < 45);
            let wall_y = r % 100 < 3 && !(c % 50 > 10 && c % 50 < 30);
            if wall_x || wall_y {
                m.set(c, r, true);
            }
        }
    }
    for _ in 0..60 {
        let cx = (rng.f() * w as f32) as i32;
        let cy = (rng.f() * h as f32) as i32;
        let rad = 1 + (rng.f() * 6.0) as i32;
        for r in (cy - rad).max(0)..(cy + rad).min(h as i32) {
            for c in (cx - rad).max(0)..(cx + rad).min(w as i32) {
                if (r - cy).pow(2) + (c - cx).pow(2) <= rad * rad {
                    m.set(c as usize, r as usize, true);
                }
            }
        }
    }
    m
}

fn random_free_point(m: &Map, rng: &mut XorShift) -> [f32; 2] {
    loop {
        let x = m.origin[0] + rng.f() * m.w as f32 * m.res;
        let y = m.origin[1] + rng.f() * m.h as f32 * m.res;
        let c = ((x - m.origin[0]) / m.res) as usize;
        let r = ((y - m.origin[1]) / m.res) as usize;
        if !m.occ[r * m.w + c] {
            return [x, y];
        }
    }
}

fn agree(a: f32, b: f32) -> bool {
    (a.is_infinite() && b.is_infinite()) || (a - b).abs() < 1e-3
}

/// A scan beam agrees with the cell walk, or sits on a discontinuity: a beam through the exact
/// corner of an obstacle (within float error), where nudging it by 2e-5 rad gives its value.
fn agree_or_corner(m: &Map, p: [f32; 2], a: f32, max: f32, r: f32, corners: &mut usize) -> bool {
    if agree(r, m.dda(p, a, max)) {
        return true;
    }
    let nudged = [m.dda(p, a - 2e-5, max), m.dda(p, a + 2e-5, max)];
    if nudged.iter().any(|&n| agree(r, n)) {
        *corners += 1;
        return true;
    }
    false
}
