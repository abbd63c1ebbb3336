//! Loading (validating, checksum included) the embedded default tables, and expanding a compact
//! table's grids (what the first plan that needs them pays).
//!
//! `cargo bench -p subtess --bench table_load`
//!
//! `load default table (SCHEME)` is the public call. `expand every grid` builds a fresh
//! Catmull–Clark table and asks it for every section of the grid layout (27 patches x 24 rates x
//! 3 kinds x 2 grids: what the version-3 table stored), the most any sequence of plans can ask;
//! `expand one patch at rate N` is the three kinds of one valence-5 patch, both grids. The
//! `(loop)` ones do the same with the default Loop table (31 patches: valences 3..=12, boundary
//! vertices with 1..=6 triangles). The `(butterfly)` and `(sqrt3)` ones expand the default
//! region tables (46 regions: the nine of valences 3, 4, 5, 7, 8 and region 0 of valence 6;
//! the 28,518,480 weights of the version-4 grid layout at n = 1..=24); their one-patch rows
//! are the nine regions of valence 5 (a plan reads all of a valence's regions), both grids,
//! three kinds.
#![allow(missing_docs)] // criterion_group! generates an undocumented function

use criterion::{criterion_group, criterion_main, Criterion};
use subtess::stencil_table::StencilTable;
use subtess::{BoundaryMode, Scheme};
use table_format::{PointSet, SectionKey, StencilKind};

/// Every patch of a table of the default coverage, interior valences `3..=max_valence`:
/// `(boundary, faces, sector)`.
fn patches(max_valence: u32) -> Vec<(bool, u32, u32)> {
    let interior = (3..=max_valence).map(|v| (false, v, 0));
    let boundary = (1..=6).flat_map(|f| (0..f).map(move |s| (true, f, s)));
    interior.chain(boundary).collect()
}

/// The grid point sets of a quad table, then of a triangle table.
const QUAD: [PointSet; 2] = [PointSet::Primal, PointSet::Dual];
const TRIANGLE: [PointSet; 2] = [PointSet::TrianglePrimal, PointSet::TriangleDual];

fn grids(
    table: &StencilTable,
    patches: &[(bool, u32, u32)],
    rates: &[u32],
    point_sets: [PointSet; 2],
) -> usize {
    let mut weights = 0;
    for &(boundary, faces, sector) in patches {
        for &n in rates {
            for kind in [
                StencilKind::Position,
                StencilKind::DerivativeU,
                StencilKind::DerivativeV,
            ] {
                for points in point_sets {
                    let key = SectionKey {
                        kind,
                        points,
                        boundary,
                        feature: table_format::Feature::None,
                        faces,
                        sector,
                        n,
                    };
                    weights += table.weights(&key).map_or(0, <[f32]>::len);
                }
            }
        }
    }
    weights
}

fn bench(c: &mut Criterion) {
    let schemes = [
        Scheme::CatmullClark,
        Scheme::Loop,
        Scheme::Butterfly,
        Scheme::Sqrt3,
    ];
    for scheme in schemes {
        // Timing an error would measure nothing (a table the reader refuses fails in
        // nanoseconds).
        if let Err(e) = scheme.default_table(BoundaryMode::EdgeOnly) {
            panic!("the embedded {scheme} table does not load: {e}");
        }
        c.bench_function(&format!("load default table ({scheme})"), |b| {
            b.iter(|| {
                scheme
                    .default_table(BoundaryMode::EdgeOnly)
                    .map(|t| t.index().entries.len())
            })
        });
    }
    let rates: Vec<u32> = (1..=24).collect();
    let mut group = c.benchmark_group("expand");
    group.sample_size(10);
    let fresh = || StencilTable::default_catmull_clark().expect("loads");
    let all = patches(8);
    assert_eq!(grids(&fresh(), &all, &rates, QUAD), 14_791_656);
    group.bench_function("expand every grid of the default table", |b| {
        b.iter(|| grids(&fresh(), &all, &rates, QUAD))
    });
    for n in [8, 24] {
        group.bench_function(format!("expand one patch at rate {n}"), |b| {
            b.iter(|| grids(&fresh(), &[(false, 5, 0)], &[n], QUAD))
        });
    }
    let fresh = || StencilTable::default_loop().expect("loads");
    let all = patches(12);
    assert_eq!(grids(&fresh(), &all, &rates, TRIANGLE), 8_473_392);
    group.bench_function("expand every grid of the default table (loop)", |b| {
        b.iter(|| grids(&fresh(), &all, &rates, TRIANGLE))
    });
    for n in [8, 24] {
        group.bench_function(format!("expand one patch at rate {n} (loop)"), |b| {
            b.iter(|| grids(&fresh(), &[(false, 5, 0)], &[n], TRIANGLE))
        });
    }
    for scheme in [Scheme::Butterfly, Scheme::Sqrt3] {
        let fresh = || scheme.default_table(BoundaryMode::EdgeOnly).expect("loads");
        let regions = |k: u32| (0..if k == 6 { 1 } else { 9 }).map(move |r| (false, k, r));
        let all: Vec<(bool, u32, u32)> = (3..=8).flat_map(regions).collect();
        assert_eq!(grids(&fresh(), &all, &rates, TRIANGLE), 28_518_480);
        group.bench_function(
            format!("expand every grid of the default table ({scheme})"),
            |b| b.iter(|| grids(&fresh(), &all, &rates, TRIANGLE)),
        );
        let five: Vec<(bool, u32, u32)> = regions(5).collect();
        for n in [8, 24] {
            group.bench_function(format!("expand one valence at rate {n} ({scheme})"), |b| {
                b.iter(|| grids(&fresh(), &five, &[n], TRIANGLE))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
