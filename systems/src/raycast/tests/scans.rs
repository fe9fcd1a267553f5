//! Scans, batches and the vector kernels against the cell walk; doors edited in place.

use super::*;

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
