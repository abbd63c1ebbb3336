//! One uniform Loop refinement step on a triangle mesh (Loop 1987, with Warren's weights: the
//! rules of `schemes::TriangleScheme` "loop" that the Loop stencil tables were generated with).
//!
//! The new vertices, the four children of every triangle and their parameters are numbered as
//! [`crate::scheme::triangle::split`] says. Rules:
//!
//! * interior vertex of valence `v`: `(1 - v beta) V + beta sum E_i`, `beta = 3/(8v)` for
//!   `v > 3` and `3/16` for `v = 3`;
//! * boundary vertex (any number of triangles): `(E_a + 6 V + E_b) / 8` with its two boundary
//!   neighbours;
//! * interior edge: `3/8` of each end point and `1/8` of each opposite vertex; boundary edge: the
//!   midpoint.

use crate::mesh::geometry::{add, scale};
use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::{neighbours, require_triangles};
use crate::scheme::triangle::split::TriangleSplit;
use crate::MeshError;

/// The refined mesh and what its edge points were made from.
#[derive(Clone, Debug)]
pub struct LoopRefinement {
    /// The refined mesh (four triangles per triangle, `4f + c` from triangle `f`).
    pub mesh: Mesh,
    /// The end points of the edge of every edge point: refined vertex `coarse + e` sits on
    /// coarse edge `edges[e]` (`coarse` = the coarse vertex count).
    pub edges: Vec<[u32; 2]>,
}

/// Loop's vertex weight `beta` for an interior vertex of valence `v` (Warren's weights).
pub fn loop_beta(valence: usize) -> f64 {
    if valence == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * valence as f64)
    }
}

/// Refine the triangle mesh `mesh` once.
pub fn loop_refine(mesh: &Mesh) -> Result<LoopRefinement, MeshError> {
    require_triangles(mesh)?;
    let p = &mesh.positions;
    let nv = p.len();
    let split = TriangleSplit::new(mesh);
    let edge_points = split.first_halfedge.iter().map(|&h| {
        let h = h as usize;
        let ends = add(p[mesh.face_vertices[h] as usize], p[mesh.head(h) as usize]);
        match mesh.twin[h] {
            NONE => scale(0.5, ends),
            t => {
                // The vertices opposite the edge in its two triangles.
                let c = mesh.head(mesh.next(h)) as usize;
                let d = mesh.head(mesh.next(t as usize)) as usize;
                add(scale(3.0 / 8.0, ends), scale(1.0 / 8.0, add(p[c], p[d])))
            }
        }
    });
    let mut positions: Vec<[f64; 3]> = (0..nv)
        .map(|v| {
            let ring = neighbours(mesh, v);
            if ring.is_empty() {
                return p[v];
            }
            if mesh.is_boundary_vertex(v) {
                let ends = add(p[ring[0] as usize], p[ring[ring.len() - 1] as usize]);
                return add(scale(0.75, p[v]), scale(0.125, ends));
            }
            let beta = loop_beta(ring.len());
            let sum = ring
                .iter()
                .fold([0.0; 3], |acc, &e| add(acc, p[e as usize]));
            add(
                scale(1.0 - ring.len() as f64 * beta, p[v]),
                scale(beta, sum),
            )
        })
        .collect();
    positions.extend(edge_points);
    let faces = split.child_faces(mesh, nv);
    let mesh = Mesh::new(positions, &faces, &[], mesh.boundary)?;
    Ok(LoopRefinement {
        mesh,
        edges: split.edges,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::BoundaryMode;

    fn tetrahedron() -> Mesh {
        let p = vec![
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        let f = vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 1], vec![1, 3, 2]];
        Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("valid tetrahedron")
    }

    /// Expected numbers by hand from the rules in the module docs.
    #[test]
    fn a_tetrahedron_refines_by_the_rules() {
        let t = tetrahedron();
        let r = loop_refine(&t).expect("refines");
        assert_eq!((r.mesh.positions.len(), r.mesh.faces()), (10, 16));
        assert_eq!(r.mesh.euler_characteristic(), 2);
        // Valence 3: beta = 3/16, centre weight 7/16; the neighbours' sum is -V0 = (-1,-1,-1)
        // (the four corners sum to zero): 7/16 - 3/16 = 1/4.
        for c in r.mesh.positions[0] {
            assert!((c - 0.25).abs() < 1e-15);
        }
        // Edge (0, 1): 3/8 (V0 + V1) + 1/8 (V2 + V3) = 3/8 (2,0,0) + 1/8 (-2,0,0) = (1/2, 0, 0).
        let e = r.edges.iter().position(|e| *e == [0, 1]).expect("edge 0-1");
        let q = r.mesh.positions[4 + e];
        assert!((q[0] - 0.5).abs() < 1e-15 && q[1].abs() < 1e-15 && q[2].abs() < 1e-15);
    }

    #[test]
    fn a_single_triangle_keeps_its_boundary_rules() {
        let p = vec![[0.0, 0.0, 0.0], [8.0, 0.0, 0.0], [0.0, 8.0, 0.0]];
        let m = Mesh::new(p, &[vec![0, 1, 2]], &[], BoundaryMode::EdgeOnly).expect("valid");
        let r = loop_refine(&m).expect("refines");
        assert_eq!(r.mesh.boundary_loops(), 1);
        // Corner 0: 3/4 (0,0) + 1/8 ((8,0) + (0,8)) = (1, 1).
        assert_eq!(r.mesh.positions[0], [1.0, 1.0, 0.0]);
        // Boundary edge points are midpoints.
        assert_eq!(r.mesh.positions[3], [4.0, 0.0, 0.0]);
        // Child 3 (the middle) is (e01, e12, e20), child 1 is (c1, e12, e01).
        assert_eq!(r.mesh.face(3), &[3, 4, 5]);
        assert_eq!(r.mesh.face(1), &[1, 4, 3]);
    }
}
