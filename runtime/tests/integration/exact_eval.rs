//! Exact evaluation (`subtess::eval::exact_eval`) against independent references:
//!
//! * `stencilgen`'s exact substitution stencils (`Substitution<BigRational>`, Schaefer–Warren
//!   section 5.2) applied in rationals to the same control points — the oracle — around interior
//!   vertices of valence 3..8 and boundary vertices with 1..6 faces, both boundary modes;
//!   at the vertex itself its f64 tangent masks (`Substitution<f64>`, `ev_tangents`);
//! * the bicubic B-spline closed form on regular faces, and the cubic B-spline of the boundary
//!   polygon along a boundary edge;
//! * the embedded f32 table at primal and dual grid points;
//! * itself across shared edges (the same point from two faces) and across isolation (the
//!   original face's parameters against the refined mesh's faces).

use std::collections::HashMap;

use crate::common::cube;
use num_rational::BigRational;
use num_traits::{ToPrimitive, Zero};
use schemes::{BoundaryMode, QuadScheme};
use stencilgen::extraordinary_patch::{canonical, GridPoint, Neighbourhood};
use stencilgen::regular_patch::StencilKind as Kind;
use stencilgen::substitution::Substitution;
use subtess::eval::exact_eval::{evaluate, ExactEvaluator, LimitPoint};
use subtess::mesh::topology::Mesh;
use subtess::scheme::catmull_clark::refine::refine;
use subtess::scheme::patch::face_patch;
use subtess::stencil_table::StencilTable;
use table_format::{PointSet, SectionKey, StencilKind};

fn q(p: i64, d: i64) -> BigRational {
    BigRational::new(p.into(), d.into())
}

/// Parameters the tests visit: corners, edges, the vertex, thirds and sevenths, points very
/// close to the vertex (many doublings), dual points.
/// (The oracle solves the curve scheme on the grid of the sub-patch parameter's denominator,
/// at most 1024: hence 1/5 and 1/64 beside 1/1000 and 2/7.)
fn parameters() -> Vec<(BigRational, BigRational)> {
    [
        ((0, 1), (0, 1)),
        ((1, 3), (2, 7)),
        ((1, 1000), (1, 5)),
        ((2, 7), (1, 64)),
        ((1, 1000), (1, 1000)),
        ((1, 1), (1, 1)),
        ((1, 1), (0, 1)),
        ((0, 1), (1, 1)),
        ((1, 2), (1, 2)),
        ((1, 6), (5, 6)),
        ((3, 10), (0, 1)),
        ((0, 1), (5, 9)),
        ((1, 1 << 20), (3, 1 << 22)),
    ]
    .iter()
    .map(|&((a, b), (c, d))| (q(a, b), q(c, d)))
    .collect()
}

