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
//!
//! Every weight is rational, so the rules are written once as a [`Stencil`] over any
//! [`Weight`] ([`loop_stencil`]): in `f64` they refine positions ([`loop_refine`]) and make the
//! per-frame stencils, in `BigRational` they give the exact evaluator
//! ([`crate::eval::loop_exact_eval`]) its refined control points.

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::{neighbours, require_triangles};
use crate::scheme::stencil::{Stencil, Weight};
use crate::scheme::triangle::split::TriangleSplit;
use crate::MeshError;

/// The refined mesh, what its edge points were made from, and the step as a linear map.
#[derive(Clone, Debug)]
pub struct LoopRefinement {
    /// The refined mesh (four triangles per triangle, `4f + c` from triangle `f`).
    pub mesh: Mesh,
    /// The end points of the edge of every edge point: refined vertex `coarse + e` sits on
    /// coarse edge `edges[e]` (`coarse` = the coarse vertex count).
    pub edges: Vec<[u32; 2]>,
    /// The step's rules: row `i` is refined vertex `i` over the coarse vertices, so
    /// `stencil.apply(&coarse.positions) == mesh.positions` (how the positions were made).
    pub stencil: Stencil<f64>,
}

/// Loop's vertex weight `beta` for an interior vertex of valence `v` (Warren's weights):
/// `3/16` at `v = 3`, `3/(8v)` otherwise, exact in `W` where `W` holds rationals.
pub fn loop_beta<W: Weight>(valence: usize) -> W {
    let (p, q) = beta_ratio(valence);
    W::ratio(p, q)
}

/// `beta` as the integer ratio `(p, q)`, so that the centre weight `1 - v beta` is the exact
/// ratio `(q - v p, q)` too.
fn beta_ratio(valence: usize) -> (i64, i64) {
    if valence == 3 {
        (3, 16)
    } else {
        (3, 8 * valence as i64)
    }
}

/// One Loop step of the triangle mesh `mesh` as rows over its vertices, in `W`: refined vertex
/// `i` (numbered as [`crate::scheme::triangle::split`] says) is `sum w p_j` over row `i`.
/// Why a map rather than points: the same rules then serve f64 positions, exact evaluation and
/// the composed per-frame stencil of an isolation. Refuses a face that is not a triangle.
pub fn loop_stencil<W: Weight>(mesh: &Mesh) -> Result<Stencil<W>, MeshError> {
    require_triangles(mesh)?;
    Ok(rows(mesh, &TriangleSplit::new(mesh)))
}

/// The rules of the module docs over `split`'s numbering (`mesh` all triangles).
fn rows<W: Weight>(mesh: &Mesh, split: &TriangleSplit) -> Stencil<W> {
    let nv = mesh.positions.len();
    let mut stencil = Stencil::new(nv);
    for v in 0..nv {
        let ring = neighbours(mesh, v);
        let centre = v as u32;
        let row = match (ring.first(), ring.last()) {
            // An unused vertex stays where it is.
            (None, _) | (_, None) => vec![(centre, W::ratio(1, 1))],
            (Some(&a), Some(&b)) if mesh.is_boundary_vertex(v) => vec![
                (a, W::ratio(1, 8)),
                (centre, W::ratio(3, 4)),
                (b, W::ratio(1, 8)),
            ],
            _ => {
                let n = ring.len();
                let (p, q) = beta_ratio(n);
                let mut row = vec![(centre, W::ratio(q - n as i64 * p, q))];
                row.extend(ring.iter().map(|&e| (e, W::ratio(p, q))));
                row
            }
        };
        stencil.push_row(row);
    }
    for &h in &split.first_halfedge {
        let h = h as usize;
        let (a, b) = (mesh.face_vertices[h], mesh.head(h));
        let row = match mesh.twin[h] {
            NONE => vec![(a, W::ratio(1, 2)), (b, W::ratio(1, 2))],
            t => {
                // The vertices opposite the edge in its two triangles.
                let c = mesh.head(mesh.next(h));
                let d = mesh.head(mesh.next(t as usize));
                vec![
                    (a, W::ratio(3, 8)),
                    (b, W::ratio(3, 8)),
                    (c, W::ratio(1, 8)),
                    (d, W::ratio(1, 8)),
                ]
            }
        };
        stencil.push_row(row);
    }
    stencil
}

/// Refine the triangle mesh `mesh` once: the positions are [`loop_stencil`]'s rows applied to
/// the coarse positions, and the rows come back with the mesh.
pub fn loop_refine(mesh: &Mesh) -> Result<LoopRefinement, MeshError> {
    require_triangles(mesh)?;
    let nv = mesh.positions.len();
    let split = TriangleSplit::new(mesh);
    let stencil = rows::<f64>(mesh, &split);
    let positions = stencil.apply(&mesh.positions);
    let faces = split.child_faces(mesh, nv);
    let mesh = Mesh::refined(positions, &faces, &[], mesh.boundary)?;
    Ok(LoopRefinement {
        mesh,
        edges: split.edges,
        stencil,
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

    /// One rule function serves both scalars: the f64 rows are the exact rows rounded, and
    /// every exact row sums to exactly 1 (affine invariance), on a mesh with interior
    /// vertices of valence 3 and 4, boundary vertices and boundary edges (the tetrahedron
    /// without a face, and the closed one).
    #[test]
    fn the_exact_and_f64_rows_are_one_rule() {
        use num_rational::BigRational;
        use num_traits::{One, ToPrimitive};
        let closed = tetrahedron();
        let faces: Vec<Vec<i64>> = (1..closed.faces())
            .map(|f| closed.face(f).iter().map(|&v| i64::from(v)).collect())
            .collect();
        let open = Mesh::new(
            closed.positions.clone(),
            &faces,
            &[],
            BoundaryMode::EdgeOnly,
        )
        .expect("valid");
        for mesh in [closed, open] {
            let exact = loop_stencil::<BigRational>(&mesh).expect("triangles");
            let float = loop_refine(&mesh).expect("refines").stencil;
            assert_eq!(exact.rows(), float.rows());
            for i in 0..exact.rows() {
                let (js, ws) = exact.row(i);
                assert_eq!(js, float.row(i).0, "row {i}");
                let rounded: Vec<f64> = ws.iter().map(|w| w.to_f64().expect("finite")).collect();
                assert_eq!(rounded, float.row(i).1, "row {i}");
                assert_eq!(ws.iter().cloned().sum::<BigRational>(), BigRational::one());
            }
        }
        assert_eq!(loop_beta::<f64>(3), 3.0 / 16.0);
        assert_eq!(
            loop_beta::<BigRational>(5),
            BigRational::new(3.into(), 40.into())
        );
    }
}
