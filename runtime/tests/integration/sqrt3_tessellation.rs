//! √3 meshes end to end: isolation by ternary steps, the region patches and their layouts, and
//! the tessellation from the default √3 table.
//!
//! √3 approximates, so the independent reference is Kobbelt's limit-position rule
//! (`subtess::scheme::sqrt3::refine::sqrt3_limit_position`, a closed form checked there to be invariant
//! under the step): at a ternary parameter `(i/3^m, j/3^m)` of a triangle the limit surface is
//! the limit position of the vertex that `m` whole-mesh ternary steps (two √3 steps each, the
//! rules written out in `subtess::scheme::sqrt3::refine`) put there. That checks the table's stencils,
//! the region layouts and their rotations, and the triangle dual grid's point maps together,
//! without the solver that made the table.

use crate::common;

use proptest::prelude::*;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_topology::neighbours;
use subtess::scheme::region_isolate::isolate_regions;
use subtess::scheme::sqrt3::refine::{sqrt3_limit_position, sqrt3_refine};
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::scheme::triangle::region_patch::RegionScheme;
use subtess::scheme::triangle::split::ternary_child_to_parent;
use subtess::stencil_table::StencilTable;
use subtess::tessellate::triangle_dual_grid::TriangleDualGrid;
use subtess::tessellate::GridPlan;

use common::{
    check_rates_give_a_manifold, check_region_layouts, check_spot_at_mixed_rates, check_topology,
    icosahedron, octahedron, region_kinds, tetrahedron, torus, worst_normal_angle,
};

/// `m` ternary steps of `mesh`, every level kept.
fn levels_of(mesh: &Mesh, m: usize) -> Vec<Mesh> {
    let mut levels = vec![mesh.clone()];
    for _ in 0..m {
        let next = sqrt3_refine(&levels[levels.len() - 1])
            .expect("refines")
            .mesh;
        levels.push(next);
    }
    levels
}

/// Two ternary steps separate neighbouring extraordinary vertices (nine edges apart; one step
/// leaves them three apart, inside each other's regions); a regular torus needs none. Every
/// region of the valence shows up, and nothing else.
#[test]
fn isolation_separates_the_extraordinary_vertices() {
    let cases: Vec<(&str, Mesh, usize, u32)> = vec![
        ("tetrahedron", tetrahedron(), 2, 3),
        ("octahedron", octahedron(), 2, 4),
        ("icosahedron", icosahedron(), 2, 5),
        ("torus", torus(12, 12), 0, 6),
    ];
    for (name, m, steps, k) in cases {
        let iso =
            isolate_regions(&m, RegionScheme::Sqrt3).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(iso.steps, steps, "{name}");
        assert_eq!(
            iso.mesh.faces(),
            m.faces() * 9usize.pow(steps as u32),
            "{name}"
        );
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
            isolate_regions(&m, RegionScheme::Sqrt3).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_region_layouts(name, RegionScheme::Sqrt3, &iso);
    }
}

/// The vertex of the `m`-times refined mesh at the ternary point `(u, v) / 3^m` of triangle
/// `f`, found by searching the children (the inverse of `ternary_child_to_parent`).
fn refined_vertex(levels: &[Mesh], f: usize, u: u32, v: u32, m: usize) -> u32 {
    let (mut f, mut u, mut v, mut d) = (f, u, v, 3u32.pow(m as u32));
    while d > 1 {
        let child = (0..9u8).find_map(|c| {
            (0..=d / 3).find_map(|s| {
                (0..=d / 3 - s)
                    .find(|&t| ternary_child_to_parent(c, s, t, d / 3) == (u, v))
                    .map(|t| (c, s, t))
            })
        });
        let (c, s, t) = child.unwrap_or_else(|| panic!("({u}, {v}) / {d} is outside"));
        (f, u, v, d) = (9 * f + c as usize, s, t, d / 3);
    }
    let corner = match (u, v) {
        (0, 0) => 0,
        (1, 0) => 1,
        _ => 2,
    };
    levels[m].face(f)[corner]
}

/// Kobbelt's limit position of vertex `v` of `mesh`.
fn limit_position(mesh: &Mesh, v: usize) -> [f64; 3] {
    let ring = neighbours(mesh, v);
    let sum = ring.iter().fold([0.0; 3], |acc, &e| {
        [0, 1, 2].map(|c| acc[c] + mesh.positions[e as usize][c])
    });
    let k = ring.len();
    sqrt3_limit_position(mesh.positions[v], sum.map(|c| c / k as f64), k)
}

/// The ternary level `m <= max` of `(u, v) / d` and its numerators over `3^m`, if it has one.
fn ternary_point(u: u32, v: u32, d: u32, max: usize) -> Option<(usize, u32, u32)> {
    (0..=max).find_map(|m| {
        let p = 3u32.pow(m as u32);
        (u * p % d == 0 && v * p % d == 0).then(|| (m, u * p / d, v * p / d))
    })
}

