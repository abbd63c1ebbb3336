//! Isolation for triangle schemes: whole-mesh refinement steps until every triangle is a table
//! patch, with every refined triangle remembering where it lies in the input triangle.
//!
//! The schemes differ in how they refine ([`crate::scheme::loop_scheme::refine`], [`crate::scheme::butterfly::refine`],
//! [`crate::scheme::sqrt3::refine`]), into four or nine ([`Split`]), and in what makes a triangle a patch
//! ([`crate::scheme::loop_scheme::isolate`], [`crate::scheme::triangle::region_patch`]); the bookkeeping of children and
//! parameters ([`crate::scheme::triangle::split`]) is this module's.

use crate::mesh::topology::Mesh;
use crate::mesh::VertexSource;
use crate::scheme::triangle::patch::{Phantoms, TrianglePatch};
use crate::scheme::triangle::split::Split;
use crate::RuntimeError;

/// The most refinement steps any triangle scheme's isolation takes.
pub const MAX_ISOLATION_STEPS: usize = 4;

/// An isolated triangle mesh and where its triangles come from.
#[derive(Clone, Debug)]
pub struct TriangleIsolation {
    /// The (possibly refined) mesh, every triangle a table patch.
    pub mesh: Mesh,
    /// The patch of every triangle.
    pub patches: Vec<TrianglePatch>,
    /// The phantom points some patches read (control points numbered after the mesh's
    /// vertices).
    pub phantoms: Phantoms,
    /// Refinement steps taken.
    pub steps: usize,
    /// How every step split a triangle.
    pub split: Split,
    /// The input triangle every triangle of `mesh` lies in.
    pub origin: Vec<u32>,
    /// For every triangle of `mesh`, which child of its parent it is ([`crate::scheme::triangle::split`]
    /// numbering), one per step, the first for the step from the input mesh.
    pub child: Vec<[u8; MAX_ISOLATION_STEPS]>,
}

impl TriangleIsolation {
    /// The input triangle and its own barycentric parameters of a point given on triangle
    /// `source.face` of the isolated mesh, exactly: a child's domain is an affine image of its
    /// parent's ([`Split::child_to_parent`]), so the denominator grows by the split's factor
    /// per step.
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        let f = source.face as usize;
        let (mut u, mut v, mut d) = (source.u, source.v, source.denominator);
        for level in (0..self.steps).rev() {
            (u, v) = self.split.child_to_parent(self.child[f][level], u, v, d);
            d *= self.split.factor();
        }
        VertexSource {
            face: self.origin[f],
            u,
            v,
            denominator: d,
            subface: 0,
        }
    }
}

/// Refine `mesh` with `refine` (which splits as `split` says) until `gather` finds every
/// triangle's patch, at most `max_steps` times (`<=` [`MAX_ISOLATION_STEPS`]); the last
/// attempt's error is returned if it never does.
pub fn isolate_by_refinement(
    mesh: &Mesh,
    split: Split,
    max_steps: usize,
    refine: impl Fn(&Mesh) -> Result<Mesh, RuntimeError>,
    gather: impl Fn(&Mesh) -> Result<(Vec<TrianglePatch>, Phantoms), RuntimeError>,
) -> Result<TriangleIsolation, RuntimeError> {
    let max_steps = max_steps.min(MAX_ISOLATION_STEPS);
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    let mut child = vec![[0u8; MAX_ISOLATION_STEPS]; mesh.faces()];
    let mut steps = 0;
    loop {
        match gather(&current) {
            Ok((patches, phantoms)) => {
                return Ok(TriangleIsolation {
                    mesh: current,
                    patches,
                    phantoms,
                    steps,
                    split,
                    origin,
                    child,
                })
            }
            Err(e) if steps == max_steps => return Err(e),
            Err(_) => {
                // Triangle f's children are nf .. nf + n - 1.
                let (faces, n) = (current.faces(), split.children());
                origin = (0..n * faces).map(|c| origin[c / n]).collect();
                child = (0..n * faces)
                    .map(|c| {
                        let mut path = child[c / n];
                        path[steps] = (c % n) as u8;
                        path
                    })
                    .collect();
                current = refine(&current)?;
                steps += 1;
            }
        }
    }
}
