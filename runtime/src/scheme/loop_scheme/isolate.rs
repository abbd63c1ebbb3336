//! Isolation for Loop: one whole-mesh Loop step where some triangle is not a table patch
//! ([`crate::scheme::triangle::isolation`] keeps track of the children).
//!
//! A triangle with two irregular corners, or with an interior irregular corner and a boundary
//! corner, has no table patch. One Loop step separates them: the input vertices keep their
//! valences, every new vertex is regular (interior valence 6, or on the boundary with three
//! triangles), and no two input vertices share a refined triangle. The refined mesh is checked
//! anyway; a triangle that still has no patch is an error naming it.
//!
//! Next to a boundary corner with one triangle (an "ear") every Loop step leaves a triangle with
//! two boundary corners joined by an interior edge, which no boundary layout (a half-plane
//! around one boundary vertex) describes; its corners are regular, so it is the regular patch
//! with phantom points ([`crate::scheme::triangle::patch::Phantoms`]).

use crate::mesh::topology::Mesh;
use crate::mesh::triangle_topology::{isolation_defect, require_triangles};
use crate::scheme::loop_scheme::refine::loop_refine;
use crate::scheme::triangle::isolation::{isolate_by_refinement, TriangleIsolation};
use crate::scheme::triangle::patch::{gather_triangle_patches, Phantoms};
use crate::scheme::triangle::split::Split;
use crate::MeshError;
use crate::RuntimeError;

/// At most this many Loop steps are taken: one separates the irregular vertices.
pub const MAX_LOOP_STEPS: usize = 1;

/// Check that `mesh` is a Loop mesh the tables can evaluate (triangles only), refine it if some
/// triangle needs it, and gather every triangle's patch.
pub fn isolate_loop(mesh: &Mesh) -> Result<TriangleIsolation, RuntimeError> {
    require_triangles(mesh)?;
    isolate_by_refinement(
        mesh,
        Split::Dyadic,
        MAX_LOOP_STEPS,
        |m| {
            let step = loop_refine(m)?;
            Ok((step.mesh, step.stencil))
        },
        |m| {
            let phantoms = Phantoms::new(m);
            if let Some((face, reason)) = isolation_defect(m) {
                return Err(MeshError::NotIsolated { face, reason }.into());
            }
            let patches = gather_triangle_patches(m, &phantoms)?;
            Ok((patches, phantoms))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron, tetrahedron};
    use crate::scheme::triangle::isolation::testing::check_refinement;
    use schemes::BoundaryMode;

    /// The octahedron without its face `(0, 2, 4)`: a boundary triangle loop, interior
    /// vertices of valence 4 and boundary corners with two and three triangles.
    fn open_octahedron() -> Mesh {
        let o = octahedron();
        let faces: Vec<Vec<i64>> = (1..o.faces())
            .map(|f| o.face(f).iter().map(|&v| i64::from(v)).collect())
            .collect();
        Mesh::new(o.positions.clone(), &faces, &[], BoundaryMode::EdgeOnly).expect("valid")
    }

    /// The composed stencil reproduces the isolated positions, and moved input positions give
    /// what isolating the moved mesh gives; a regular torus takes no step (the identity).
    #[test]
    fn the_refinement_stencil_is_the_isolation() {
        for (name, mesh) in [
            ("octahedron", octahedron()),
            ("tetrahedron", tetrahedron()),
            ("open octahedron", open_octahedron()),
        ] {
            assert_eq!(check_refinement(name, &mesh, isolate_loop), 1, "{name}");
        }
        let torus = lattice_torus(6, |a, b| [a as f64, b as f64, (a * b) as f64 * 0.1]);
        assert_eq!(check_refinement("torus", &torus, isolate_loop), 0);
    }
}
