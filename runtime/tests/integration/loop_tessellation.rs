//! Loop (triangle) meshes end to end: isolation, patches, the triangle dual-grid plan, and its
//! output's topology and parameters.
//!
//! Without weights from a Loop table, the geometry-free properties are checked with *flat*
//! stencils ([`FlatStencils`]): every point of a patch is the linear interpolation of the
//! patch's own triangle (`V`, and the two corners after it), which is what a table's layout
//! would give for the piecewise-linear surface. With them:
//!
//! * the output is an oriented 2-manifold (it builds a valid [`Mesh`]: every edge in at most two
//!   triangles, traversed both ways, every vertex a single fan) with the input's Euler
//!   characteristic and number of boundary loops, for random per-face rates;
//! * every output vertex lies on its input triangle at its exact source: tessellating the
//!   isolated mesh with its vertices placed linearly (input vertices where they are, edge points
//!   at the input edges' midpoints) puts every vertex at `(1-u-v) v0 + u v1 + v v2` of its
//!   source, and every normal along the input triangle's normal — which checks the rotations
//!   into the patches, the patch corners' order and the exact child parameters.

use crate::common;

use std::collections::HashMap;

use proptest::prelude::*;
use schemes::BoundaryMode;
use subtess::mesh::topology::Mesh;
use subtess::mesh::triangle_mesh::TriangleMesh;
use subtess::scheme::loop_scheme::isolate::isolate_loop;
use subtess::scheme::loop_scheme::refine::loop_refine;
use subtess::scheme::triangle::isolation::TriangleIsolation;
use subtess::tessellate::triangle_dual_grid::{TriangleDualGrid, TriangleStencils};
use subtess::tessellate::GridPlan;
use subtess::{MeshError, RuntimeError};
use table_format::{PointSet, SectionKey, StencilKind};

use common::{check_topology, icosahedron, load, mesh, models, octahedron, tetrahedron, torus};

/// The largest rate the flat stencils cover.
const MAX_N: u32 = 12;

/// Stencils of the piecewise-linear surface in the Loop tables' layout: a patch's point
/// `(u, v)` is `(1-u-v) V + u A + v B`, where `A`, `B` are the patch's `(1,0)` and `(0,1)`
/// corners: layout entries 1 and 2 of an interior patch (`E_0`, `E_1`), `1 + s` and `2 + s` of a
/// boundary patch in sector `s` (`E_s`, `E_{s+1}`).
struct FlatStencils {
    sections: HashMap<SectionKey, Vec<f32>>,
}

/// The points of a triangle point set at rate `n`, in table order.
fn grid_points(points: PointSet, n: u32) -> Vec<(f64, f64)> {
    let n_f = f64::from(n);
    let mut out = Vec::new();
    match points {
        PointSet::TrianglePrimal => {
            for j in 0..=n {
                for i in 0..=n - j {
                    out.push((f64::from(i) / n_f, f64::from(j) / n_f));
                }
            }
        }
        _ => {
            for j in 0..n {
                for i in 0..n - j {
                    let at = |shift: u32| {
                        (
                            f64::from(3 * i + shift) / (3.0 * n_f),
                            f64::from(3 * j + shift) / (3.0 * n_f),
                        )
                    };
                    out.push(at(1));
                    if i + j + 1 < n {
                        out.push(at(2));
                    }
                }
            }
        }
    }
    out
}

impl FlatStencils {
    fn new() -> Self {
        let mut patches = Vec::new();
        for valence in 3..=12u32 {
            patches.push((false, valence, 0u32, valence as usize + 6, 1usize));
        }
        for k in 1..=6u32 {
            for s in 0..k {
                let size = 1 + (k + 1) + 3 + u32::from(s >= 1) + u32::from(s + 2 <= k);
                patches.push((true, k, s, size as usize, 1 + s as usize));
            }
        }
        let mut sections = HashMap::new();
        for (boundary, faces, sector, size, a) in patches {
            for n in 1..=MAX_N {
                for points in [PointSet::TrianglePrimal, PointSet::TriangleDual] {
                    for kind in [
                        StencilKind::Position,
                        StencilKind::DerivativeU,
                        StencilKind::DerivativeV,
                    ] {
                        let mut w = Vec::new();
                        for (u, v) in grid_points(points, n) {
                            let mut row = vec![0.0f32; size];
                            let (c, cu, cv) = match kind {
                                StencilKind::Position => (1.0 - u - v, u, v),
                                StencilKind::DerivativeU => (-1.0, 1.0, 0.0),
                                StencilKind::DerivativeV => (-1.0, 0.0, 1.0),
                            };
                            row[0] = c as f32;
                            row[a] = cu as f32;
                            row[a + 1] = cv as f32;
                            w.extend(row);
                        }
                        let key = SectionKey {
                            kind,
                            points,
                            boundary,
                            feature: table_format::Feature::None,
                            faces,
                            sector,
                            n,
                        };
                        sections.insert(key, w);
                    }
                }
            }
        }
        FlatStencils { sections }
    }
}

impl TriangleStencils for FlatStencils {
    fn triangle_weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError> {
        self.sections
            .get(key)
            .map(Vec::as_slice)
            .ok_or_else(|| RuntimeError::Unsupported(format!("flat stencils lack {key}")))
    }
}

fn single_triangle() -> Mesh {
    mesh(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.9, 0.3]],
        &[[0, 1, 2]],
    )
}

