//! Two uniform steps of √3 subdivision (Kobbelt 2000) on a triangle mesh, taken as one
//! ternary step aligned with the mesh (Schaefer–Warren section 5.1): the rules of
//! `schemes::TriangleScheme` "sqrt3" that the √3 stencil tables were generated with, numbered
//! as the ternary split of [`crate::scheme::triangle::split`] says.
//!
//! One √3 step inserts every triangle's centroid `c_f = (a + b + c) / 3`, moves every old vertex
//! of valence `k` to `(1 - alpha_k) p + (alpha_k / k) sum` of its neighbours,
//! `alpha_k = (4 - 2 cos(2π/k)) / 9` (Kobbelt 2000), and flips every old edge, so that
//! centroids of neighbouring triangles are joined. A second step does the same to that mesh:
//! its triangles are `(a, c_g, c_f)` and `(b, c_f, c_g)` around the old edge `(a, b)` between
//! triangles `f` and `g`, and their centroids lie on the old edge at its thirds. Composed, with
//! `h_v` an old vertex after the first step:
//!
//! * old vertex `v` of valence `k`: `(1 - alpha_k) h_v + (alpha_k / k) sum_{f ∋ v} c_f`
//!   (after the first step its neighbours are the centroids of its triangles);
//! * the third of edge `(a, b)` nearer `a`: `(h_a + c_f + c_g) / 3`;
//! * the centre of triangle `f = (a, b, c)`: `c_f` moved by the valence-6 rule
//!   (`alpha_6 = 1/3`), `2/3 c_f + 1/18 (h_a + h_b + h_c + c_g1 + c_g2 + c_g3)`, `g_i` the
//!   triangles across `f`'s edges.
//!
//! Old vertices keep their valence; every new vertex has valence 6.
//!
//! # Boundaries
//!
//! Kobbelt's boundary rules (2000, section 4) take the two steps differently. The first step
//! keeps the boundary vertices where they are and does not flip boundary edges: a triangle
//! `f = (a, b, c)` with boundary edge `(a, b)` keeps `(a, b, c_f)`. The second step trisects
//! every boundary edge by the univariate ternary rules
//! `(p_{i-1} + 16 p_i + 10 p_{i+1}) / 27` (the third nearer `p_i`) and moves every boundary vertex
//! to `(4 p_{i-1} + 19 p_i + 4 p_{i+1}) / 27`; a triangle with a boundary edge gets no centroid
//! but is split into three by the edge's thirds, and its two inner edges are flipped with the
//! rest. Interior points follow the interior rules, with the valences they have:
//!
//! * an interior vertex's neighbours are counted boundary vertices included;
//! * the centroid `c_f` of a triangle with `j` inner (non-boundary) edges has valence `3 + j`
//!   after the first step (its three corners and the centroids across the inner edges), so it
//!   moves to `(1 - alpha_{3+j}) c_f + (alpha_{3+j} / (3 + j)) (h_a + h_b + h_c + sum c_g)`;
//!   `j = 3` is the interior rule above;
//! * the thirds of an inner edge are `(h_a + c_f + c_g) / 3` as above, with `h = p` at a
//!   boundary vertex.
//!
//! The two steps together split every triangle as the ternary split does (the boundary edge's
//! thirds, the centre `c_f` and the inner edges' thirds are the nine children's corners), so the
//! numbering of [`crate::scheme::triangle::split`] holds with a boundary too. Along the boundary
//! the composed rule reads boundary points only, and it is the ternary subdivision of the
//! uniform cubic B-spline (mask `(1 + z + z^2)^4 / 27`): the limit boundary is the cubic B-spline
//! of the boundary polygon, and a boundary vertex's limit is `(p_{i-1} + 4 p_i + p_{i+1}) / 6`
//! ([`sqrt3_boundary_limit_position`]).

use schemes::triangle::TriangleVertexRule;

use crate::mesh::geometry::{add, scale};
use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::{neighbours, require_triangles};
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::split::TriangleSplit;
use crate::RuntimeError;

/// The vertex weight `alpha_k` of √3 at valence `k` (`k` times the neighbour weight
/// `TriangleVertexRule::Sqrt3` gives).
pub fn sqrt3_alpha(valence: usize) -> f64 {
    let (_, beta) = TriangleVertexRule::Sqrt3.weights(valence as u32);
    beta.value * valence as f64
}

/// The limit position of an old vertex `p` of valence `k` with neighbours averaging `m`:
/// `(p + 3 alpha_k m) / (1 + 3 alpha_k)` (Kobbelt 2000, section 4). Why: one step maps the
/// pair `(p, m)` to `((1 - alpha) p + alpha m, (p + 2m) / 3)` (each neighbour lies in two of
/// the new neighbours, the centroids), whose left eigenvector for eigenvalue 1 is
/// `(1, 3 alpha)`.
pub fn sqrt3_limit_position(p: [f64; 3], ring_average: [f64; 3], valence: usize) -> [f64; 3] {
    let w = 3.0 * sqrt3_alpha(valence);
    scale(1.0 / (1.0 + w), add(p, scale(w, ring_average)))
}

