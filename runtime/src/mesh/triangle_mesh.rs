//! The tessellators' output: an indexed triangle mesh with normals and, per vertex, the face and
//! exact rational parameters it was evaluated at.

use std::collections::HashSet;

use crate::mesh::watertight::DirectedEdges;
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
    ///
    /// Exact, and linear but for a sort of the edges outside the faces' grids and the strips
    /// between them (`mesh::watertight`).
    pub fn is_watertight(&self) -> bool {
        crate::mesh::watertight::is_closed(&self.triangles, self.positions.len(), &self.seam_copies)
    }

    /// The boundary edges (directed edges without an opposite one), or `None` when some directed
    /// edge is used twice (inconsistent orientation or a non-manifold edge).
    pub fn boundary_edges(&self) -> Option<Vec<(u32, u32)>> {
        let directed = self.directed_edges()?;
        Some(
            directed
                .edges()
                .filter(|&(a, b)| !directed.contains(b, a))
                .collect(),
        )
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

    /// The triangles' directed edges between position vertices, grouped by tail; `None` when
    /// one is used twice or a triangle indexes past the vertices.
    fn directed_edges(&self) -> Option<DirectedEdges> {
        let of = self.position_vertices();
        let n = of.len();
        if self.triangles.iter().flatten().any(|&i| i as usize >= n)
            || of.iter().any(|&o| o as usize >= n)
        {
            return None;
        }
        DirectedEdges::new(n, || {
            self.triangles
                .iter()
                .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
                .map(|(a, b)| (of[a as usize], of[b as usize]))
        })
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
