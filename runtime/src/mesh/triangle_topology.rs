//! What triangle schemes (Loop) need of a mesh's topology beyond [`Mesh`]: every face a
//! triangle, one-rings in counter-clockwise order, and which vertices are regular.
//!
//! The half-edge structure and its validation (manifold edges, one fan per vertex) are
//! [`crate::mesh::topology`]'s; this module only reads it. Around a vertex `V` the fan of
//! [`Mesh::fan`] runs counter-clockwise (for counter-clockwise faces), starting on an interior
//! vertex anywhere and on a boundary vertex at the boundary edge leaving `V`; its `i`-th
//! half-edge `V -> E_i` lies in the triangle `(V, E_i, E_{i+1})`, sector `i`.

use crate::mesh::topology::{Mesh, NONE};
use crate::{MeshError, RuntimeError};

/// Refuse a mesh with a face that is not a triangle, naming the face and its vertex count.
pub fn require_triangles(mesh: &Mesh) -> Result<(), MeshError> {
    match (0..mesh.faces()).find(|&f| mesh.face(f).len() != 3) {
        Some(face) => Err(MeshError::NotTriangle {
            face,
            vertices: mesh.face(face).len(),
        }),
        None => Ok(()),
    }
}

/// The neighbours of vertex `v`, counter-clockwise: on an interior vertex its `valence`
/// neighbours starting anywhere, on a boundary vertex with `k` triangles the `k + 1`
/// neighbours `E_0, .., E_k` from the boundary edge leaving `v` to the one entering it.
pub fn neighbours(mesh: &Mesh, v: usize) -> Vec<u32> {
    let fan = mesh.fan(v);
    let mut out: Vec<u32> = fan.iter().map(|&h| mesh.head(h)).collect();
    if let (true, Some(&last)) = (mesh.is_boundary_vertex(v), fan.last()) {
        out.push(mesh.face_vertices[mesh.prev(last)]);
    }
    out
}

/// Refuse a mesh that `scheme` (named in the message) cannot tessellate because it has no
/// boundary patches (the butterfly has no boundary rules either; √3's are in
/// [`crate::scheme::sqrt3::refine`]): not all triangles, or with a boundary edge (named).
pub fn require_closed_triangles(mesh: &Mesh, scheme: &str) -> Result<(), RuntimeError> {
    require_triangles(mesh)?;
    if let Some(h) = mesh.twin.iter().position(|&t| t == NONE) {
        return Err(RuntimeError::Unsupported(format!(
            "edge ({}, {}) is on the boundary, and --scheme {scheme} does not tessellate \
             boundaries yet: it tessellates closed triangle meshes",
            mesh.face_vertices[h],
            mesh.head(h)
        )));
    }
    Ok(())
}

/// The neighbours of the tail of half-edge `h` counter-clockwise from `h`'s head, on a closed
/// mesh (every half-edge has a twin): `E_0 = head(h)`, `E_{i+1}` the head of
/// `twin(prev(.))` of the half-edge to `E_i`.
pub fn ring_from(mesh: &Mesh, h: usize) -> Vec<u32> {
    debug_assert!(
        !mesh.is_boundary_vertex(mesh.face_vertices[h] as usize),
        "ring_from needs an interior vertex"
    );
    let mut ring = vec![mesh.head(h)];
    let mut g = mesh.twin[mesh.prev(h)] as usize;
    while g != h && ring.len() <= mesh.face_vertices.len() {
        ring.push(mesh.head(g));
        g = mesh.twin[mesh.prev(g)] as usize;
    }
    ring
}

/// Whether vertex `v` is regular for Loop: interior of valence 6, or on the boundary with three
/// triangles (where the surface is the quartic box spline, or its boundary restriction).
pub fn is_regular(mesh: &Mesh, v: usize) -> bool {
    let faces = mesh.fan_iter(v).count();
    if mesh.is_boundary_vertex(v) {
        faces == 3
    } else {
        faces == 6
    }
}

