//! Map pyramid tests: interpolation and gradient, combine rules, corner samples, and windowed
//! updates against full rebuilds.

use super::*;
use crate::core::stream_rng;
use rand::RngExt;

fn grid(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> ProbGrid {
    let mut g = ProbGrid::new(w, h, 0.1, [-1.0, 2.0], 0.0);
    for r in 0..h {
        for c in 0..w {
            g.p[r * w + c] = f(c, r);
        }
    }
    g
}

#[test]
fn map_pyramid_sample_interpolates_between_centres_with_its_gradient() {
    let g = grid(5, 4, |c, r| ((c * 7 + r * 3) % 5) as f32 / 4.0);
    let p = MapPyramid::with_options(&g, 1, PyramidOptions::slam_map());
    let l = p.level(0);
    // at a centre: the cell's value; at the middle of four centres: their mean
    let s = l.sample(-1.0 + 2.5 * 0.1, 2.0 + 1.5 * 0.1).unwrap();
    assert!((s.value - g.get(2, 1) as f64).abs() < 1e-6);
    let s = l.sample(-1.0 + 0.2, 2.0 + 0.2).unwrap();
    let mean = (g.get(1, 2) + g.get(2, 2) + g.get(1, 1) + g.get(2, 1)) as f64 / 4.0;
    assert!((s.value - mean).abs() < 1e-6);
    // the gradient is the derivative of the value (eqs. 2–3), per metre
    let mut rng = stream_rng(1, "map-pyramid", "gradient");
    for _ in 0..100 {
        let x = rng.random_range(-0.93..-0.57);
        let y = rng.random_range(2.07..2.33);
        let (s, h) = (l.sample(x, y).unwrap(), 1e-6);
        let dx =
            (l.sample(x + h, y).unwrap().value - l.sample(x - h, y).unwrap().value) / (2.0 * h);
        let dy =
            (l.sample(x, y + h).unwrap().value - l.sample(x, y - h).unwrap().value) / (2.0 * h);
        assert!((dx - s.gradient[0]).abs() < 1e-4 && (dy - s.gradient[1]).abs() < 1e-4);
    }
    // off the centres' hull, or not a number: nothing
    assert!(l.sample(-1.0 + 0.04, 2.2).is_none());
    assert!(l.sample(-1.0 + 0.47, 2.2).is_none());
    assert!(l.sample(f64::NAN, 2.2).is_none());
}

#[test]
fn map_pyramid_max_keeps_thin_walls_and_mean_fades_them() {
    // a one-cell wall in column 5 of a free 16 × 16 grid
    let g = grid(16, 16, |c, _| if c == 5 { 1.0 } else { 0.0 });
    let unsmoothed = |combine| PyramidOptions {
        combine,
        smoothing: 0,
        ..PyramidOptions::slam_map()
    };
    let max = MapPyramid::with_options(&g, 3, unsmoothed(Combine::Max));
    let mean = MapPyramid::with_options(&g, 3, unsmoothed(Combine::Mean));
    for k in 0..3 {
        let top = |p: &MapPyramid| p.level(k).m.iter().cloned().fold(0f32, f32::max);
        assert_eq!(top(&max), 1.0);
        assert_eq!(top(&mean), 0.5f32.powi(k as i32));
        assert_eq!(max.level(k).resolution, 0.1 * (1 << k) as f64);
    }
    // max-preserving smoothing keeps the ridge at 1 and gives it slopes
    let smooth = MapPyramid::with_options(&g, 2, PyramidOptions::slam_map());
    let row = &smooth.level(1).m[..8];
    assert_eq!(row[2], 1.0);
    // three passes reach three coarse cells
    assert!(row[0] > 0.0 && row[1] > row[0] && row[3] > row[4] && row[5] > 0.0 && row[6] == 0.0);
}

#[test]
fn map_pyramid_on_faces_peaks_where_beams_end() {
    // a 2 × 2 block, cells (3..5, 2..4), in free space: M is 1 on its faces, 0 at its centre
    // and away from it
    let g = grid(8, 6, |c, r| {
        if (3..5).contains(&c) && (2..4).contains(&r) {
            1.0
        } else {
            0.0
        }
    });
    let p = MapPyramid::with_options(&g, 1, PyramidOptions::static_map());
    let l = p.level(0);
    assert_eq!((l.width, l.height), (9, 7));
    let m = |x: f64, y: f64| l.sample(-1.0 + x, 2.0 + y).unwrap().value;
    for (x, y) in [(0.3, 0.23), (0.5, 0.37), (0.34, 0.2), (0.46, 0.4)] {
        assert!((m(x, y) - 1.0).abs() < 1e-6, "face ({x}, {y}): {}", m(x, y));
    }
    assert!(m(0.4, 0.3).abs() < 1e-6);
    assert!(m(0.15, 0.3).abs() < 1e-6);
    assert!((m(0.35, 0.3) - 0.5).abs() < 1e-6);
}

#[test]
fn map_pyramid_windowed_update_equals_a_rebuild() {
    let mut rng = stream_rng(2, "map-pyramid", "update");
    for (surfaces, smoothing) in [
        (Surfaces::InCells, 0),
        (Surfaces::InCells, 3),
        (Surfaces::OnFaces, 2),
    ] {
        let options = PyramidOptions {
            surfaces,
            combine: Combine::Max,
            smoothing,
        };
        // odd sizes exercise the edges
        let mut g = grid(61, 45, |c, r| if (c * r) % 11 == 0 { 1.0 } else { 0.0 });
        let mut p = MapPyramid::with_options(&g, 4, options);
        for _ in 0..30 {
            let (c0, r0) = (rng.random_range(0..61), rng.random_range(0..45));
            let (c1, r1) = (
                (c0 + rng.random_range(1..6)).min(61),
                (r0 + rng.random_range(1..6)).min(45),
            );
            for r in r0..r1 {
                for c in c0..c1 {
                    g.p[r * 61 + c] = rng.random_range(0.0..1.0);
                }
            }
            p.update_region(&g, c0, r0, c1, r1);
            assert_eq!(p, MapPyramid::with_options(&g, 4, options), "{options:?}");
        }
        // scattered cells, binned into tiles
        let cells: Vec<(usize, usize)> = (0..40)
            .map(|_| (rng.random_range(0..70), rng.random_range(0..50)))
            .collect();
        for &(c, r) in &cells {
            if c < 61 && r < 45 {
                g.p[r * 61 + c] = rng.random_range(0.0..1.0);
            }
        }
        p.update_cells(&g, &cells);
        assert_eq!(p, MapPyramid::with_options(&g, 4, options), "{options:?}");
        let before = p.clone();
        p.rebuild(&g);
        assert_eq!(p, before);
    }
}
