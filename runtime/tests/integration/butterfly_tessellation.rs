//! Butterfly meshes end to end: isolation, the region patches and their layouts, and the
//! tessellation from the default butterfly table.
//!
//! The butterfly interpolates, so its limit surface passes through every vertex of every
//! refinement level: at a dyadic parameter `(i/2^m, j/2^m)` of a triangle the surface is the
//! vertex that `m` whole-mesh butterfly steps (`subtess::scheme::butterfly::refine`, the rules written
//! out) put there. That checks the table's stencils, the region layouts and their rotations,
//! and the triangle dual grid's point maps together, without the solver that made the table.

use crate::common;

use proptest::prelude::*;
use subtess::mesh::topology::Mesh;
use subtess::scheme::butterfly::refine::butterfly_refine;
use subtess::scheme::region_isolate::isolate_regions;
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::scheme::triangle::region_patch::RegionScheme;
use subtess::scheme::triangle::split::child_to_parent;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::triangle_dual_grid::TriangleDualGrid;
use subtess::tessellate::GridPlan;

use common::{
    check_rates_give_a_manifold, check_region_layouts, check_spot_at_mixed_rates, check_topology,
    icosahedron, octahedron, region_kinds, tetrahedron, torus, worst_normal_angle,
};

/// Three steps separate neighbouring extraordinary vertices (six edges apart, module docs of
/// `subtess::scheme::region_isolate`); a regular torus needs none. Every region of the valence shows
/// up, and nothing else.
#[test]
fn isolation_separates_the_extraordinary_vertices() {
    let cases: Vec<(&str, Mesh, usize, u32)> = vec![
        ("tetrahedron", tetrahedron(), 3, 3),
        ("octahedron", octahedron(), 3, 4),
        ("icosahedron", icosahedron(), 3, 5),
        ("torus", torus(12, 12), 0, 6),
    ];
    for (name, m, steps, k) in cases {
        let iso =
            isolate_regions(&m, RegionScheme::Butterfly).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(iso.steps, steps, "{name}");
        assert_eq!(iso.mesh.faces(), m.faces() << (2 * steps), "{name}");
        let mut expected: Vec<(u32, u32)> = vec![(6, 0)];
        if k != 6 {
            expected.extend((0..9).map(|r| (k, r)));
        }
        expected.sort_unstable();
        assert_eq!(region_kinds(&iso), expected, "{name}");
    }
}

#[test]
fn gathered_layouts_match_whole_mesh_refinement() {
    for (name, m) in [
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
    ] {
        let iso =
            isolate_regions(&m, RegionScheme::Butterfly).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_region_layouts(name, RegionScheme::Butterfly, &iso);
    }
}

/// The child of a triangle holding the point `(u, v) / 2d` of the parent, and the point in the
/// child's own parameters over `d` (the inverse of `child_to_parent`).
fn child_holding(u: u32, v: u32, d: u32) -> (u8, u32, u32) {
    let (u, v, d) = (i64::from(u), i64::from(v), i64::from(d));
    let candidates = [
        (0u8, u, v),
        (1, v, 2 * d - u - v),
        (2, 2 * d - u - v, u),
        (3, v - d + u, d - u),
    ];
    for (c, s, t) in candidates {
        if s >= 0 && t >= 0 && s + t <= d {
            let (s, t) = (s as u32, t as u32);
            assert_eq!(child_to_parent(c, s, t, d as u32), (u as u32, v as u32));
            return (c, s, t);
        }
    }
    panic!("({u}, {v}) / {} is outside the triangle", 2 * d)
}

/// The vertex of the `m`-times refined mesh at the dyadic point `(u, v) / 2^m` of triangle `f`.
fn refined_vertex(levels: &[Mesh], f: usize, u: u32, v: u32, m: usize) -> u32 {
    let (mut f, mut u, mut v, mut d) = (f, u, v, 1u32 << m);
    for _ in 0..m {
        let (c, s, t) = child_holding(u, v, d / 2);
        (f, u, v, d) = (4 * f + c as usize, s, t, d / 2);
    }
    let corner = match (u, v) {
        (0, 0) => 0,
        (1, 0) => 1,
        _ => 2,
    };
    levels[m].face(f)[corner]
}