/// A deterministic pseudo-random number in [-1, 1).
fn noise(seed: u64) -> f64 {
    let mut x = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(0x6A09_E667);
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The neighbourhood of a vertex as a mesh: every sector's cells `[0,2] x [0,2]` (named by
/// `canonical`, so that the mesh is exactly the neighbourhood `stencilgen` models), with
/// positions on a curved, noisy sheet. Returns the mesh, the vertex of every grid point and the
/// face of every sector's cell `(0,0)`. `rotate` lists that cell starting at corner `rotate`.
fn neighbourhood_mesh(
    nb: Neighbourhood,
    mode: BoundaryMode,
    rotate: usize,
) -> (Mesh, HashMap<GridPoint, usize>, Vec<usize>) {
    let mut ids: HashMap<GridPoint, usize> = HashMap::new();
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut patch_faces = Vec::new();
    let f = nb.faces as i64;
    let step = match nb.boundary {
        None => 2.0 * std::f64::consts::PI / f as f64,
        Some(_) => std::f64::consts::PI / f.max(2) as f64,
    };
    for s in 0..f {
        for b in 0..2 {
            for a in 0..2 {
                let corners = [(a, b), (a + 1, b), (a + 1, b + 1), (a, b + 1)];
                let mut face: Vec<i64> = corners
                    .iter()
                    .map(|&(x, y)| {
                        let p = canonical(nb, s, x, y).expect("inside the neighbourhood");
                        let next = ids.len();
                        let id = *ids.entry(p).or_insert(next);
                        if id == positions.len() {
                            let (t0, t1) = (step * s as f64, step * (s + 1) as f64);
                            let (x, y) = (x as f64, y as f64);
                            let px = x * t0.cos() + y * t1.cos();
                            let py = x * t0.sin() + y * t1.sin();
                            let seed = id as u64 * 3 + 1;
                            positions.push([
                                px + 0.1 * noise(seed),
                                py + 0.1 * noise(seed + 1),
                                0.3 * (px * px - 0.5 * py * py) + 0.2 * noise(seed + 2),
                            ]);
                        }
                        id as i64
                    })
                    .collect();
                if a == 0 && b == 0 {
                    face.rotate_left(rotate);
                    patch_faces.push(faces.len());
                }
                faces.push(face);
            }
        }
    }
    let mesh = Mesh::new(positions, &faces, &[], mode).expect("a valid neighbourhood");
    (mesh, ids, patch_faces)
}

fn exact_point(p: [f64; 3]) -> [BigRational; 3] {
    p.map(|c| BigRational::from_float(c).expect("finite"))
}

/// The oracle: `stencilgen`'s stencils at patch parameters `(u, v)` applied to the control
/// points in rationals (f64 tangent masks at the vertex itself).
struct Oracle {
    exact: Substitution<BigRational>,
    float: Substitution<f64>,
    points: Vec<[f64; 3]>,
}

impl Oracle {
    fn new(nb: Neighbourhood, sector: u32, mesh: &Mesh, ids: &HashMap<GridPoint, usize>) -> Self {
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        let exact = Substitution::<BigRational>::new(&cc, nb, sector).expect("substitution");
        let float = Substitution::<f64>::new(&cc, nb, sector).expect("substitution");
        let points = exact
            .matrices
            .layout
            .iter()
            .map(|p| mesh.positions[ids[p]])
            .collect();
        Oracle {
            exact,
            float,
            points,
        }
    }

    fn at(&mut self, u: &BigRational, v: &BigRational) -> [[f64; 3]; 3] {
        let kinds = [Kind::Position, Kind::DerivativeU, Kind::DerivativeV];
        kinds.map(|kind| {
            if u.is_zero() && v.is_zero() && kind != Kind::Position {
                let w = self.float.stencil(u, v, kind).expect("f64 stencil");
                std::array::from_fn(|c| w.iter().zip(&self.points).map(|(w, p)| w * p[c]).sum())
            } else {
                let w = self.exact.stencil(u, v, kind).expect("exact stencil");
                std::array::from_fn(|c| {
                    let sum = w
                        .iter()
                        .zip(&self.points)
                        .fold(BigRational::zero(), |acc, (w, p)| {
                            acc + w * exact_point(*p)[c].clone()
                        });
                    sum.to_f64().expect("finite")
                })
            }
        })
    }
}

/// The largest deviation of `got` from `expected`, relative to `max(|expected|, scale)`.
fn deviation(got: [f64; 3], expected: [f64; 3], scale: f64) -> f64 {
    let size = expected.iter().fold(scale, |m, c| m.max(c.abs()));
    (0..3)
        .map(|c| (got[c] - expected[c]).abs() / size)
        .fold(0.0, f64::max)
}

/// Face derivatives from patch derivatives for a face whose corner `corner` is the patch's
/// `(0,0)` (the inverse of `patch::to_patch`'s rotation).
fn to_face(corner: usize, du: [f64; 3], dv: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let neg = |x: [f64; 3]| x.map(|c| -c);
    match corner {
        0 => (du, dv),
        1 => (neg(dv), du),
        2 => (neg(du), neg(dv)),
        _ => (dv, neg(du)),
    }
}

/// Face parameters of patch parameters `(u', v')` for patch corner `corner`.
fn from_patch(corner: usize, u: &BigRational, v: &BigRational) -> (BigRational, BigRational) {
    let one = q(1, 1);
    match corner {
        0 => (u.clone(), v.clone()),
        1 => (&one - v, u.clone()),
        2 => (&one - u, &one - v),
        _ => (v.clone(), &one - u),
    }
}

/// How closely the tangents at the vertex itself can agree with `ev_tangents` (f64 SVD null
/// spaces with a 1e-8 threshold). At a boundary vertex with 4 faces the eigenvalue 1/2 is
/// defective (algebraic multiplicity 2 — found exactly in rationals while writing this — and
/// one eigenvector, the boundary tangent `E_1 - E_5`), so the SVD's null vector is only good to
/// about sqrt(eps): measured 3.1e-9.
fn vertex_tolerance(nb: Neighbourhood) -> f64 {
    match (nb.boundary, nb.faces) {
        (Some(_), 4) => 1e-8,
        _ => 1e-12,
    }
}

/// Compare the evaluator with the oracle on every sector's patch of `nb`, every parameter,
/// each face listed from each of its corners; returns the largest deviations (away from the
/// vertex, and of the tangents at the vertex).
fn check_against_oracle(nb: Neighbourhood, mode: BoundaryMode) -> (f64, f64) {
    let (mut worst, mut worst_at_vertex) = (0.0f64, 0.0f64);
    let meshes: Vec<_> = (0..4).map(|r| neighbourhood_mesh(nb, mode, r)).collect();
    // The positions do not depend on how the patch face is listed: one oracle per sector.
    let scale = meshes[0]
        .0
        .positions
        .iter()
        .flatten()
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let evaluators: Vec<ExactEvaluator> = meshes
        .iter()
        .map(|(m, _, _)| ExactEvaluator::new(m))
        .collect();
    for sector in 0..nb.sectors() {
        let mut oracle = Oracle::new(nb, sector, &meshes[0].0, &meshes[0].1);
        for (pu, pv) in parameters() {
            let expected = oracle.at(&pu, &pv);
            for (rotate, (mesh, _, patch_faces)) in meshes.iter().enumerate() {
                let face = patch_faces[sector as usize];
                let corner = (4 - rotate) % 4;
                let patch = face_patch(mesh, face).expect("a patch");
                // (A regular face may put any regular corner at its patch's (0,0).)
                if !nb.is_regular() {
                    assert_eq!(patch.corner, corner, "{nb:?} rotate {rotate}");
                }
                let (fu, fv) = from_patch(corner, &pu, &pv);
                let got = evaluators[rotate]
                    .evaluate(face, &fu, &fv)
                    .expect("evaluates");
                let (du, dv) = to_face(corner, expected[1], expected[2]);
                let at_vertex = pu.is_zero() && pv.is_zero() && !nb.is_regular();
                let d = deviation(got.position, expected[0], scale);
                let t = deviation(got.du, du, scale).max(deviation(got.dv, dv, scale));
                if at_vertex {
                    worst = worst.max(d);
                    worst_at_vertex = worst_at_vertex.max(t);
                } else {
                    worst = worst.max(d.max(t));
                }
                assert!(
                    d <= 1e-13 && t <= if at_vertex { vertex_tolerance(nb) } else { 1e-13 },
                    "{nb:?} sector {sector} rotate {rotate} at patch ({pu}, {pv}): {got:?} vs {expected:?} (deviations {d:e}, {t:e})"
                );
            }
        }
    }
    (worst, worst_at_vertex)
}

#[test]
fn interior_valences_3_to_8_match_the_exact_substitution_oracle() {
    for v in 3..=8 {
        let (d, t) = check_against_oracle(Neighbourhood::interior(v), BoundaryMode::EdgeOnly);
        println!("valence {v}: max deviation {d:.1e}, tangents at the vertex {t:.1e}");
    }
}

#[test]
fn boundary_vertices_match_the_exact_substitution_oracle_in_both_modes() {
    for mode in [BoundaryMode::EdgeOnly, BoundaryMode::EdgeAndCorner] {
        for f in 1..=6 {
            let (d, t) = check_against_oracle(Neighbourhood::boundary(f, mode), mode);
            println!("boundary {f} faces ({mode:?}): max deviation {d:.1e}, tangents at the vertex {t:.1e}");
        }
    }
}

/// The uniform cubic B-spline basis on the four control points of a cell, and its derivative.
fn bspline(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ],
        [
            -s * s / 2.0,
            (3.0 * t * t - 4.0 * t) / 2.0,
            (-3.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
    )
}

#[test]
fn regular_faces_are_the_bicubic_b_spline() {
    // A torus of 5 x 6 quads: every vertex has valence 4.
    let (nu, nv) = (5usize, 6usize);
    let id = |i: usize, j: usize| (j % nv) * nu + (i % nu);
    let mut positions = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = (
                2.0 * std::f64::consts::PI * i as f64 / nu as f64,
                2.0 * std::f64::consts::PI * j as f64 / nv as f64,
            );
            let r = 3.0 + (1.0 + 0.1 * noise(id(i, j) as u64)) * b.cos();
            positions.push([
                r * a.cos(),
                r * a.sin(),
                b.sin() + 0.1 * noise(7 + id(i, j) as u64),
            ]);
        }
    }
    let faces: Vec<Vec<i64>> = (0..nv)
        .flat_map(|j| {
            (0..nu).map(move |i| {
                [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]
                    .map(|x| x as i64)
                    .to_vec()
            })
        })
        .collect();
    let mesh = Mesh::new(positions.clone(), &faces, &[], BoundaryMode::EdgeOnly).expect("torus");
    let evaluator = ExactEvaluator::new(&mesh);
    let mut worst = 0.0f64;
    for (face, (i, j)) in [(0, (0, 0)), (7, (2, 1)), (29, (4, 5))] {
        for (u, v) in parameters() {
            let got = evaluator.evaluate(face, &u, &v).expect("evaluates");
            let (uf, vf) = (u.to_f64().expect("f64"), v.to_f64().expect("f64"));
            let ((bu, du), (bv, dv)) = (bspline(uf), bspline(vf));
            let mut expected = [[0.0; 3]; 3];
            for b in 0..4 {
                for a in 0..4 {
                    let p = positions[id(i + nu + a - 1, j + nv + b - 1)];
                    for c in 0..3 {
                        expected[0][c] += bu[a] * bv[b] * p[c];
                        expected[1][c] += du[a] * bv[b] * p[c];
                        expected[2][c] += bu[a] * dv[b] * p[c];
                    }
                }
            }
            for (g, e) in [got.position, got.du, got.dv].iter().zip(expected) {
                let d = deviation(*g, e, 4.0);
                worst = worst.max(d);
                assert!(d < 1e-14, "face {face} ({u}, {v}): {got:?} vs {expected:?}");
            }
        }
    }
    println!("regular faces vs the bicubic closed form: max deviation {worst:.1e}");
}

