//! Single rays (`RayMap::cast`) and the segment traversal against the plain walk.

use super::*;

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
