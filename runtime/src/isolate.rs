//! Isolation: Catmull–Clark steps until every face is a table patch (a quad with at most one
//! irregular corner, and no interior irregular corner next to the boundary).
//!
//! This version refines the whole mesh (one step makes every face a quad, a second separates
//! irregular vertices); rates then apply to the faces of the refined mesh, and every refined face
//! remembers the input face it lies in ([`Isolation::origin`]).

use crate::dual_grid::gather_patches;
use crate::patch::FacePatch;
use crate::refine::refine;
use crate::topology::Mesh;
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
}

/// Refine until every face is a patch; keeps the face ancestry. A refinement step turns face `f`
/// into one quad per corner, numbered by the face's half-edges (`refine.rs`), so a child's parent
/// is the face of its half-edge.
pub fn isolate_with_origins(mesh: &Mesh) -> Result<Isolation, MeshError> {
    let mut current = mesh.clone();
    let mut origin: Vec<u32> = (0..mesh.faces() as u32).collect();
    for steps in 0..=MAX_STEPS {
        match gather_patches(&current) {
            Ok(patches) => {
                return Ok(Isolation {
                    mesh: current,
                    patches,
                    steps,
                    origin,
                })
            }
            Err(e) if steps == MAX_STEPS => return Err(e),
            Err(_) => {
                origin = current
                    .face_of
                    .iter()
                    .map(|&f| origin[f as usize])
                    .collect();
                current = refine(&current).mesh;
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