/// The limit position of a boundary vertex `p` between boundary neighbours `prev` and `next`:
/// `(prev + 4 p + next) / 6`, the uniform cubic B-spline at its knot. Why: the composed step's
/// boundary rules (module docs) are the ternary refinement of the cubic B-spline, whose mask
/// `(1 + z + z^2)^4 / 27` maps the triple `(prev, p, next)` by `(4, 19, 4) / 27` and
/// `(1, 16, 10) / 27`, `(10, 16, 1) / 27`; the left eigenvector for eigenvalue 1 is
/// `(1, 4, 1) / 6`.
pub fn sqrt3_boundary_limit_position(prev: [f64; 3], p: [f64; 3], next: [f64; 3]) -> [f64; 3] {
    scale(1.0 / 6.0, add(add(prev, next), scale(4.0, p)))
}

/// Two √3 steps of a triangle mesh as one ternary step, and the rules that made it.
#[derive(Clone, Debug)]
pub struct Sqrt3Refinement {
    /// The refined mesh (nine triangles per triangle, `9f + c` from triangle `f`, numbered as
    /// the ternary split of [`crate::scheme::triangle::split`] says).
    pub mesh: Mesh,
    /// The composed step's rules: row `i` is refined vertex `i` over the coarse vertices, so
    /// `stencil.apply(&coarse.positions) == mesh.positions` (how the positions were made).
    pub stencil: Stencil<f64>,
}

/// Two √3 steps of the triangle mesh `mesh`, composed, as rows over its vertices (f64:
/// `alpha_k` has a cosine): refined vertex `i`, numbered as the ternary split of
/// [`crate::scheme::triangle::split`] says, is `sum w p_j` over row `i`; Kobbelt's boundary
/// rules where `mesh` has a boundary (module docs). Why a map: the same rules then position the
/// refined mesh ([`sqrt3_refine`]) and compose into the per-frame stencil of an isolation.
/// Refuses a face that is not a triangle.
pub fn sqrt3_stencil(mesh: &Mesh) -> Result<Stencil<f64>, RuntimeError> {
    require_triangles(mesh)?;
    Ok(rows(mesh, &TriangleSplit::new(mesh)))
}

/// The boundary neighbours of boundary vertex `v`: the one before it along the boundary and
/// the one after it (faces counter-clockwise: the interior lies to the left of `prev -> v ->
/// next`).
fn boundary_neighbours(mesh: &Mesh, v: usize) -> (u32, u32) {
    let ring = neighbours(mesh, v);
    (ring[ring.len() - 1], ring[0])
}

/// The module docs' two steps over `split`'s ternary numbering (`mesh` all triangles),
/// composed: the first step's points are the old vertices moved (`h_v`, numbered as the
/// vertices) and then every triangle's centroid `c_f` (number `nv + f`); the second step's rows
/// are over those.
fn rows(mesh: &Mesh, split: &TriangleSplit) -> Stencil<f64> {
    let nv = mesh.positions.len();
    let centroid = |f: usize| (nv + f) as u32;
    let across = |h: usize| {
        let t = mesh.twin[h];
        (t != NONE).then(|| centroid(mesh.face_of[t as usize] as usize))
    };
    let mut first = Stencil::new(nv);
    let mut second = Stencil::new(nv + mesh.faces());
    for v in 0..nv {
        let fan = mesh.fan(v);
        let k = fan.len();
        if k == 0 {
            // An unused vertex stays where it is.
            first.push_row(vec![(v as u32, 1.0)]);
            second.push_row(vec![(v as u32, 1.0)]);
            continue;
        }
        if mesh.is_boundary_vertex(v) {
            // Kept by the first step; the second reads the boundary neighbours, kept too.
            let (prev, next) = boundary_neighbours(mesh, v);
            first.push_row(vec![(v as u32, 1.0)]);
            second.push_row(vec![
                (prev, 4.0 / 27.0),
                (v as u32, 19.0 / 27.0),
                (next, 4.0 / 27.0),
            ]);
            continue;
        }
        let alpha = sqrt3_alpha(k);
        let ring = alpha / k as f64;
        let mut h = vec![(v as u32, 1.0 - alpha)];
        h.extend(neighbours(mesh, v).iter().map(|&e| (e, ring)));
        first.push_row(h);
        let mut moved = vec![(v as u32, 1.0 - alpha)];
        moved.extend(
            fan.iter()
                .map(|&g| (centroid(mesh.face_of[g] as usize), ring)),
        );
        second.push_row(moved);
    }
    for f in 0..mesh.faces() {
        first.push_row(mesh.face(f).iter().map(|&v| (v, 1.0 / 3.0)).collect());
    }
    for (&[a, b], &h) in split.edges.iter().zip(&split.first_halfedge) {
        let h = h as usize;
        match across(h) {
            Some(g) => {
                let f = centroid(mesh.face_of[h] as usize);
                for end in [a, b] {
                    second.push_row(vec![(end, 1.0 / 3.0), (f, 1.0 / 3.0), (g, 1.0 / 3.0)]);
                }
            }
            None => {
                // `a -> b` runs along the boundary: `a`'s other boundary neighbour comes
                // before it, `b`'s after it.
                let (before, _) = boundary_neighbours(mesh, a as usize);
                let (_, after) = boundary_neighbours(mesh, b as usize);
                second.push_row(vec![
                    (before, 1.0 / 27.0),
                    (a, 16.0 / 27.0),
                    (b, 10.0 / 27.0),
                ]);
                second.push_row(vec![
                    (a, 10.0 / 27.0),
                    (b, 16.0 / 27.0),
                    (after, 1.0 / 27.0),
                ]);
            }
        }
    }
    for f in 0..mesh.faces() {
        let inner: Vec<u32> = mesh.face_halfedges(f).filter_map(across).collect();
        let valence = 3 + inner.len();
        let alpha = sqrt3_alpha(valence);
        let ring = alpha / valence as f64;
        let mut centre = vec![(centroid(f), 1.0 - alpha)];
        centre.extend(mesh.face(f).iter().map(|&v| (v, ring)));
        centre.extend(inner.iter().map(|&g| (g, ring)));
        second.push_row(centre);
    }
    first.then(&second)
}