/// A disc of two rings around a centre on the hexagonal lattice: the centre and the inner ring
/// regular, the rim on the boundary with two or three triangles.
fn disc() -> Mesh {
    let lattice = |a: i64, b: i64| [a as f64 + 0.5 * b as f64, 0.75f64.sqrt() * b as f64, 0.0];
    let mut points = Vec::new();
    let mut index = HashMap::new();
    for b in -2i64..=2 {
        for a in -2i64..=2 {
            if (a + b).abs() <= 2 {
                index.insert((a, b), points.len() as i64);
                points.push(lattice(a, b));
            }
        }
    }
    let mut faces = Vec::new();
    let at = |a: i64, b: i64| index.get(&(a, b)).copied();
    for b in -3i64..=2 {
        for a in -3i64..=2 {
            // Up triangle (a,b),(a+1,b),(a,b+1) and down (a+1,b),(a+1,b+1),(a,b+1).
            if let (Some(v), Some(x), Some(y)) = (at(a, b), at(a + 1, b), at(a, b + 1)) {
                faces.push([v, x, y]);
            }
            if let (Some(x), Some(z), Some(y)) = (at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)) {
                faces.push([x, z, y]);
            }
        }
    }
    faces.sort_unstable();
    mesh(points, &faces)
}

/// Tessellate with flat stencils at per-input-face rates; sources in the input's triangles.
fn tessellate_flat(
    stencils: &FlatStencils,
    iso: &TriangleIsolation,
    positions: &[[f64; 3]],
    input_rates: &[u32],
) -> TriangleMesh {
    let rates: Vec<u32> = iso
        .origin
        .iter()
        .map(|&f| input_rates[f as usize])
        .collect();
    let grid = TriangleDualGrid::new(stencils, &iso.mesh, &iso.patches, &rates)
        .unwrap_or_else(|e| panic!("plan: {e}"));
    let mut placed = iso.mesh.clone();
    placed.positions = positions.to_vec();
    let mut out = grid.tessellate(&placed);
    for s in &mut out.sources {
        *s = iso.input_source(*s);
    }
    assert_eq!(out.positions.len(), grid.vertex_count());
    assert_eq!(out.triangles.len(), grid.triangle_count());
    out
}

/// The isolated mesh's vertices placed linearly on the input: input vertices where they are,
/// edge points at their edge's midpoint, step by step (from the refinement's own edge lists).
fn linear_positions(input: &Mesh, iso: &TriangleIsolation) -> Vec<[f64; 3]> {
    let mut current = input.clone();
    let mut linear = input.positions.clone();
    for _ in 0..iso.steps {
        let refinement = loop_refine(&current).expect("refines");
        for [a, b] in refinement.edges {
            let (p, q) = (linear[a as usize], linear[b as usize]);
            linear.push([0, 1, 2].map(|c| 0.5 * (p[c] + q[c])));
        }
        current = refinement.mesh;
    }
    linear
}

/// Every output vertex at its source on its input triangle, every normal along the triangle's.
fn check_on_input(input: &Mesh, out: &TriangleMesh, label: &str) {
    let scale = input
        .positions
        .iter()
        .flat_map(|p| p.iter().map(|c| c.abs()))
        .fold(1.0f64, f64::max);
    for ((p, normal), s) in out.positions.iter().zip(&out.normals).zip(&out.sources) {
        let corners = input.face(s.face as usize);
        let [a, b, c] = [0, 1, 2].map(|k| input.positions[corners[k] as usize]);
        let (u, v) = s.uv();
        assert!(
            u >= 0.0 && v >= 0.0 && u + v <= 1.0,
            "{label}: source {s:?}"
        );
        for k in 0..3 {
            let expected = (1.0 - u - v) * a[k] + u * b[k] + v * c[k];
            assert!(
                (f64::from(p[k]) - expected).abs() <= 1e-5 * scale,
                "{label}: vertex at {s:?} is {p:?}, its source on the input is at {k}: {expected}"
            );
        }
        let (e1, e2) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let cosine = (0..3).map(|k| f64::from(normal[k]) * n[k]).sum::<f64>() / length;
        assert!(
            cosine > 1.0 - 1e-5,
            "{label}: normal {normal:?} at {s:?} is not the input triangle's {n:?}"
        );
    }
}

/// The disc with a triangle glued to its rim: a boundary corner with one triangle (an ear),
/// whose neighbour after a Loop step has two boundary corners joined by an interior edge (the
/// regular patch with phantoms).
fn eared_disc() -> Mesh {
    let m = disc();
    let rim = (0..m.positions.len())
        .find(|&v| m.is_boundary_vertex(v))
        .expect("a rim");
    let h = m.vertex_halfedge[rim] as usize;
    let (a, b) = (m.face_vertices[h], m.head(h));
    let mut positions = m.positions.clone();
    let (p, q) = (positions[a as usize], positions[b as usize]);
    positions.push([0, 1, 2].map(|c| 0.5 * (p[c] + q[c]) + if c == 2 { 0.7 } else { 0.0 }));
    let apex = (positions.len() - 1) as i64;
    let mut faces: Vec<Vec<i64>> = (0..m.faces())
        .map(|f| m.face(f).iter().map(|&v| i64::from(v)).collect())
        .collect();
    faces.push(vec![i64::from(b), i64::from(a), apex]);
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("valid")
}

fn small_meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("tetrahedron", tetrahedron()),
        ("octahedron", octahedron()),
        ("icosahedron", icosahedron()),
        ("disc", disc()),
        ("torus", torus(6, 5)),
        ("single triangle", single_triangle()),
        ("eared disc", eared_disc()),
    ]
}

