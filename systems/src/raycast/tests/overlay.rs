//! Circles and segments overlaid on a scan against their analytic distances.

use super::*;

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