/// An open grid of `nx x ny` quads in the plane z = noise.
fn grid(nx: usize, ny: usize, mode: BoundaryMode) -> Mesh {
    let positions = (0..=ny)
        .flat_map(|j| {
            (0..=nx).map(move |i| {
                let k = (j * (nx + 1) + i) as u64;
                [
                    i as f64 + 0.2 * noise(k),
                    j as f64 + 0.2 * noise(k + 100),
                    0.5 * noise(k + 200),
                ]
            })
        })
        .collect();
    let faces: Vec<Vec<i64>> = (0..ny)
        .flat_map(|j| {
            (0..nx).map(move |i| {
                let v = (j * (nx + 1) + i) as i64;
                let w = (nx + 1) as i64;
                vec![v, v + 1, v + w + 1, v + w]
            })
        })
        .collect();
    Mesh::new(positions, &faces, &[], mode).expect("grid")
}

#[test]
fn boundary_edges_are_the_cubic_b_spline_of_the_boundary_polygon() {
    for mode in [BoundaryMode::EdgeOnly, BoundaryMode::EdgeAndCorner] {
        let mesh = grid(5, 3, mode);
        let evaluator = ExactEvaluator::new(&mesh);
        // Faces 1..=3 of the bottom row: their v = 0 edge runs from vertex i to i + 1, a
        // segment of the cubic B-spline of the bottom row of vertices.
        for i in 1..=3usize {
            for (u, _) in parameters() {
                let got = evaluator.evaluate(i, &u, &q(0, 1)).expect("evaluates");
                let (b, d) = bspline(u.to_f64().expect("f64"));
                let mut expected = [[0.0; 3]; 2];
                for a in 0..4 {
                    let p = mesh.positions[i + a - 1];
                    for c in 0..3 {
                        expected[0][c] += b[a] * p[c];
                        expected[1][c] += d[a] * p[c];
                    }
                }
                assert!(
                    deviation(got.position, expected[0], 5.0) < 1e-14,
                    "{mode:?} face {i} u = {u}"
                );
                assert!(
                    deviation(got.du, expected[1], 5.0) < 1e-14,
                    "{mode:?} face {i} u = {u}"
                );
            }
        }
        // The corner face: in "edge and corner" mode the surface interpolates the corner.
        let corner = evaluator
            .evaluate(0, &q(0, 1), &q(0, 1))
            .expect("evaluates");
        if mode == BoundaryMode::EdgeAndCorner {
            assert_eq!(corner.position, mesh.positions[0]);
        } else {
            assert_ne!(corner.position, mesh.positions[0]);
        }
    }
}