#[test]
fn the_small_meshes_have_the_expected_topology() {
    for (name, m) in small_meshes() {
        let expected = match name {
            "tetrahedron" | "octahedron" | "icosahedron" => (2, 0),
            "torus" => (0, 0),
            _ => (1, 1),
        };
        assert_eq!(
            (m.euler_characteristic(), m.boundary_loops()),
            expected,
            "{name}"
        );
    }
    // The disc has 19 vertices, 24 triangles.
    assert_eq!((disc().positions.len(), disc().faces()), (19, 24));
    // Next to a one-triangle corner some patch reads phantom points (indices past the mesh's
    // vertices); elsewhere none does.
    for (name, m) in small_meshes() {
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        let vertices = iso.mesh.positions.len() as u32;
        let phantom = iso
            .patches
            .iter()
            .any(|p| p.points.iter().any(|&c| c >= vertices));
        assert_eq!(
            phantom,
            matches!(name, "single triangle" | "eared disc"),
            "{name}"
        );
    }
}

#[test]
fn isolation_refines_exactly_when_a_triangle_needs_it() {
    for (name, m) in small_meshes() {
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        // The torus (all valence 6) and the disc (its only irregular vertices are rim corners
        // with two triangles, never two in one triangle) are table patches as given.
        let patches_as_given = name == "torus" || name == "disc";
        assert_eq!(iso.steps, usize::from(!patches_as_given), "{name}");
        assert_eq!(iso.mesh.faces(), m.faces() * 4usize.pow(iso.steps as u32));
    }
}

#[test]
fn uniform_and_mixed_rates_give_manifolds_on_the_input() {
    let stencils = FlatStencils::new();
    for (name, m) in small_meshes() {
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        let linear = linear_positions(&m, &iso);
        for rates in [
            vec![1; m.faces()],
            vec![2; m.faces()],
            vec![5; m.faces()],
            (0..m.faces()).map(|f| 1 + (f as u32 * 7) % 12).collect(),
        ] {
            let label = format!("{name}, rates {:?}", &rates[..rates.len().min(6)]);
            let out = tessellate_flat(&stencils, &iso, &linear, &rates);
            check_topology(&m, &out, &label);
            check_on_input(&m, &out, &label);
        }
    }
}

/// Closed meshes: `3n^2 - 3n + 3` triangles per tessellated triangle at uniform rate `n`
/// (`3(n-1)(n-2)` in its hexagons, `3 (2n - 2)` in its half of three edge strips, 3 in its
/// share of the vertex fans).
#[test]
fn a_closed_mesh_at_uniform_rate_has_the_counted_triangles() {
    let stencils = FlatStencils::new();
    let m = icosahedron();
    let iso = isolate_loop(&m).expect("isolates");
    for n in 1..=6u32 {
        let out = tessellate_flat(&stencils, &iso, &iso.mesh.positions, &vec![n; m.faces()]);
        let per_face = (3 * n * n - 3 * n + 3) as usize;
        assert_eq!(out.triangles.len(), per_face * iso.mesh.faces(), "n = {n}");
    }
}

#[test]
fn non_triangles_and_non_manifold_input_are_named() {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let quad = Mesh::new(
        p.clone(),
        &[vec![1, 4, 2], vec![0, 1, 2, 3]],
        &[],
        BoundaryMode::EdgeOnly,
    )
    .expect("valid");
    let e = isolate_loop(&quad).expect_err("a quad");
    assert!(
        matches!(
            e,
            RuntimeError::Mesh(MeshError::NotTriangle {
                face: 1,
                vertices: 4
            })
        ),
        "{e}"
    );
    // Two triangles sharing only a vertex: the topology splits the vertex (Catmull–Clark takes
    // it as OpenSubdiv does), the Loop surface refuses it by name.
    let bowtie = Mesh::new(
        vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ],
        &[vec![0, 1, 2], vec![0, 3, 4]],
        &[],
        BoundaryMode::EdgeOnly,
    )
    .expect("split");
    assert_eq!(bowtie.copies, vec![0]);
    let e = subtess::Surface::new(&bowtie, subtess::Scheme::Loop).expect_err("non-manifold");
    assert!(e.to_string().contains("non-manifold"), "{e}");
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn the_models_tessellate_to_manifolds_on_the_input() {
    let dir = models();
    let stencils = FlatStencils::new();
    for (file, euler, loops) in [
        ("crane/spot_triangulated.obj", 2, 0),
        ("odedstein/hand_lowres.obj", 1, 1),
    ] {
        let m = load(&dir.join(file));
        assert_eq!(
            (m.euler_characteristic(), m.boundary_loops()),
            (euler, loops),
            "{file}"
        );
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{file}: {e}"));
        let linear = linear_positions(&m, &iso);
        let rates: Vec<u32> = (0..m.faces()).map(|f| 1 + (f as u32 * 5) % 7).collect();
        let out = tessellate_flat(&stencils, &iso, &linear, &rates);
        check_topology(&m, &out, file);
        check_on_input(&m, &out, file);
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn the_hand_has_one_boundary_loop_of_16_edges_with_2_3_and_4_triangles() {
    let m = load(&models().join("odedstein/hand_lowres.obj"));
    let boundary: Vec<usize> = (0..m.positions.len())
        .filter(|&v| m.is_boundary_vertex(v))
        .collect();
    assert_eq!(boundary.len(), 16);
    let mut ks: Vec<usize> = boundary.iter().map(|&v| m.fan(v).len()).collect();
    ks.sort_unstable();
    ks.dedup();
    assert_eq!(ks, vec![2, 3, 4]);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random per-face rates on the small meshes.
    #[test]
    fn random_rates_on_small_meshes(which in 0usize..7, seed in proptest::collection::vec(1u32..=12, 80)) {
        let stencils = FlatStencils::new();
        let (name, m) = small_meshes().swap_remove(which);
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        let rates: Vec<u32> = (0..m.faces()).map(|f| seed[f % seed.len()]).collect();
        let linear = linear_positions(&m, &iso);
        let out = tessellate_flat(&stencils, &iso, &linear, &rates);
        check_topology(&m, &out, name);
        check_on_input(&m, &out, name);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2, ..ProptestConfig::default() })]

    /// Random per-face rates 1..=12 on Spot (closed, genus 0) and the hand (one boundary loop).
    #[test]
    #[cfg_attr(not(shared_models), ignore = "needs ../shared/models beside the repository")]
    fn random_rates_on_the_models(hand in any::<bool>(), seed in proptest::collection::vec(1u32..=12, 1..400)) {
        let dir = models();
        let stencils = FlatStencils::new();
        let file = if hand { "odedstein/hand_lowres.obj" } else { "crane/spot_triangulated.obj" };
        let m = load(&dir.join(file));
        let iso = isolate_loop(&m).unwrap_or_else(|e| panic!("{file}: {e}"));
        let rates: Vec<u32> = (0..m.faces()).map(|f| seed[(f * 31 + f / 7) % seed.len()]).collect();
        let out = tessellate_flat(&stencils, &iso, &iso.mesh.positions, &rates);
        check_topology(&m, &out, file);
    }
}

