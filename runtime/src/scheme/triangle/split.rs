//! The topology of one uniform split of a triangle mesh, shared by the triangle schemes' whole-
//! mesh refinements (they differ only in where the new points go): the dyadic split, each
//! triangle into four at its edge midpoints (Loop, the butterfly), and the ternary split, each
//! triangle into nine at its edge thirds and centre (two √3 steps, [`crate::scheme::sqrt3::refine`]).
//!
//! # The dyadic split
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
//!
//! # The ternary split
//!
//! New vertices are the old ones, then two per edge `e` (`2e` nearer the edge's first end
//! [`TriangleSplit::edges`]`[e][0]`, `2e + 1` nearer its second), then one per triangle. In
//! the parent's level-1 coordinates `(i, j)` (`(u, v) = (i, j) / 3`: `c_0 = (0,0)`,
//! `c_1 = (3,0)`, `c_2 = (0,3)`) triangle `f` becomes nine, numbered `9f + c`: the upward
//! triangles `(i,j), (i+1,j), (i,j+1)` at `(i, j) = (0,0), (1,0), (2,0), (0,1), (1,1), (0,2)`
//! for `c = 0..=5`, then the downward ones `(i+1,j+1), (i,j+1), (i+1,j)` at
//! `(i, j) = (0,0), (1,0), (0,1)` for `c = 6, 7, 8` ([`ternary_child_to_parent`]).
//!
//! Row by row from `c_0`'s edge, in the direction of `c_1`: `0 6 1 7 2`, `3 8 4`, `5`.

use crate::mesh::topology::{Mesh, NONE};

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

    /// The nine children of every triangle (ternary split), as vertex lists of the refined mesh
    /// numbered as the module docs say (`vertices`: the coarse vertex count).
    pub fn ternary_child_faces(&self, mesh: &Mesh, vertices: usize) -> Vec<Vec<i64>> {
        let edge_points = vertices + 2 * self.edges.len();
        let mut faces = Vec::with_capacity(9 * mesh.faces());
        for f in 0..mesh.faces() {
            let hs: Vec<usize> = mesh.face_halfedges(f).collect();
            // The third of half-edge `h`'s edge nearer its tail (`near_tail`) or its head.
            let third = |h: usize, near_tail: bool| -> i64 {
                let e = self.edge_of[h] as usize;
                let tail_first = self.edges[e][0] == mesh.face_vertices[h];
                (vertices + 2 * e + usize::from(tail_first != near_tail)) as i64
            };
            let corner = |i: usize| i64::from(mesh.face_vertices[hs[i]]);
            let point = |i: u32, j: u32| -> i64 {
                match (i, j) {
                    (0, 0) => corner(0),
                    (3, 0) => corner(1),
                    (0, 3) => corner(2),
                    (1, 0) => third(hs[0], true),
                    (2, 0) => third(hs[0], false),
                    (2, 1) => third(hs[1], true),
                    (1, 2) => third(hs[1], false),
                    (0, 2) => third(hs[2], true),
                    (0, 1) => third(hs[2], false),
                    _ => (edge_points + f) as i64,
                }
            };
            for &((i, j), down) in &TERNARY_CHILDREN {
                faces.push(if down {
                    vec![point(i + 1, j + 1), point(i, j + 1), point(i + 1, j)]
                } else {
                    vec![point(i, j), point(i + 1, j), point(i, j + 1)]
                });
            }
        }
        faces
    }
}

/// The two uniform splits of a triangle (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Into four at the edge midpoints.
    Dyadic,
    /// Into nine at the edge thirds and the centre.
    Ternary,
}

impl Split {
    /// How many children a triangle has.
    pub fn children(self) -> usize {
        match self {
            Split::Dyadic => 4,
            Split::Ternary => 9,
        }
    }

    /// How much finer a child's parameters are than its parent's.
    pub fn factor(self) -> u32 {
        match self {
            Split::Dyadic => 2,
            Split::Ternary => 3,
        }
    }

    /// The parent's integer barycentric numerators `(u, v)` over `factor * d` of the point
    /// `(s, t) / d` of child `child`, exactly.
    pub fn child_to_parent(self, child: u8, s: u32, t: u32, d: u32) -> (u32, u32) {
        match self {
            Split::Dyadic => child_to_parent(child, s, t, d),
            Split::Ternary => ternary_child_to_parent(child, s, t, d),
        }
    }
}

/// The lower-left level-1 point `(i, j)` of ternary child `c` and whether it points down.
const TERNARY_CHILDREN: [((u32, u32), bool); 9] = [
    ((0, 0), false),
    ((1, 0), false),
    ((2, 0), false),
    ((0, 1), false),
    ((1, 1), false),
    ((0, 2), false),
    ((0, 0), true),
    ((1, 0), true),
    ((0, 1), true),
];

/// The parent's integer barycentric numerators `(u, v)` over `3d` of the point `(s, t) / d` of
/// ternary child `child` (module docs), exactly.
pub fn ternary_child_to_parent(child: u8, s: u32, t: u32, d: u32) -> (u32, u32) {
    match TERNARY_CHILDREN[child as usize % 9] {
        ((i, j), false) => (i * d + s, j * d + t),
        ((i, j), true) => ((i + 1) * d - s, (j + 1) * d - t),
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

    /// The nine ternary children, drawn in the module docs, tile the parent: their corners over
    /// `d = 1` are the level-1 points of the picture, and every child keeps the orientation.
    #[test]
    fn ternary_children_tile_the_parent() {
        let expect = [
            [(0, 0), (1, 0), (0, 1)],
            [(1, 0), (2, 0), (1, 1)],
            [(2, 0), (3, 0), (2, 1)],
            [(0, 1), (1, 1), (0, 2)],
            [(1, 1), (2, 1), (1, 2)],
            [(0, 2), (1, 2), (0, 3)],
            [(1, 1), (0, 1), (1, 0)],
            [(2, 1), (1, 1), (2, 0)],
            [(1, 2), (0, 2), (1, 1)],
        ];
        for (c, corners) in expect.iter().enumerate() {
            let got = [(0, 0), (1, 0), (0, 1)]
                .map(|(s, t)| Split::Ternary.child_to_parent(c as u8, s, t, 1));
            assert_eq!(&got, corners, "child {c}");
            let [a, b, e] = got.map(|(u, v)| (i64::from(u), i64::from(v)));
            let area = (b.0 - a.0) * (e.1 - a.1) - (b.1 - a.1) * (e.0 - a.0);
            assert_eq!(
                area, 1,
                "child {c} keeps the orientation and has 1/9 of the area"
            );
        }
    }
}
