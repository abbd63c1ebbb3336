//! Isolation: Catmull–Clark steps until every face is a table patch (a quad with at most one
//! irregular corner, and no interior irregular corner next to the boundary).
//!
//! This first version refines the whole mesh (one step makes every face a quad, a second
//! separates irregular vertices); the rate then applies to the faces of the refined mesh.
//! Refining only the faces that need it, keeping the original faces' parameterization, is the
//! next step.

use crate::dual_grid::gather_patches;
use crate::patch::FacePatch;
use crate::refine::refine;
use crate::topology::Mesh;
use crate::MeshError;

/// At most this many steps are tried (two always suffice for a valid mesh).
pub const MAX_STEPS: usize = 3;

/// The isolated mesh, its patches and the number of refinement steps taken.
pub fn isolate(mesh: &Mesh) -> Result<(Mesh, Vec<FacePatch>, usize), MeshError> {
    let mut current = mesh.clone();
    for steps in 0..=MAX_STEPS {
        match gather_patches(&current) {
            Ok(patches) => return Ok((current, patches, steps)),
            Err(e) if steps == MAX_STEPS => return Err(e),
            Err(_) => current = refine(&current).mesh,
        }
    }
    unreachable!("the loop returns at its last step")
}
