//! Isolation for the region schemes (the butterfly, √3): whole-mesh steps until every triangle
//! is a table patch ([`crate::scheme::triangle::region_patch`]), the children tracked by
//! [`crate::scheme::triangle::isolation`].
//!
//! A step keeps every vertex's valence and makes every new vertex regular, so it doubles (the
//! butterfly) or triples (√3's ternary step) the graph distance between extraordinary vertices.
//! A region's layout reaches five rings from its vertex, so two extraordinary vertices need to
//! be about six edges apart: three butterfly steps or two ternary √3 steps for neighbours,
//! fewer for vertices already apart.

use std::collections::BTreeSet;

use crate::mesh::topology::Mesh;
use crate::mesh::triangle_topology::{require_closed_triangles, require_triangles};
use crate::scheme::butterfly::refine::butterfly_refine;
use crate::scheme::sqrt3::boundary_patch::gather_boundary_patches;
use crate::scheme::sqrt3::refine::sqrt3_refine;
use crate::scheme::stencil::Stencil;
use crate::scheme::triangle::isolation::{
    isolate_by_refinement, TriangleIsolation, MAX_ISOLATION_STEPS,
};
use crate::scheme::triangle::patch::Phantoms;
use crate::scheme::triangle::region_patch::{gather_region_patches, RegionCatalogue, RegionScheme};
use crate::scheme::triangle::split::Split;
use crate::RuntimeError;

impl RegionScheme {
    /// How one of the scheme's whole-mesh steps splits a triangle.
    pub fn split(self) -> Split {
        match self {
            RegionScheme::Butterfly => Split::Dyadic,
            RegionScheme::Sqrt3 => Split::Ternary,
        }
    }

    /// At most this many steps are taken: three butterfly steps or two ternary √3 steps separate
    /// neighbouring extraordinary vertices, and one more covers meshes whose small size makes a
    /// chart close on itself. The cap bounds a failing isolation's memory: 4^4 = 256 or
    /// 9^3 = 729 times the input's triangles.
    pub fn max_steps(self) -> usize {
        match self {
            RegionScheme::Butterfly => MAX_ISOLATION_STEPS,
            RegionScheme::Sqrt3 => 3,
        }
    }

    /// One whole-mesh step: a butterfly step, or two √3 steps.
    pub fn refine(self, mesh: &Mesh) -> Result<Mesh, RuntimeError> {
        Ok(self.refine_with_stencil(mesh)?.0)
    }

    /// One whole-mesh step ([`RegionScheme::refine`]) and its rules, rows over `mesh`'s
    /// vertices ([`butterfly_refine`], [`sqrt3_refine`]): what an isolation composes into its
    /// per-frame stencil.
    pub fn refine_with_stencil(self, mesh: &Mesh) -> Result<(Mesh, Stencil<f64>), RuntimeError> {
        match self {
            RegionScheme::Butterfly => {
                let step = butterfly_refine(mesh)?;
                Ok((step.mesh, step.stencil))
            }
            RegionScheme::Sqrt3 => {
                let step = sqrt3_refine(mesh)?;
                Ok((step.mesh, step.stencil))
            }
        }
    }
}

/// Check that `mesh` is a triangle mesh (closed, for the butterfly, which has no boundary rules
/// here), refine it by `scheme` until every triangle is a patch, and gather every triangle's
/// patch: √3's boundary patches ([`gather_boundary_patches`]) first, then the regions.
pub fn isolate_regions(
    mesh: &Mesh,
    scheme: RegionScheme,
) -> Result<TriangleIsolation, RuntimeError> {
    match scheme {
        RegionScheme::Butterfly => require_closed_triangles(mesh, scheme.name())?,
        RegionScheme::Sqrt3 => require_triangles(mesh)?,
    }
    // The interior vertices' valences (a boundary vertex's triangles are boundary patches).
    let valences: BTreeSet<u32> = mesh
        .valences()
        .into_iter()
        .enumerate()
        .filter(|&(v, k)| k != 0 && !mesh.is_boundary_vertex(v))
        .map(|(_, k)| k as u32)
        .collect();
    let catalogue = RegionCatalogue::new(scheme, valences)?;
    isolate_by_refinement(
        mesh,
        scheme.split(),
        scheme.max_steps(),
        |m| scheme.refine_with_stencil(m),
        |m| {
            let claimed = match scheme {
                RegionScheme::Sqrt3 => gather_boundary_patches(m)?,
                RegionScheme::Butterfly => vec![None; m.faces()],
            };
            Ok((
                gather_region_patches(m, &catalogue, claimed)?,
                Phantoms::new(m),
            ))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron, tetrahedron};
    use crate::scheme::triangle::isolation::testing::check_refinement;

    /// For the butterfly and √3: the composed stencil reproduces the isolated positions over
    /// every step, and moved input positions give what isolating the moved mesh gives; a
    /// regular torus takes no step.
    #[test]
    fn the_refinement_stencil_is_the_isolation() {
        for scheme in [RegionScheme::Butterfly, RegionScheme::Sqrt3] {
            let isolate = |m: &Mesh| isolate_regions(m, scheme);
            for (name, mesh) in [("octahedron", octahedron()), ("tetrahedron", tetrahedron())] {
                let name = format!("{name} ({})", scheme.name());
                let steps = check_refinement(&name, &mesh, isolate);
                assert!(steps >= 2, "{name}: {steps} steps");
            }
            let torus = lattice_torus(8, |a, b| [a as f64, b as f64, 0.0]);
            assert_eq!(check_refinement("torus", &torus, isolate), 0);
        }
    }
}
