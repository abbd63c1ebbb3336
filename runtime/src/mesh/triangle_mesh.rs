//! The tessellators' output: an indexed triangle mesh with normals and, per vertex, the face and
//! exact rational parameters it was evaluated at.

use std::collections::HashSet;

pub use crate::mesh::VertexSource;

/// Directed edges grouped by tail: the heads of the edges leaving `a` are
/// `heads[start[a]..start[a + 1]]`, sorted.
struct DirectedEdges {
    start: Vec<u32>,
    heads: Vec<u32>,
}

impl DirectedEdges {
    fn leaving(&self, a: u32) -> &[u32] {
        let a = a as usize;
        &self.heads[self.start[a] as usize..self.start[a + 1] as usize]
    }

    fn contains(&self, a: u32, b: u32) -> bool {
        self.leaving(a).binary_search(&b).is_ok()
    }

    /// Every edge, by tail, then head.
    fn edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..self.start.len() as u32 - 1)
            .flat_map(move |a| self.leaving(a).iter().map(move |&b| (a, b)))
    }
}

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
        match self.directed_edges() {
            Some(d) => d.edges().all(|(a, b)| d.contains(b, a)),
            None => false,
        }
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
        if self.triangles.iter().flatten().any(|&i| i as usize >= n) {
            return None;
        }
        // Counting sort by tail: linear, where hashing 3 edges per triangle took seconds for
        // millions of triangles.
        let mut start = vec![0u32; n + 1];
        for t in &self.triangles {
            for &a in t {
                start[of[a as usize] as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut heads = vec![0u32; start[n] as usize];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (of[t[k] as usize] as usize, of[t[(k + 1) % 3] as usize]);
                heads[fill[a] as usize] = b;
                fill[a] += 1;
            }
        }
        for v in 0..n {
            let around = &mut heads[start[v] as usize..start[v + 1] as usize];
            around.sort_unstable();
            if around.windows(2).any(|w| w[0] == w[1]) {
                return None;
            }
        }
        Some(DirectedEdges { start, heads })
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
