//! The topology of one uniform split of a triangle mesh, each triangle into four at its edge
//! points, shared by Loop's and the butterfly's refinement (they differ only in where the new
//! points go).
//!
//! New vertices are numbered vertex points first (old vertex `i` stays vertex `i`), then one
//! edge point per edge in order of first appearance ([`TriangleSplit::edges`]). Triangle `f`
//! `(c_0, c_1, c_2)` with half-edges `h_i = c_i -> c_{i+1}` becomes four, numbered `4f + c`:
//! the corner triangles `(c_i, e(h_i), e(h_{i-1}))` for `c = i = 0, 1, 2`, then the middle one
//! `(e(h_0), e(h_1), e(h_2))`; all keep the parent's orientation. In the parent's barycentric
//! `(u, v)` (DESIGN.md: `(0,0)` at `c_0`, `(1,0)` at `c_1`, `(0,1)` at `c_2`) a child's own
//! `(s, t)` is, for `c = 0, 1, 2, 3`:
//! `(s/2, t/2)`, `(1 - s/2 - t/2, s/2)`, `(t/2, 1 - s/2 - t/2)`, `(1/2 - t/2, s/2 + t/2)`
//! ([`child_to_parent`]).

use crate::topology::{Mesh, NONE};

/// The edges of a triangle mesh, numbered in order of first appearance over the half-edges.
#[derive(Clone, Debug)]
pub struct TriangleSplit {
    /// The end points of every edge: the tail and head of [`Self::first_halfedge`].
    pub edges: Vec<[u32; 2]>,
    /// The half-edge every edge was first met at.
    pub first_halfedge: Vec<u32>,
    /// The edge of every half-edge.
    pub edge_of: Vec<u32>,
}

impl TriangleSplit {
    /// Number the edges of the triangle mesh `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let halfedges = mesh.face_vertices.len();
        let mut edge_of = vec![NONE; halfedges];
        let mut edges = Vec::new();
        let mut first_halfedge = Vec::new();
        for h in 0..halfedges {
            if edge_of[h] != NONE {
                continue;
            }
            let id = edges.len() as u32;
            edge_of[h] = id;
            if mesh.twin[h] != NONE {
                edge_of[mesh.twin[h] as usize] = id;
            }
            edges.push([mesh.face_vertices[h], mesh.head(h)]);
            first_halfedge.push(h as u32);
        }
        TriangleSplit {
            edges,
            first_halfedge,
            edge_of,
        }
    }

    /// The four children of every triangle, as vertex lists of the refined mesh (`vertices`:
    /// the coarse vertex count, the number of the first edge point).
    pub fn child_faces(&self, mesh: &Mesh, vertices: usize) -> Vec<Vec<i64>> {
        let mut faces = Vec::with_capacity(4 * mesh.faces());
        for f in 0..mesh.faces() {
            let hs: Vec<usize> = mesh.face_halfedges(f).collect();
            let e = |i: usize| (vertices + self.edge_of[hs[i % 3]] as usize) as i64;
            for (i, &h) in hs.iter().enumerate() {
                let c = i64::from(mesh.face_vertices[h]);
                faces.push(vec![c, e(i), e(i + 2)]);
            }
            faces.push(vec![e(0), e(1), e(2)]);
        }
        faces
    }
}

/// The parent's integer barycentric numerators `(u, v)` over `2d` of the point `(s, t) / d` of
/// child `child` (module docs), exactly.
pub fn child_to_parent(child: u8, s: u32, t: u32, d: u32) -> (u32, u32) {
    match child {
        0 => (s, t),
        1 => (2 * d - s - t, s),
        2 => (t, 2 * d - s - t),
        _ => (d - t, s + t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_map_their_corners_onto_the_parents_points() {
        // Child corners (0,0), (1,0), (0,1) over d = 1 land on the parent's corners and edge
        // midpoints (over 2): the child triangles listed in the module docs.
        let expect = [
            [(0, 0), (1, 0), (0, 1)],
            [(2, 0), (1, 1), (1, 0)],
            [(0, 2), (0, 1), (1, 1)],
            [(1, 0), (1, 1), (0, 1)],
        ];
        for (c, corners) in expect.iter().enumerate() {
            let got = [(0, 0), (1, 0), (0, 1)].map(|(s, t)| child_to_parent(c as u8, s, t, 1));
            assert_eq!(&got, corners, "child {c}");
        }
    }
}
