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

/// Refine the closed triangle mesh `mesh` by two √3 steps, one ternary step (module docs).
pub fn sqrt3_refine(mesh: &Mesh) -> Result<Mesh, RuntimeError> {
    require_closed_triangles(mesh, "sqrt3")?;
    let p = &mesh.positions;
    let nv = p.len();
    let centroid: Vec<[f64; 3]> = (0..mesh.faces())
        .map(|f| {
            let sum = mesh
                .face(f)
                .iter()
                .fold([0.0; 3], |acc, &v| add(acc, p[v as usize]));
            scale(1.0 / 3.0, sum)
        })
        .collect();
    // The old vertices after the first step, and after the second.
    let mut half = Vec::with_capacity(nv);
    let mut positions = Vec::with_capacity(nv + 3 * mesh.faces());
    for v in 0..nv {
        let fan = mesh.fan(v);
        let k = fan.len();
        let alpha = sqrt3_alpha(k);
        let ring = neighbours(mesh, v)
            .iter()
            .fold([0.0; 3], |acc, &e| add(acc, p[e as usize]));
        let h = add(scale(1.0 - alpha, p[v]), scale(alpha / k as f64, ring));
        let centroids = fan.iter().fold([0.0; 3], |acc, &g| {
            add(acc, centroid[mesh.face_of[g] as usize])
        });
        positions.push(add(
            scale(1.0 - alpha, h),
            scale(alpha / k as f64, centroids),
        ));
        half.push(h);
    }
    let split = TriangleSplit::new(mesh);
    for (&[a, b], &h) in split.edges.iter().zip(&split.first_halfedge) {
        let h = h as usize;
        let across = add(
            centroid[mesh.face_of[h] as usize],
            centroid[mesh.face_of[mesh.twin[h] as usize] as usize],
        );
        for end in [a, b] {
            positions.push(scale(1.0 / 3.0, add(half[end as usize], across)));
        }
    }
    for f in 0..mesh.faces() {
        let ring = mesh.face_halfedges(f).fold([0.0; 3], |acc, h| {
            let g = mesh.face_of[mesh.twin[h] as usize] as usize;
            add(acc, add(half[mesh.face_vertices[h] as usize], centroid[g]))
        });
        positions.push(add(scale(2.0 / 3.0, centroid[f]), scale(1.0 / 18.0, ring)));
    }
    let faces = split.ternary_child_faces(mesh, nv);
    Ok(Mesh::new(positions, &faces, &[], mesh.boundary)?)
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
        let r = sqrt3_refine(&torus).expect("refines");
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
        let fine = sqrt3_refine(&coarse).expect("refines");
        let finer = sqrt3_refine(&fine).expect("refines");
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
