//! Tolerance rates for the triangle schemes (`subtess::tessellate::triangle_rates`): the output meets the
//! tolerance on samples the selection never saw (Loop: exact rational evaluation, an
//! independent method), rates are monotone in the tolerance and minimal, faces that cannot meet
//! it are reported. The closed forms on a quadratic lattice are unit tests of the module.

use crate::common;

use std::sync::OnceLock;

use num_rational::BigRational;
use subtess::eval::loop_exact_eval::LoopExactEvaluator;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_mesh::TriangleMesh;
use subtess::scheme::loop_scheme::isolate::isolate_loop;
use subtess::scheme::region_isolate::isolate_regions;
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::scheme::triangle::region_patch::RegionScheme;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::triangle_dual_grid::tessellate_triangles;
use subtess::tessellate::triangle_rates::{
    measure_triangle_deviation, triangle_face_deviation, triangle_table_rates,
    triangle_tolerance_rates, triangle_tolerance_rates_among,
};

use common::{brute_force_deviation, diagonal, icosahedron, load, models, octahedron, torus};

fn loop_table() -> &'static StencilTable {
    static TABLE: OnceLock<StencilTable> = OnceLock::new();
    TABLE.get_or_init(|| StencilTable::default_loop().expect("embedded table"))
}

fn sqrt3_table() -> &'static StencilTable {
    static TABLE: OnceLock<StencilTable> = OnceLock::new();
    TABLE.get_or_init(|| StencilTable::default_sqrt3().expect("embedded table"))
}

fn butterfly_table() -> &'static StencilTable {
    static TABLE: OnceLock<StencilTable> = OnceLock::new();
    TABLE.get_or_init(|| StencilTable::default_butterfly().expect("embedded table"))
}

/// Exact limit points of every input triangle at `(i/q, j/q)`, `i + j <= q`, by rational
/// evaluation (`LoopExactEvaluator`: exact refinement and Loop's exact local matrices), a method
/// that shares nothing with the tables.
fn exact_samples(mesh: &Mesh, q: i64) -> Vec<[f64; 3]> {
    let evaluator = LoopExactEvaluator::new(mesh).expect("evaluates");
    let mut out = Vec::new();
    for f in 0..mesh.faces() {
        for j in 0..=q {
            for i in 0..=q - j {
                let (u, v) = (BigRational::new(i.into(), q.into()), {
                    BigRational::new(j.into(), q.into())
                });
                out.push(evaluator.evaluate(f, &u, &v).expect("a point").position);
            }
        }
    }
    out
}

fn tessellate(table: &StencilTable, iso: &TriangleIsolation, rates: &[u32]) -> TriangleMesh {
    tessellate_triangles(table, &iso.mesh, &iso.patches, rates)
        .expect("tessellates")
        .0
}

#[test]
fn loop_rates_meet_the_tolerance_on_exact_samples() {
    let mesh = octahedron();
    let iso = isolate_loop(&mesh).expect("isolates");
    // Denominators 7 and 10: apart from a few points (the corners, 1/2), not points of the
    // selection's grids at 24 and 23.
    let exact: Vec<[f64; 3]> = [7, 10]
        .iter()
        .flat_map(|&q| exact_samples(&mesh, q))
        .collect();
    for relative in [1e-2, 3e-3, 1e-3] {
        let t = relative * diagonal(&mesh);
        let chosen = triangle_tolerance_rates(loop_table(), &iso, t).expect("rates");
        assert!(chosen.unmet.is_empty(), "T = {t}");
        assert!(chosen.deviations.iter().all(|&e| e <= t));
        let out = tessellate(loop_table(), &iso, &chosen.rates);
        let measured = brute_force_deviation(&exact, &out);
        assert!(
            measured <= t,
            "T = {t}: measured {measured} with rates {:?}",
            chosen.rates
        );
        // The library's measurement on other table grids (22 and 19) stays within T too.
        for grid in [22, 19] {
            let library = measure_triangle_deviation(loop_table(), &iso, &out, grid).expect("m");
            assert!(library <= t, "T = {t}: {library} on grid {grid}");
        }
    }
}