// ---------------------------------------------------------------------------------------------
// With the default Loop table: the surface itself.

fn rational(p: i64, q: i64) -> num_rational::BigRational {
    num_rational::BigRational::new(p.into(), q.into())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

mod with_the_table {
    use super::*;
    use num_rational::BigRational;
    use num_traits::ToPrimitive;
    use subtess::stencil_table::StencilTable;
    use subtess_tests::box_spline::{box_spline, DIRECTIONS};

    fn table() -> StencilTable {
        StencilTable::default_loop().unwrap_or_else(|e| panic!("the embedded Loop table: {e}"))
    }

    /// `M_{222}` with direction `drop` removed once (`None`: none), centred like Loop's basis
    /// (`x + (2, 0)`), by exact box-spline recurrences (`subtess_tests::box_spline`).
    fn centred(drop: Option<usize>, x: &(BigRational, BigRational)) -> BigRational {
        let mut c = [2u32, 2, 2];
        if let Some(j) = drop {
            c[j] -= 1;
        }
        box_spline(c, &(&x.0 + rational(2, 1), x.1.clone()))
    }

    /// Lattice points `(a, b)` with their weights in a value and its three derivatives.
    type Weights = Vec<((i64, i64), [f64; 4])>;

    /// Weights of the control points of lattice points `(a, b)` near `x` in the value and the
    /// derivatives along `DIRECTIONS[0]`, `[1]`, `[2]` of the regular Loop surface over the
    /// lattice: the quartic box spline `sum_p P_p M_{222}(x - p + (2,0))`, with the box-spline
    /// derivative identity `D_xi M_Xi(x) = M_{Xi \ xi}(x) - M_{Xi \ xi}(x - xi)`.
    fn box_spline_weights(x: &(BigRational, BigRational)) -> Weights {
        let (fa, fb) = (
            x.0.floor().to_integer().to_i64().expect("small"),
            x.1.floor().to_integer().to_i64().expect("small"),
        );
        let mut out = Vec::new();
        for b in fb - 2..=fb + 3 {
            for a in fa - 2..=fa + 3 {
                let d = (&x.0 - rational(a, 1), &x.1 - rational(b, 1));
                // The support is the hexagon max(|a|, |b|, |a + b|) <= 2 around p.
                let (da, db) = (d.0.to_f64().expect("finite"), d.1.to_f64().expect("finite"));
                if da.abs().max(db.abs()).max((da + db).abs()) > 3.0 {
                    continue;
                }
                let mut w = [centred(None, &d).to_f64().expect("finite"), 0.0, 0.0, 0.0];
                for (j, xi) in DIRECTIONS.iter().enumerate() {
                    let shifted = (&d.0 - rational(xi.0, 1), &d.1 - rational(xi.1, 1));
                    w[j + 1] = (centred(Some(j), &d) - centred(Some(j), &shifted))
                        .to_f64()
                        .expect("finite");
                }
                out.push(((a, b), w));
            }
        }
        out
    }

    fn combine(
        weights: &[((i64, i64), [f64; 4])],
        control: impl Fn(i64, i64) -> [f64; 3],
    ) -> [[f64; 3]; 4] {
        let mut out = [[0.0; 3]; 4];
        for &((a, b), w) in weights {
            let p = control(a, b);
            for (o, w) in out.iter_mut().zip(w) {
                for c in 0..3 {
                    o[c] += w * p[c];
                }
            }
        }
        out
    }

    /// On a torus whose every vertex has valence 6, every output vertex is the quartic box
    /// spline at its exact source, and every normal its normal.
    #[test]
    fn a_regular_torus_is_the_quartic_box_spline_at_every_output_vertex() {
        let table = table();
        let (m, n) = (6usize, 5usize);
        let t = torus(m, n);
        let iso = isolate_loop(&t).expect("isolates");
        assert_eq!(iso.steps, 0);
        let rates: Vec<u32> = (0..t.faces()).map(|f| 1 + (f as u32 * 5) % 4).collect();
        let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates).expect("plan");
        let out = grid.tessellate(&iso.mesh);
        let control = |a: i64, b: i64| {
            t.positions[(b.rem_euclid(n as i64) as usize) * m + a.rem_euclid(m as i64) as usize]
        };
        let mut cache: HashMap<(BigRational, BigRational, bool), Weights> = HashMap::new();
        for ((p, normal), s) in out.positions.iter().zip(&out.normals).zip(&out.sources) {
            // Face 2(j m + i) is the up triangle at lattice (i, j), the next one the down.
            let (cell, down) = (s.face as usize / 2, s.face % 2 == 1);
            let (i, j) = ((cell % m) as i64, (cell / m) as i64);
            let d = i64::from(s.denominator);
            let (u, v) = (rational(i64::from(s.u), d), rational(i64::from(s.v), d));
            // Lattice offsets from the triangle's lattice point (i, j), on which the weights
            // depend only through (u, v) and the orientation (up: (u, v); down: (1 - v, u + v)).
            let local = if down {
                (rational(1, 1) - &v, &u + &v)
            } else {
                (u.clone(), v.clone())
            };
            let weights = cache
                .entry((u, v, down))
                .or_insert_with(|| box_spline_weights(&local));
            // The box spline reproduces linear functions: the lattice coordinates themselves
            // come back, a check on the reference.
            let linear = combine(weights, |a, b| [a as f64, b as f64, 0.0]);
            assert!((linear[0][0] - local.0.to_f64().expect("finite")).abs() < 1e-12);
            assert!((linear[0][1] - local.1.to_f64().expect("finite")).abs() < 1e-12);
            let value = combine(weights, |a, b| control(a + i, b + j));
            // d/du, d/dv of the face: up (xi_1, xi_2); down (xi_2, -xi_3).
            let (du, dv) = if down {
                (value[2], value[3].map(|c| -c))
            } else {
                (value[1], value[2])
            };
            for c in 0..3 {
                assert!(
                    (f64::from(p[c]) - value[0][c]).abs() <= 1e-5 * 4.0,
                    "vertex at {s:?}: {p:?}, box spline {:?}",
                    value[0]
                );
            }
            let expected = cross(du, dv);
            let length = expected.iter().map(|c| c * c).sum::<f64>().sqrt();
            let cosine = (0..3)
                .map(|c| f64::from(normal[c]) * expected[c])
                .sum::<f64>()
                / length;
            assert!(
                cosine > 1.0 - 1e-6,
                "normal at {s:?}: {normal:?} vs {expected:?}"
            );
        }
    }

    /// Loop's closed-form limit position (Loop 1987; chi = 1 / (3 / (8 beta) + v)):
    /// `(1 - v chi) V + chi sum E_i`, Warren's `beta` (3/16 at valence 3, 3/(8v) above).
    fn limit_position(mesh: &Mesh, v: usize) -> [f64; 3] {
        let fan = mesh.fan(v);
        let valence = fan.len() as f64;
        let beta = if fan.len() == 3 {
            3.0 / 16.0
        } else {
            3.0 / (8.0 * valence)
        };
        let chi = 1.0 / (3.0 / (8.0 * beta) + valence);
        let mut out = mesh.positions[v].map(|c| (1.0 - valence * chi) * c);
        for h in fan {
            let e = mesh.positions[mesh.head(h) as usize];
            for c in 0..3 {
                out[c] += chi * e[c];
            }
        }
        out
    }

    fn check_limit_points(mesh: &Mesh, label: &str) {
        let table = table();
        let iso = isolate_loop(mesh).unwrap_or_else(|e| panic!("{label}: {e}"));
        let rates: Vec<u32> = (0..iso.mesh.faces()).map(|f| 1 + f as u32 % 5).collect();
        let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates).expect("plan");
        let out = grid.tessellate(&iso.mesh);
        let scale = iso
            .mesh
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|c| c.abs()))
            .fold(0.0f64, f64::max);
        let mut valences = std::collections::BTreeSet::new();
        for v in 0..iso.mesh.positions.len() {
            let at = grid.limit_point(v).expect("used") as usize;
            valences.insert(iso.mesh.fan(v).len());
            let expected = limit_position(&iso.mesh, v);
            for c in 0..3 {
                assert!(
                    (f64::from(out.positions[at][c]) - expected[c]).abs() <= 1e-5 * scale,
                    "{label}: vertex {v} (valence {}): {:?} vs {expected:?}",
                    iso.mesh.fan(v).len(),
                    out.positions[at]
                );
            }
        }
        println!("{label}: valences {valences:?}");
    }

    /// On convex, centred solids every normal points outwards, and every output triangle turns
    /// the same way as the surface (its geometric normal along its vertices' normals).
    #[test]
    fn normals_point_outwards_and_triangles_agree_with_them() {
        let table = table();
        for (name, m) in [("octahedron", octahedron()), ("icosahedron", icosahedron())] {
            let iso = isolate_loop(&m).expect("isolates");
            let rates: Vec<u32> = (0..iso.mesh.faces()).map(|f| 1 + f as u32 % 7).collect();
            let grid =
                TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates).expect("plan");
            let out = grid.tessellate(&iso.mesh);
            for (p, n) in out.positions.iter().zip(&out.normals) {
                let outward: f32 = (0..3).map(|c| p[c] * n[c]).sum();
                assert!(outward > 0.0, "{name}: normal {n:?} at {p:?}");
            }
            for t in &out.triangles {
                let [a, b, c] = t.map(|v| out.positions[v as usize].map(f64::from));
                let e1 = [0, 1, 2].map(|k| b[k] - a[k]);
                let e2 = [0, 1, 2].map(|k| c[k] - a[k]);
                let g = cross(e1, e2);
                let n: [f64; 3] = [0, 1, 2].map(|k| {
                    t.iter()
                        .map(|&v| f64::from(out.normals[v as usize][k]))
                        .sum()
                });
                let along: f64 = (0..3).map(|k| g[k] * n[k]).sum();
                assert!(
                    along > 0.0,
                    "{name}: triangle {t:?} turns against the surface"
                );
            }
        }
    }

    #[test]
    fn interior_limit_points_are_loops_closed_form() {
        for (name, m) in [
            ("tetrahedron", tetrahedron()),
            ("octahedron", octahedron()),
            ("icosahedron", icosahedron()),
        ] {
            check_limit_points(&m, name);
        }
    }

    #[test]
    #[cfg_attr(
        not(shared_models),
        ignore = "needs ../shared/models beside the repository"
    )]
    fn spots_interior_limit_points_are_loops_closed_form() {
        check_limit_points(&load(&models().join("crane/spot_triangulated.obj")), "spot");
    }
}

