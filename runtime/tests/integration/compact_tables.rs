//! Compact quad tables (docs/table-format.md, "Compact quad tables"): the grids the runtime
//! expands from the scaling relation's pieces equal the grids `stencilgen` solves on the grid
//! (the layout the tables had before), to 1 ulp of f32, for every patch kind, rate, kind and
//! grid point. The reference is an independent computation: the whole scaling-relation system
//! of each grid solved by `stencilgen`'s orbit solver, not the substitution the runtime runs.

use stencilgen::stencil_set::StencilSetSpec;
use stencilgen::table::{build_table, QuadLayout, TableSpec};
use subtess::stencil_table::StencilTable;
use table_format::Precision;

/// How far apart two f32 weights are, in units in the last place of the larger one. Weights
/// below 2^-40 (where the f64 solves' own rounding, about 1e-16 absolute, exceeds an f32 ulp)
/// are compared at the ulp of 2^-40.
fn ulps(a: f32, b: f32) -> f64 {
    let floor = 2f32.powi(-40);
    let scale = a.abs().max(b.abs()).max(floor);
    let ulp = f64::from(f32::from_bits(scale.to_bits() + 1) - scale);
    (f64::from(a) - f64::from(b)).abs() / ulp
}

/// The embedded default (compact) against a grid table of the same patches at `rates`, solved
/// now; returns the largest difference in ulps and the number of weights compared.
fn compare(corners: bool, rates: Vec<u32>) -> (f64, usize) {
    let mut spec = if corners {
        TableSpec::default_corners()
    } else {
        TableSpec::default_catmull_clark()
    }
    .expect("spec");
    spec.set = StencilSetSpec { rates, ..spec.set };
    spec.layout = QuadLayout::Grids;
    spec.precision = Precision::F32;
    let grids = StencilTable::from_bytes(&build_table(&spec, &|_, _| {}).expect("grid table"))
        .expect("valid grid table");
    let compact = if corners {
        StencilTable::default_for(schemes::BoundaryMode::EdgeAndCorner)
    } else {
        StencilTable::default_catmull_clark()
    }
    .expect("embedded table");
    assert!(compact.is_compact() && !grids.is_compact());
    let (mut worst, mut count) = (0.0f64, 0);
    for entry in &grids.index().entries {
        let want = grids.weights(&entry.key).expect("grid section");
        let got = compact.weights(&entry.key).expect("expanded section");
        assert_eq!(got.len(), want.len(), "{}", entry.key);
        for (p, (g, w)) in got.iter().zip(want).enumerate() {
            let d = ulps(*g, *w);
            assert!(
                d <= 1.0,
                "{}: weight {p} (point {}) is {g:e} expanded, {w:e} solved: {d} ulps",
                entry.key,
                p / entry.width as usize
            );
            worst = worst.max(d);
        }
        count += want.len();
    }
    (worst, count)
}

/// Every kind (interior valences 3..=8, boundary vertices with 1..=6 faces, every sector), both
/// grids, positions and both derivatives, every rate 1..=24: 14.8 M weights (about 15 s in the
/// dev profile on two cores, mostly the grid solves). Measured: 0 ulp everywhere (the
/// expansion and the orbit solver substitute in the same order).
#[test]
fn compact_grids_equal_solved_grids() {
    let (worst, count) = compare(false, (1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert_eq!(count, 14_791_656);
}

/// The pinned-corner companion, every rate.
#[test]
fn compact_corner_grids_equal_solved_grids() {
    let (worst, count) = compare(true, (1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert!(count > 200_000);
}

/// A compact table whose pieces do not fit together is refused when it is loaded, naming the
/// piece, never expanded into a panic: a missing vertex mask, a curve basis that is not four
/// weights a row, pieces stored in f32. A grid it does not cover is `MissingSection`.
#[test]
fn inconsistent_compact_tables_are_refused_at_load() {
    use table_format::{encode, PointSet, SectionKey, StencilKind, Table, TableMeta};
    let mut spec = TableSpec::default_catmull_clark().expect("spec");
    spec.set = StencilSetSpec {
        valences: vec![3],
        boundary_faces: vec![2],
        rates: vec![1, 2],
        ..spec.set
    };
    let bytes = build_table(&spec, &|_, _| {}).expect("compact table");
    let aligned = table_format::AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    let sections: Vec<(SectionKey, u32, Vec<f64>)> = table
        .entries
        .iter()
        .map(|e| {
            let w = table.weights_f64(&e.key).expect("f64");
            (e.key, e.width, w.to_vec())
        })
        .collect();
    let load = |meta: TableMeta, sections: &[(SectionKey, u32, Vec<f64>)]| {
        StencilTable::from_bytes(&encode(meta, sections).expect("encodes"))
    };
    let good = load(table.meta, &sections).expect("the table as written loads");
    let grid = |n| SectionKey {
        kind: StencilKind::Position,
        points: PointSet::Dual,
        boundary: false,
        faces: 3,
        sector: 0,
        n,
    };
    assert_eq!(good.weights(&grid(2)).expect("covered").len(), 4 * 14);
    let e = good.weights(&grid(3)).expect_err("rate 3 is not covered");
    assert!(e.to_string().contains("n = 1..=2"), "{e}");

    let without_mask: Vec<_> = sections
        .iter()
        .filter(|(k, _, _)| {
            !(k.points == PointSet::VertexMask && k.kind == StencilKind::DerivativeV && !k.boundary)
        })
        .cloned()
        .collect();
    let e = load(table.meta, &without_mask).expect_err("a mask is missing");
    assert!(e.to_string().contains("vertex mask"), "{e}");

    let narrow: Vec<_> = sections
        .iter()
        .map(|(k, w, v)| {
            if k.points == PointSet::CurveBasis && k.n == 1 {
                (*k, 3, v[..6].to_vec())
            } else {
                (*k, *w, v.clone())
            }
        })
        .collect();
    let e = load(table.meta, &narrow).expect_err("three weights a row");
    assert!(e.to_string().contains("not 4 weights a row"), "{e}");

    let f32_meta = TableMeta {
        precision: Precision::F32,
        ..table.meta
    };
    let e = load(f32_meta, &sections).expect_err("f32 pieces");
    assert!(e.to_string().contains("f32"), "{e}");
}