/// Parameters of corner `k` of a quad face.
fn corner_uv(k: usize) -> (i64, i64) {
    [(0, 0), (1, 0), (1, 1), (0, 1)][k]
}

/// Evaluate the point at fraction `t` along the edge `(a, b)` of quad faces `fa` and `fb`,
/// returning the position and the derivative along the edge (towards `b`) from each face.
fn along_edge(
    evaluator: &ExactEvaluator,
    fa: usize,
    fb: usize,
    (a, b): (u32, u32),
    t: &BigRational,
) -> [([f64; 3], [f64; 3]); 2] {
    let mesh = evaluator.mesh();
    [fa, fb].map(|f| {
        let corners = mesh.face(f);
        let ka = corners.iter().position(|&x| x == a).expect("a on the face");
        let kb = corners.iter().position(|&x| x == b).expect("b on the face");
        let ((ua, va), (ub, vb)) = (corner_uv(ka), corner_uv(kb));
        let u = q(ua, 1) + t * q(ub - ua, 1);
        let v = q(va, 1) + t * q(vb - va, 1);
        let p: LimitPoint = evaluator.evaluate(f, &u, &v).expect("evaluates");
        let along =
            std::array::from_fn(|c| (ub - ua) as f64 * p.du[c] + (vb - va) as f64 * p.dv[c]);
        (p.position, along)
    })
}