#[test]
fn tolerance_rates_meet_the_tolerance_on_other_grids() {
    let cases: Vec<(&str, &StencilTable, TriangleIsolation)> = vec![
        (
            "loop icosahedron",
            loop_table(),
            isolate_loop(&icosahedron()).expect("isolates"),
        ),
        (
            "loop torus",
            loop_table(),
            isolate_loop(&torus(8, 5)).expect("isolates"),
        ),
        (
            "butterfly octahedron",
            butterfly_table(),
            isolate_regions(&octahedron(), RegionScheme::Butterfly).expect("isolates"),
        ),
        (
            "sqrt3 octahedron",
            sqrt3_table(),
            isolate_regions(&octahedron(), RegionScheme::Sqrt3).expect("isolates"),
        ),
    ];
    let mut checked = 0;
    for (name, table, iso) in cases {
        let d = diagonal(&iso.mesh);
        for relative in [1e-2, 3e-3] {
            let t = relative * d;
            let chosen = triangle_tolerance_rates(table, &iso, t).expect("rates");
            if !chosen.unmet.is_empty() {
                // Only where the table's largest rate cannot reach T (the butterfly's and √3's 8).
                assert!(chosen.unmet.iter().all(|&f| chosen.rates[f] == 8), "{name}");
                continue;
            }
            let out = tessellate(table, &iso, &chosen.rates);
            // Grids the selection does not sample (it uses the table's two largest rates).
            for grid in [6, 5] {
                let measured = measure_triangle_deviation(table, &iso, &out, grid).expect("m");
                assert!(measured <= t, "{name}: T = {t}, {measured} on grid {grid}");
            }
            checked += 1;
        }
    }
    assert_eq!(
        checked, 8,
        "every mesh meets both tolerances within the table's rates"
    );
}

#[test]
fn smaller_tolerances_never_lower_a_rate() {
    for (name, mesh) in [("octahedron", octahedron()), ("icosahedron", icosahedron())] {
        let iso = isolate_loop(&mesh).expect("isolates");
        let d = diagonal(&mesh);
        let mut previous: Option<Vec<u32>> = None;
        let mut raised = 0;
        for relative in [3e-2, 1e-2, 3e-3, 1e-3, 3e-4] {
            let rates = triangle_tolerance_rates(loop_table(), &iso, relative * d)
                .expect("rates")
                .rates;
            if let Some(before) = &previous {
                for (f, (&a, &b)) in before.iter().zip(&rates).enumerate() {
                    assert!(b >= a, "{name} face {f}: rate {a} became {b} at {relative}");
                }
                raised += before.iter().zip(&rates).filter(|(a, b)| b > a).count();
            }
            previous = Some(rates);
        }
        assert!(raised > 0, "{name}: no rate changed over two decades of T");
    }
}

/// Every chosen rate meets `T` and every smaller rate of the table exceeds it, by the
/// per-face deviation (computed face by face, apart from the selection's batch).
#[test]
fn tolerance_rates_are_minimal() {
    let mesh = icosahedron();
    let iso = isolate_loop(&mesh).expect("isolates");
    let t = 2e-3 * diagonal(&mesh);
    let chosen = triangle_tolerance_rates(loop_table(), &iso, t).expect("rates");
    assert!(chosen.unmet.is_empty());
    assert!(chosen.rates.iter().any(|&n| n > 1), "{:?}", chosen.rates);
    for (f, &n) in chosen.rates.iter().enumerate() {
        let e = triangle_face_deviation(loop_table(), &iso, f, n).expect("deviation");
        assert!(e <= t && (e - chosen.deviations[f]).abs() <= 1e-12 * t.max(1.0));
        for m in 1..n {
            let e = triangle_face_deviation(loop_table(), &iso, f, m).expect("deviation");
            assert!(e > t, "face {f}: rate {m} already meets T ({e})");
        }
    }
}

