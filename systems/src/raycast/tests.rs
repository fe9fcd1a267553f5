use super::*;
use std::f32::consts::PI;

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

#[test]
fn square_room_matches_closed_form() {
    let m = square_room();
    let rm = m.raymap();
    let p = [3.3, 4.1];
    let n = 1440;
    let inc = 2.0 * PI / n as f32;
    let mut out = vec![0.0; n];
    rm.cast_scan(p, -PI, inc, 30.0, &mut out);
    for (k, &r) in out.iter().enumerate() {
        let a = -PI + k as f32 * inc;
        let want = room_range(p[0], p[1], a);
        assert!((r - want).abs() < 1e-3, "beam {k}: {r} vs {want}");
        assert!((rm.cast(p, a, 30.0) - want).abs() < 1e-3);
        assert!((m.dda(p, a, 30.0) - want).abs() < 1e-3);
    }
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

#[test]
fn raymap_agrees_with_dda_on_random_rays() {
    let m = random_map(99);
    let rm = m.raymap();
    let mut rng = XorShift(7);
    let mut mismatches = 0;
    // a ray through the exact corner of an obstacle may go either way (see `agree_or_corner`)
    let mut corners = 0;
    for _ in 0..20_000 {
        let p = random_free_point(&m, &mut rng);
        let a = rng.f() * 2.0 * PI - PI;
        let max = 1.0 + rng.f() * 25.0;
        if !agree_or_corner(&m, p, a, max, rm.cast(p, a, max), &mut corners) {
            mismatches += 1;
        }
    }
    assert_eq!(mismatches, 0);
    assert!(corners <= 20, "{corners} corner cases in 20 000 rays");
    // scans, 50 of each kind from random poses and starts: narrow ones (≤ 180°: the sweep also
    // culls the half-plane behind the sensor), SICK ones, and full turns (a face across the
    // fan's start is met by its last and first beams)
    let mut corners = 0;
    for (kind, beams, inc, max) in [
        ("narrow", 180, PI / 179.0, 8.0),
        ("sick", 1081, 0.25f32.to_radians(), 20.0),
        ("full-turn", 720, 0.5f32.to_radians(), 20.0),
    ] {
        for _ in 0..50 {
            let p = random_free_point(&m, &mut rng);
            let start = rng.f() * 10.0 - 5.0;
            let mut out = vec![0.0; beams];
            rm.cast_scan(p, start, inc, max, &mut out);
            for (k, r) in out.iter().enumerate() {
                let a = start + k as f32 * inc;
                assert!(
                    agree_or_corner(&m, p, a, max, *r, &mut corners),
                    "{kind} beam {k}: {r} at {p:?}"
                );
            }
        }
    }
    // corner grazes are rare: at most 0.1 % of the 99 050 beams
    assert!(corners <= 99, "{corners} corner cases");
}

#[test]
fn edits_open_and_close_a_door() {
    let mut m = Map {
        w: 200,
        h: 100,
        res: 0.05,
        origin: [0.0, 0.0],
        occ: vec![false; 200 * 100],
    };
    for r in 0..100 {
        if !(40..60).contains(&r) {
            m.set(100, r, true);
        }
    }
    let mut rm = m.raymap();
    let p = [2.0, 2.5];
    assert!(rm.cast(p, 0.0, 20.0).is_infinite(), "open door");
    let door: Vec<(usize, usize, bool)> = (40..60).map(|r| (100, r, true)).collect();
    rm.set_cells(&door);
    for &(c, r, v) in &door {
        m.set(c, r, v);
    }
    assert!((rm.cast(p, 0.0, 20.0) - 3.0).abs() < 1e-4, "closed door");
    let mut rng = XorShift(3);
    for _ in 0..2000 {
        let p = random_free_point(&m, &mut rng);
        let a = rng.f() * 2.0 * PI;
        assert!(agree(rm.cast(p, a, 20.0), m.dda(p, a, 20.0)));
    }
    // whole scans (the face sweep) see the edit too
    for _ in 0..20 {
        let p = random_free_point(&m, &mut rng);
        let mut out = vec![0.0; 720];
        let inc = 2.0 * PI / 720.0;
        rm.cast_scan(p, -PI, inc, 20.0, &mut out);
        for (k, r) in out.iter().enumerate() {
            assert!(agree(*r, m.dda(p, -PI + k as f32 * inc, 20.0)), "beam {k}");
        }
    }
    let open: Vec<(usize, usize, bool)> = (40..60).map(|r| (100, r, false)).collect();
    rm.set_cells(&open);
    assert!(rm.cast(p, 0.0, 20.0).is_infinite(), "open again");
    assert!(rm.is_occupied(100, 10) && !rm.is_occupied(100, 50));
}

#[test]
fn edge_cases() {
    let m = square_room();
    let rm = m.raymap();
    // inside an obstacle
    assert_eq!(rm.cast([0.0, 5.0], 0.3, 20.0), 0.0);
    assert_eq!(m.dda([0.0, 5.0], 0.3, 20.0), 0.0);
    // origin outside the grid, looking in and looking away
    let r = rm.cast([-5.0, 5.0], 0.0, 20.0);
    assert!((r - 4.9).abs() < 1e-3, "{r}");
    assert!(rm.cast([-5.0, 5.0], PI, 20.0).is_infinite());
    // max range cut-off
    assert!(rm.cast([5.0, 5.0], 0.0, 4.0).is_infinite());
    assert!((rm.cast([5.0, 5.0], 0.0, 4.95) - 4.9).abs() < 1e-4);
}

/// Every beam of the fan `start + k·inc` reads, within 1 mm, the distance `exact(dx, dy)` gives
/// for its direction (in f64; +Inf for a miss), unless `exact` calls the beam grazing.
fn assert_beams_agree(out: &[f32], start: f32, inc: f32, exact: impl Fn(f64, f64) -> (f64, bool)) {
    for (k, &got) in out.iter().enumerate() {
        let (dy, dx) = (start as f64 + k as f64 * inc as f64).sin_cos();
        let (want, grazing) = exact(dx, dy);
        assert!(
            grazing
                || (got.is_infinite() && want.is_infinite())
                || (got as f64 - want).abs() < 1e-3,
            "{} beams from {start} by {inc}, beam {k}: {got} against {want}",
            out.len()
        );
    }
}

/// Fans of up to half a turn skip circles wholly behind the sensor without missing one: every
/// beam agrees with the analytic distance to the nearest circle, also for circles just behind,
/// on or just in front of the line across the fan's central direction.
#[test]
fn half_turn_fans_see_every_circle_in_front() {
    let mut rng = crate::core::stream_rng(7, "overlay", "circles");
    let mut next = || rand::RngExt::random::<f32>(&mut rng);
    for (n, fov) in [(181usize, PI), (91, PI / 2.0), (181, PI - 1e-3)] {
        let inc = fov / (n - 1) as f32;
        for _ in 0..200 {
            let start = next() * 2.0 * PI - PI;
            let (s, c) = (start + fov / 2.0).sin_cos();
            let p = [next() * 4.0 - 2.0, next() * 4.0 - 2.0];
            // circles placed relative to the line across the central direction: behind it,
            // straddling it, in front of it, at every lateral offset
            let circles: Vec<[f32; 3]> = (0..12)
                .map(|_| {
                    let r = 0.1 + next() * 0.4;
                    let ahead = -r + (next() - 0.5) * 0.02 + (next() - 0.5) * 2.0 * next();
                    let side = (next() - 0.5) * 16.0;
                    [p[0] + ahead * c - side * s, p[1] + ahead * s + side * c, r]
                })
                .filter(|&[x, y, r]| (x - p[0]).hypot(y - p[1]) > r + 0.01)
                .collect();
            let mut out = vec![f32::INFINITY; n];
            overlay_circles(p, start, inc, &mut out, &circles);
            assert_beams_agree(&out, start, inc, |dx, dy| {
                let mut want = f64::INFINITY;
                let mut grazing = false;
                for &[x, y, r] in &circles {
                    let (vx, vy) = ((x - p[0]) as f64, (y - p[1]) as f64);
                    let b = dx * vx + dy * vy;
                    let disc = b * b - (vx * vx + vy * vy - (r * r) as f64);
                    grazing |= disc.abs() < 1e-3;
                    if disc >= 0.0 && b - disc.sqrt() >= 0.0 {
                        want = want.min(b - disc.sqrt());
                    }
                }
                (want, grazing)
            });
        }
    }
}

/// Every beam that crosses a segment reads its distance, whatever the fan and wherever the
/// segment: the beam intervals come from an approximate arctangent, so none may fall short.
#[test]
fn fans_see_every_segment_they_cross() {
    let mut rng = crate::core::stream_rng(7, "overlay", "segments");
    let mut next = || rand::RngExt::random::<f32>(&mut rng);
    for (n, fov) in [(181usize, PI), (1081, 1.5 * PI), (360, 2.0 * PI - 0.01)] {
        let inc = fov / (n - 1) as f32;
        for _ in 0..100 {
            let start = next() * 2.0 * PI - PI;
            let p = [next() * 4.0 - 2.0, next() * 4.0 - 2.0];
            let segments: Vec<[f32; 4]> = (0..8)
                .map(|_| {
                    let (x, y) = (p[0] + (next() - 0.5) * 12.0, p[1] + (next() - 0.5) * 12.0);
                    let (a, l) = (next() * 2.0 * PI, 0.05 + next() * 1.5);
                    [x, y, x + l * a.cos(), y + l * a.sin()]
                })
                .collect();
            let mut out = vec![f32::INFINITY; n];
            overlay_segments(p, start, inc, &mut out, &segments);
            assert_beams_agree(&out, start, inc, |dx, dy| {
                let mut want = f64::INFINITY;
                let mut grazing = false;
                for &[x0, y0, x1, y1] in &segments {
                    let (ax, ay) = ((x0 - p[0]) as f64, (y0 - p[1]) as f64);
                    let (ex, ey) = ((x1 - x0) as f64, (y1 - y0) as f64);
                    let den = dx * ey - dy * ex;
                    if den.abs() < 1e-9 {
                        grazing = true;
                        continue;
                    }
                    let t = (ax * ey - ay * ex) / den;
                    let u = (ax * dy - ay * dx) / den;
                    grazing |= t >= 0.0 && (u.abs() < 1e-3 || (u - 1.0).abs() < 1e-3);
                    if t >= 0.0 && (0.0..=1.0).contains(&u) {
                        want = want.min(t);
                    }
                }
                (want, grazing)
            });
        }
    }
}

#[test]
fn circles_and_segments_overlay_analytically() {
    // full 360° scan starting at -π; a circle behind the sensor (across the ±π wrap)
    let n = 720;
    let inc = 2.0 * PI / n as f32;
    let mut out = vec![f32::INFINITY; n];
    overlay_circles([0.0, 0.0], -PI, inc, &mut out, &[[-3.0, 0.0, 0.5]]);
    assert!((out[0] - 2.5).abs() < 1e-4, "{}", out[0]);
    let hit: Vec<usize> = (0..n).filter(|&k| out[k].is_finite()).collect();
    let half = (0.5f32 / 3.0).asin();
    let expected = (2.0 * half / inc).floor() as usize;
    assert!(
        hit.len() >= expected && hit.len() <= expected + 2,
        "{}",
        hit.len()
    );
    // beam at angle 0 misses it
    assert!(out[n / 2].is_infinite());
    // a farther obstacle does not override a nearer reading
    let mut out = vec![1.0; n];
    overlay_circles([0.0, 0.0], -PI, inc, &mut out, &[[3.0, 0.0, 0.5]]);
    assert_eq!(out[n / 2], 1.0);
    // segment across the +x axis at x = 2, seen by a 270° scan starting at -135°
    let inc = 0.25f32.to_radians();
    let mut out = vec![f32::INFINITY; 1081];
    overlay_segments(
        [0.0, 0.0],
        -0.75 * PI,
        inc,
        &mut out,
        &[[2.0, -1.0, 2.0, 1.0]],
    );
    for (k, r) in out.iter().enumerate() {
        let a = -0.75 * PI + k as f32 * inc;
        let want = if a.tan().abs() <= 0.5 && a.cos() > 0.0 {
            2.0 / a.cos()
        } else {
            f32::INFINITY
        };
        assert!(
            agree(*r, want) || (a.tan().abs() - 0.5).abs() < 1e-3,
            "beam {k}: {r} vs {want}"
        );
    }
    // segment behind the sensor is seen by a 360° scan only
    let mut out = vec![f32::INFINITY; 1081];
    overlay_segments(
        [0.0, 0.0],
        -0.75 * PI,
        inc,
        &mut out,
        &[[-2.0, -1.0, -2.0, 1.0]],
    );
    assert!(out.iter().all(|r| r.is_infinite()));
    let mut out = vec![f32::INFINITY; 1440];
    overlay_segments(
        [0.0, 0.0],
        0.0,
        2.0 * PI / 1440.0,
        &mut out,
        &[[-2.0, -1.0, -2.0, 1.0]],
    );
    assert!((out[720] - 2.0).abs() < 1e-4);
    // sensor inside a circle
    let mut out = vec![5.0; 10];
    overlay_circles([0.0, 0.0], 0.0, 0.1, &mut out, &[[0.1, 0.0, 0.3]]);
    assert!(out.iter().all(|r| *r == 0.0));
}

#[test]
fn batched_rays_agree_with_the_cell_walk() {
    let m = random_map(5);
    let rm = m.raymap();
    let mut rng = XorShift(11);
    // free origins, and every fourth anywhere around the map: inside obstacles or outside it
    let rays: Vec<([f32; 2], f32)> = (0..8000)
        .map(|i| {
            let p = if i % 4 == 0 {
                [
                    m.origin[0] - 4.0 + rng.f() * 28.0,
                    m.origin[1] - 4.0 + rng.f() * 23.0,
                ]
            } else {
                random_free_point(&m, &mut rng)
            };
            (p, rng.f() * 2.0 * PI - PI)
        })
        .collect();
    let mut corners = 0;
    for max in [0.3, 4.0, 40.0] {
        let mut out = vec![-1.0; rays.len()];
        rm.cast_many(&rays, max, &mut out);
        for (&(p, a), &r) in rays.iter().zip(&out) {
            assert!(
                agree_or_corner(&m, p, a, max, r, &mut corners),
                "ray from {p:?} at {a}: {r} vs {}",
                m.dda(p, a, max)
            );
        }
    }
    assert!(corners <= 3, "{corners} corner cases");
    rm.cast_many(&[], 5.0, &mut []);
}

/// The AVX2 stream kernel gives every ray the scalar kernel's answer, to the bit (±0 aside):
/// free origins, origins in obstacles and outside the map, short and long rays, batches that
/// do not fill the vectors, and a ray along a cell boundary beside a wall.
#[test]
fn stream_avx2_matches_scalar() {
    let m = random_map(9);
    let fast = m.raymap();
    if !fast.stream_avx2() {
        eprintln!("no AVX2 on this machine: one kernel only");
        return;
    }
    let slow = m.raymap().without_avx2();
    let mut rng = XorShift(23);
    let mut rays: Vec<([f32; 2], f32)> = (0..20_000)
        .map(|i| {
            let p = if i % 3 == 0 {
                [
                    m.origin[0] - 4.0 + rng.f() * 28.0,
                    m.origin[1] - 4.0 + rng.f() * 23.0,
                ]
            } else {
                random_free_point(&m, &mut rng)
            };
            // axis-aligned directions too (a step sign of zero)
            let a = if i % 7 == 0 {
                (i % 4) as f32 * PI / 2.0 - PI
            } else {
                rng.f() * 2.0 * PI - PI
            };
            (p, a)
        })
        .collect();
    rays.push(([f32::NAN, 1.0], 0.3));
    rays.push(([m.origin[0] + 7.0, m.origin[1] + 5.0], 0.0));
    for max in [0.2, 3.0, 40.0] {
        for n in [rays.len(), 1, 7, 9, 17, 100] {
            let (mut a, mut b) = (vec![-1.0; n], vec![-2.0; n]);
            fast.cast_many(&rays[..n], max, &mut a);
            slow.cast_many(&rays[..n], max, &mut b);
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                assert!(
                    x == y || (x.is_nan() && y.is_nan()),
                    "ray {i} {:?}, max {max}: AVX2 {x} scalar {y}",
                    rays[i]
                );
            }
        }
    }
}