mod boundary_with_the_table {
    use super::*;
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use num_traits::ToPrimitive;
    use subtess::mesh::topology::NONE;
    use subtess::stencil_table::StencilTable;
    use subtess_tests::bspline::uniform_bspline;

    /// The centred uniform cubic B-spline `N(x) = B_3(x + 2)` (support `[-2, 2]`) at the
    /// rational `x`, from its truncated-power definition (`subtess_tests::bspline`).
    fn cubic(x: BigRational) -> f64 {
        uniform_bspline(3, &(x + BigRational::from_integer(BigInt::from(2))))
            .to_f64()
            .expect("finite")
    }

    /// Tessellate with the default table (boundary sections included) at mixed rates; sources
    /// in the input's triangles.
    fn tessellate_with_boundary(m: &Mesh, label: &str) -> TriangleMesh {
        let table = StencilTable::default_loop().expect("embedded");
        let iso = isolate_loop(m).unwrap_or_else(|e| panic!("{label}: {e}"));
        let rates: Vec<u32> = (0..iso.mesh.faces()).map(|f| 1 + f as u32 % 6).collect();
        let mut out = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates)
            .unwrap_or_else(|e| panic!("{label}: {e}"))
            .tessellate(&iso.mesh);
        for s in &mut out.sources {
            *s = iso.input_source(*s);
        }
        out
    }

    /// Every output vertex on the output's boundary is the uniform cubic B-spline of the input's
    /// boundary polygon at its source (limit points included: `(E_0 + 4V + E_k)/6`).
    fn check_boundary_curve(m: &Mesh, label: &str) {
        let out = tessellate_with_boundary(m, label);
        check_topology(m, &out, label);
        let edges = out.boundary_edges().expect("oriented");
        let scale = m
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|c| c.abs()))
            .fold(1.0f64, f64::max);
        let mut checked = 0;
        for &(a, _) in &edges {
            let s = out.sources[a as usize];
            let face = s.face as usize;
            let (u, v, d) = (s.u, s.v, s.denominator);
            // The face's side the source lies on, and the parameter along it.
            let sides = [(v == 0, u), (u + v == d, v), (u == 0, d - v)];
            let halfedges: Vec<usize> = m.face_halfedges(face).collect();
            // A corner (a vertex's limit point) is `t = 0` on the boundary edge leaving it.
            let corner = [(0, 0), (d, 0), (0, d)].iter().position(|&c| c == (u, v));
            let corner_edge = corner.map(|c| {
                let h = m.vertex_halfedge[m.face_vertices[halfedges[c]] as usize] as usize;
                (h, BigRational::from_integer(BigInt::from(0)))
            });
            let Some((h, t)) = corner_edge
                .into_iter()
                .chain(
                    (0..3)
                        .filter(|&k| sides[k].0 && m.twin[halfedges[k]] == NONE)
                        .map(|k| {
                            let t = BigRational::new(BigInt::from(sides[k].1), BigInt::from(d));
                            (halfedges[k], t)
                        }),
                )
                .next()
            else {
                panic!("{label}: boundary output vertex {a} at {s:?} is not on a boundary edge");
            };
            let (p1, p2) = (m.face_vertices[h] as usize, m.head(h) as usize);
            // The boundary neighbours before p1 and after p2.
            let p0 = m.face_vertices[m.prev(*m.fan(p1).last().expect("used"))] as usize;
            let p3 = m.head(m.vertex_halfedge[p2] as usize) as usize;
            let mut expected = [0.0; 3];
            for (k, p) in [p0, p1, p2, p3].into_iter().enumerate() {
                let w = cubic(&t + BigRational::from_integer(BigInt::from(1 - k as i64)));
                for (e, x) in expected.iter_mut().zip(m.positions[p]) {
                    *e += w * x;
                }
            }
            let got = out.positions[a as usize];
            for c in 0..3 {
                assert!(
                    (f64::from(got[c]) - expected[c]).abs() <= 1e-5 * scale,
                    "{label}: boundary vertex at {s:?} (t = {t} on {p1} -> {p2}): {got:?} vs {expected:?}"
                );
            }
            checked += 1;
        }
        assert_eq!(checked, edges.len());
    }

    /// The limit position at the point `t = i/n` along side `side` of triangle `f` (from its
    /// corner `side` to the next), from the triangle's own patch: the patch at face corner `r`
    /// has `(u', v') = (w_{r+1}, w_{r+2})` of the face's barycentric weights `w`.
    fn on_side(
        stencils: &dyn TriangleStencils,
        mesh: &Mesh,
        patch: &subtess::scheme::triangle::patch::TrianglePatch,
        side: usize,
        i: u32,
        n: u32,
    ) -> [f64; 3] {
        let mut w = [0u32; 3];
        w[side] = n - i;
        w[(side + 1) % 3] = i;
        let r = patch.corner;
        let (pu, pv) = (w[(r + 1) % 3], w[(r + 2) % 3]);
        // Row pv of the primal grid starts after rows of n + 1, n, .. points.
        let at = (0..pv).map(|j| (n + 1 - j) as usize).sum::<usize>() + pu as usize;
        let key = SectionKey {
            kind: StencilKind::Position,
            points: PointSet::TrianglePrimal,
            boundary: patch.kind.boundary,
            feature: patch.kind.feature,
            faces: patch.kind.faces,
            sector: patch.kind.sector,
            n,
        };
        let weights = stencils.triangle_weights(&key).expect("covered");
        let k = patch.points.len();
        let control = subtess::scheme::triangle::patch::Phantoms::new(mesh).extend(&mesh.positions);
        let mut out = [0.0; 3];
        for (weight, &v) in weights[at * k..(at + 1) * k].iter().zip(&patch.points) {
            for (o, x) in out.iter_mut().zip(control[v as usize]) {
                *o += f64::from(*weight) * x;
            }
        }
        out
    }

    /// Two triangles sharing an edge evaluate the same limit curve on it, each from its own
    /// patch (different patch kinds, corners, sectors and layouts): a control point gathered in
    /// the wrong order shows up as a mismatch.
    fn check_edges_agree(m: &Mesh, label: &str) {
        let n = 4;
        let iso = isolate_loop(m).unwrap_or_else(|e| panic!("{label}: {e}"));
        let stencils = StencilTable::default_loop().expect("embedded");
        let mesh = &iso.mesh;
        let scale = mesh
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|c| c.abs()))
            .fold(1.0f64, f64::max);
        let mut compared = 0;
        for h in 0..mesh.face_vertices.len() {
            let t = mesh.twin[h];
            if t == NONE || (t as usize) < h {
                continue;
            }
            let (f, g) = (mesh.face_of[h] as usize, mesh.face_of[t as usize] as usize);
            let side_f = h - mesh.face_halfedges(f).start;
            let side_g = t as usize - mesh.face_halfedges(g).start;
            for i in 0..=n {
                // The twin runs the other way: its parameter n - i is the same point.
                let a = on_side(&stencils, mesh, &iso.patches[f], side_f, i, n);
                let b = on_side(&stencils, mesh, &iso.patches[g], side_g, n - i, n);
                for c in 0..3 {
                    assert!(
                        (a[c] - b[c]).abs() <= 1e-5 * scale,
                        "{label}: edge {h} ({:?} vs {:?}), point {i}/{n}: {a:?} vs {b:?}",
                        iso.patches[f].kind,
                        iso.patches[g].kind
                    );
                }
                compared += 1;
            }
        }
        assert!(compared > 0);
    }

    #[test]
    fn neighbouring_triangles_agree_on_their_shared_edges() {
        check_edges_agree(&disc(), "disc");
        check_edges_agree(&single_triangle(), "single triangle");
        check_edges_agree(&eared_disc(), "eared disc");
        check_edges_agree(&icosahedron(), "icosahedron");
    }

    #[test]
    #[cfg_attr(
        not(shared_models),
        ignore = "needs ../shared/models beside the repository"
    )]
    fn neighbouring_triangles_of_the_hand_agree_on_their_shared_edges() {
        check_edges_agree(&hand(), "hand");
    }

    /// Every `stride`-th output vertex (mixed rates) against exact evaluation at its source on
    /// the input triangle (`subtess::eval::loop_exact_eval`: substitution with exact local matrices
    /// and the regular patch from subdivision; no stencil system): positions to f32 rounding,
    /// normals within 1e-4.
    fn check_exact_evaluation(m: &Mesh, label: &str, stride: usize) {
        let out = tessellate_with_boundary(m, label);
        let eval = subtess::eval::loop_exact_eval::LoopExactEvaluator::new(m)
            .unwrap_or_else(|e| panic!("{label}: {e}"));
        let scale = m
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|c| c.abs()))
            .fold(1.0f64, f64::max);
        let mut checked = 0;
        for (i, s) in out.sources.iter().enumerate().step_by(stride) {
            let d = i64::from(s.denominator);
            let (u, v) = (rational(i64::from(s.u), d), rational(i64::from(s.v), d));
            let exact = eval
                .evaluate(s.face as usize, &u, &v)
                .unwrap_or_else(|e| panic!("{label}: {s:?}: {e}"));
            let got = out.positions[i];
            for c in 0..3 {
                assert!(
                    (f64::from(got[c]) - exact.position[c]).abs() <= 2e-6 * scale,
                    "{label}: vertex {i} at {s:?}: {got:?} vs {:?}",
                    exact.position
                );
            }
            let n = cross(exact.du, exact.dv);
            let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            let table = out.normals[i];
            let dot: f64 = (0..3).map(|c| n[c] / length * f64::from(table[c])).sum();
            assert!(
                dot > 1.0 - 1e-4,
                "{label}: normal at vertex {i} ({s:?}): {table:?} vs {n:?} (dot {dot})"
            );
            checked += 1;
        }
        assert!(checked > 0);
    }

    #[test]
    fn every_output_vertex_is_the_exact_limit_surface_at_its_source() {
        check_exact_evaluation(&icosahedron(), "icosahedron", 7);
        check_exact_evaluation(&disc(), "disc", 3);
        check_exact_evaluation(&single_triangle(), "single triangle", 1);
        check_exact_evaluation(&eared_disc(), "eared disc", 1);
    }

    #[test]
    #[cfg_attr(
        not(shared_models),
        ignore = "needs ../shared/models beside the repository"
    )]
    fn every_output_vertex_of_the_hand_is_the_exact_limit_surface_at_its_source() {
        check_exact_evaluation(&hand(), "hand", 97);
    }

    #[test]
    fn the_boundary_curve_is_the_cubic_bspline_of_the_boundary_polygon() {
        check_boundary_curve(&disc(), "disc");
        // One-triangle corners: the corner patches (k = 1) and the phantom-extended regular
        // patches next to them.
        check_boundary_curve(&single_triangle(), "single triangle");
        check_boundary_curve(&eared_disc(), "eared disc");
    }

    #[test]
    #[cfg_attr(
        not(shared_models),
        ignore = "needs ../shared/models beside the repository"
    )]
    fn the_hands_boundary_curve_is_the_cubic_bspline_of_its_boundary_polygon() {
        check_boundary_curve(&hand(), "hand");
    }

    /// Oded Stein's hand (one boundary loop), from `../shared/models`.
    fn hand() -> Mesh {
        load(&models().join("odedstein/hand_lowres.obj"))
    }
}

