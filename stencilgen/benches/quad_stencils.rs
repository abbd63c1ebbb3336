//! Generating the default Catmull–Clark stencil set (interior valences 3..=8, boundary 1..=6
//! faces, n = 1..=24, primal + dual points, positions + tangents) in f64. The exact set takes
//! about a minute and a half, too long for criterion's ten samples: time it with
//! `cargo run --release -p stencilgen --example default_set_timing`.
//!
//! `cargo bench -p stencilgen --bench quad_stencils`
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use criterion::{criterion_group, criterion_main, Criterion};
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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