/// Every output vertex at a ternary source (level 0..=2: primal points at rates divisible by
/// 3, triangle centres of the dual grid) equals Kobbelt's limit position of the refined mesh's
/// vertex there.
fn check_against_limit_positions(
    name: &str,
    table: &StencilTable,
    iso: &TriangleIsolation,
    levels: &[Mesh],
    rate: u32,
) {
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
    let mut checked = [0usize; 3];
    let mut worst = 0.0f64;
    for (p, s) in out.positions.iter().zip(&out.sources) {
        let Some((m, u, v)) = ternary_point(s.u, s.v, s.denominator, levels.len() - 1) else {
            continue;
        };
        let w = refined_vertex(levels, s.face as usize, u, v, m);
        let q = limit_position(&levels[m], w as usize);
        for c in 0..3 {
            worst = worst.max((f64::from(p[c]) - q[c]).abs() / scale);
        }
        checked[m] += 1;
    }
    println!("{name}: ternary vertices per level {checked:?}, worst relative error {worst:.2e}");
    assert!(checked.iter().sum::<usize>() > 0, "{name}: nothing checked");
    assert!(worst < 2e-6, "{name}: {worst:.2e}");
    check_topology(&iso.mesh, &out, name);
}

#[test]
fn the_surface_meets_the_limit_positions_of_refined_vertices() {
    let table = StencilTable::default_sqrt3().expect("embedded sqrt3 table");
    for (name, m) in [
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
        ("torus", torus(12, 12)),
    ] {
        let iso =
            isolate_regions(&m, RegionScheme::Sqrt3).unwrap_or_else(|e| panic!("{name}: {e}"));
        let levels = levels_of(&iso.mesh, 2);
        for rate in [1, 3, 6] {
            check_against_limit_positions(
                &format!("{name} at rate {rate}"),
                &table,
                &iso,
                &levels,
                rate,
            );
        }
    }
}

/// The table's normals (from the d/du, d/dv stencils; at the extraordinary vertices Loop's
/// eigenvector convention) against the ring normals of the mesh refined three more ternary
/// steps at the same level-1 vertices; the normals of the convex shapes point out.
#[test]
fn normals_follow_the_refined_surface() {
    let table = StencilTable::default_sqrt3().expect("embedded sqrt3 table");
    for (name, m) in [("octahedron", octahedron()), ("tetrahedron", tetrahedron())] {
        let iso =
            isolate_regions(&m, RegionScheme::Sqrt3).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (rate, extra) = (3u32, 3usize);
        let levels = levels_of(&iso.mesh, extra);
        let grid = TriangleDualGrid::new(
            &table,
            &iso.mesh,
            &iso.patches,
            &vec![rate; iso.mesh.faces()],
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let out = grid.tessellate(&iso.mesh);
        // The level-1 vertex keeps its number at every later level.
        let worst = worst_normal_angle(name, &out, &levels[extra], |s| {
            let (_, u, v) = ternary_point(s.u, s.v, s.denominator, 1).filter(|t| t.0 == 1)?;
            Some(refined_vertex(&levels, s.face as usize, u, v, 1))
        });
        assert!(worst < 5e-3, "{name}: {worst}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    #[test]
    fn random_rates_give_manifolds(rates in proptest::collection::vec(1u32..=8, 1620)) {
        let iso = isolate_regions(&icosahedron(), RegionScheme::Sqrt3).expect("isolates");
        prop_assert_eq!(iso.mesh.faces(), rates.len());
        let table = StencilTable::default_sqrt3().expect("embedded table");
        check_rates_give_a_manifold(&table, "icosahedron", &iso, &rates);
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn spot_tessellates_to_a_closed_manifold_at_mixed_rates() {
    let table = StencilTable::default_sqrt3().expect("embedded table");
    check_spot_at_mixed_rates(RegionScheme::Sqrt3, &table, 2);
}

/// Issue 18: the embedded (compact) table covers every rate 1..=24. On the octahedron (every
/// vertex of valence 4) the surface meets the limit positions of twice-refined vertices at
/// rate 9, and at rates 9, 12, 16 and 24 (those the grid table before format version 5 lacked;
/// `cli::every_rate_is_watertight` runs every rate 1..=24) the tessellation is a watertight
/// oriented manifold of the input's Euler characteristic (`check_topology`).
#[test]
fn the_embedded_table_covers_the_new_rates_watertight() {
    let table = StencilTable::default_sqrt3().expect("embedded sqrt3 table");
    let iso = isolate_regions(&octahedron(), RegionScheme::Sqrt3).expect("isolates");
    let levels = levels_of(&iso.mesh, 2);
    check_against_limit_positions("octahedron at rate 9", &table, &iso, &levels, 9);
    for rate in [9, 12, 16, 24] {
        let grid = TriangleDualGrid::new(
            &table,
            &iso.mesh,
            &iso.patches,
            &vec![rate; iso.mesh.faces()],
        )
        .unwrap_or_else(|e| panic!("rate {rate}: {e}"));
        check_topology(
            &iso.mesh,
            &grid.tessellate(&iso.mesh),
            &format!("octahedron at rate {rate}"),
        );
    }
}
