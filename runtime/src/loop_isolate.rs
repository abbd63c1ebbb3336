//! Isolation for Loop: one whole-mesh Loop step where some triangle is not a table patch, with
//! every refined triangle remembering where it lies in the input triangle.
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
//! with phantom points ([`crate::triangle_patch::Phantoms`]).

use crate::loop_refine::{child_to_parent, loop_refine};
use crate::topology::Mesh;
use crate::triangle_mesh::VertexSource;
use crate::triangle_patch::{gather_triangle_patches, Phantoms, TrianglePatch};
use crate::triangle_topology::{isolation_defect, require_triangles};
use crate::{MeshError, RuntimeError};

/// At most this many Loop steps are taken: one separates the irregular vertices.
pub const MAX_LOOP_STEPS: usize = 1;

/// An isolated triangle mesh and where its triangles come from.
#[derive(Clone, Debug)]
pub struct LoopIsolation {
    /// The (possibly refined) mesh, every triangle a table patch.
    pub mesh: Mesh,
    /// The patch of every triangle.
    pub patches: Vec<TrianglePatch>,
    /// The phantom points some patches read (control points numbered after the mesh's
    /// vertices).
    pub phantoms: Phantoms,
    /// Loop steps taken.
    pub steps: usize,
    /// The input triangle every triangle of `mesh` lies in.
    pub origin: Vec<u32>,
    /// For every triangle of `mesh`, which child of its parent it is (`crate::loop_refine`
    /// numbering), one per step, the first for the step from the input mesh.
    pub child: Vec<[u8; MAX_LOOP_STEPS]>,
}

impl LoopIsolation {
    /// The input triangle and its own barycentric parameters of a point given on triangle
    /// `source.face` of the isolated mesh, exactly: a child's domain is an affine image of its
    /// parent's ([`child_to_parent`]), so the denominator doubles per step.
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        let f = source.face as usize;
        let (mut u, mut v, mut d) = (source.u, source.v, source.denominator);
        for level in (0..self.steps).rev() {
            (u, v) = child_to_parent(self.child[f][level], u, v, d);
            d *= 2;
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

/// Check that `mesh` is a Loop mesh the tables can evaluate (triangles only), refine it if some
/// triangle needs it, and gather every triangle's patch.
pub fn isolate_loop(mesh: &Mesh) -> Result<LoopIsolation, RuntimeError> {
    require_triangles(mesh)?;
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    let mut child = vec![[0u8; MAX_LOOP_STEPS]; mesh.faces()];
    for steps in 0..=MAX_LOOP_STEPS {
        let phantoms = Phantoms::new(&current);
        let attempt = match isolation_defect(&current) {
            Some((face, reason)) => Err(MeshError::NotIsolated { face, reason }),
            None => gather_triangle_patches(&current, &phantoms),
        };
        match attempt {
            Ok(patches) => {
                return Ok(LoopIsolation {
                    mesh: current,
                    patches,
                    phantoms,
                    steps,
                    origin,
                    child,
                })
            }
            Err(e) if steps == MAX_LOOP_STEPS => return Err(e.into()),
            Err(_) => {
                // Triangle f's children are 4f .. 4f + 3.
                let faces = current.faces();
                origin = (0..4 * faces).map(|c| origin[c / 4]).collect();
                child = (0..4 * faces)
                    .map(|c| {
                        let mut path = child[c / 4];
                        path[steps] = (c % 4) as u8;
                        path
                    })
                    .collect();
                current = loop_refine(&current)?.mesh;
            }
        }
    }
    Err(RuntimeError::Unsupported(
        "isolation ended without a result".to_owned(),
    ))
}
