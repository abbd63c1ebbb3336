//! Loading (validating, checksum included) the embedded default table.
//!
//! `cargo bench -p subtess --bench table_load`
//!
//! `load default table` is the public call; the table's bytes are a constant, so the same parse
//! with the bytes behind `black_box` is measured too (the optimizer cannot see through it), and
//! the two checksums alone: format version 3's (every byte but its own, streamed in two runs)
//! beside version 2's (the bytes after the 64-byte header, one shot) over the same bytes.
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use subtess::stencil_table::StencilTable;

fn bench(c: &mut Criterion) {
    // Timing an error would measure nothing (a table the reader refuses fails in nanoseconds).
    if let Err(e) = StencilTable::default_catmull_clark() {
        panic!("the embedded default table does not load: {e}");
    }
    c.bench_function("load default table", |b| {
        b.iter(|| StencilTable::default_catmull_clark().map(|t| t.index().entries.len()))
    });
    let bytes = tables::default_catmull_clark();
    c.bench_function("parse default table (black_box bytes)", |b| {
        b.iter(|| table_format::TableIndex::parse(black_box(bytes)).map(|t| t.entries.len()))
    });
    c.bench_function("checksum v3 (all but its own 8 bytes)", |b| {
        b.iter(|| table_format::checksum(black_box(bytes)))
    });
    c.bench_function("checksum v2 range (bytes 64..)", |b| {
        b.iter(|| xxhash_rust::xxh3::xxh3_64(&black_box(bytes)[table_format::HEADER_SIZE..]))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