#[test]
fn scans_beyond_the_sweep_reach_or_from_outside_fall_back_to_rays() {
    // 2 mm cells: the face sweep reaches about 8 m, so a 10 m scan goes ray by ray
    let mut m = random_map(3);
    m.res = 0.002;
    let rm = m.raymap();
    let mut rng = XorShift(5);
    let n = 721;
    let inc = PI / 360.0;
    let mut out = vec![0.0; n];
    let outside = [m.origin[0] - 0.5, m.origin[1] + 0.3];
    let mut corners = 0;
    for p in (0..20)
        .map(|_| random_free_point(&m, &mut rng))
        .chain([outside])
    {
        for max in [10.0, 2.0] {
            rm.cast_scan(p, -PI, inc, max, &mut out);
            for (k, r) in out.iter().enumerate() {
                let a = -PI + k as f32 * inc;
                assert!(
                    agree_or_corner(&m, p, a, max, *r, &mut corners),
                    "beam {k} from {p:?}: {r}"
                );
            }
        }
    }
    assert!(corners <= 30, "{corners} corner cases");
}

#[test]
fn segment_traversal_visits_exactly_the_crossed_cells() {
    let (w, h, res, origin) = (13usize, 9usize, 0.3f32, [-1.0f32, 0.5f32]);
    let cell = |x: f32, y: f32| {
        (
            ((x - origin[0]) / res).floor() as i32,
            ((y - origin[1]) / res).floor() as i32,
        )
    };
    let inside = |c: (i32, i32)| c.0 >= 0 && c.1 >= 0 && c.0 < w as i32 && c.1 < h as i32;
    let mut rng = XorShift(23);
    let (mut full, mut clipped) = (0, 0);
    for _ in 0..4000 {
        // start and end anywhere in a margin around the grid
        let p = [
            origin[0] - 1.0 + rng.f() * (w as f32 * res + 2.0),
            origin[1] - 1.0 + rng.f() * (h as f32 * res + 2.0),
        ];
        let a = rng.f() * 2.0 * PI - PI;
        let len = rng.f() * 5.0;
        let dir = [a.cos(), a.sin()];
        let e = [p[0] + dir[0] * len, p[1] + dir[1] * len];
        let mut seen = Vec::new();
        let end = traverse_segment(w, h, res, origin, p, dir, len, |i| seen.push(i));
        let to_cell = |i: usize| ((i % w) as i32, (i / w) as i32);
        let mut chain: Vec<(i32, i32)> = seen.iter().map(|&i| to_cell(i)).collect();
        // the end cell is returned exactly when the end point is inside the grid
        assert_eq!(end.is_some(), inside(cell(e[0], e[1])), "{p:?} {a} {len}");
        if let Some(i) = end {
            assert_eq!(to_cell(i), cell(e[0], e[1]));
            chain.push(to_cell(i));
        }
        // consecutive cells are 4-neighbours (each boundary crossed once, no cell skipped)
        for pair in chain.windows(2) {
            let d = (pair[1].0 - pair[0].0).abs() + (pair[1].1 - pair[0].1).abs();
            assert_eq!(d, 1, "{p:?} {a} {len}: {chain:?}");
        }
        // a start inside the grid: the chain runs from the start cell to the end cell
        if inside(cell(p[0], p[1])) && end.is_some() {
            full += 1;
            let (s, t) = (cell(p[0], p[1]), cell(e[0], e[1]));
            assert_eq!(chain[0], s);
            assert_eq!(seen.len() as i32, (t.0 - s.0).abs() + (t.1 - s.1).abs());
        } else if !chain.is_empty() {
            clipped += 1;
        }
        // every point of the segment inside the grid lies in a listed cell
        for k in 0..=200 {
            let t = len * k as f32 / 200.0;
            let c = cell(p[0] + dir[0] * t, p[1] + dir[1] * t);
            if inside(c) {
                assert!(chain.contains(&c), "{p:?} {a} {len}: {c:?} missing");
            }
        }
    }
    assert!(full > 300 && clipped > 300, "{full} {clipped}");
}

