//! One uniform Catmull–Clark refinement step on a polygon mesh (Catmull and Clark 1978; the
//! same rules as `schemes::QuadScheme` "catmull-clark", for any valence and any polygon).
//!
//! New vertices are numbered vertex points first (so old vertex `i` becomes new vertex `i`),
//! then one edge point per edge (in order of first appearance), then one face point per face.
//! Face `f` with `k` corners becomes `k` quads, corner `i` giving
//! `(vertex point v_i, edge point (v_i, v_{i+1}), face point f, edge point (v_{i-1}, v_i))`,
//! which keeps the orientation. Rules:
//!
//! * face point: the centroid;
//! * interior edge: `(v_0 + v_1 + f_left + f_right) / 4`; boundary edge: the midpoint;
//! * interior vertex of valence `n`: `(Q + 2R + (n - 3) V) / n` (`Q`: mean of the new face points
//!   around it, `R`: mean of the midpoints of its edges); boundary vertex:
//!   `(E_a + 6 V + E_b) / 8` with its two boundary neighbours, except a vertex with one face in
//!   "edge and corner" mode, which stays put.

use schemes::BoundaryMode;

use crate::mesh::topology::{Mesh, NONE};
use crate::scheme::stencil::{Stencil, Weight};

/// The refined mesh, and for each refined vertex what it was made from.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The refined mesh (all quads).
    pub mesh: Mesh,
    /// Number of vertex points (= the coarse vertex count); edge points follow, then face points.
    pub vertex_points: usize,
    /// Number of edge points.
    pub edge_points: usize,
    /// Every refined vertex as a combination of the coarse ones (the rules above).
    pub stencil: Stencil<f64>,
}

/// The edge numbering of one step: edge points in order of the first half-edge of each edge.
#[derive(Clone, Debug)]
pub struct EdgeIds {
    /// The first half-edge of every edge.
    pub halfedge: Vec<usize>,
    /// The edge of every half-edge.
    pub of_halfedge: Vec<u32>,
}

impl EdgeIds {
    /// Number the edges of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let mut of_halfedge = vec![NONE; mesh.face_vertices.len()];
        let mut halfedge = Vec::new();
        for h in 0..of_halfedge.len() {
            if of_halfedge[h] != NONE {
                continue;
            }
            of_halfedge[h] = halfedge.len() as u32;
            if mesh.twin[h] != NONE {
                of_halfedge[mesh.twin[h] as usize] = halfedge.len() as u32;
            }
            halfedge.push(h);
        }
        EdgeIds {
            halfedge,
            of_halfedge,
        }
    }
}

/// `(index, weight)` terms of the centroid of face `f`, scaled by `s`.
fn face_terms<W: Weight>(mesh: &Mesh, f: usize, s: W, out: &mut Vec<(u32, W)>) {
    let face = mesh.face(f);
    let w = s * W::ratio(1, face.len() as i64);
    out.extend(face.iter().map(|&v| (v, w.clone())));
}