/// Every output vertex at a dyadic source equals the refined mesh's vertex there; `rate` is a
/// power of two.
fn check_against_refinement(name: &str, table: &StencilTable, iso: &TriangleIsolation, rate: u32) {
    let m = rate.trailing_zeros() as usize;
    let mut levels = vec![iso.mesh.clone()];
    for _ in 0..m {
        let next = butterfly_refine(&levels[levels.len() - 1])
            .expect("refines")
            .mesh;
        levels.push(next);
    }
    let rates = vec![rate; iso.mesh.faces()];
    let grid = TriangleDualGrid::new(table, &iso.mesh, &iso.patches, &rates)
        .unwrap_or_else(|e| panic!("{name}: plan: {e}"));
    let out = grid.tessellate(&iso.mesh);
    let scale = iso
        .mesh
        .positions
        .iter()
        .flatten()
        .fold(0.0f64, |a, c| a.max(c.abs()));
    let mut checked = 0;
    let mut worst = 0.0f64;
    for (p, s) in out.positions.iter().zip(&out.sources) {
        if s.denominator != rate {
            continue;
        }
        let w = refined_vertex(&levels, s.face as usize, s.u, s.v, m);
        let q = levels[m].positions[w as usize];
        for c in 0..3 {
            worst = worst.max((f64::from(p[c]) - q[c]).abs() / scale);
        }
        checked += 1;
    }
    println!("{name}: {checked} dyadic vertices, worst relative error {worst:.2e}");
    assert!(checked > 0, "{name}: nothing checked");
    assert!(worst < 2e-6, "{name}: {worst:.2e}");
    check_topology(&iso.mesh, &out, name);
}

#[test]
fn the_surface_passes_through_every_refined_vertex() {
    let table = StencilTable::default_butterfly().expect("embedded butterfly table");
    for (name, m) in [
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
        ("torus", torus(12, 12)),
    ] {
        let iso =
            isolate_regions(&m, RegionScheme::Butterfly).unwrap_or_else(|e| panic!("{name}: {e}"));
        for rate in [1, 2, 4, 8] {
            check_against_refinement(&format!("{name} at rate {rate}"), &table, &iso, rate);
        }
    }
}

/// The table's normals (from the d/du, d/dv stencils, at the extraordinary vertices the
/// spectral-projector tangents) against the ring normals of the mesh refined four more times
/// at the same vertices: the surface is only C1, so the fine mesh's ring normal approaches the
/// limit normal slowly, and the bound is loose; the normals of the convex shapes point out.
#[test]
fn normals_follow_the_refined_surface() {
    let table = StencilTable::default_butterfly().expect("embedded butterfly table");
    for (name, m) in [("octahedron", octahedron()), ("icosahedron", icosahedron())] {
        let iso =
            isolate_regions(&m, RegionScheme::Butterfly).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (rate, extra) = (2u32, 4usize);
        let mut levels = vec![iso.mesh.clone()];
        for _ in 0..extra {
            let next = butterfly_refine(&levels[levels.len() - 1])
                .expect("refines")
                .mesh;
            levels.push(next);
        }
        let grid = TriangleDualGrid::new(
            &table,
            &iso.mesh,
            &iso.patches,
            &vec![rate; iso.mesh.faces()],
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let out = grid.tessellate(&iso.mesh);
        // The vertex at level 1 (rate 2) is the same vertex at every later level.
        let worst = worst_normal_angle(name, &out, &levels[extra], |s| {
            (s.denominator == rate).then(|| refined_vertex(&levels, s.face as usize, s.u, s.v, 1))
        });
        assert!(worst < 5e-3, "{name}: {worst}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    #[test]
    fn random_rates_give_manifolds(rates in proptest::collection::vec(1u32..=8, 1280)) {
        let iso = isolate_regions(&icosahedron(), RegionScheme::Butterfly).expect("isolates");
        prop_assert_eq!(iso.mesh.faces(), rates.len());
        let table = StencilTable::default_butterfly().expect("embedded table");
        check_rates_give_a_manifold(&table, "icosahedron", &iso, &rates);
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn spot_tessellates_to_a_closed_manifold_at_mixed_rates() {
    let table = StencilTable::default_butterfly().expect("embedded table");
    check_spot_at_mixed_rates(RegionScheme::Butterfly, &table, 3);
}

/// Issue 18: the embedded (compact) table covers every rate 1..=24. On the icosahedron (every
/// vertex of valence 5, irrational weights) the surface passes through the vertices that four
/// whole-mesh butterfly steps make at rate 16, and at rates 9, 12, 16 and 24 (those the grid
/// table before format version 5 lacked; `cli::every_rate_is_watertight` runs every rate
/// 1..=24 on the octahedron) the tessellation is a watertight oriented manifold of the input's
/// Euler characteristic (`check_topology`).
#[test]
fn the_embedded_table_covers_the_new_rates_watertight() {
    let table = StencilTable::default_butterfly().expect("embedded butterfly table");
    let iso = isolate_regions(&icosahedron(), RegionScheme::Butterfly).expect("isolates");
    check_against_refinement("icosahedron at rate 16", &table, &iso, 16);
    for rate in [9, 12, 16, 24] {
        let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &vec![rate; 1280])
            .unwrap_or_else(|e| panic!("rate {rate}: {e}"));
        check_topology(
            &iso.mesh,
            &grid.tessellate(&iso.mesh),
            &format!("icosahedron at rate {rate}"),
        );
    }
}