/// Every interior edge of every quad face: the same point from both faces agrees, and so does
/// the derivative along the edge (d/ds = (corner_b - corner_a) . grad in each face's own
/// parameters: the rotation between the two parameterizations).
fn check_edges(mesh: &Mesh, limit: usize) -> f64 {
    let evaluator = ExactEvaluator::new(mesh);
    let mut worst = 0.0f64;
    let mut checked = 0;
    for h in 0..mesh.face_vertices.len() {
        let t = mesh.twin[h];
        if t == subtess::mesh::topology::NONE || (t as usize) < h || checked >= limit {
            continue;
        }
        let (fa, fb) = (mesh.face_of[h] as usize, mesh.face_of[t as usize] as usize);
        if mesh.face(fa).len() != 4 || mesh.face(fb).len() != 4 {
            continue;
        }
        checked += 1;
        let edge = (mesh.face_vertices[h], mesh.head(h));
        for s in [q(0, 1), q(1, 3), q(2, 7), q(1, 1000), q(1, 2), q(1, 1)] {
            let [(pa, da), (pb, db)] = along_edge(&evaluator, fa, fb, edge, &s);
            let d = deviation(pa, pb, 1.0).max(deviation(da, db, 1.0));
            worst = worst.max(d);
            assert!(
                d < 1e-12,
                "faces {fa} {fb} edge {edge:?} at {s}: {pa:?} {da:?} vs {pb:?} {db:?}"
            );
        }
    }
    assert!(checked > 0);
    worst
}