/// Refined vertex `child` of `mesh` (numbered as [`refine`] numbers them) as `(coarse vertex,
/// weight)` terms: the one statement of the Catmull–Clark rules, in any [`Weight`] (f64 for
/// positions and per-frame stencils, rationals for exact evaluation).
pub fn refined_vertex<W: Weight>(mesh: &Mesh, edges: &EdgeIds, child: usize) -> Vec<(u32, W)> {
    let nv = mesh.positions.len();
    let ne = edges.halfedge.len();
    let mut terms = Vec::new();
    if child >= nv + ne {
        face_terms(mesh, child - nv - ne, W::ratio(1, 1), &mut terms);
    } else if child >= nv {
        let h = edges.halfedge[child - nv];
        let (a, b) = (mesh.face_vertices[h], mesh.head(h));
        match mesh.twin[h] {
            NONE => terms.extend([(a, W::ratio(1, 2)), (b, W::ratio(1, 2))]),
            t => {
                terms.extend([(a, W::ratio(1, 4)), (b, W::ratio(1, 4))]);
                face_terms(mesh, mesh.face_of[h] as usize, W::ratio(1, 4), &mut terms);
                face_terms(
                    mesh,
                    mesh.face_of[t as usize] as usize,
                    W::ratio(1, 4),
                    &mut terms,
                );
            }
        }
    } else {
        let v = child;
        let fan = mesh.fan(v);
        let corner = fan.len() == 1 && mesh.boundary == BoundaryMode::EdgeAndCorner;
        if fan.is_empty() || (corner && mesh.is_boundary_vertex(v)) {
            terms.push((v as u32, W::ratio(1, 1)));
        } else if mesh.is_boundary_vertex(v) {
            // Boundary neighbours: the head of the first outgoing edge (no twin) and the tail
            // of the last face's incoming edge.
            let first = mesh.head(fan[0]);
            let last = mesh.face_vertices[mesh.prev(fan[fan.len() - 1])];
            terms.extend([
                (first, W::ratio(1, 8)),
                (last, W::ratio(1, 8)),
                (v as u32, W::ratio(3, 4)),
            ]);
        } else {
            // (Q + 2R + (n - 3) V) / n = (sum F / n + sum (V + E) / n + (n - 3) V) / n.
            let n = fan.len() as i64;
            let nn = n * n;
            terms.push((
                v as u32,
                W::ratio(n - 3, n) + W::ratio(fan.len() as i64, nn),
            ));
            for &h in &fan {
                terms.push((mesh.head(h), W::ratio(1, nn)));
                face_terms(mesh, mesh.face_of[h] as usize, W::ratio(1, nn), &mut terms);
            }
        }
    }
    terms
}

/// Every refined vertex of one step of `mesh` as a combination of its vertices.
pub fn refinement_stencil<W: Weight>(mesh: &Mesh, edges: &EdgeIds) -> Stencil<W> {
    let rows = mesh.positions.len() + edges.halfedge.len() + mesh.faces();
    let mut stencil = Stencil::new(mesh.positions.len());
    for child in 0..rows {
        stencil.push_row(refined_vertex(mesh, edges, child));
    }
    stencil
}

/// Refine `mesh` once.
pub fn refine(mesh: &Mesh) -> Refinement {
    let nv = mesh.positions.len();
    let edges = EdgeIds::new(mesh);
    let ne = edges.halfedge.len();
    let stencil = refinement_stencil::<f64>(mesh, &edges);
    let positions = stencil.apply(&mesh.positions);
    let mut faces = Vec::with_capacity(mesh.face_vertices.len());
    for f in 0..mesh.faces() {
        for h in mesh.face_halfedges(f) {
            let v = i64::from(mesh.face_vertices[h]);
            let e_next = (nv + edges.of_halfedge[h] as usize) as i64;
            let e_prev = (nv + edges.of_halfedge[mesh.prev(h)] as usize) as i64;
            let fp = (nv + ne + f) as i64;
            faces.push(vec![v, e_next, fp, e_prev]);
        }
    }
    let mesh = Mesh::new(positions, &faces, &[], mesh.boundary)
        .unwrap_or_else(|e| unreachable!("refining a valid mesh gives a valid mesh: {e}"));
    Refinement {
        mesh,
        vertex_points: nv,
        edge_points: ne,
        stencil,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_refines_to_the_textbook_counts_and_stays_closed() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let f = vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![1, 2, 6, 5],
            vec![2, 3, 7, 6],
            vec![3, 0, 4, 7],
        ];
        let cube = Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("valid cube");
        let r = refine(&cube);
        assert_eq!((r.mesh.positions.len(), r.mesh.faces()), (26, 24));
        assert_eq!(r.mesh.euler_characteristic(), 2);
        // Vertex point of corner 0 (valence 3): Q = (1/3)(1,1,1) (mean of the three face
        // centroids), R = (1/6)(1,1,1) (mean of the edge midpoints): (Q + 2R)/3 = (2/9)(1,1,1).
        let v0 = r.mesh.positions[0];
        for c in v0 {
            assert!((c - 2.0 / 9.0).abs() < 1e-15, "{v0:?}");
        }
    }
}
