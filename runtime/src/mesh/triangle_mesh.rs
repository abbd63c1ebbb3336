//! The tessellators' output: an indexed triangle mesh with normals and, per vertex, the face and
//! exact rational parameters it was evaluated at.

use std::collections::HashSet;

pub use crate::mesh::VertexSource;

/// An indexed triangle mesh: limit positions, unit normals, sources, triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Limit positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals (from the tangent stencils); zero where the tangents are degenerate.
    pub normals: Vec<[f32; 3]>,
    /// Where each vertex was evaluated (same length as `positions`).
    pub sources: Vec<VertexSource>,
    /// Triangles, counter-clockwise seen from outside (for counter-clockwise input faces).
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, one per vertex, or empty for none.
    pub uvs: Vec<[f32; 2]>,
    /// Vertices that repeat another's position across a texture seam, `[copy, original]`:
    /// split for their texture coordinates only, the same position bits.
    pub seam_copies: Vec<[u32; 2]>,
}

impl TriangleMesh {
    /// Whether every edge is shared by exactly two triangles that traverse it in opposite
    /// directions (a closed, consistently oriented, edge-manifold surface), in positions: a
    /// vertex split along a texture seam counts as its original ([`TriangleMesh::seam_copies`]).
    pub fn is_watertight(&self) -> bool {
        let directed = match self.directed_edges() {
            Some(d) => d,
            None => return false,
        };
        directed.iter().all(|&(a, b)| directed.contains(&(b, a)))
    }

    /// The boundary edges (directed edges without an opposite one), or `None` when some directed
    /// edge is used twice (inconsistent orientation or a non-manifold edge).
    pub fn boundary_edges(&self) -> Option<Vec<(u32, u32)>> {
        let directed = self.directed_edges()?;
        let mut out: Vec<(u32, u32)> = directed
            .iter()
            .filter(|&&(a, b)| !directed.contains(&(b, a)))
            .copied()
            .collect();
        out.sort_unstable();
        Some(out)
    }

    /// Every vertex's position vertex: itself, or the original of a seam copy.
    fn position_vertices(&self) -> Vec<u32> {
        let mut of: Vec<u32> = (0..self.positions.len() as u32).collect();
        for &[copy, original] in &self.seam_copies {
            if let Some(slot) = of.get_mut(copy as usize) {
                *slot = original;
            }
        }
        of
    }

    fn directed_edges(&self) -> Option<HashSet<(u32, u32)>> {
        let of = self.position_vertices();
        let at = |i: u32| of.get(i as usize).copied().unwrap_or(i);
        let mut directed = HashSet::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            for k in 0..3 {
                if !directed.insert((at(t[k]), at(t[(k + 1) % 3]))) {
                    return None;
                }
            }
        }
        Some(directed)
    }

    /// Euler characteristic `V - E + F` of the triangle mesh.
    pub fn euler_characteristic(&self) -> i64 {
        let mut edges = HashSet::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        self.positions.len() as i64 - edges.len() as i64 + self.triangles.len() as i64
    }
}
