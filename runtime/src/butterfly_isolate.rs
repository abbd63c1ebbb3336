//! Isolation for the butterfly: whole-mesh butterfly steps until every triangle is a table
//! patch ([`crate::butterfly_patch`]), the children tracked by [`crate::triangle_isolation`].
//!
//! A step keeps every vertex's valence and makes every new vertex regular, so it doubles the
//! graph distance between extraordinary vertices. A region's layout reaches about five rings
//! from its vertex, so two extraordinary vertices need to be about six edges apart: three steps
//! for neighbours, fewer for vertices already apart.

use std::collections::BTreeSet;

use crate::butterfly_patch::{gather_butterfly_patches, RegionCatalogue};
use crate::butterfly_refine::{butterfly_refine, require_closed_triangles};
use crate::topology::Mesh;
use crate::triangle_isolation::{isolate_by_refinement, TriangleIsolation, MAX_ISOLATION_STEPS};
use crate::triangle_patch::Phantoms;
use crate::RuntimeError;

/// At most this many butterfly steps are taken (three separate neighbouring extraordinary
/// vertices; one more covers meshes whose small size makes a chart close on itself).
pub const MAX_BUTTERFLY_STEPS: usize = MAX_ISOLATION_STEPS;

/// Check that `mesh` is a closed triangle mesh, refine it until every triangle is a butterfly
/// table patch, and gather every triangle's patch.
pub fn isolate_butterfly(mesh: &Mesh) -> Result<TriangleIsolation, RuntimeError> {
    require_closed_triangles(mesh)?;
    let valences: BTreeSet<u32> = (0..mesh.positions.len())
        .map(|v| mesh.fan(v).len() as u32)
        .filter(|&k| k != 0)
        .collect();
    let catalogue = RegionCatalogue::new(valences)?;
    isolate_by_refinement(
        mesh,
        MAX_BUTTERFLY_STEPS,
        |m| Ok(butterfly_refine(m)?.mesh),
        |m| Ok((gather_butterfly_patches(m, &catalogue)?, Phantoms::new(m))),
    )
}
