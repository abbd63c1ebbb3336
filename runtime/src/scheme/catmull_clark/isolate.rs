//! Isolation: Catmull–Clark steps until every face is a table patch (a quad with at most one
//! irregular corner, and no interior irregular corner next to the boundary).
//!
//! This version refines the whole mesh (one step makes every face a quad, a second separates
//! irregular vertices); rates then apply to the faces of the refined mesh, and every refined face
//! remembers the input face it lies in ([`Isolation::origin`]).

use crate::mesh::topology::Mesh;
use crate::mesh::VertexSource;
use crate::scheme::catmull_clark::refine::refine;
use crate::scheme::patch::gather_patches;
use crate::scheme::patch::FacePatch;
use crate::scheme::stencil::Stencil;
use crate::MeshError;

/// At most this many steps are tried (two always suffice for a valid mesh).
pub const MAX_STEPS: usize = 3;

/// An isolated mesh and where its faces come from.
#[derive(Clone, Debug)]
pub struct Isolation {
    /// The refined mesh, every face a table patch.
    pub mesh: Mesh,
    /// The patch of every face.
    pub patches: Vec<FacePatch>,
    /// Refinement steps taken.
    pub steps: usize,
    /// The input face every face of `mesh` lies in.
    pub origin: Vec<u32>,
    /// For every face of `mesh`, the corner of its parent it was made at, one per step (the
    /// first for the step from the input mesh).
    pub corners: Vec<[u8; MAX_STEPS]>,
    /// Number of sides of every input face.
    pub input_sides: Vec<u32>,
    /// Every vertex of `mesh` as a combination of the input mesh's vertices: the refinement
    /// steps composed, so a moved input maps to the isolated control points without refining
    /// again (the identity when no step was taken and no vertex was split).
    pub refinement: Stencil<f64>,
}

impl Isolation {
    /// The input face and its own parameters of a point given on face `source.face` of the
    /// isolated mesh, exactly. Child `c` of a quad covers the quarter at its corner `c` and runs
    /// from that corner (`refine.rs`): its `(s, t)` is the parent's
    /// `(s/2, t/2)`, `(1 - t/2, s/2)`, `(1 - s/2, 1 - t/2)`, `(t/2, 1 - s/2)` for `c = 0..3`, so
    /// the denominator doubles per step. A non-quad input face has no parameterization of its
    /// own: the point is left in the parameters of the sub-face (the quad of the first step at
    /// its corner `subface`), the Ptex / OpenSubdiv convention.
    pub fn input_source(&self, source: VertexSource) -> VertexSource {
        let face = source.face as usize;
        let (mut u, mut v, mut d) = (source.u, source.v, source.denominator);
        let mut subface = 0;
        for level in (0..self.steps).rev() {
            let c = self.corners[face][level];
            if level == 0 && self.input_sides[self.origin[face] as usize] != 4 {
                subface = c;
                break;
            }
            (u, v) = match c {
                0 => (u, v),
                1 => (2 * d - v, u),
                2 => (2 * d - u, 2 * d - v),
                _ => (v, 2 * d - u),
            };
            d *= 2;
        }
        VertexSource {
            face: self.origin[face],
            u,
            v,
            denominator: d,
            subface,
        }
    }
}

/// Refine until every face is a patch; keeps the face ancestry. A refinement step turns face `f`
/// into one quad per corner, numbered by the face's half-edges (`refine.rs`), so a child's parent
/// is the face of its half-edge.
pub fn isolate_with_origins(mesh: &Mesh) -> Result<Isolation, MeshError> {
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    let mut corners = vec![[0u8; MAX_STEPS]; mesh.faces()];
    // Vertices that split non-manifold ones start as copies of their input vertex.
    let mut refinement = Stencil::new(mesh.input_vertices());
    for v in 0..mesh.positions.len() {
        refinement.push_row(vec![(mesh.origin(v) as u32, 1.0)]);
    }
    let input_sides = (0..mesh.faces())
        .map(|f| mesh.face(f).len() as u32)
        .collect();
    for steps in 0..=MAX_STEPS {
        match gather_patches(&current) {
            Ok(patches) => {
                return Ok(Isolation {
                    mesh: current,
                    patches,
                    steps,
                    origin,
                    corners,
                    input_sides,
                    refinement,
                })
            }
            Err(e) if steps == MAX_STEPS => return Err(e),
            Err(_) => {
                // Child h of the refined mesh is made at half-edge h of the current one.
                corners = (0..current.face_vertices.len())
                    .map(|h| {
                        let f = current.face_of[h] as usize;
                        let mut path = corners[f];
                        path[steps] = (h - current.face_halfedges(f).start) as u8;
                        path
                    })
                    .collect();
                origin = current
                    .face_of
                    .iter()
                    .map(|&f| origin[f as usize])
                    .collect();
                let step = refine(&current);
                refinement = refinement.then(&step.stencil);
                current = step.mesh;
            }
        }
    }
    unreachable!("the loop returns at its last step")
}

/// The isolated mesh, its patches and the number of refinement steps taken.
pub fn isolate(mesh: &Mesh) -> Result<(Mesh, Vec<FacePatch>, usize), MeshError> {
    isolate_with_origins(mesh).map(|i| (i.mesh, i.patches, i.steps))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pentagon and a triangle sharing an edge: one step, five quads then three.
    #[test]
    fn origins_follow_the_half_edges() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.5, 1.0, 0.0],
            [0.5, 1.5, 0.0],
            [-0.5, 1.0, 0.0],
            [0.5, -1.0, 0.0],
        ];
        let faces = vec![vec![0, 1, 2, 3, 4], vec![1, 0, 5]];
        let mesh = Mesh::new(p, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("valid");
        let iso = isolate_with_origins(&mesh).expect("isolates");
        assert!(iso.steps >= 1);
        let quads = 8 * 4usize.pow(iso.steps as u32 - 1);
        assert_eq!(iso.origin.len(), quads);
        let fives = iso.origin.iter().filter(|&&f| f == 0).count();
        assert_eq!(fives * 3, (quads - fives) * 5);
    }
}
