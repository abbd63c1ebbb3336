//! Loading (validating, checksum included) the embedded default table.
//!
//! `cargo bench -p subtess --bench table_load`
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use criterion::{criterion_group, criterion_main, Criterion};
use subtess::stencil_table::StencilTable;

fn bench(c: &mut Criterion) {
    c.bench_function("load default table", |b| {
        b.iter(|| StencilTable::default_catmull_clark().map(|t| t.index().entries.len()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
