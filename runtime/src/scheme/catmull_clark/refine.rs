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

/// The refined mesh, and for each refined vertex what it was made from.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The refined mesh (all quads).
    pub mesh: Mesh,
    /// Number of vertex points (= the coarse vertex count); edge points follow, then face points.
    pub vertex_points: usize,
    /// Number of edge points.
    pub edge_points: usize,
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Refine `mesh` once.
pub fn refine(mesh: &Mesh) -> Refinement {
    let p = &mesh.positions;
    let nv = p.len();
    let nf = mesh.faces();
    let halfedges = mesh.face_vertices.len();
    let face_points: Vec<[f64; 3]> = (0..nf)
        .map(|f| {
            let face = mesh.face(f);
            let sum = face
                .iter()
                .fold([0.0; 3], |acc, &v| add(acc, p[v as usize]));
            scale(sum, 1.0 / face.len() as f64)
        })
        .collect();
    // Edge ids: one per half-edge pair.
    let mut edge_of = vec![NONE; halfedges];
    let mut edge_points = Vec::new();
    for h in 0..halfedges {
        if edge_of[h] != NONE {
            continue;
        }
        let id = edge_points.len() as u32;
        edge_of[h] = id;
        let (a, b) = (p[mesh.face_vertices[h] as usize], p[mesh.head(h) as usize]);
        let t = mesh.twin[h];
        let point = if t == NONE {
            scale(add(a, b), 0.5)
        } else {
            edge_of[t as usize] = id;
            let fl = face_points[mesh.face_of[h] as usize];
            let fr = face_points[mesh.face_of[t as usize] as usize];
            scale(add(add(a, b), add(fl, fr)), 0.25)
        };
        edge_points.push(point);
    }
    let vertex_points: Vec<[f64; 3]> = (0..nv)
        .map(|v| {
            let fan = mesh.fan(v);
            if fan.is_empty() {
                return p[v];
            }
            if mesh.is_boundary_vertex(v) {
                if fan.len() == 1 && mesh.boundary == BoundaryMode::EdgeAndCorner {
                    return p[v];
                }
                // Boundary neighbours: the head of the first outgoing edge (no twin) and the tail
                // of the last face's incoming edge.
                let first = mesh.head(fan[0]);
                let last = mesh.face_vertices[mesh.prev(fan[fan.len() - 1])];
                let ends = add(p[first as usize], p[last as usize]);
                return scale(add(ends, scale(p[v], 6.0)), 1.0 / 8.0);
            }
            let n = fan.len() as f64;
            let q = fan.iter().fold([0.0; 3], |acc, &h| {
                add(acc, face_points[mesh.face_of[h] as usize])
            });
            let r = fan.iter().fold([0.0; 3], |acc, &h| {
                add(acc, scale(add(p[v], p[mesh.head(h) as usize]), 0.5))
            });
            let (q, r) = (scale(q, 1.0 / n), scale(r, 1.0 / n));
            scale(add(add(q, scale(r, 2.0)), scale(p[v], n - 3.0)), 1.0 / n)
        })
        .collect();
    let ne = edge_points.len();
    let mut positions = vertex_points;
    positions.extend(edge_points);
    positions.extend(face_points);
    let mut faces = Vec::with_capacity(halfedges);
    for f in 0..nf {
        for h in mesh.face_halfedges(f) {
            let v = i64::from(mesh.face_vertices[h]);
            let e_next = (nv + edge_of[h] as usize) as i64;
            let e_prev = (nv + edge_of[mesh.prev(h)] as usize) as i64;
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