#[test]
fn unmet_faces_are_reported_and_bad_input_refused() {
    let iso = isolate_loop(&octahedron()).expect("isolates");
    let chosen = triangle_tolerance_rates(loop_table(), &iso, 1e-9).expect("rates");
    assert_eq!(chosen.unmet.len(), iso.patches.len());
    assert!(chosen.rates.iter().all(|&n| n == 24));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = triangle_tolerance_rates(loop_table(), &iso, bad).expect_err("invalid");
        assert!(e.to_string().contains("tolerance"), "{e}");
    }
    for candidates in [&[][..], &[0, 4], &[25]] {
        let e = triangle_tolerance_rates_among(loop_table(), &iso, 0.1, candidates)
            .expect_err("not the table's rates");
        assert!(e.to_string().contains("candidate"), "{e}");
    }
    let butterfly = isolate_regions(&octahedron(), RegionScheme::Butterfly).expect("isolates");
    assert_eq!(
        triangle_table_rates(butterfly_table()),
        (1..=24).collect::<Vec<_>>()
    );
    let e = triangle_tolerance_rates_among(butterfly_table(), &butterfly, 0.1, &[25])
        .expect_err("the butterfly table stops at 24");
    assert!(e.to_string().contains("1..=24"), "{e}");
    // A quad table has no triangle grids.
    let quads = StencilTable::default_catmull_clark().expect("table");
    assert!(triangle_tolerance_rates(&quads, &iso, 0.1).is_err());
}

/// Spot (`../shared/models/crane`): rates and the measured deviation for a few tolerances
/// (`cargo test -p subtess --test integration triangle_rates -- --ignored --nocapture`; the numbers
/// are in docs/cli.md).
#[test]
#[ignore = "a report on a real model: about a minute"]
fn spot_report() {
    let mesh = load(&models().join("crane/spot_triangulated.obj"));
    let iso = isolate_loop(&mesh).expect("isolates");
    let d = diagonal(&mesh);
    for relative in [1e-3, 3e-4, 1e-4] {
        let t = relative * d;
        let chosen = triangle_tolerance_rates(loop_table(), &iso, t).expect("rates");
        let out = tessellate(loop_table(), &iso, &chosen.rates);
        let measured = [22, 19]
            .iter()
            .map(|&g| measure_triangle_deviation(loop_table(), &iso, &out, g).expect("m"))
            .fold(0.0, f64::max);
        let mut histogram = std::collections::BTreeMap::new();
        for &n in &chosen.rates {
            *histogram.entry(n).or_insert(0) += 1;
        }
        println!(
            "spot T = {relative:e} x {d:.4} = {t:.3e}: {} triangles, rates {histogram:?}, unmet {}, measured {measured:.3e} ({:.3} T)",
            out.triangles.len(),
            chosen.unmet.len(),
            measured / t
        );
        assert!(chosen.unmet.is_empty());
    }
}

/// As for quads: stopping a rate's measurement at the first sample beyond the tolerance still
/// picks the full search's rate (the smallest table rate with `e_f(n) <= T`, else the largest)
/// and reports its full deviation.
#[test]
fn triangle_tolerance_rates_equal_the_full_search() {
    let iso = isolate_loop(&icosahedron()).expect("isolates");
    let rates = triangle_table_rates(loop_table());
    let largest = *rates.last().expect("rates");
    for t in [3e-2, 1e-3, 1e-6] {
        let chosen = triangle_tolerance_rates(loop_table(), &iso, t).expect("rates");
        for f in 0..iso.patches.len() {
            let full = |n| triangle_face_deviation(loop_table(), &iso, f, n).expect("deviation");
            let expected = rates
                .iter()
                .copied()
                .find(|&n| full(n) <= t)
                .unwrap_or(largest);
            assert_eq!(chosen.rates[f], expected, "triangle {f} T = {t}");
            assert_eq!(chosen.deviations[f], full(expected), "triangle {f} T = {t}");
        }
    }
}
