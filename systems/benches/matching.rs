//! Scan matching on realistic scans: 1081-beam SICK LMS100 scans (270°, 0.25°, 0.5–20 m, 12 mm
//! range noise) ray-cast on the hospital map, a pair like the experiment's 10-step pairs
//! (`sim experiment de-match`: ~0.7 m and up to ~17° apart).
//!
//! * `improved` — one whole alignment by the improved matcher (±3 m, ±180°);
//! * `thesis_de` — the thesis's DE (rand/1, binomial, population 20, F 0.5, CR 0.9, §7.2) with
//!   the raster correlation fitness (eq. 29) for a fixed 200 generations (no early stop);
//! * `fitness` — one evaluation of each fitness kernel of the [Hospital thesis]: the raster
//!   correlation (eq. 29), the Euclidean reference on a distance field (5 cm cells) and brute
//!   force (§7.1); throughput is evaluations/s, over a fixed set of candidate transforms.
//!
//! Short on purpose (few samples, a few seconds each): `cargo bench -p systems --bench matching`.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;
use systems::core::{Pose2, SimRng, stream_rng};
use systems::matching::{
    CorrelationFitness, Crossover, DeParams, EuclideanField, MatchConfig, RasterSpec, Strategy,
    ThesisFitness, euclidean_brute, match_scans, scan_to_points,
};
use systems::raycast::RayMap;
use systems::world::{Cell, OccupancyGrid, load_map};

const BEAMS: usize = 1081;

struct Hospital {
    grid: OccupancyGrid,
    map: RayMap,
}

impl Hospital {
    fn load() -> Hospital {
        let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
        let grid = load_map(&path).expect("the hospital map loads");
        let map = RayMap::new(
            grid.width,
            grid.height,
            grid.resolution as f32,
            [grid.origin[0] as f32, grid.origin[1] as f32],
            &grid.obstacles(),
        );
        Hospital { grid, map }
    }

    fn free(&self, x: f64, y: f64) -> bool {
        self.grid
            .cell_of(x, y)
            .is_some_and(|(c, r)| self.grid.get(c, r) == Cell::Free)
            && self.grid.disc_is_clear(x, y, 0.3)
    }

    /// A SICK LMS100 scan at `pose` (sensor-frame points), 12 mm range noise.
    fn scan(&self, pose: Pose2, rng: &mut SimRng) -> Vec<[f32; 2]> {
        let (angle_min, inc) = (-135f32.to_radians(), 0.25f32.to_radians());
        let mut ranges = vec![0f32; BEAMS];
        self.map.cast_scan(
            [pose.x as f32, pose.y as f32],
            pose.theta as f32 + angle_min,
            inc,
            20.0,
            &mut ranges,
        );
        for r in ranges.iter_mut().filter(|r| r.is_finite()) {
            let n: f64 = rng.sample(StandardNormal);
            *r += (0.012 * n) as f32;
        }
        scan_to_points(angle_min, inc, &ranges, 0.5, 20.0)
    }

    /// A reference pose with a free pose 0.7 m ahead (turned by up to ±15°) in line of sight:
    /// the two scans of a 10-step pair of the experiment.
    fn driving_pair(&self, rng: &mut SimRng) -> (Pose2, Pose2) {
        let b = self.grid.bounds();
        loop {
            let (x, y) = (rng.random_range(b[0]..b[2]), rng.random_range(b[1]..b[3]));
            if !self.free(x, y) {
                continue;
            }
            let reference = Pose2::new(x, y, rng.random_range(-PI..PI));
            let turn = rng.random_range(-15f64..15.0).to_radians();
            let truth = Pose2::new(0.7 * (0.5 * turn).cos(), 0.7 * (0.5 * turn).sin(), turn);
            let current = reference.compose(&truth);
            let clear = self.map.cast(
                [x as f32, y as f32],
                (reference.theta + 0.5 * turn) as f32,
                1.0,
            );
            if self.free(current.x, current.y) && clear > 1.0 {
                return (reference, truth);
            }
        }
    }
}

