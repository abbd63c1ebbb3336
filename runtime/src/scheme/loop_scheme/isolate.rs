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
        |m| Ok(loop_refine(m)?.mesh),
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
