//! Isolation for Loop: at most one whole-mesh Loop step, so that every triangle is a table
//! patch, with every refined triangle remembering where it lies in the input triangle.
//!
//! A triangle with two irregular corners, or with an interior irregular corner and a boundary
//! corner, has no table patch. One Loop step separates them: the input vertices keep their
//! valences and every new vertex is regular (interior valence 6, or on the boundary with three
//! triangles), and no two input vertices share a refined triangle. The refined mesh is checked
//! anyway; a triangle that still has no patch is an error naming it.

use crate::loop_refine::{child_to_parent, loop_refine};
use crate::topology::Mesh;
use crate::triangle_mesh::VertexSource;
use crate::triangle_patch::{gather_triangle_patches, TrianglePatch};
use crate::triangle_topology::{isolation_defect, require_triangles};
use crate::{MeshError, RuntimeError};

/// An isolated triangle mesh and where its triangles come from.
#[derive(Clone, Debug)]
pub struct LoopIsolation {
    /// The (possibly refined) mesh, every triangle a table patch.
    pub mesh: Mesh,
    /// The patch of every triangle.
    pub patches: Vec<TrianglePatch>,
    /// Loop steps taken (0 or 1).
    pub steps: usize,
    /// The input triangle every triangle of `mesh` lies in.
    pub origin: Vec<u32>,
    /// Which child of its input triangle every triangle is (`crate::loop_refine` numbering;
    /// 0 when no step was taken).
    pub child: Vec<u8>,
}

impl LoopIsolation {
    /// The input triangle and its own barycentric parameters of a point given on triangle
    /// `source.face` of the isolated mesh, exactly (the child's domain is an affine image of
    /// the parent's: [`child_to_parent`]; the denominator doubles).
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        if self.steps == 0 {
            return source;
        }
        let f = source.face as usize;
        let (u, v) = child_to_parent(self.child[f], source.u, source.v, source.denominator);
        VertexSource {
            face: self.origin[f],
            u,
            v,
            denominator: 2 * source.denominator,
            subface: 0,
        }
    }
}

/// Check that `mesh` is a Loop mesh the tables can evaluate (triangles only; with
/// "edge and corner" boundaries no one-triangle corner, since Loop's boundary rule here pins
/// nothing), refine it once if some triangle needs it, and gather every triangle's patch.
pub fn isolate_loop(mesh: &Mesh) -> Result<LoopIsolation, RuntimeError> {
    require_triangles(mesh)?;
    if mesh.boundary == schemes::BoundaryMode::EdgeAndCorner {
        if let Some(v) = (0..mesh.positions.len())
            .find(|&v| mesh.is_boundary_vertex(v) && mesh.fan(v).len() == 1)
        {
            return Err(RuntimeError::Unsupported(format!(
                "`interpolateboundary 1` (pinned corners) with Loop: vertex {v} is a one-triangle corner, and the Loop tables smooth every boundary vertex by (1, 6, 1)/8"
            )));
        }
    }
    let faces = mesh.faces();
    // A triangle can also lack a patch with no irregular corner in the way (a boundary that
    // cuts through a neighbourhood, e.g. a one-triangle-wide strip): one step may fix that too,
    // and if it does not, the refined mesh's error names the triangle.
    if isolation_defect(mesh).is_none() {
        if let Ok(patches) = gather_triangle_patches(mesh) {
            return Ok(LoopIsolation {
                patches,
                mesh: mesh.clone(),
                steps: 0,
                origin: (0..faces as u32).collect(),
                child: vec![0; faces],
            });
        }
    }
    let refined = loop_refine(mesh)?.mesh;
    if let Some((face, reason)) = isolation_defect(&refined) {
        return Err(MeshError::NotIsolated { face, reason }.into());
    }
    Ok(LoopIsolation {
        patches: gather_triangle_patches(&refined)?,
        mesh: refined,
        steps: 1,
        origin: (0..4 * faces as u32).map(|f| f / 4).collect(),
        child: (0..4 * faces).map(|f| (f % 4) as u8).collect(),
    })
}
