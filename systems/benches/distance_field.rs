//! The exact distance transform that the localization map's likelihood field and the navigation
//! costmaps are built with, on the hospital floor (1280 × 640 cells): `fast` (both passes over
//! rayon's threads, a blocked transpose between them) against `plain` (one line at a time).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use systems::world::distance_field::{squared_distances, squared_distances_plain};
use systems::world::map_file::load_map;

fn distance_field(c: &mut Criterion) {
    let path = systems::core::source::source_path("assets/maps/hospital/hospital.yaml");
    let grid = load_map(&path).expect("hospital map");
    let (w, h) = (grid.width, grid.height);
    let occ = |x: usize, y: usize| grid.is_obstacle(x, y);
    let mut g = c.benchmark_group("squared_distances");
    g.bench_function("fast", |b| {
        b.iter(|| black_box(squared_distances(w, h, occ)))
    });
    g.bench_function("plain", |b| {
        b.iter(|| black_box(squared_distances_plain(w, h, occ)))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .measurement_time(std::time::Duration::from_secs(3));
    targets = distance_field
}
criterion_main!(benches);