/// A ray running along a cell boundary next to a wall (hospital_patrol seed 15, a DE filter
/// member): the boundary it crosses lies a rounding error behind it, and the walk used to cycle
/// between two cells for ever. Both walks now end, and agree.
#[test]
fn a_ray_along_a_cell_boundary_beside_a_wall_ends() {
    let (w, h) = (1280, 640);
    let mut occupied = vec![false; w * h];
    for c in 0..w {
        occupied[518 * w + c] = true;
    }
    let rm = RayMap::new(w, h, 0.05, [0.0, 0.0], &occupied);
    let (p, dx, dy) = ([12.828864f32, 25.85018f32], 1.0f32, -3.8027763e-5f32);
    let angle = dy.atan2(dx);
    let mut out = [0.0f32];
    rm.cast_many(&[(p, angle)], 20.0, &mut out);
    let one = rm.cast(p, angle, 20.0);
    assert_eq!(out[0].to_bits(), one.to_bits());
    assert_eq!(one.to_bits(), rm.cast_plain(p, angle, 20.0).to_bits());
    assert_eq!(one, f32::INFINITY, "the ray runs below the wall to its end");
}

/// The single-ray walk computes in cell units (see `leap::InCells`): on a large map its ranges
/// still agree with the cell walk in metres, apart from the corner cases and a few grazing hits
/// (a wall met at hundredths of a degree) that land a few millimetres away.
#[test]
fn single_rays_on_a_large_map_agree_with_dda_to_millimetres() {
    let m = Map::hospital(2, 1);
    let rm = m.raymap();
    let mut rng = XorShift(11);
    let (mut corners, mut grazing, mut mismatches) = (0, 0, 0);
    for _ in 0..300_000 {
        // anywhere on the map, free or not, and a little beyond its edges
        let x = m.origin[0] - 2.0 + rng.f() * (m.w as f32 * m.res + 4.0);
        let y = m.origin[1] - 2.0 + rng.f() * (m.h as f32 * m.res + 4.0);
        let a = rng.f() * 2.0 * PI - PI;
        let r = rm.cast([x, y], a, 30.0);
        if agree_or_corner(&m, [x, y], a, 30.0, r, &mut corners) {
            continue;
        }
        if (r - m.dda([x, y], a, 30.0)).abs() < 0.01 {
            grazing += 1;
        } else {
            mismatches += 1;
        }
    }
    assert_eq!(mismatches, 0);
    assert!(grazing <= 5, "{grazing} grazing hits off by 1–10 mm");
    assert!(corners <= 30, "{corners} corner cases");
}

