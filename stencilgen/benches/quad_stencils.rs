//! Generating the default Catmull–Clark stencil set (interior valences 3..=8, boundary 1..=6
//! faces, n = 1..=24, primal + dual points, positions + tangents), exact and f64.
//!
//! `cargo bench -p stencilgen --bench quad_stencils`
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use criterion::{criterion_group, criterion_main, Criterion};
use num_rational::BigRational;
use schemes::QuadScheme;
use stencilgen::stencil_set::{stencil_set, StencilSetSpec};

fn bench(c: &mut Criterion) {
    let Some(cc) = QuadScheme::by_name("catmull-clark") else {
        return;
    };
    let spec = StencilSetSpec::default_catmull_clark();
    let mut group = c.benchmark_group("default catmull-clark set");
    group.sample_size(10);
    group.bench_function("f64", |b| {
        b.iter(|| stencil_set::<f64>(&cc, &spec).map(|s| s.len()))
    });
    group.sample_size(10);
    group.measurement_time(std::time::Duration::from_secs(60));
    group.bench_function("exact", |b| {
        b.iter(|| stencil_set::<BigRational>(&cc, &spec).map(|s| s.len()))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