/// The first triangle that is not yet a table patch, and why: two irregular corners, or an
/// interior irregular corner and a boundary corner. `None` when every triangle is one.
pub fn isolation_defect(mesh: &Mesh) -> Option<(usize, String)> {
    let regular: Vec<bool> = (0..mesh.positions.len())
        .map(|v| mesh.vertex_halfedge[v] == NONE || is_regular(mesh, v))
        .collect();
    let boundary: Vec<bool> = (0..mesh.positions.len())
        .map(|v| mesh.is_boundary_vertex(v))
        .collect();
    (0..mesh.faces()).find_map(|f| {
        let corners = mesh.face(f);
        let irregular = corners.iter().filter(|&&c| !regular[c as usize]).count();
        let interior_irregular = corners
            .iter()
            .any(|&c| !regular[c as usize] && !boundary[c as usize]);
        let on_boundary = corners.iter().any(|&c| boundary[c as usize]);
        if irregular >= 2 {
            Some((f, format!("{irregular} of its corners are irregular")))
        } else if interior_irregular && on_boundary {
            Some((
                f,
                "an interior irregular corner and a boundary corner".to_owned(),
            ))
        } else {
            None
        }
    })
}

/// `ring` rotated so that it starts at `first` (`None` when `first` is not in it).
pub fn rotate_to(ring: &[u32], first: u32) -> Option<Vec<u32>> {
    let at = ring.iter().position(|&x| x == first)?;
    let mut out = ring[at..].to_vec();
    out.extend_from_slice(&ring[..at]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::BoundaryMode;

    /// Six triangles around vertex 0 (interior, valence 6), rim 1..=6 on the boundary.
    fn hexagon() -> Mesh {
        let mut p = vec![[0.0; 3]];
        for i in 0..6 {
            let a = std::f64::consts::PI / 3.0 * f64::from(i);
            p.push([a.cos(), a.sin(), 0.0]);
        }
        let faces: Vec<Vec<i64>> = (0..6).map(|i| vec![0, 1 + i, 1 + (i + 1) % 6]).collect();
        Mesh::new(p, &faces, &[], BoundaryMode::EdgeOnly).expect("valid fan")
    }

    #[test]
    fn a_hexagon_fan_has_a_regular_centre_and_irregular_rim() {
        let m = hexagon();
        assert!(is_regular(&m, 0));
        // Rim vertices are boundary vertices with two triangles.
        assert!(!is_regular(&m, 1));
        let ring = rotate_to(&neighbours(&m, 0), 1).expect("1 is a neighbour");
        assert_eq!(ring, vec![1, 2, 3, 4, 5, 6]);
        // Boundary vertex 1: E_0 is the head of the boundary edge leaving it (1 -> 2).
        assert_eq!(neighbours(&m, 1), vec![2, 0, 6]);
        // Every triangle has two irregular rim corners.
        assert!(isolation_defect(&m).is_some());
    }

    #[test]
    fn a_ring_from_a_halfedge_runs_counter_clockwise_from_its_head() {
        let m = crate::mesh::test_meshes::octahedron();
        for h in 0..m.face_vertices.len() {
            let v = m.face_vertices[h];
            let want = rotate_to(&neighbours(&m, v as usize), m.head(h)).expect("a neighbour");
            assert_eq!(ring_from(&m, h), want, "half-edge {h}");
        }
    }

    #[test]
    fn a_quad_is_named_with_its_vertex_count() {
        let p = vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let faces = [vec![0, 1, 2], vec![0, 2, 3, 1]];
        let m = Mesh::new(p, &faces, &[], BoundaryMode::EdgeOnly).expect("valid");
        let e = require_triangles(&m).expect_err("a quad");
        assert_eq!(
            e,
            MeshError::NotTriangle {
                face: 1,
                vertices: 4
            }
        );
        assert!(e.to_string().contains("face 1"), "{e}");
        assert!(e.to_string().contains("4 vertices"), "{e}");
    }
}