/// The regular faces' quartic polynomials (`runtime/src/tessellate/loop_quartic.rs`) against
/// the same plan evaluating every face from its table stencils (`without_quartics`): the two
/// are independent ways of evaluating the same section (the stencils are the table's rows; the
/// quartic is interpolated from `schemes::loop_regular`'s closed form).
mod quartic_against_stencils {
    use super::*;
    use subtess::stencil_table::StencilTable;
    use subtess::tessellate::triangle_dual_grid::MIN_QUARTIC_RATE;

    /// Tessellate `m` at `rates` (of its isolated mesh's triangles) both ways; the largest
    /// position difference over the bounding box's largest side, the largest normal difference,
    /// the quartic faces and the patch corners among them.
    fn compare(
        m: &Mesh,
        rates: impl Fn(usize) -> u32,
        label: &str,
    ) -> (f64, f64, usize, [bool; 3]) {
        let table = StencilTable::default_loop().expect("embedded");
        let iso = isolate_loop(m).unwrap_or_else(|e| panic!("{label}: {e}"));
        let rates: Vec<u32> = (0..iso.mesh.faces()).map(rates).collect();
        let grid = TriangleDualGrid::new(&table, &iso.mesh, &iso.patches, &rates)
            .unwrap_or_else(|e| panic!("{label}: {e}"));
        let regular: Vec<usize> = (0..iso.patches.len())
            .filter(|&f| {
                let p = &iso.patches[f];
                !p.kind.boundary
                    && p.kind.faces == 6
                    && p.points.len() == 12
                    && rates[f] >= MIN_QUARTIC_RATE
            })
            .collect();
        // Every regular patch of the Loop table at a rate from MIN_QUARTIC_RATE on takes the
        // quartic: it reproduces every rate.
        assert_eq!(grid.separable_faces(), regular.len(), "{label}");
        let mut corners = [false; 3];
        for &f in &regular {
            corners[iso.patches[f].corner] = true;
        }
        let quartic = grid.tessellate(&iso.mesh);
        let stencils = grid.without_quartics();
        assert_eq!(stencils.separable_faces(), 0);
        let reference = stencils.tessellate(&iso.mesh);
        assert_eq!(quartic.triangles, reference.triangles, "{label}");
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in &reference.positions {
            for c in 0..3 {
                lo[c] = lo[c].min(f64::from(p[c]));
                hi[c] = hi[c].max(f64::from(p[c]));
            }
        }
        let size = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
        let largest = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter()
                .zip(b)
                .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).abs()))
                .fold(0.0f64, f64::max)
        };
        let position = largest(&quartic.positions, &reference.positions) / size;
        let normal = largest(&quartic.normals, &reference.normals);
        println!(
            "{label}: {} quartic faces, position {position:.2e} of the box, normal {normal:.2e}",
            regular.len()
        );
        (position, normal, regular.len(), corners)
    }

    fn check(m: &Mesh, rates: impl Fn(usize) -> u32, label: &str) -> [bool; 3] {
        let (position, normal, faces, corners) = compare(m, rates, label);
        assert!(faces > 0, "{label}: no regular face");
        assert!(
            position < 1e-6,
            "{label}: positions differ by {position:e} of the box"
        );
        // Unit normals from derivatives rounded differently (differences of control points
        // against absolute positions): within 1e-4, the tolerance of the exact-evaluation test.
        assert!(normal < 1e-4, "{label}: normals differ by {normal:e}");
        corners
    }

    #[test]
    fn small_meshes_agree_at_mixed_rates() {
        let mut corners = [false; 3];
        for (name, m) in small_meshes() {
            for (label, rates) in [("uniform 7", 0u32), ("mixed", 1)] {
                let found = check(
                    &m,
                    |f| {
                        if rates == 0 {
                            7
                        } else {
                            1 + (f as u32 * 7) % 12
                        }
                    },
                    &format!("{name}, {label}"),
                );
                for c in 0..3 {
                    corners[c] |= found[c];
                }
            }
        }
        // The phantom patches of the eared disc sit at other face corners: the rotated
        // quartics are exercised, not only corner 0's.
        assert_eq!(corners, [true, true, false]);
    }

    #[test]
    #[cfg_attr(
        not(shared_models),
        ignore = "needs ../shared/models beside the repository"
    )]
    fn spot_agrees_at_every_rate() {
        let spot = load(&models().join("crane/spot_triangulated.obj"));
        for n in [5, 6, 8, 13, 16] {
            check(&spot, |_| n, &format!("spot at rate {n}"));
        }
        check(&spot, |f| 1 + (f as u32 * 5) % 16, "spot at mixed rates");
        let hand = load(&models().join("odedstein/hand_lowres.obj"));
        let corners = check(&hand, |f| 1 + (f as u32 * 3) % 10, "hand at mixed rates");
        println!("hand: regular patches at corners {corners:?}");
    }
}