/// Refine the triangle mesh `mesh` by two √3 steps, one ternary step (module docs): the
/// positions are [`sqrt3_stencil`]'s rows applied to the coarse positions, and the rows come
/// back with the mesh.
pub fn sqrt3_refine(mesh: &Mesh) -> Result<Sqrt3Refinement, RuntimeError> {
    require_triangles(mesh)?;
    let nv = mesh.positions.len();
    let split = TriangleSplit::new(mesh);
    let stencil = rows(mesh, &split);
    let positions = stencil.apply(&mesh.positions);
    let faces = split.ternary_child_faces(mesh, nv);
    let mesh = Mesh::new(positions, &faces, &[], mesh.boundary)?;
    Ok(Sqrt3Refinement { mesh, stencil })
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use schemes::BoundaryMode;

    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron};

    /// One √3 step done literally, as Kobbelt describes it and independent of the composed
    /// rows: relax the old vertices, insert centroids (on an odd step, split a triangle with a
    /// boundary edge by the edge's two new points instead), then flip every old inner edge.
    /// Faces are vertex triples, counter-clockwise.
    fn literal_step(
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
        odd: bool,
    ) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let edges = |fs: &[[u32; 3]]| -> HashMap<(u32, u32), usize> {
            let mut map = HashMap::new();
            for (f, t) in fs.iter().enumerate() {
                for i in 0..3 {
                    assert!(map.insert((t[i], t[(i + 1) % 3]), f).is_none(), "manifold");
                }
            }
            map
        };
        let old = edges(faces);
        let boundary = |a: u32, b: u32| !old.contains_key(&(b, a));
        let n = positions.len();
        let mut ring: Vec<Vec<u32>> = vec![Vec::new(); n];
        let (mut next, mut prev) = (vec![u32::MAX; n], vec![u32::MAX; n]);
        for &(a, b) in old.keys() {
            if !ring[a as usize].contains(&b) {
                ring[a as usize].push(b);
            }
            if !ring[b as usize].contains(&a) {
                ring[b as usize].push(a);
            }
            if boundary(a, b) {
                next[a as usize] = b;
                prev[b as usize] = a;
            }
        }
        let p = |v: u32| positions[v as usize];
        let combine = |terms: &[(u32, f64)]| {
            terms
                .iter()
                .fold([0.0; 3], |acc, &(v, w)| add(acc, scale(w, p(v))))
        };
        let mut out: Vec<[f64; 3]> = (0..n as u32)
            .map(|v| {
                let i = v as usize;
                if next[i] != u32::MAX {
                    if odd {
                        combine(&[
                            (prev[i], 4.0 / 27.0),
                            (v, 19.0 / 27.0),
                            (next[i], 4.0 / 27.0),
                        ])
                    } else {
                        p(v)
                    }
                } else {
                    let k = ring[i].len();
                    let alpha = sqrt3_alpha(k);
                    let mut terms = vec![(v, 1.0 - alpha)];
                    terms.extend(ring[i].iter().map(|&e| (e, alpha / k as f64)));
                    combine(&terms)
                }
            })
            .collect();
        let mut split = Vec::new();
        for t in faces {
            let cut = (0..3).find(|&i| odd && boundary(t[i], t[(i + 1) % 3]));
            if let Some(i) = cut {
                let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
                let (l, r) = (out.len() as u32, out.len() as u32 + 1);
                out.push(
                    combine(&[(prev[a as usize], 1.0), (a, 16.0), (b, 10.0)]).map(|x| x / 27.0),
                );
                out.push(
                    combine(&[(a, 10.0), (b, 16.0), (next[b as usize], 1.0)]).map(|x| x / 27.0),
                );
                split.extend([[a, l, c], [l, r, c], [r, b, c]]);
            } else {
                let m = out.len() as u32;
                out.push(combine(&[
                    (t[0], 1.0 / 3.0),
                    (t[1], 1.0 / 3.0),
                    (t[2], 1.0 / 3.0),
                ]));
                split.extend([[t[0], t[1], m], [t[1], t[2], m], [t[2], t[0], m]]);
            }
        }
        let new = edges(&split);
        let mut flipped = vec![false; split.len()];
        let mut result = Vec::new();
        for (&(a, b), _) in old.iter().filter(|(&(a, b), _)| a < b && !boundary(a, b)) {
            // Faces (a, b, u) and (b, a, w) become (a, w, u) and (w, b, u).
            let (f, g) = (new[&(a, b)], new[&(b, a)]);
            let apex = |t: [u32; 3], x: u32, y: u32| {
                t.into_iter()
                    .find(|&z| z != x && z != y)
                    .expect("a triangle")
            };
            let (u, w) = (apex(split[f], a, b), apex(split[g], a, b));
            assert!(!flipped[f] && !flipped[g], "one old edge per new triangle");
            flipped[f] = true;
            flipped[g] = true;
            result.extend([[a, w, u], [w, b, u]]);
        }
        result.extend((0..split.len()).filter(|&f| !flipped[f]).map(|f| split[f]));
        (out, result)
    }

    /// A mesh from vertex triples, positions perturbed by a fixed pseudo-random offset so that
    /// refined vertices can be matched by position.
    fn jittered(positions: Vec<[f64; 3]>, faces: &[[u32; 3]]) -> Mesh {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut jitter = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 0.2 - 0.1
        };
        let positions = positions
            .into_iter()
            .map(|p| p.map(|x| x + jitter()))
            .collect();
        let faces: Vec<Vec<i64>> = faces
            .iter()
            .map(|t| t.iter().map(|&v| i64::from(v)).collect())
            .collect();
        Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a valid mesh")
    }

    /// Kobbelt's limit position of `m`'s vertex `v`: [`sqrt3_boundary_limit_position`] on the
    /// boundary, [`sqrt3_limit_position`] inside (closed forms, no refinement).
    fn kobbelt_limit(m: &Mesh, v: usize) -> [f64; 3] {
        let ring = neighbours(m, v);
        let p = |i: u32| m.positions[i as usize];
        if m.is_boundary_vertex(v) {
            let (prev, next) = boundary_neighbours(m, v);
            return sqrt3_boundary_limit_position(p(prev), m.positions[v], p(next));
        }
        let sum = ring.iter().fold([0.0; 3], |acc, &e| add(acc, p(e)));
        sqrt3_limit_position(
            m.positions[v],
            scale(1.0 / ring.len() as f64, sum),
            ring.len(),
        )
    }

    /// The lattice triangles with every corner `(a, b)` in `0..=m` squared, at `(a, b, 0)`:
    /// a parallelogram whose corners have one and two triangles and whose sides are regular
    /// boundary vertices (three triangles).
    fn lattice_patch(m: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let index = |a: u32, b: u32| a + (m + 1) * b;
        let positions = (0..(m + 1) * (m + 1))
            .map(|k| [f64::from(k % (m + 1)), f64::from(k / (m + 1)), 0.0])
            .collect();
        let mut faces = Vec::new();
        for b in 0..m {
            for a in 0..m {
                faces.push([index(a, b), index(a + 1, b), index(a, b + 1)]);
                faces.push([index(a + 1, b), index(a + 1, b + 1), index(a, b + 1)]);
            }
        }
        (positions, faces)
    }

    /// Meshes with boundaries: one triangle, an open fan of five triangles, the octahedron
    /// without one face, and a lattice parallelogram.
    fn open_meshes() -> Vec<(&'static str, Mesh)> {
        let fan: Vec<[f64; 3]> = (0..6)
            .map(|i| {
                let t = f64::from(i) * 0.9;
                [t.cos(), t.sin(), 0.3 * f64::from(i % 2)]
            })
            .chain([[0.0, 0.0, 0.5]])
            .collect();
        let octahedron_faces: Vec<[u32; 3]> = (0..octahedron().faces())
            .skip(1)
            .map(|f| {
                let t = octahedron().face(f).to_vec();
                [t[0], t[1], t[2]]
            })
            .collect();
        let (patch, patch_faces) = lattice_patch(4);
        vec![
            (
                "triangle",
                jittered(
                    vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                    &[[0, 1, 2]],
                ),
            ),
            (
                "open fan",
                jittered(fan, &(0..5).map(|i| [6, i, i + 1]).collect::<Vec<_>>()),
            ),
            (
                "octahedron without a face",
                jittered(octahedron().positions, &octahedron_faces),
            ),
            ("lattice parallelogram", jittered(patch, &patch_faces)),
        ]
    }

    /// Kobbelt's two steps, taken literally (an even step, then an odd one), give the mesh
    /// and the positions of the composed ternary step: the same vertices (matched by position,
    /// to 1e-13) and the same triangles.
    #[test]
    fn the_composed_step_is_two_literal_steps_with_boundaries() {
        let mut cases = open_meshes();
        cases.push(("octahedron", octahedron()));
        for (name, mesh) in cases {
            let faces: Vec<[u32; 3]> = (0..mesh.faces())
                .map(|f| {
                    let t = mesh.face(f);
                    [t[0], t[1], t[2]]
                })
                .collect();
            let (p1, f1) = literal_step(&mesh.positions, &faces, false);
            let (p2, f2) = literal_step(&p1, &f1, true);
            let refined = sqrt3_refine(&mesh).expect("refines").mesh;
            assert_eq!(p2.len(), refined.positions.len(), "{name}: vertices");
            assert_eq!(f2.len(), refined.faces(), "{name}: triangles");
            let matched: Vec<u32> = p2
                .iter()
                .map(|q| {
                    let distance =
                        |r: &[f64; 3]| (0..3).map(|x| (q[x] - r[x]).abs()).fold(0.0, f64::max);
                    let (best, d) = refined
                        .positions
                        .iter()
                        .enumerate()
                        .map(|(i, r)| (i as u32, distance(r)))
                        .min_by(|x, y| x.1.total_cmp(&y.1))
                        .expect("vertices");
                    assert!(
                        d < 1e-13,
                        "{name}: literal vertex {q:?} is {d} from the nearest"
                    );
                    best
                })
                .collect();
            let canonical = |t: [u32; 3]| {
                let i = (0..3).min_by_key(|&i| t[i]).expect("three");
                [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
            };
            let mut want: Vec<[u32; 3]> = f2
                .iter()
                .map(|t| canonical(t.map(|v| matched[v as usize])))
                .collect();
            let mut got: Vec<[u32; 3]> = (0..refined.faces())
                .map(|f| {
                    let t = refined.face(f);
                    canonical([t[0], t[1], t[2]])
                })
                .collect();
            want.sort_unstable();
            got.sort_unstable();
            assert_eq!(want, got, "{name}: triangles");
        }
    }

    /// Along the boundary the composed step is the ternary refinement of the uniform cubic
    /// B-spline: refined boundary point `3i + r` is `sum_j s[3(i - j) + r + 4] p_j` over the
    /// coarse boundary polygon, `s` the coefficients of `(1 + z + z^2)^4 / 27` (the B-spline's
    /// symbol, expanded here). And the boundary limit `(prev + 4 p + next) / 6` of every coarse
    /// boundary vertex, the interior one of every interior vertex, is where the refined vertex's
    /// limit is.
    #[test]
    fn the_boundary_is_the_ternary_cubic_b_spline() {
        let mut symbol = vec![1.0];
        for _ in 0..4 {
            let mut next = vec![0.0; symbol.len() + 2];
            for (i, c) in symbol.iter().enumerate() {
                for d in 0..3 {
                    next[i + d] += c;
                }
            }
            symbol = next;
        }
        let mask: Vec<f64> = symbol.iter().map(|c| c / 27.0).collect();
        assert_eq!(mask.len(), 9);
        for (name, coarse) in open_meshes() {
            let fine = sqrt3_refine(&coarse).expect("refines").mesh;
            // The boundary loop through coarse vertex `start`, in boundary order.
            let walk = |m: &Mesh, start: usize| {
                let mut loop_ = vec![start as u32];
                loop {
                    let (_, next) = boundary_neighbours(m, loop_[loop_.len() - 1] as usize);
                    if next as usize == start {
                        break loop_;
                    }
                    loop_.push(next);
                }
            };
            let start = (0..coarse.positions.len())
                .find(|&v| coarse.is_boundary_vertex(v))
                .expect("a boundary");
            let coarse_loop = walk(&coarse, start);
            let fine_loop = walk(&fine, start);
            let n = coarse_loop.len();
            assert_eq!(fine_loop.len(), 3 * n, "{name}");
            for (k, &v) in fine_loop.iter().enumerate() {
                let (i, r) = (k / 3, k % 3);
                let mut want = [0.0; 3];
                for dj in -2i64..=2 {
                    let index = 3 * dj + r as i64 + 4;
                    if !(0..9).contains(&index) {
                        continue;
                    }
                    let j = (i as i64 - dj).rem_euclid(n as i64) as usize;
                    want = add(
                        want,
                        scale(
                            mask[index as usize],
                            coarse.positions[coarse_loop[j] as usize],
                        ),
                    );
                }
                let got = fine.positions[v as usize];
                for x in 0..3 {
                    assert!(
                        (got[x] - want[x]).abs() < 1e-14,
                        "{name}: boundary point {k}"
                    );
                }
            }
            for v in 0..coarse.positions.len() {
                let (a, b) = (kobbelt_limit(&coarse, v), kobbelt_limit(&fine, v));
                for x in 0..3 {
                    assert!(
                        (a[x] - b[x]).abs() < 1e-14,
                        "{name}: vertex {v}: {a:?} {b:?}"
                    );
                }
            }
        }
    }

    /// The faces' corners after a ternary step, in their parents' charts: a face lies in one
    /// chart, its corners at `corners[f]` in it; a child's corner is at three times the
    /// parent's coordinates plus its ternary offset. Also every refined vertex's chart and
    /// coordinates (from any face it is in).
    #[allow(clippy::type_complexity)]
    fn refined_corners(
        mesh: &Mesh,
        fine: &Mesh,
        corners: &[[(i64, i64); 3]],
        chart: &[i64],
    ) -> (Vec<[(i64, i64); 3]>, Vec<i64>, Vec<(i64, (i64, i64))>) {
        let mut out = vec![None; fine.positions.len()];
        let mut fine_corners = vec![[(0, 0); 3]; fine.faces()];
        let mut fine_chart = vec![0; fine.faces()];
        for f in 0..mesh.faces() {
            let c = corners[f];
            for g in 9 * f..9 * f + 9 {
                fine_chart[g] = chart[f];
                for (i, (&corner, (s, t))) in fine
                    .face(g)
                    .iter()
                    .zip([(0, 0), (1, 0), (0, 1)])
                    .enumerate()
                {
                    let (u, v) = crate::scheme::triangle::split::ternary_child_to_parent(
                        (g % 9) as u8,
                        s,
                        t,
                        1,
                    );
                    let (u, v) = (i64::from(u), i64::from(v));
                    let q = (
                        3 * c[0].0 + u * (c[1].0 - c[0].0) + v * (c[2].0 - c[0].0),
                        3 * c[0].1 + u * (c[1].1 - c[0].1) + v * (c[2].1 - c[0].1),
                    );
                    fine_corners[g][i] = q;
                    out[corner as usize].get_or_insert((chart[f], q));
                }
            }
        }
        let out = out
            .into_iter()
            .map(|q| q.expect("every vertex in a face"))
            .collect();
        (fine_corners, fine_chart, out)
    }

    /// The fan of `k` triangles around a boundary vertex with `rings` rings, named by
    /// `schemes::sqrt3_boundary`'s charts, at jittered generic positions: its points' names
    /// (vertex `i` is `names[i]`), the mesh, and every face's chart and corners in it.
    #[allow(clippy::type_complexity)]
    fn fan_mesh(
        k: u32,
        rings: i64,
    ) -> (
        Vec<schemes::sqrt3_boundary::FanPoint>,
        Mesh,
        Vec<i64>,
        Vec<[(i64, i64); 3]>,
    ) {
        use schemes::sqrt3_boundary::{BoundaryFan, FanPoint};
        let fan = BoundaryFan::new(k);
        let mut names: Vec<FanPoint> = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::new();
        let mut chart = Vec::new();
        let mut corners = Vec::new();
        let id = |p: FanPoint, names: &mut Vec<FanPoint>| {
            names.iter().position(|&q| q == p).unwrap_or_else(|| {
                names.push(p);
                names.len() - 1
            }) as u32
        };
        for s in 0..i64::from(k) {
            let name = |q: (i64, i64)| fan.canonical(s, q).expect("in the fan");
            for b in 0..rings {
                for a in 0..rings - b {
                    let mut triangles = vec![[(a, b), (a + 1, b), (a, b + 1)]];
                    if a + b + 2 <= rings {
                        triangles.push([(a + 1, b), (a + 1, b + 1), (a, b + 1)]);
                    }
                    for t in triangles {
                        faces.push(t.map(|q| id(name(q), &mut names)));
                        chart.push(s);
                        corners.push(t);
                    }
                }
            }
        }
        let positions: Vec<[f64; 3]> = names
            .iter()
            .map(|&p| {
                let t = f64::from(p.0) + 0.1 * p.1 as f64;
                [
                    p.1 as f64 * t.cos(),
                    p.1 as f64 * t.sin() + p.2 as f64,
                    0.2 * p.2 as f64,
                ]
            })
            .collect();
        (names, jittered(positions, &faces), chart, corners)
    }

    /// The boundary rules of `schemes::sqrt3_boundary` (the generator's side, written in
    /// lattice charts) are this whole-mesh step's: on the fan of `K = 1..=7` triangles around
    /// a boundary vertex (seven rings, jittered positions), every vertex after one and after
    /// two ternary steps within three level-0 units of the fan's vertex is its row applied to the
    /// coarse positions (to 1e-14); `K = 3` is the half-plane beside a straight boundary.
    #[test]
    fn the_fan_rules_are_the_whole_mesh_rules_next_to_a_boundary_vertex() {
        use schemes::sqrt3_boundary::{BoundaryFan, BoundaryRows};
        let mut checked = 0;
        for k in 1..=7u32 {
            let fan = BoundaryFan::new(k);
            let (names, coarse, chart, mut corners) = fan_mesh(k, 7);
            let mut rows = BoundaryRows::new(fan);
            let (mut mesh, mut mesh_chart) = (coarse.clone(), chart);
            for level in 1..=2u32 {
                let fine = sqrt3_refine(&mesh).expect("refines").mesh;
                let (fine_corners, fine_chart, located) =
                    refined_corners(&mesh, &fine, &corners, &mesh_chart);
                let unit = 3i64.pow(level);
                for (v, &(s, q)) in located.iter().enumerate() {
                    if q.0.max(0) + q.1.max(0) > 3 * unit {
                        continue;
                    }
                    let name = fan.canonical(s, q).expect("in the fan");
                    let want = rows.row(level, name).iter().fold([0.0; 3], |acc, (p, &w)| {
                        let i = names.iter().position(|q| q == p).expect("a coarse vertex");
                        add(acc, scale(w, coarse.positions[i]))
                    });
                    let got = fine.positions[v];
                    for x in 0..3 {
                        assert!(
                            (got[x] - want[x]).abs() < 1e-14,
                            "K = {k}, level {level}, {name:?}: {got:?} {want:?}"
                        );
                    }
                    checked += 1;
                }
                corners = fine_corners;
                mesh_chart = fine_chart;
                mesh = fine;
            }
        }
        assert!(checked > 2000, "{checked} points checked");
    }

    /// The generator's surface on the fan (`stencilgen::sqrt3_strip::fan`: the
    /// regular basis over certified levels, the B-spline on the boundary) is the limit of this
    /// whole-mesh step: for `K = 1..=6`, at every ternary point `(i/9, j/9)` of a sector within
    /// three units of the boundary vertex (`V` and the boundary rays included), the position
    /// stencil applied to the coarse points is Kobbelt's limit position of the vertex two
    /// whole-mesh steps put there (to 1e-12).
    #[test]
    fn the_fan_surface_is_the_limit_of_whole_mesh_refinement() {
        use schemes::loop_regular::RegularDerivative;
        use stencilgen::sqrt3_strip;
        let mut checked = 0;
        for k in 1..=6u32 {
            let (names, coarse, chart, corners) = fan_mesh(k, 7);
            let one = sqrt3_refine(&coarse).expect("refines").mesh;
            let (corners, chart, _) = refined_corners(&coarse, &one, &corners, &chart);
            let two = sqrt3_refine(&one).expect("refines").mesh;
            let (_, _, located) = refined_corners(&one, &two, &corners, &chart);
            let mut surface = sqrt3_strip::fan(k, 9).expect("psi on 1/9");
            for (v, &(s, q)) in located.iter().enumerate() {
                if q.0 + q.1 > 27 {
                    continue;
                }
                let stencil = surface
                    .stencil(s, q, RegularDerivative::Position)
                    .expect("evaluates");
                let got = stencil.iter().fold([0.0; 3], |acc, (p, &w)| {
                    let i = names.iter().position(|q| q == p).expect("a coarse vertex");
                    add(acc, scale(w, coarse.positions[i]))
                });
                let want = kobbelt_limit(&two, v);
                for x in 0..3 {
                    assert!(
                        (got[x] - want[x]).abs() < 1e-12,
                        "K = {k}, sector {s}, ({}/9, {}/9): {got:?} {want:?}",
                        q.0,
                        q.1
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 1500, "{checked} points checked");
    }

    /// The generator's tangent masks at a boundary vertex (`stencilgen::sqrt3_fan_tangents`,
    /// from the local matrix's eigenvectors) give the plane the whole-mesh surface's normals
    /// converge to: the normal of `V`'s ring of limit positions after `m = 1, 2, 3` ternary
    /// steps (the sum of its triangles' normals) turns towards `du x dv` at every step, for the
    /// fans with a tangent plane (`K = 1..=5`). `--nocapture` prints the angles.
    #[test]
    fn boundary_vertex_normals_converge_to_the_tangent_masks() {
        use crate::mesh::geometry::{cross, dot, norm, sub};
        use stencilgen::sqrt3_fan_tangents::sqrt3_fan_tangents;
        let angle =
            |a: [f64; 3], b: [f64; 3]| (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0).acos();
        for k in 1..=5u32 {
            let (names, coarse, _, _) = fan_mesh(k, 7);
            let masks = sqrt3_fan_tangents(k, 0).expect("tangents");
            let apply = |w: &[f64]| {
                masks.layout.iter().zip(w).fold([0.0; 3], |acc, (p, &x)| {
                    let i = names.iter().position(|q| q == p).expect("a coarse vertex");
                    add(acc, scale(x, coarse.positions[i]))
                })
            };
            let normal = cross(apply(&masks.du), apply(&masks.dv));
            let v = names.iter().position(|&q| q == (0, 0, 0)).expect("V");
            let mut mesh = coarse.clone();
            let mut angles = Vec::new();
            for _ in 0..3 {
                mesh = sqrt3_refine(&mesh).expect("refines").mesh;
                let centre = kobbelt_limit(&mesh, v);
                let ring: Vec<[f64; 3]> = neighbours(&mesh, v)
                    .iter()
                    .map(|&e| sub(kobbelt_limit(&mesh, e as usize), centre))
                    .collect();
                let ring_normal = ring
                    .windows(2)
                    .fold([0.0; 3], |acc, w| add(acc, cross(w[0], w[1])));
                angles.push(angle(ring_normal, normal));
            }
            println!(
                "K = {k}: angles {angles:?}, cross eigenvalue {}",
                masks.across
            );
            assert!(
                angles[1] < angles[0] && angles[2] < angles[1],
                "K = {k}: {angles:?}"
            );
        }
    }

    /// Affine functions are reproduced: on a lattice torus whose positions are the lattice
    /// coordinates, every new vertex sits at its level-1 lattice point (away from the seams,
    /// where the positions do not wrap).
    #[test]
    fn a_flat_lattice_refines_onto_the_ternary_lattice() {
        let m = 9i64;
        let torus = lattice_torus(m, |a, b| [a as f64, b as f64, 2.0 * a as f64 - b as f64]);
        let r = sqrt3_refine(&torus).expect("refines").mesh;
        assert_eq!(r.faces(), 9 * torus.faces());
        assert_eq!(r.euler_characteristic(), 0);
        let mut checked = 0;
        for f in 0..torus.faces() {
            let c: Vec<[f64; 3]> = torus
                .face(f)
                .iter()
                .map(|&v| torus.positions[v as usize])
                .collect();
            if c.iter()
                .any(|q| q[0] < 2.0 || q[0] > 6.0 || q[1] < 2.0 || q[1] > 6.0)
            {
                continue;
            }
            for g in 9 * f..9 * f + 9 {
                let children = r.face(g);
                for (corner, (s, t)) in children.iter().zip([(0, 0), (1, 0), (0, 1)]) {
                    let (u, v) = crate::scheme::triangle::split::ternary_child_to_parent(
                        (g % 9) as u8,
                        s,
                        t,
                        1,
                    );
                    let (u, v) = (f64::from(u) / 3.0, f64::from(v) / 3.0);
                    let want: Vec<f64> = (0..3)
                        .map(|x| c[0][x] + u * (c[1][x] - c[0][x]) + v * (c[2][x] - c[0][x]))
                        .collect();
                    let got = r.positions[*corner as usize];
                    for x in 0..3 {
                        assert!((got[x] - want[x]).abs() < 1e-12, "face {f} child {g}");
                    }
                }
            }
            checked += 1;
        }
        assert!(checked > 10, "{checked} faces checked");
    }

    /// The limit position is the same before and after a step (it is what the step converges
    /// to), for every vertex of the octahedron (valence 4) and for the new regular ones.
    #[test]
    fn the_limit_position_is_invariant_under_the_step() {
        let coarse = octahedron();
        let fine = sqrt3_refine(&coarse).expect("refines").mesh;
        let finer = sqrt3_refine(&fine).expect("refines").mesh;
        for (m, n) in [(&coarse, &fine), (&fine, &finer)] {
            for v in 0..m.positions.len() {
                let (a, b) = (kobbelt_limit(m, v), kobbelt_limit(n, v));
                for x in 0..3 {
                    assert!((a[x] - b[x]).abs() < 1e-14, "vertex {v}: {a:?} {b:?}");
                }
            }
        }
        for v in 0..fine.positions.len() {
            let k = fine.fan_iter(v).count();
            assert_eq!(k, if v < 6 { 4 } else { 6 }, "vertex {v}");
        }
    }
}