/// `RayMap::cast` (the walk of `leap::Single`) gives every ray the plain walk's answer to the
/// bit, signed zeros included: the hospital map and a random one; free origins, origins in
/// walls, outside the map and on cell boundaries; every octant, the axes and the diagonals;
/// ranges from zero to infinite.
#[test]
fn single_rays_match_the_plain_walk_to_the_bit() {
    for m in [Map::hospital(1, 1), random_map(13)] {
        let rm = m.raymap();
        let mut rng = XorShift(31);
        let (wf, hf) = (m.w as f32 * m.res, m.h as f32 * m.res);
        let mut rays: Vec<([f32; 2], f32, f32)> = (0..300_000)
            .map(|i| {
                let p = match i % 4 {
                    0 | 1 => random_free_point(&m, &mut rng),
                    // anywhere, and a little beyond the edges: in walls, outside the map
                    2 => [
                        m.origin[0] - 2.0 + rng.f() * (wf + 4.0),
                        m.origin[1] - 2.0 + rng.f() * (hf + 4.0),
                    ],
                    // on a cell boundary, or on a corner
                    _ => {
                        let c = (rng.f() * m.w as f32) as usize;
                        let r = (rng.f() * m.h as f32) as usize;
                        let y = if i % 8 == 3 { 0.0 } else { rng.f() };
                        [
                            m.origin[0] + c as f32 * m.res,
                            m.origin[1] + (r as f32 + y) * m.res,
                        ]
                    }
                };
                let a = if i % 5 == 0 {
                    (i / 5 % 8) as f32 * PI / 4.0 - PI
                } else {
                    rng.f() * 2.0 * PI - PI
                };
                let max = [20.0, 0.0, 0.04, 3.0, 1e30, f32::INFINITY, 0.3][i % 7];
                (p, a, max)
            })
            .collect();
        rays.extend([
            ([f32::NAN, 1.0], 0.3, 20.0),
            ([1.0, 1.0], f32::NAN, 20.0),
            ([1.0, f32::INFINITY], 0.3, 20.0),
            ([m.origin[0] + 3.0, m.origin[1] + 2.0], 1e-13, 20.0),
        ]);
        let mut negative_zeros = 0;
        for &(p, a, max) in &rays {
            let (fast, plain) = (rm.cast(p, a, max), rm.cast_plain(p, a, max));
            assert!(
                fast.to_bits() == plain.to_bits() || (fast.is_nan() && plain.is_nan()),
                "ray from {p:?} at {a}, max {max}: {fast} against the plain walk's {plain}"
            );
            negative_zeros += (plain.to_bits() == (-0.0f32).to_bits()) as usize;
        }
        // rays from a boundary into the wall behind it answer −0: signed zeros were compared
        assert!(negative_zeros > 0);
    }
}
