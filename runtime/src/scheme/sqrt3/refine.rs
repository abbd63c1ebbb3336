//! Two uniform steps of √3 subdivision (Kobbelt 2000) on a closed triangle mesh, taken as one
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
//! Old vertices keep their valence; every new vertex has valence 6. Kobbelt's boundary rules
//! (a different step on odd and even levels) are not implemented: a mesh with a boundary is
//! refused.

use schemes::triangle::TriangleVertexRule;

use crate::mesh::geometry::{add, scale};
use crate::mesh::topology::Mesh;
use crate::mesh::triangle_topology::{neighbours, require_closed_triangles};
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

/// Two √3 steps of a closed triangle mesh as one ternary step, and the rules that made it.
#[derive(Clone, Debug)]
pub struct Sqrt3Refinement {
    /// The refined mesh (nine triangles per triangle, `9f + c` from triangle `f`, numbered as
    /// the ternary split of [`crate::scheme::triangle::split`] says).
    pub mesh: Mesh,
    /// The composed step's rules: row `i` is refined vertex `i` over the coarse vertices, so
    /// `stencil.apply(&coarse.positions) == mesh.positions` (how the positions were made).
    pub stencil: Stencil<f64>,
}

/// Two √3 steps of the closed triangle mesh `mesh`, composed, as rows over its vertices (f64:
/// `alpha_k` has a cosine): refined vertex `i`, numbered as the ternary split of
/// [`crate::scheme::triangle::split`] says, is `sum w p_j` over row `i`. Why a map: the same
/// rules then position the refined mesh ([`sqrt3_refine`]) and compose into the per-frame
/// stencil of an isolation. Refuses a boundary.
pub fn sqrt3_stencil(mesh: &Mesh) -> Result<Stencil<f64>, RuntimeError> {
    require_closed_triangles(mesh, "sqrt3")?;
    Ok(rows(mesh, &TriangleSplit::new(mesh)))
}

/// The module docs' two steps over `split`'s ternary numbering (`mesh` closed, all
/// triangles), composed: the first step's points are the old vertices moved (`h_v`, numbered
/// as the vertices) and then every triangle's centroid `c_f` (number `nv + f`); the second
/// step's rows are over those.
fn rows(mesh: &Mesh, split: &TriangleSplit) -> Stencil<f64> {
    let nv = mesh.positions.len();
    let centroid = |f: usize| (nv + f) as u32;
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
        let across = [
            centroid(mesh.face_of[h] as usize),
            centroid(mesh.face_of[mesh.twin[h] as usize] as usize),
        ];
        for end in [a, b] {
            let mut third = vec![(end, 1.0 / 3.0)];
            third.extend(across.iter().map(|&c| (c, 1.0 / 3.0)));
            second.push_row(third);
        }
    }
    for f in 0..mesh.faces() {
        let mut centre = vec![(centroid(f), 2.0 / 3.0)];
        for h in mesh.face_halfedges(f) {
            let g = mesh.face_of[mesh.twin[h] as usize] as usize;
            centre.push((mesh.face_vertices[h], 1.0 / 18.0));
            centre.push((centroid(g), 1.0 / 18.0));
        }
        second.push_row(centre);
    }
    first.then(&second)
}

/// Refine the closed triangle mesh `mesh` by two √3 steps, one ternary step (module docs): the
/// positions are [`sqrt3_stencil`]'s rows applied to the coarse positions, and the rows come
/// back with the mesh.
pub fn sqrt3_refine(mesh: &Mesh) -> Result<Sqrt3Refinement, RuntimeError> {
    require_closed_triangles(mesh, "sqrt3")?;
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
    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron};

    /// Kobbelt's closed form: `alpha_3 = 5/9`, `alpha_4 = 4/9`, `alpha_6 = 1/3`.
    #[test]
    fn alpha_is_kobbelts() {
        for (k, alpha) in [(3, 5.0 / 9.0), (4, 4.0 / 9.0), (6, 1.0 / 3.0)] {
            assert!((sqrt3_alpha(k) - alpha).abs() < 1e-15, "valence {k}");
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
        let limit = |m: &Mesh, v: usize| {
            let ring = neighbours(m, v);
            let sum = ring
                .iter()
                .fold([0.0; 3], |acc, &e| add(acc, m.positions[e as usize]));
            sqrt3_limit_position(
                m.positions[v],
                scale(1.0 / ring.len() as f64, sum),
                ring.len(),
            )
        };
        for (m, n) in [(&coarse, &fine), (&fine, &finer)] {
            for v in 0..m.positions.len() {
                let (a, b) = (limit(m, v), limit(n, v));
                for x in 0..3 {
                    assert!((a[x] - b[x]).abs() < 1e-14, "vertex {v}: {a:?} {b:?}");
                }
            }
        }
        for v in 0..fine.positions.len() {
            let k = fine.fan(v).len();
            assert_eq!(k, if v < 6 { 4 } else { 6 }, "vertex {v}");
        }
    }
}