#[test]
fn shared_edges_agree_from_both_faces() {
    for (nb, mode) in [
        (Neighbourhood::interior(5), BoundaryMode::EdgeOnly),
        (Neighbourhood::interior(3), BoundaryMode::EdgeOnly),
        (
            Neighbourhood::boundary(3, BoundaryMode::EdgeOnly),
            BoundaryMode::EdgeOnly,
        ),
        (
            Neighbourhood::boundary(1, BoundaryMode::EdgeAndCorner),
            BoundaryMode::EdgeAndCorner,
        ),
    ] {
        let (mesh, _, _) = neighbourhood_mesh(nb, mode, 1);
        // Faces whose patches exist: the cells (0,0) and their neighbours; outer cells lack
        // outer points and are skipped by the evaluator's error, so check only patch faces.
        let patch_faces: Vec<usize> = (0..mesh.faces())
            .filter(|&f| face_patch(&mesh, f).is_ok())
            .collect();
        let evaluator = ExactEvaluator::new(&mesh);
        for &fa in &patch_faces {
            for &fb in &patch_faces {
                if fa >= fb {
                    continue;
                }
                let shared: Vec<u32> = mesh
                    .face(fa)
                    .iter()
                    .copied()
                    .filter(|v| mesh.face(fb).contains(v))
                    .collect();
                if shared.len() != 2 {
                    continue;
                }
                for s in [q(0, 1), q(1, 3), q(1, 1000), q(1, 1)] {
                    let [(pa, da), (pb, db)] =
                        along_edge(&evaluator, fa, fb, (shared[0], shared[1]), &s);
                    assert!(
                        deviation(pa, pb, 1.0) < 1e-13 && deviation(da, db, 1.0) < 1e-11,
                        "{nb:?}: faces {fa} {fb} at {s}: {pa:?} {da:?} vs {pb:?} {db:?}"
                    );
                }
            }
        }
    }
    println!(
        "cube (isolated): max deviation along shared edges {:.1e}",
        check_edges(&cube(), usize::MAX)
    );
}

#[test]
#[cfg(feature = "catmull-clark")]
fn grid_points_agree_with_the_embedded_f32_table() {
    let table = StencilTable::default_catmull_clark().expect("embedded table");
    let mut worst = 0.0f64;
    for (nb, sector) in [
        (Neighbourhood::interior(3), 0),
        (Neighbourhood::interior(5), 0),
        (Neighbourhood::interior(8), 0),
        (Neighbourhood::boundary(1, BoundaryMode::EdgeOnly), 0),
        (Neighbourhood::boundary(3, BoundaryMode::EdgeOnly), 1),
        (Neighbourhood::boundary(4, BoundaryMode::EdgeOnly), 3),
    ] {
        let (mesh, _, patch_faces) = neighbourhood_mesh(nb, BoundaryMode::EdgeOnly, 0);
        let face = patch_faces[sector as usize];
        let patch = face_patch(&mesh, face).expect("patch");
        let evaluator = ExactEvaluator::new(&mesh);
        let k = patch.points.len();
        for n in [1u32, 3, 4, 7] {
            for points in [PointSet::Primal, PointSet::Dual] {
                let side = if points == PointSet::Primal { n + 1 } else { n } as usize;
                let weights = [
                    StencilKind::Position,
                    StencilKind::DerivativeU,
                    StencilKind::DerivativeV,
                ]
                .map(|kind| {
                    table
                        .weights(&SectionKey {
                            kind,
                            points,
                            boundary: patch.kind.boundary,
                            feature: patch.kind.feature,
                            faces: patch.kind.faces,
                            sector: patch.kind.sector,
                            n,
                        })
                        .expect("section")
                });
                for j in 0..side {
                    for i in 0..side {
                        let (u, v) = if points == PointSet::Primal {
                            (q(i as i64, n as i64), q(j as i64, n as i64))
                        } else {
                            (
                                q(2 * i as i64 + 1, 2 * n as i64),
                                q(2 * j as i64 + 1, 2 * n as i64),
                            )
                        };
                        let got = evaluator.evaluate(face, &u, &v).expect("evaluates");
                        for (w, g) in weights.iter().zip([got.position, got.du, got.dv]) {
                            let row = &w[(j * side + i) * k..][..k];
                            let expected: [f64; 3] = std::array::from_fn(|c| {
                                row.iter()
                                    .zip(&patch.points)
                                    .map(|(w, &p)| f64::from(*w) * mesh.positions[p as usize][c])
                                    .sum()
                            });
                            let d = deviation(g, expected, 1.0);
                            worst = worst.max(d);
                            assert!(d < 2e-6, "{nb:?} sector {sector} n = {n} {points:?} ({u}, {v}): {g:?} vs {expected:?}");
                        }
                    }
                }
            }
        }
    }
    println!("grid points vs the f32 table: max deviation {worst:.1e}");
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = a.iter().map(|c| c * c).sum::<f64>().sqrt();
    a.map(|c| c / l)
}