struct Setup {
    reference: Vec<[f32; 2]>,
    current: Vec<[f32; 2]>,
    truth: Pose2,
    /// Candidate transforms in the ±3 m, ±180° window, for the per-evaluation benches.
    candidates: Vec<[f64; 3]>,
}

fn setup() -> Setup {
    let h = Hospital::load();
    let mut rng = stream_rng(1, "bench", "matching");
    let (pose, truth) = h.driving_pair(&mut rng);
    let reference = h.scan(pose, &mut rng);
    let current = h.scan(pose.compose(&truth), &mut rng);
    let candidates = (0..64)
        .map(|_| {
            [
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-PI..PI),
            ]
        })
        .collect();
    Setup {
        reference,
        current,
        truth,
        candidates,
    }
}

fn thesis_de(generations: usize) -> DeParams {
    DeParams {
        population: 20,
        generations,
        f: 0.5,
        cr: 0.9,
        strategy: Strategy::Rand1,
        crossover: Crossover::Binomial,
        either_or_probability: None,
        max_evaluations: None,
        time_limit: None,
        stall: None,
        collapse_tolerance: None,
        parallel: false,
    }
}

fn bench(c: &mut Criterion) {
    let s = setup();
    let improved = MatchConfig::improved();
    // the bench measures a right alignment, not a lucky early exit
    let r = match_scans(&s.reference, &s.current, &improved).expect("the pair matches");
    let (dx, dy) = (r.transform.x - s.truth.x, r.transform.y - s.truth.y);
    assert!(
        dx.hypot(dy) < 0.1
            && systems::core::wrap_angle(r.transform.theta - s.truth.theta).abs()
                < 2f64.to_radians(),
        "improved matcher found {:?}, truth {:?}",
        r.transform,
        s.truth
    );

    let mut g = c.benchmark_group("improved");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("hospital_pair_1081_beams", |b| {
        b.iter(|| match_scans(black_box(&s.reference), black_box(&s.current), &improved).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("thesis_de");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    let generations = 200;
    let de = MatchConfig::thesis(ThesisFitness::Correlation, thesis_de(generations));
    g.throughput(Throughput::Elements((20 * (generations + 1)) as u64));
    g.bench_function(
        BenchmarkId::new("rand1_correlation", format!("{generations}_generations")),
        |b| b.iter(|| match_scans(black_box(&s.reference), black_box(&s.current), &de).unwrap()),
    );
    g.finish();

    let mut g = c.benchmark_group("fitness");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    let n = s.candidates.len() as u64;
    g.throughput(Throughput::Elements(n));
    let corr = CorrelationFitness::new(&s.reference, &s.current, RasterSpec::default()).unwrap();
    g.bench_function("correlation_raster", |b| {
        b.iter(|| {
            s.candidates
                .iter()
                .map(|p| corr.correlation(black_box(p)))
                .sum::<u32>()
        })
    });
    let field = EuclideanField::new(&s.reference, 0.05, 0.5).unwrap();
    g.bench_function("euclidean_field", |b| {
        b.iter(|| {
            s.candidates
                .iter()
                .map(|p| field.sum(black_box(&s.current), p))
                .sum::<f64>()
        })
    });
    g.throughput(Throughput::Elements(4));
    g.bench_function("euclidean_brute", |b| {
        b.iter(|| {
            s.candidates[..4]
                .iter()
                .map(|p| euclidean_brute(black_box(&s.reference), &s.current, p))
                .sum::<f64>()
        })
    });
    g.finish();

    // the once-per-match set-up of the kernels
    let mut g = c.benchmark_group("fitness_setup");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    g.bench_function("correlation_raster", |b| {
        b.iter(|| {
            CorrelationFitness::new(black_box(&s.reference), &s.current, RasterSpec::default())
                .unwrap()
        })
    });
    g.bench_function("euclidean_field", |b| {
        b.iter(|| EuclideanField::new(black_box(&s.reference), 0.05, 0.5).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
