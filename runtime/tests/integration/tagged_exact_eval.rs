//! Exact evaluation on meshes with sharp features (`subtess::eval::exact_eval::feature`) against
//! independent references:
//!
//! * an infinitely sharp crease is the uniform cubic B-spline of its vertices (DeRose, Kass and
//!   Truong 1998): the closed form in rationals, compared bit for bit;
//! * an edge of sharpness 1 is one step of the infinitely sharp rules, then the smooth limit:
//!   the mesh stepped with the sharp rules and evaluated by the untagged exact path
//!   (Schaefer–Warren substitution, no feature code), compared bit for bit;
//! * the f64 feature-adaptive limit stencils (`adaptive::limit_stencils`: f64 refinement, f64
//!   masks, eigen-iteration at darts) on every tagged all-quad OpenSubdiv regression shape;
//! * holes and `interpolateboundary 0` boundary faces are refused with a message.

use num_rational::BigRational;
use num_traits::ToPrimitive;
use schemes::crease::INFINITE;
use schemes::BoundaryMode;
use subtess::eval::exact_eval::{ExactEvaluator, LimitPoint};
use subtess::eval::limit_point;
use subtess::io::obj::parse_obj;
use subtess::mesh::topology::{Mesh, NONE};
use subtess::scheme::catmull_clark::adaptive::{limit_of, limit_stencils, LimitQuery};
use subtess::scheme::catmull_clark::refine::refine;
use subtess::Scheme;

use crate::common::{cube, refined_query};

fn q(p: i64, d: i64) -> BigRational {
    BigRational::new(p.into(), d.into())
}

/// An `m x m` grid of quads with boundary, vertex `(i, j)` at `j * (m + 1) + i`, heights small
/// dyadic numbers (so that every refined point of a valence-4 grid is an exact f64).
fn grid(m: i64) -> Mesh {
    let positions = (0..=m)
        .flat_map(|j| {
            (0..=m).map(move |i| {
                let z = ((3 * i + 5 * j + i * j) % 7) as f64 / 4.0 - 0.75;
                [i as f64, j as f64 + 0.125 * (i % 2) as f64, z]
            })
        })
        .collect();
    let faces: Vec<Vec<i64>> = (0..m)
        .flat_map(|j| {
            (0..m).map(move |i| {
                let v = j * (m + 1) + i;
                vec![v, v + 1, v + m + 2, v + m + 1]
            })
        })
        .collect();
    Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid grid")
}

/// The uniform cubic B-spline basis at `t` (values and derivatives) on control points
/// `-1..=2`, in rationals (the closed form, not the library's).
fn bspline(t: &BigRational) -> ([BigRational; 4], [BigRational; 4]) {
    let one = q(1, 1);
    let s = &one - t;
    let (t2, t3) = (t * t, t * t * t);
    let sixth = q(1, 6);
    let half = q(1, 2);
    (
        [
            &s * &s * &s * &sixth,
            (q(3, 1) * &t3 - q(6, 1) * &t2 + q(4, 1)) * &sixth,
            (q(-3, 1) * &t3 + q(3, 1) * &t2 + q(3, 1) * t + &one) * &sixth,
            &t3 * &sixth,
        ],
        [
            -(&s * &s) * &half,
            (q(3, 1) * &t2 - q(4, 1) * t) * &half,
            (q(-3, 1) * &t2 + q(2, 1) * t + &one) * &half,
            &t2 * &half,
        ],
    )
}