/// Deviation of a point from a reference: positions always; derivatives away from the
/// (sub-)face's corners, where an extraordinary vertex may sit and only the tangent plane is
/// geometric (the tangent masks' lengths depend on the level they are applied at): there, the
/// unit normals.
fn compare(
    u: &BigRational,
    v: &BigRational,
    got: LimitPoint,
    position: [f64; 3],
    du: [f64; 3],
    dv: [f64; 3],
) -> f64 {
    let integral = |x: &BigRational| x.is_integer();
    let d = deviation(got.position, position, 1.0);
    if integral(u) && integral(v) {
        d.max(deviation(
            unit(cross(got.du, got.dv)),
            unit(cross(du, dv)),
            1.0,
        ))
    } else {
        d.max(deviation(got.du, du, 1.0))
            .max(deviation(got.dv, dv, 1.0))
    }
}

/// The original face's parameters on a mesh that needs isolation agree with evaluating the
/// corresponding face of the once-refined mesh (quarter `i` of a quad at its own parameters;
/// sub-face `k` of an n-gon at the same parameters).
fn check_isolation(mesh: &Mesh) -> f64 {
    let original = ExactEvaluator::new(mesh);
    let refined_mesh = refine(mesh).mesh;
    let refined = ExactEvaluator::new(&refined_mesh);
    let mut worst = 0.0f64;
    for face in 0..mesh.faces() {
        let sides = mesh.face(face).len();
        let child = mesh.face_offsets[face] as usize;
        for (u, v) in parameters() {
            if sides == 4 {
                let got = original.evaluate(face, &u, &v).expect("evaluates");
                // Quarter and child parameters (module docs of exact_eval).
                let (half, one, two) = (q(1, 2), q(1, 1), q(2, 1));
                let (i, s, t, m): (usize, _, _, [[f64; 2]; 2]) = match (u > half, v > half) {
                    (false, false) => (0, &two * &u, &two * &v, [[2.0, 0.0], [0.0, 2.0]]),
                    (true, false) => (1, &two * &v, &two * (&one - &u), [[0.0, 2.0], [-2.0, 0.0]]),
                    (true, true) => (
                        2,
                        &two * (&one - &u),
                        &two * (&one - &v),
                        [[-2.0, 0.0], [0.0, -2.0]],
                    ),
                    (false, true) => (3, &two * (&one - &v), &two * &u, [[0.0, -2.0], [2.0, 0.0]]),
                };
                let c = refined.evaluate(child + i, &s, &t).expect("evaluates");
                let du = std::array::from_fn(|k| m[0][0] * c.du[k] + m[1][0] * c.dv[k]);
                let dv = std::array::from_fn(|k| m[0][1] * c.du[k] + m[1][1] * c.dv[k]);
                let d = compare(&u, &v, got, c.position, du, dv);
                worst = worst.max(d);
                assert!(d < 1e-12, "face {face} ({u}, {v}): {got:?} vs {c:?}");
            } else {
                for k in 0..sides {
                    let got = original
                        .evaluate_subface(face, k, &u, &v)
                        .expect("evaluates");
                    let c = refined.evaluate(child + k, &u, &v).expect("evaluates");
                    let d = compare(&u, &v, got, c.position, c.du, c.dv);
                    worst = worst.max(d);
                    assert!(
                        d < 1e-12,
                        "face {face} corner {k} ({u}, {v}): {got:?} vs {c:?}"
                    );
                }
            }
        }
    }
    worst
}

