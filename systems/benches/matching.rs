//! Scan-matching kernels (placeholder until the DE matcher lands).

use criterion::{Criterion, criterion_group, criterion_main};

fn matching(_c: &mut Criterion) {}

criterion_group!(benches, matching);
criterion_main!(benches);
