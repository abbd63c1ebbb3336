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
    ulps_above(a, b, 2f32.powi(-40))
}

/// [`ulps`] with the weights below `floor` compared at the ulp of `floor`.
fn ulps_above(a: f32, b: f32, floor: f32) -> f64 {
    let scale = a.abs().max(b.abs()).max(floor);
    let ulp = f64::from(f32::from_bits(scale.to_bits() + 1) - scale);
    (f64::from(a) - f64::from(b)).abs() / ulp
}

/// Every grid section of `grids` against the same section expanded by `compact`, each weight to
/// 1 ulp of f32; returns the largest difference in ulps and the number of weights compared.
fn same_grids(compact: &StencilTable, grids: &StencilTable) -> (f64, usize) {
    same_grids_above(compact, grids, |_| 2f32.powi(-40))
}

/// [`same_grids`] with the weights of a row (one point's stencil) below `floor(row)` compared at
/// the ulp of that floor ([`ulps_above`]).
fn same_grids_above(
    compact: &StencilTable,
    grids: &StencilTable,
    floor: impl Fn(&[f32]) -> f32,
) -> (f64, usize) {
    assert!(compact.is_compact() && !grids.is_compact());
    let (mut worst, mut count, mut below) = (0.0f64, 0, 0usize);
    for entry in &grids.index().entries {
        let want = grids.weights(&entry.key).expect("grid section");
        let got = compact.weights(&entry.key).expect("expanded section");
        assert_eq!(got.len(), want.len(), "{}", entry.key);
        let width = entry.width.max(1) as usize;
        for (point, (g_row, w_row)) in got.chunks(width).zip(want.chunks(width)).enumerate() {
            let floor = floor(w_row);
            for (g, w) in g_row.iter().zip(w_row) {
                let d = ulps_above(*g, *w, floor);
                below += usize::from(g.abs().max(w.abs()) < floor);
                assert!(
                    d <= 1.0,
                    "{}: point {point}: {g:e} expanded, {w:e} solved: {d} ulps (floor {floor:e})",
                    entry.key,
                );
                worst = worst.max(d);
            }
        }
        count += want.len();
    }
    eprintln!("{below} of {count} weights below the floor");
    (worst, count)
}

/// Which of the default table's patches a comparison solves grids for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Patches {
    /// Interior valences and boundary vertices, no darts.
    Smooth,
    /// The pinned-corner companion.
    Corners,
    /// The darts only (every sector of valences 3..=8).
    Darts,
}

/// The embedded default (compact) against a grid table of the same patches at `rates`, solved
/// now; returns the largest difference in ulps and the number of weights compared.
fn compare(patches: Patches, rates: Vec<u32>) -> (f64, usize) {
    let corners = patches == Patches::Corners;
    let mut spec = if corners {
        TableSpec::default_corners()
    } else {
        TableSpec::default_catmull_clark()
    }
    .expect("spec");
    spec.set = StencilSetSpec { rates, ..spec.set };
    match patches {
        Patches::Smooth => spec.set.darts = Vec::new(),
        Patches::Darts => {
            spec.set.valences = Vec::new();
            spec.set.boundary_faces = Vec::new();
        }
        Patches::Corners => {}
    }
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
    same_grids(&compact, &grids)
}