#[test]
fn original_face_parameters_agree_with_the_isolated_mesh() {
    // A cube (quads with four valence-3 corners) and a pentagonal pyramid with one corner
    // pulled out (a pentagon and five triangles).
    let mut p: Vec<[f64; 3]> = (0..5)
        .map(|i| {
            let a = 2.0 * std::f64::consts::PI * f64::from(i) / 5.0;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    p.push([0.1, -0.2, 1.3]);
    let faces = vec![
        vec![4, 3, 2, 1, 0],
        vec![0, 1, 5],
        vec![1, 2, 5],
        vec![2, 3, 5],
        vec![3, 4, 5],
        vec![4, 0, 5],
    ];
    let pyramid = Mesh::new(p, &faces, &[], BoundaryMode::EdgeOnly).expect("pyramid");
    // An open mesh: a triangle fan with a quad, boundary vertices with 1, 2, 3 faces.
    let fan = Mesh::new(
        vec![
            [0.0, 0.0, 0.3],
            [1.0, 0.0, 0.0],
            [0.7, 0.8, 0.1],
            [-0.5, 0.9, 0.0],
            [-1.0, -0.2, 0.2],
            [0.1, -1.0, 0.0],
        ],
        &[vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4, 5]],
        &[],
        BoundaryMode::EdgeAndCorner,
    )
    .expect("fan");
    for (name, mesh) in [("cube", cube()), ("pyramid", pyramid), ("open fan", fan)] {
        println!(
            "{name}: original vs isolated faces, max deviation {:.1e}",
            check_isolation(&mesh)
        );
    }
    // The convenience function is the evaluator.
    let e = evaluate(&cube(), 2, &q(1, 3), &q(1, 7)).expect("evaluates");
    assert_eq!(
        Some(e),
        ExactEvaluator::new(&cube())
            .evaluate(2, &q(1, 3), &q(1, 7))
            .ok()
    );
}

#[test]
fn bad_requests_are_errors_that_say_what_is_wrong() {
    let mesh = cube();
    let e = evaluate(&mesh, 6, &q(0, 1), &q(0, 1))
        .expect_err("no face 6")
        .to_string();
    assert!(e.contains("face 6") && e.contains("6 faces"), "{e}");
    let e = evaluate(&mesh, 0, &q(3, 2), &q(0, 1))
        .expect_err("u > 1")
        .to_string();
    assert!(e.contains("u = 3/2"), "{e}");
    let e = ExactEvaluator::new(&mesh)
        .evaluate_subface(0, 1, &q(0, 1), &q(0, 1))
        .expect_err("a quad")
        .to_string();
    assert!(e.contains("quad"), "{e}");
    let tri = Mesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[vec![0, 1, 2]],
        &[],
        BoundaryMode::EdgeOnly,
    )
    .expect("triangle");
    let e = ExactEvaluator::new(&tri)
        .evaluate_subface(0, 3, &q(0, 1), &q(0, 1))
        .expect_err("3 corners")
        .to_string();
    assert!(e.contains("3 corners"), "{e}");
}

/// Real models: OpenSubdiv shapes and Keenan Crane's Spot.
#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs ../shared/models beside the repository"
)]
fn real_models_evaluate_consistently_with_their_isolated_meshes() {
    let dir = crate::common::models();
    let models = [
        "opensubdiv/catmark_pyramid.obj",
        "opensubdiv/catmark_tent.obj",
        "opensubdiv/catmark_edgecorner.obj",
        "opensubdiv/catmark_flap.obj",
        "crane/spot_control_mesh.obj",
    ]
    .map(|file| dir.join(file));
    for path in models {
        let obj = subtess::io::obj::read_obj(&path).expect("reads");
        let (mesh, _) = Mesh::from_obj(&obj).expect("valid");
        // A subset of the faces on a big model.
        let step = (mesh.faces() / 40).max(1);
        let sub = Mesh::new(
            mesh.positions.clone(),
            &(0..mesh.faces())
                .map(|f| mesh.face(f).iter().map(|&v| i64::from(v)).collect())
                .collect::<Vec<_>>(),
            &[],
            mesh.boundary,
        )
        .expect("valid");
        let worst = if step == 1 {
            check_isolation(&sub)
        } else {
            check_edges(&sub, 40)
        };
        println!("{}: max deviation {worst:.1e}", path.display());
    }
}