fn exact(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

/// The uniform cubic B-spline of `points` at `t` and its derivative, exact in rationals and
/// rounded once to f64.
fn curve_point(points: [[f64; 3]; 4], t: &BigRational) -> ([f64; 3], [f64; 3]) {
    let (b, db) = bspline(t);
    let sum = |w: &[BigRational; 4], c: usize| {
        let total = (0..4).fold(q(0, 1), |acc, a| acc + &w[a] * exact(points[a][c]));
        total.to_f64().expect("finite")
    };
    (
        std::array::from_fn(|c| sum(&b, c)),
        std::array::from_fn(|c| sum(&db, c)),
    )
}

/// The sharp crease along row 2 of a 6 x 6 grid: the faces above it meet the crease along
/// their first edge (`v = 0`); there the limit and its `d/du` are the cubic B-spline of the
/// crease's vertices, exactly (the crease curve ends at the boundary in corners, so only the
/// segments away from the ends are uniform).
#[test]
fn an_infinitely_sharp_crease_is_exactly_the_cubic_b_spline_of_its_vertices() {
    let m = 6;
    let mut mesh = grid(m);
    let row = |i: i64| (2 * (m + 1) + i) as usize;
    for i in 0..m {
        mesh.set_edge_sharpness(row(i), row(i + 1), INFINITE)
            .expect("an edge");
    }
    let evaluator = ExactEvaluator::new(&mesh);
    let mut checked = 0;
    for i in 1..m - 1 {
        let face = (2 * m + i) as usize;
        for t in [q(0, 1), q(1, 3), q(1, 2), q(5, 7), q(1, 1), q(1, 1 << 20)] {
            let got = evaluator.evaluate(face, &t, &q(0, 1)).expect("evaluates");
            let points = std::array::from_fn(|a| mesh.positions[row(i - 1 + a as i64)]);
            let (curve, tangent) = curve_point(points, &t);
            assert_eq!(got.position, curve, "face {face} u {t}: {got:?}");
            // At the segment's ends the point is a crease vertex: its frame tangents are
            // masks, not derivatives; inside, `d/du` is the curve's.
            if t != q(0, 1) && t != q(1, 1) {
                assert_eq!(got.du, tangent, "face {face} u {t}: {got:?}");
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 24);
}

/// A cube whose top rim is an infinitely sharp crease: its corners are crease vertices of
/// valence 3, with a one-face sector on top, so the top face's quarters there are boundary
/// patches of their sectors (`patch::crease_sector`) where the descent stops. Along the top
/// face's first edge the limit and its `d/du` are the closed cubic B-spline of the rim's four
/// vertices, exactly, at the edge's midpoint too (a vertex of the first refinement, where the
/// vertex masks would give a tangent's direction only).
#[test]
fn a_crease_through_valence_3_corners_is_exactly_the_cubic_b_spline_of_its_vertices() {
    let mut mesh = cube();
    // Off the cube's symmetry, by a dyadic step (exact in f64).
    mesh.positions[5][2] = 1.25;
    let rim = [6usize, 4, 5, 7];
    for k in 0..4 {
        mesh.set_edge_sharpness(rim[k], rim[(k + 1) % 4], INFINITE)
            .expect("an edge");
    }
    let evaluator = ExactEvaluator::new(&mesh);
    // Face 1 runs along its first edge from vertex 4 to vertex 5: the rim's points 6, 4, 5, 7.
    for t in [q(1, 3), q(1, 2), q(5, 7), q(1, 1 << 20)] {
        let got = evaluator.evaluate(1, &t, &q(0, 1)).expect("evaluates");
        let (curve, tangent) = curve_point(rim.map(|v| mesh.positions[v]), &t);
        assert_eq!(got.position, curve, "u {t}: {got:?}");
        assert_eq!(got.du, tangent, "u {t}: {got:?}");
    }
}

/// Sharpness 1 is one infinitely sharp step, then smooth limits (OpenSubdiv's semantics of
/// sharpness): the semi-sharp mesh's exact limit equals, bit for bit, the untagged exact limit
/// (Schaefer–Warren substitution, the path without feature code) of the grid stepped once with
/// the infinitely sharp rules and then made smooth. On a valence-4 grid with dyadic heights the
/// stepped positions are exact in f64 (the weights are dyadic), checked below.
#[test]
fn sharpness_one_is_exactly_one_sharp_step_then_smooth() {
    let m = 5;
    let tag = |mesh: &mut Mesh, s: f32| {
        for (a, b) in [(8, 9), (9, 10), (15, 9), (13, 19)] {
            mesh.set_edge_sharpness(a, b, s).expect("an edge");
        }
        mesh.set_vertex_sharpness(20, s).expect("a vertex");
    };
    let mut semi = grid(m);
    tag(&mut semi, 1.0);
    let mut sharp = grid(m);
    tag(&mut sharp, INFINITE);
    let step = refine(&sharp);
    let mut stepped = step.mesh.clone();
    for h in 0..stepped.twin.len() {
        if stepped.twin[h] != NONE {
            stepped.edge_sharpness[h] = 0.0;
        }
    }
    stepped.vertex_sharpness.iter_mut().for_each(|s| *s = 0.0);
    assert!(!stepped.has_sharp_features());
    // The stepped positions are exact: the rational stencil gives the same numbers.
    let exact_step = subtess::scheme::catmull_clark::refine::refinement_stencil::<BigRational>(
        &sharp,
        &subtess::scheme::catmull_clark::refine::LevelEdges::new(&sharp),
    );
    for (child, p) in stepped.positions.iter().enumerate() {
        let (js, ws) = exact_step.row(child);
        for (c, &x) in p.iter().enumerate() {
            let sum = js.iter().zip(ws).fold(q(0, 1), |acc, (&j, w)| {
                acc + w * exact(sharp.positions[j as usize][c])
            });
            assert_eq!(exact(x), sum, "refined vertex {child}");
        }
    }
    let (semi_eval, stepped_eval) = (ExactEvaluator::new(&semi), ExactEvaluator::new(&stepped));
    let mut checked = 0;
    for f in 0..semi.faces() {
        // Face f's child at corner 0 is the quarter [0, 1/2]^2 in f's parameters, with
        // parameters (2u, 2v) and derivatives halved.
        let child = semi.face_halfedges(f).start;
        for (u, v) in [(q(1, 10), q(1, 5)), (q(1, 3), q(2, 5)), (q(1, 4), q(0, 1))] {
            let a = semi_eval.evaluate(f, &u, &v).expect("evaluates");
            let b = stepped_eval
                .evaluate(child, &(q(2, 1) * &u), &(q(2, 1) * &v))
                .expect("evaluates");
            assert_eq!(a.position, b.position, "face {f} ({u}, {v})");
            assert_eq!(a.du, b.du.map(|x| 2.0 * x), "face {f} ({u}, {v})");
            assert_eq!(a.dv, b.dv.map(|x| 2.0 * x), "face {f} ({u}, {v})");
            checked += 1;
        }
    }
    assert_eq!(checked, 75);
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The angle between `a` and `b`, `atan2(|a x b|, a . b)` (accurate near 0, unlike `acos`,
/// whose resolution there is 1.5e-8).
fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot: f64 = (0..3).map(|c| a[c] * b[c]).sum();
    let c = cross(a, b);
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().atan2(dot)
}

/// The tagged OpenSubdiv regression shapes (a `t` line), read, and the parameters the
/// comparisons visit: corners, an edge midpoint, and points inside.
fn tagged_shapes() -> Vec<(String, Mesh)> {
    let dir = crate::common::models().join("opensubdiv");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("the models folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".obj"))
        .collect();
    names.sort();
    names
        .into_iter()
        .filter(|name| {
            let text = std::fs::read_to_string(dir.join(name)).expect("readable");
            text.lines().any(|l| l.starts_with("t "))
        })
        .map(|name| {
            let mesh = crate::common::load(&dir.join(&name));
            (name, mesh)
        })
        .collect()
}

const PARAMETERS: [((i64, i64), (i64, i64)); 8] = [
    ((0, 1), (0, 1)),
    ((1, 1), (0, 1)),
    ((1, 1), (1, 1)),
    ((0, 1), (1, 1)),
    ((1, 2), (0, 1)),
    ((1, 3), (2, 7)),
    ((5, 8), (1, 2)),
    ((1, 1000), (3, 5)),
];

/// Compares the exact limit of sub-face `k` of every face (about `faces` a shape; holes skipped) at
/// [`PARAMETERS`] with the f64 adaptive stencils on `reference` at the query `query(f, k, u,
/// v)`: positions to 1e-12 of the diagonal, normals to 1e-7 rad (at the face's corners only
/// with `corner_normals`); the largest deviations.
fn compare_with_adaptive(
    name: &str,
    mesh: &Mesh,
    reference: &Mesh,
    corner_normals: bool,
    faces: usize,
    query: impl Fn(usize, usize, f64, f64) -> LimitQuery,
) -> (f64, f64, usize) {
    let diagonal = crate::common::diagonal(mesh);
    let evaluator = ExactEvaluator::new(mesh);
    let (mut worst, mut worst_normal, mut points) = (0.0f64, 0.0f64, 0);
    let stride = mesh.faces().div_ceil(faces);
    for f in (0..mesh.faces()).step_by(stride) {
        if mesh.holes[f] {
            continue;
        }
        let sides = mesh.face(f).len();
        let subfaces = if sides == 4 { 1 } else { sides };
        for k in 0..subfaces {
            for ((a, b), (c, d)) in PARAMETERS {
                let (u, v) = (q(a, b), q(c, d));
                let got: LimitPoint = evaluator
                    .evaluate_subface(f, k, &u, &v)
                    .unwrap_or_else(|e| panic!("{name} face {f}.{k} ({u}, {v}): {e}"));
                let at = query(f, k, a as f64 / b as f64, c as f64 / d as f64);
                let stencil = limit_stencils(reference, &[at]).expect("reached");
                let [p, du, dv] = limit_of(&stencil[0], reference);
                let e = (0..3)
                    .map(|c| (got.position[c] - p[c]).abs())
                    .fold(0.0, f64::max);
                worst = worst.max(e / diagonal);
                let at_corner = (a == 0 || a == b) && (c == 0 || c == d);
                // A vanishing tangent (both sides agree on it to rounding) has no normal: the
                // edge midpoints of `catmark_val2_nonman`'s degenerate faces.
                let length = |x: [f64; 3]| x.iter().map(|c| c * c).sum::<f64>().sqrt();
                let degenerate = length(du).min(length(dv)) < 1e-9 * diagonal;
                let normal = if (at_corner && !corner_normals) || degenerate {
                    0.0
                } else {
                    angle(cross(got.du, got.dv), cross(du, dv))
                };
                worst_normal = worst_normal.max(normal);
                assert!(
                    e <= 1e-12 * diagonal,
                    "{name} face {f}.{k} ({u}, {v}): {:?} vs {p:?}",
                    got.position
                );
                assert!(
                    normal <= 1e-7,
                    "{name} face {f}.{k} ({u}, {v}): normal off by {normal:.2e} rad: {got:?} vs {du:?} {dv:?}"
                );
                points += 1;
            }
        }
    }
    println!(
        "{name}: {points} points, position {worst:.2e} of the diagonal, normal {worst_normal:.2e} rad"
    );
    (worst, worst_normal, points)
}

/// The tagged all-quad OpenSubdiv regression shapes: at the corners, an edge midpoint and a few
/// rational points of every face (of about 100 faces a shape; holes skipped), the exact limit
/// agrees with the f64 feature-adaptive limit stencils to 1e-12 of the bounding box's diagonal
/// (measured: at most 1.3e-15, the pawn; 1.8e-16 or less elsewhere), and so does the normal
/// (the cross product of the two tangents) to 1e-7 rad. Measured: 2.3e-13 rad or less, except
/// at the boundary vertices with three faces of `catmark_quadstrips` and
/// `catmark_gregory_test4` (7.6e-9 and 6.4e-9 rad), where the tables' tangent masks (an exact
/// elimination in f64) meet the adaptive side's eigen-iteration, which stops when a step turns
/// the tangents by `1 - cos < 1e-15`, about 4.5e-8 rad.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn tagged_regression_shapes_agree_with_the_f64_adaptive_limit() {
    let mut shapes = 0;
    for (name, mesh) in tagged_shapes() {
        if (0..mesh.faces()).any(|f| mesh.face(f).len() != 4) {
            continue;
        }
        compare_with_adaptive(&name, &mesh, &mesh, true, 100, |f, _, u, v| LimitQuery {
            face: f as u32,
            u,
            v,
        });
        shapes += 1;
    }
    assert!(shapes >= 20, "{shapes} tagged all-quad shapes");
}

/// The tagged regression shapes with other polygons (creased pyramids, the bishop, smooth
/// triangles, valence-2 and non-manifold shapes): sub-face `k` of an n-gon is its child at
/// corner `k` in the same parameters, a quad's point lies in the child of its quarter (about 30
/// faces a shape); the f64
/// adaptive stencils of the once-refined mesh (all quads) there agree as above. Normals are
/// compared off the faces' corners: at a corner vertex (a cone, with no tangent plane) the
/// frame tangents are its edges at the level where the descent stops, which differ between a
/// mesh and its refinement (`catmark_nonman_verts`' pinned corners: 9.6e-2 rad). Measured:
/// positions 4.7e-15 of the diagonal (the bishop), normals 1.7e-12 rad. The valence-2 shapes
/// take the feature descent everywhere near their valence-2 vertices (no patch of the scaling
/// relation exists there), in rationals on one side and in f64 on the other.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn tagged_shapes_with_other_polygons_agree_on_their_sub_faces() {
    let mut shapes = 0;
    for (name, mesh) in tagged_shapes() {
        if (0..mesh.faces()).all(|f| mesh.face(f).len() == 4) {
            continue;
        }
        let refined = refine(&mesh).mesh;
        compare_with_adaptive(&name, &mesh, &refined, false, 30, |f, k, u, v| {
            refined_query(&mesh, f, k, u, v)
        });
        shapes += 1;
    }
    assert!(shapes >= 5, "{shapes} tagged shapes with other polygons");
    println!("{shapes} shapes");
}

/// A hole face has no surface: evaluating it is refused by name, the faces beside it evaluate.
#[test]
fn a_hole_face_is_refused_clearly() {
    let mut mesh = grid(3);
    mesh.holes[4] = true;
    let e = limit_point(&mesh, Scheme::CatmullClark, 4, 0, &q(1, 2), &q(1, 2))
        .expect_err("a hole")
        .to_string();
    assert!(e.contains("face 4") && e.contains("hole"), "{e}");
    limit_point(&mesh, Scheme::CatmullClark, 3, 0, &q(1, 2), &q(1, 2)).expect("beside the hole");
}

/// `interpolateboundary 0`: the faces at the boundary make no surface (OpenSubdiv), so
/// evaluating one is refused; the interior face of a 3 x 3 grid is not at the boundary and
/// evaluates.
#[test]
fn interpolateboundary_0_boundary_faces_are_refused_clearly() {
    let mut text = String::new();
    for j in 0..4 {
        for i in 0..4 {
            text += &format!("v {i} {j} {}\n", (i * j) % 3);
        }
    }
    for j in 0..3 {
        for i in 0..3 {
            let v = j * 4 + i + 1;
            text += &format!("f {} {} {} {}\n", v, v + 1, v + 5, v + 4);
        }
    }
    text += "t interpolateboundary 1/0/0 0\n";
    let obj = parse_obj(&text).expect("parses");
    let (mesh, _) = Mesh::from_obj(&obj).expect("a mesh");
    let e = limit_point(&mesh, Scheme::CatmullClark, 0, 0, &q(1, 3), &q(1, 3))
        .expect_err("no surface")
        .to_string();
    assert!(e.contains("interpolateboundary 0"), "{e}");
    let centre = limit_point(&mesh, Scheme::CatmullClark, 4, 0, &q(1, 2), &q(1, 2))
        .expect("the interior face");
    assert!(centre.position.iter().all(|c| c.is_finite()));
}

/// A star of `v` sectors of 2 x 2 quads around vertex 0, with the infinitely sharp crease from
/// vertex 0 along sector 0's first edge to the rim: a dart of valence `v`, its neighbourhood the
/// one `stencilgen`'s dart patches assume out to the two-ring. Vertex `(a, b)`, `a >= 1`,
/// `b >= 0`, of sector `s` is `1 + 6 s + 3 (a - 1) + b`; heights are small dyadic numbers.
fn dart_star(v: i64) -> (Mesh, impl Fn(i64, i64, i64) -> usize) {
    let index = move |s: i64, a: i64, b: i64| -> usize {
        match (a, b) {
            (0, 0) => 0,
            (0, _) => (1 + 6 * ((s + 1).rem_euclid(v)) + 3 * (b - 1)) as usize,
            _ => (1 + 6 * s.rem_euclid(v) + 3 * (a - 1) + b) as usize,
        }
    };
    let mut positions = vec![[0.0, 0.0, 0.25]; 1 + 6 * v as usize];
    for s in 0..v {
        let (t0, t1) = (
            2.0 * std::f64::consts::PI * s as f64 / v as f64,
            2.0 * std::f64::consts::PI * (s + 1) as f64 / v as f64,
        );
        for a in 1..=2 {
            for b in 0..=2 {
                let (x, y) = (
                    a as f64 * t0.cos() + b as f64 * t1.cos(),
                    a as f64 * t0.sin() + b as f64 * t1.sin(),
                );
                let z = ((3 * a + 5 * b + 7 * s) % 5) as f64 / 8.0 - 0.25;
                positions[index(s, a, b)] = [x, y, z];
            }
        }
    }
    let faces: Vec<Vec<i64>> = (0..v)
        .flat_map(|s| {
            [(0, 0), (1, 0), (1, 1), (0, 1)].map(move |(i, j)| {
                [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                    .map(|(a, b)| index(s, a, b) as i64)
                    .to_vec()
            })
        })
        .collect();
    let mut mesh = Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid star");
    mesh.set_edge_sharpness(0, index(0, 1, 0), INFINITE)
        .expect("an edge");
    mesh.set_edge_sharpness(index(0, 1, 0), index(0, 2, 0), INFINITE)
        .expect("an edge");
    (mesh, index)
}

/// The dart's limit position from `stencilgen`'s dart patches (the scaling relation's fixed
/// point at the patch corner: the left eigenvector of the local subdivision matrix `A` built by
/// `schemes::local_matrices` on its grid of sector coordinates) equals the runtime's exact
/// dart limit (the eigenvector of the one-ring's step built by the runtime's own refinement
/// rules on a mesh, `adaptive::stationary_step`), bit for bit after one rounding, at valences
/// 3..=8 and every sector's face; the tangent plane spanned by `stencilgen`'s f64 dart tangent
/// masks (`ev_tangents`: the subdominant left eigenvectors of `A`) is the runtime's (its
/// orthogonal subspace iteration), normals within 1e-7 rad: the iteration stops once a step
/// turns its masks by less than about 4.5e-8 rad (`1 - cos < 1e-15`), and at valence 4, where
/// it converges slowest (eigenvalue ratio 0.32/0.5), the normals differ by 9.2e-9 rad, while
/// `stencilgen`'s masks span an invariant subspace to 1e-15 (`tests/tests/dart_stencils.rs`).
#[test]
fn the_dart_limit_of_stencilgen_is_the_runtime_s() {
    use stencilgen::ev_tangents::ev_tangents;
    use stencilgen::extraordinary_patch::{GridPoint, LocalMatrices, Neighbourhood};
    use stencilgen::patch_stencils::patch_stencils;
    use stencilgen::regular_patch::StencilKind;
    let cc = schemes::QuadScheme::by_name("catmull-clark").expect("catalogued");
    for v in 3..=8i64 {
        let (mesh, index) = dart_star(v);
        let nb = Neighbourhood::dart(v as u32);
        for s in 0..v as u32 {
            let grid = patch_stencils::<BigRational>(&cc, nb, s, 1, StencilKind::Position)
                .expect("solvable");
            let mask = grid.at(0, 0).expect("the dart's mask");
            let matrices = LocalMatrices::new(&cc, nb, s).expect("valid");
            let slots: Vec<usize> = matrices
                .layout
                .iter()
                .map(|p| match *p {
                    GridPoint::Centre => 0,
                    GridPoint::Sector { s, a, b } => index(i64::from(s), a, b),
                })
                .collect();
            let expected: [f64; 3] = std::array::from_fn(|c| {
                mask.iter()
                    .zip(&slots)
                    .map(|(w, &k)| w * exact(mesh.positions[k][c]))
                    .sum::<BigRational>()
                    .to_f64()
                    .expect("finite")
            });
            let face = 4 * s as usize;
            let got = limit_point(&mesh, Scheme::CatmullClark, face, 0, &q(0, 1), &q(0, 1))
                .expect("the dart's limit");
            assert_eq!(got.position, expected, "dart {v} sector {s}");
            let tangents = ev_tangents(&matrices).expect("tangents");
            let apply = |mask: &[f64]| -> [f64; 3] {
                std::array::from_fn(|c| {
                    mask.iter()
                        .zip(&slots)
                        .map(|(w, &k)| w * mesh.positions[k][c])
                        .sum()
                })
            };
            let normal = cross(apply(&tangents.du), apply(&tangents.dv));
            let theirs = cross(got.du, got.dv);
            let a = angle(normal, theirs);
            assert!(
                a.min(std::f64::consts::PI - a) < 1e-7,
                "dart {v} sector {s}: normals {a} rad apart"
            );
        }
    }
}