/// Every kind (interior valences 3..=8, boundary vertices with 1..=6 faces, every sector), both
/// grids, positions and both derivatives, every rate 1..=24: 14.8 M weights (about 15 s in the
/// dev profile on two cores, mostly the grid solves). Measured: 0 ulp everywhere (the
/// expansion and the orbit solver substitute in the same order).
#[test]
#[cfg(feature = "catmull-clark")]
fn compact_grids_equal_solved_grids() {
    let (worst, count) = compare(Patches::Smooth, (1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert_eq!(count, 14_791_656);
}

/// Every dart patch of the default table (valences 3..=8, every sector: 33 patches), both
/// grids, positions and both derivatives, every rate 1..=24. The count is the closed form:
/// `sum_n ((n+1)^2 + n^2) = 10,424` points a patch and kind, times 3 kinds, times
/// `sum_v v (2v + 8) = 662` weights a point summed over the sectors: 20,702,064.
#[test]
#[cfg(feature = "catmull-clark")]
fn compact_dart_grids_equal_solved_grids() {
    let (worst, count) = compare(Patches::Darts, (1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert_eq!(count, 20_702_064);
}

/// The pinned-corner companion, every rate.
#[test]
#[cfg(feature = "catmull-clark")]
fn compact_corner_grids_equal_solved_grids() {
    let (worst, count) = compare(Patches::Corners, (1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert!(count > 200_000);
}

/// A compact table whose pieces do not fit together is refused when it is loaded, naming the
/// piece, never expanded into a panic: a missing vertex mask, a curve basis that is not four
/// weights a row or beyond rate 64, pieces stored in f32. A grid it does not cover is `MissingSection`.
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
        feature: table_format::Feature::None,
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

    // A curve basis at rate 65 would let one grid request allocate (n + 1)^2 K weights for a
    // rate no tessellator asks for: the rates are capped at the tessellators' 64.
    let far: Vec<_> = sections
        .iter()
        .cloned()
        .chain(
            [StencilKind::Position, StencilKind::DerivativeU].map(|kind| {
                let key = SectionKey {
                    kind,
                    points: PointSet::CurveBasis,
                    boundary: false,
                    feature: table_format::Feature::None,
                    faces: 0,
                    sector: 0,
                    n: 65,
                };
                (key, 4, vec![0.25; 66 * 4])
            }),
        )
        .collect();
    let e = load(table.meta, &far).expect_err("rate 65");
    assert!(e.to_string().contains("1..=64"), "{e}");

    let f32_meta = TableMeta {
        precision: Precision::F32,
        ..table.meta
    };
    let e = load(f32_meta, &sections).expect_err("f32 pieces");
    assert!(e.to_string().contains("f32"), "{e}");
}

/// The embedded default Loop table (compact) against a grid table of the same patches at
/// `rates`, solved now by `stencilgen`'s grid systems; returns the largest difference in ulps
/// and the number of weights compared.
#[cfg(feature = "loop")]
fn compare_loop(rates: Vec<u32>) -> (f64, usize) {
    use stencilgen::triangle_table::{build_triangle_table, TriangleLayout, TriangleTableSpec};
    let mut spec = TriangleTableSpec::default_loop().expect("spec");
    spec.rates = rates;
    spec.layout = TriangleLayout::Grids;
    spec.precision = Precision::F32;
    let grids = StencilTable::from_bytes(&build_triangle_table(&spec).expect("grid table"))
        .expect("valid grid table");
    let compact = StencilTable::default_loop().expect("embedded table");
    same_grids(&compact, &grids)
}

/// Every Loop patch (interior valences 3..=12, boundary vertices with 1..=6 triangles, every
/// sector), both triangle grids, positions and both derivatives, rates 1..=8 and 24: 1,374,327
/// weights (about 4 s in the dev profile on two cores, mostly the grid solves). Measured: 0 ulp
/// everywhere (the expansion evaluates the basis and substitutes in `stencilgen`'s order).
#[test]
#[cfg(feature = "loop")]
fn compact_loop_grids_equal_solved_grids() {
    let (worst, count) = compare_loop((1..=8).chain([24]).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert_eq!(count, 1_374_327);
}

/// [`compact_loop_grids_equal_solved_grids`] at every rate 1..=24: 8,473,392 weights
/// (30 to 45 s in the dev profile on two shared cores). Measured: 0 ulp everywhere.
#[test]
#[ignore = "30 to 45 s in the dev profile; the default test covers rates 1..=8 and 24"]
#[cfg(feature = "loop")]
fn compact_loop_grids_equal_solved_grids_at_every_rate() {
    let (worst, count) = compare_loop((1..=24).collect());
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert_eq!(count, 8_473_392);
}

/// A compact Loop table whose pieces do not fit together is refused when it is loaded, naming
/// the piece: a missing sub-triangle matrix, a basis kind missing or of even width, a vertex
/// mask of another width, a rate marker past the tessellator's rates, a patch of no control
/// points, pieces in f32 or in a butterfly table. A rate it does not list is `MissingSection`,
/// and `triangle_table_rates` reads the listed rates.
#[test]
fn inconsistent_compact_loop_tables_are_refused_at_load() {
    use stencilgen::triangle_table::{build_triangle_table, TriangleTableSpec};
    use subtess::tessellate::triangle_rates::triangle_table_rates;
    use table_format::{encode, PointSet, SchemeId, SectionKey, StencilKind, Table, TableMeta};
    let mut spec = TriangleTableSpec::default_loop().expect("spec");
    spec.valences = vec![5];
    spec.boundary_faces = vec![2];
    spec.rates = vec![1, 2, 4];
    let bytes = build_triangle_table(&spec).expect("compact table");
    let aligned = table_format::AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    type Section = (SectionKey, u32, Vec<f64>);
    let sections: Vec<Section> = table
        .entries
        .iter()
        .map(|e| {
            let w = table.weights_f64(&e.key).expect("f64");
            (e.key, e.width, w.to_vec())
        })
        .collect();
    let load = |meta: TableMeta, sections: &[Section]| {
        StencilTable::from_bytes(&encode(meta, sections).expect("encodes"))
    };
    let good = load(table.meta, &sections).expect("the table as written loads");
    assert!(good.is_compact());
    assert_eq!(triangle_table_rates(&good), vec![1, 2, 4]);
    assert!(
        table.coverage().ends_with("n = 1..=2, 4"),
        "{}",
        table.coverage()
    );
    let grid = |n, points| SectionKey {
        kind: StencilKind::DerivativeV,
        points,
        boundary: true,
        feature: table_format::Feature::None,
        faces: 2,
        sector: 1,
        n,
    };
    // Boundary K = 2 + 7 (V, E_0..E_2 and the kept outer points): whatever it is, the dual
    // grid has n^2 rows of K.
    let k = good
        .weights(&grid(4, PointSet::TrianglePrimal))
        .expect("covered")
        .len()
        / 15;
    assert_eq!(
        good.weights(&grid(4, PointSet::TriangleDual))
            .expect("covered")
            .len(),
        16 * k
    );
    let e = good
        .weights(&grid(3, PointSet::TriangleDual))
        .expect_err("rate 3 is not listed");
    assert!(e.to_string().contains("n = 1..=2, 4"), "{e}");

    let edit =
        |f: &dyn Fn(&Section) -> Option<Section>| sections.iter().filter_map(f).collect::<Vec<_>>();
    let refused = |sections: Vec<Section>, what: &str| {
        let e = load(table.meta, &sections).expect_err(what);
        assert!(e.to_string().contains(what), "{what}: {e}");
    };
    refused(
        edit(&|s| (s.0.points != PointSet::SubTriangles || s.0.boundary).then(|| s.clone())),
        "sub-triangle matrices of valence 5",
    );
    refused(
        edit(&|s| {
            (!(s.0.points == PointSet::LoopBasis && s.0.kind == StencilKind::DerivativeU))
                .then(|| s.clone())
        }),
        "d/du of the Loop basis",
    );
    refused(
        edit(&|s| {
            Some(
                if s.0.points == PointSet::LoopBasis && s.0.kind == StencilKind::Position {
                    (s.0, 2, vec![0.0; 4])
                } else {
                    s.clone()
                },
            )
        }),
        "odd width",
    );
    refused(
        edit(&|s| {
            Some(
                if s.0.points == PointSet::VertexMask && s.0.kind == StencilKind::DerivativeU {
                    (s.0, s.1 + 1, vec![0.0; s.1 as usize + 1])
                } else {
                    s.clone()
                },
            )
        }),
        "another width",
    );
    refused(
        edit(&|s| {
            Some(if s.0.points == PointSet::TriangleRate && s.0.n == 4 {
                (SectionKey { n: 65, ..s.0 }, 0, Vec::new())
            } else {
                s.clone()
            })
        }),
        "rate marker n = 65",
    );
    refused(
        edit(&|s| (s.0.points != PointSet::TriangleRate).then(|| s.clone())),
        "lists no rate",
    );
    // A patch of no control points: every piece of valence 5 with width 0.
    refused(
        edit(&|s| {
            Some(
                if !s.0.points.is_grid() && s.0.faces == 5 && !s.0.boundary {
                    (s.0, 0, Vec::new())
                } else {
                    s.clone()
                },
            )
        }),
        "at least one control point",
    );
    let f32_meta = TableMeta {
        precision: Precision::F32,
        ..table.meta
    };
    let e = load(f32_meta, &sections).expect_err("f32 pieces");
    assert!(e.to_string().contains("f32"), "{e}");
    let butterfly = TableMeta {
        scheme: SchemeId::Butterfly,
        ..table.meta
    };
    let e = load(butterfly, &sections).expect_err("a compact butterfly table");
    assert!(e.to_string().contains("compact region table"), "{e}");
}

/// The compact layout is the scaling relation's, not Catmull–Clark's: Schaefer–Warren's
/// non-polynomial quad scheme (its curve basis solved from its own scaling relation, not a
/// closed form) expands to the grids solved on the grid, for interior valences 3..=8 (it has no
/// boundary rules), rates 1..=8.
#[test]
fn compact_nonpolynomial_quad_grids_equal_solved_grids() {
    let scheme = stencilgen::patch_stencils::quad_scheme("sw-nonpoly-quad").expect("catalogued");
    let set = StencilSetSpec {
        valences: (3..=8).collect(),
        darts: Vec::new(),
        boundary_faces: Vec::new(),
        boundary_mode: schemes::BoundaryMode::EdgeOnly,
        rates: (1..=8).collect(),
    };
    let table = |layout, precision| {
        let spec = TableSpec {
            scheme: scheme.clone(),
            set: set.clone(),
            precision,
            exact: false,
            layout,
        };
        StencilTable::from_bytes(&build_table(&spec, &|_, _| {}).expect("table")).expect("valid")
    };
    let compact = table(QuadLayout::Compact, Precision::F64);
    let grids = table(QuadLayout::Grids, Precision::F32);
    let (worst, count) = same_grids(&compact, &grids);
    eprintln!("{count} weights, largest difference {worst} ulp");
    assert!(count > 50_000);
}

/// The region tables' grid layout (`stencilgen tables --schemes butterfly|sqrt3 --grids`) of
/// the embedded defaults' valences at `rates`, generated now: each rate's regular basis solved
/// on its whole grid by the orbit solver (exact and rounded, or by the SVD at the butterfly's
/// odd grids), as the tables before the compact layout were made.
#[cfg(all(feature = "butterfly", feature = "sqrt3"))]
fn region_grids(scheme: &str, rates: Vec<u32>) -> StencilTable {
    use stencilgen::region_table::{RegionLayout, RegionTableSpec};
    let mut spec = match scheme {
        "butterfly" => RegionTableSpec::default_butterfly(),
        _ => RegionTableSpec::default_sqrt3(),
    };
    spec.rates = rates;
    spec.layout = RegionLayout::Grids;
    spec.precision = Precision::F32;
    let bytes = match scheme {
        "butterfly" => stencilgen::butterfly_table::build_butterfly_table(&spec),
        _ => stencilgen::sqrt3_table::build_sqrt3_table(&spec),
    };
    StencilTable::from_bytes(&bytes.expect("grid table")).expect("valid grid table")
}

/// The embedded compact table of `scheme`.
#[cfg(all(feature = "butterfly", feature = "sqrt3"))]
fn region_compact(scheme: &str) -> StencilTable {
    match scheme {
        "butterfly" => StencilTable::default_butterfly(),
        _ => StencilTable::default_sqrt3(),
    }
    .expect("embedded table")
}

/// The region comparisons' floor: `2^-20` of the row's largest weight. The two bases are f64
/// computations of the same values by different means (the cascade iteration; the orbit
/// solver, exact for the butterfly's even grids and √3), about 1e-15 apart, so where a
/// stencil's weight cancels to zero (an interpolatory stencil at a vertex, a derivative's
/// symmetric weights) one gives exactly 0 and the other 4e-18 (a position) or 4e-15 (a
/// derivative, whose weights are up to 9 times the basis's, measured against a row of 0.53):
/// no number of f32 ulps of 0. Below the floor the weights are compared at its ulp, `2^-43`
/// of the row's largest weight: a difference that small is `2^-19` of the rounding of an f32
/// evaluation of the stencil (half an ulp of its largest term).
fn region_floor(row: &[f32]) -> f32 {
    row.iter().fold(0.0f32, |m, w| m.max(w.abs())) / (1u32 << 20) as f32
}

/// The embedded butterfly and √3 tables (compact: the basis by the cascade iteration) against
/// the grid layout solved now (the basis by the orbit solver, as the embedded tables were made
/// before), every region of valences 3..=8 (region 0 at 6), both grids, positions and both
/// derivatives, rates 1..=8: the stencils plans read are today's to 1 ulp of f32 (weights
/// below 2^-20 of their row's largest weight at that weight's ulp, [`region_floor`]).
#[test]
#[cfg(all(feature = "butterfly", feature = "sqrt3"))]
fn compact_region_grids_equal_solved_grids() {
    for (scheme, want) in [("butterfly", 1_341_360), ("sqrt3", 1_341_360)] {
        let (worst, count) = same_grids_above(
            &region_compact(scheme),
            &region_grids(scheme, (1..=8).collect()),
            region_floor,
        );
        eprintln!("{scheme}: {count} weights, largest difference {worst} ulp");
        assert_eq!(count, want, "{scheme}");
    }
}

/// [`compact_region_grids_equal_solved_grids`] at every rate 1..=24 (the orbit solves of the
/// grid layout at the rates `3n` up to 72 take about 14 CPU minutes per scheme in release).
/// Measured (2026-12-03, 28.8 minutes in the dev profile on two shared cores): 28,518,480
/// weights per scheme, largest difference 0.5 ulp (butterfly) and 0.125 ulp (√3).
#[test]
#[ignore = "the grid layout's orbit solves at n = 9..=24 take tens of minutes"]
#[cfg(all(feature = "butterfly", feature = "sqrt3"))]
fn compact_region_grids_equal_solved_grids_at_every_rate() {
    for scheme in ["butterfly", "sqrt3"] {
        let (worst, count) = same_grids_above(
            &region_compact(scheme),
            &region_grids(scheme, (1..=24).collect()),
            region_floor,
        );
        eprintln!("{scheme}: {count} weights, largest difference {worst} ulp");
    }
}

/// Every rate 1..=24 of the embedded region tables, every region, kind and grid point, against
/// `stencilgen`'s own evaluation of the regions (`ConeRegionStencils::stencil` in f64) with the
/// table's basis spread by the lattice's symmetries (`CanonicalBasis::spread`): the
/// runtime's expansion is that evaluation, rounded once, at every rate (0 ulp: the expansion's
/// operations are the evaluation's, the three kinds fused or not); with
/// [`compact_region_grids_equal_solved_grids`] (the basis itself against the orbit solves at
/// rates 1..=8, and `stencilgen::region_basis`'s test at the rates 3..=15) this covers every
/// rate the tables hold.
#[test]
#[cfg(all(feature = "butterfly", feature = "sqrt3"))]
fn compact_region_grids_are_the_region_evaluation_at_every_rate() {
    use stencilgen::cone_regions::ConeRegionStencils;
    use stencilgen::region_basis::CanonicalBasis;
    use stencilgen::region_table::{primal_points, KINDS};
    use stencilgen::triangle_table::triangle_dual_points;
    use table_format::{PointSet, SectionKey};
    for scheme_name in ["butterfly", "sqrt3"] {
        let scheme = schemes::TriangleScheme::by_name(scheme_name).expect("catalogued");
        let mask = scheme.regular_mask();
        let table = region_compact(scheme_name);
        let valences: Vec<_> = (3..=8)
            .map(|k| ConeRegionStencils::<f64>::new(&scheme, k).expect("regions"))
            .collect();
        let (mut worst, mut count) = (0.0f64, 0usize);
        for n in 1..=24u32 {
            let psi = table_format::Table::parse(table.bytes()).expect("valid");
            let canonical = CanonicalBasis {
                d: 3 * n,
                psi: psi
                    .weights_f64(&SectionKey {
                        kind: table_format::StencilKind::Position,
                        points: PointSet::RegionBasis,
                        boundary: false,
                        feature: table_format::Feature::None,
                        faces: 0,
                        sector: 0,
                        n,
                    })
                    .expect("psi")
                    .to_vec(),
                psi_1: psi
                    .weights_f64(&SectionKey {
                        kind: table_format::StencilKind::DerivativeU,
                        points: PointSet::RegionBasis,
                        boundary: false,
                        feature: table_format::Feature::None,
                        faces: 0,
                        sector: 0,
                        n,
                    })
                    .expect("psi_1")
                    .to_vec(),
            };
            let basis = stencilgen::cone_regions::RegionBasis {
                n: 3 * n,
                kinds: canonical.spread(&mask).map(Some),
            };
            for regions in &valences {
                let k = regions.regions.valence;
                let count_regions = if k == 6 {
                    1
                } else {
                    regions.regions.regions.len()
                };
                for r in 0..count_regions {
                    for (kind, table_kind) in KINDS {
                        for (set, points) in [
                            (PointSet::TrianglePrimal, primal_points(n)),
                            (PointSet::TriangleDual, triangle_dual_points(n)),
                        ] {
                            let key = SectionKey {
                                kind: table_kind,
                                points: set,
                                boundary: false,
                                feature: table_format::Feature::None,
                                faces: k,
                                sector: r as u32,
                                n,
                            };
                            let got = table.weights(&key).expect("expanded");
                            let width = regions.regions.regions[r].size();
                            assert_eq!(got.len(), points.len() * width, "{key}");
                            for (p, row) in points.iter().zip(got.chunks(width)) {
                                let want = regions.stencil(r, &basis, *p, kind).expect("stencil");
                                for (g, w) in row.iter().zip(&want) {
                                    let d = ulps(*g, *w as f32);
                                    assert!(d == 0.0, "{key} at {p:?}: {g:e} vs {w:e}");
                                    worst = worst.max(d);
                                    count += 1;
                                }
                            }
                        }
                    }
                }
            }
        }
        eprintln!("{scheme_name}: {count} weights, largest difference {worst} ulp");
        assert!(count > 20_000_000, "{count}");
    }
}

/// A compact region table whose pieces do not fit together is refused, naming the piece: at
/// load a missing mask at `V`, a missing basis kind, a rate marker past the tessellator's
/// rates, pieces in f32; when a grid is first expanded, a basis without the canonical points'
/// count or region rows of another shape than the region geometry's. A rate it does not list
/// is `MissingSection`, and `triangle_table_rates` reads the listed rates.
#[test]
fn inconsistent_compact_region_tables_are_refused() {
    use stencilgen::region_table::RegionTableSpec;
    use subtess::tessellate::triangle_rates::triangle_table_rates;
    use table_format::{encode, PointSet, SectionKey, StencilKind, Table, TableMeta};
    let mut spec = RegionTableSpec::default_butterfly();
    spec.valences = vec![5];
    spec.rates = vec![1, 2, 4];
    let bytes = stencilgen::butterfly_table::build_butterfly_table(&spec).expect("compact table");
    let aligned = table_format::AlignedBytes::from_slice(&bytes);
    let table = Table::parse(aligned.as_bytes()).expect("valid");
    type Section = (SectionKey, u32, Vec<f64>);
    let sections: Vec<Section> = table
        .entries
        .iter()
        .map(|e| {
            let w = table.weights_f64(&e.key).expect("f64");
            (e.key, e.width, w.to_vec())
        })
        .collect();
    let load = |meta: TableMeta, sections: &[Section]| {
        StencilTable::from_bytes(&encode(meta, sections).expect("encodes"))
    };
    let good = load(table.meta, &sections).expect("the table as written loads");
    assert!(good.is_compact());
    assert_eq!(triangle_table_rates(&good), vec![1, 2, 4]);
    let grid = |n, points| SectionKey {
        kind: StencilKind::DerivativeV,
        points,
        boundary: false,
        feature: table_format::Feature::None,
        faces: 5,
        sector: 4,
        n,
    };
    let primal = good
        .weights(&grid(4, PointSet::TrianglePrimal))
        .expect("covered")
        .len();
    assert_eq!(primal % 15, 0);
    let e = good
        .weights(&grid(3, PointSet::TriangleDual))
        .expect_err("rate 3 is not listed");
    assert!(e.to_string().contains("n = 1..=2, 4"), "{e}");

    let edit =
        |f: &dyn Fn(&Section) -> Option<Section>| sections.iter().filter_map(f).collect::<Vec<_>>();
    let refused = |sections: Vec<Section>, what: &str| {
        let e = load(table.meta, &sections).expect_err(what);
        assert!(e.to_string().contains(what), "{what}: {e}");
    };
    refused(
        edit(&|s| {
            (!(s.0.points == PointSet::VertexMask && s.0.kind == StencilKind::DerivativeV))
                .then(|| s.clone())
        }),
        "has no d/dv vertex mask of valence 5",
    );
    refused(
        edit(&|s| {
            (!(s.0.points == PointSet::RegionBasis
                && s.0.kind == StencilKind::DerivativeU
                && s.0.n == 2))
                .then(|| s.clone())
        }),
        "d/du of the regular basis on the grid 1/6",
    );
    refused(
        edit(&|s| {
            Some(if s.0.points == PointSet::TriangleRate && s.0.n == 4 {
                (SectionKey { n: 65, ..s.0 }, 0, Vec::new())
            } else {
                s.clone()
            })
        }),
        "rate marker n = 65",
    );
    let f32_meta = TableMeta {
        precision: Precision::F32,
        ..table.meta
    };
    let e = load(f32_meta, &sections).expect_err("f32 pieces");
    assert!(e.to_string().contains("f32"), "{e}");
    // Loaded, but refused when the grid is expanded: a basis short of a value, a region's rows
    // one row short.
    let expanded_refused = |sections: Vec<Section>, what: &str| {
        let table = load(table.meta, &sections).expect("loads");
        let e = table
            .weights(&grid(2, PointSet::TriangleDual))
            .expect_err(what);
        assert!(e.to_string().contains(what), "{what}: {e}");
    };
    expanded_refused(
        edit(&|s| {
            let mut s = s.clone();
            if s.0.points == PointSet::RegionBasis
                && s.0.n == 2
                && s.0.kind == StencilKind::Position
            {
                s.2.pop();
                s.1 -= 1;
            }
            Some(s)
        }),
        "wedge",
    );
    expanded_refused(
        edit(&|s| {
            let mut s = s.clone();
            if s.0.points == PointSet::RegionRows && s.0.sector == 4 {
                s.0.n -= 1;
                let keep = s.2.len() - s.1 as usize;
                s.2.truncate(keep);
            }
            Some(s)
        }),
        "tile rows of region 4 of valence 5",
    );
}
