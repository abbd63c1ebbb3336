//! The dual-grid watertight tessellator (Schaefer–Warren section 5.5), per-face rates, closed
//! meshes.
//!
//! Every face at rate `n` gets the `n x n` dual points `((2i+1)/2n, (2j+1)/2n)` of its
//! parameter domain, evaluated once from the table. Three kinds of polygons connect them:
//!
//! * face interiors: the `(n-1)^2` quads of the dual grid;
//! * edges: the strip between the two faces' dual rows nearest the shared edge, merged by their
//!   parameter along the edge when the two rates differ;
//! * vertices: the polygon of the surrounding faces' dual points nearest the vertex (a v-gon).
//!
//! Each quad and polygon is split into triangles. Every vertex is made exactly once and each
//! polygon refers to it by index, so the output is watertight by construction; nothing is welded
//! by distance. Boundaries (the limit boundary curve) and the fast evaluation path are the next
//! steps; boundary meshes are refused with a clear error until then.

use std::time::Instant;

use rayon::prelude::*;
use table_format::{PointSet, SectionKey, StencilKind};

use crate::patch::{dual_index_in_patch, face_patch, FacePatch};
use crate::stencil_table::StencilTable;
use crate::topology::{Mesh, NONE};
use crate::{MeshError, RuntimeError};

/// A triangle mesh with, per vertex, the face and parameters it was evaluated at.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Limit positions.
    pub positions: Vec<[f64; 3]>,
    /// Unit normals (from the tangent stencils).
    pub normals: Vec<[f64; 3]>,
    /// Source face and `(u, v)` in that face's own parameters.
    pub sources: Vec<(u32, f64, f64)>,
    /// Triangles, counter-clockwise seen from outside (for counter-clockwise input faces).
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Whether every edge is shared by exactly two triangles that traverse it in opposite
    /// directions.
    pub fn is_watertight(&self) -> bool {
        let mut directed = std::collections::HashSet::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            for k in 0..3 {
                if !directed.insert((t[k], t[(k + 1) % 3])) {
                    return false;
                }
            }
        }
        directed.iter().all(|&(a, b)| directed.contains(&(b, a)))
    }

    /// Euler characteristic V - E + F of the triangle mesh.
    pub fn euler_characteristic(&self) -> i64 {
        let mut edges = std::collections::HashSet::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        self.positions.len() as i64 - edges.len() as i64 + self.triangles.len() as i64
    }
}

/// Timings of one tessellation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TessellationTime {
    /// Seconds spent evaluating and connecting (not gathering patches).
    pub seconds: f64,
}

/// Gather the patch of every face; the first face that is not one is an error.
pub fn gather_patches(mesh: &Mesh) -> Result<Vec<FacePatch>, MeshError> {
    (0..mesh.faces()).map(|f| face_patch(mesh, f)).collect()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Tessellate a closed, isolated mesh at rate `n` on every face.
pub fn tessellate_uniform(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    n: u32,
) -> Result<(TriangleMesh, TessellationTime), RuntimeError> {
    tessellate(table, mesh, patches, &vec![n; patches.len()])
}

/// Tessellate a closed, isolated mesh with rate `rates[f]` on face `f` (any rates in the
/// table, not only powers of two). Across an edge between faces of rates `n_a` and `n_b` the
/// strip merges the two dual rows by their parameter along the edge: `n_a + n_b - 2` triangles.
pub fn tessellate(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    rates: &[u32],
) -> Result<(TriangleMesh, TessellationTime), RuntimeError> {
    if rates.len() != patches.len() || rates.contains(&0) {
        return Err(RuntimeError::Unsupported(format!(
            "{} rates for {} faces (every face needs a rate of at least 1)",
            rates.len(),
            patches.len()
        )));
    }
    if let Some(h) = mesh.twin.iter().position(|&t| t == NONE) {
        return Err(RuntimeError::Unsupported(format!(
            "the mesh has a boundary (face {}): the dual-grid tessellator handles closed meshes so far",
            mesh.face_of[h]
        )));
    }
    let started = Instant::now();
    let mut out = TriangleMesh::default();
    let section = |patch: &FacePatch, kind: StencilKind, n: u32| SectionKey {
        kind,
        points: PointSet::Dual,
        boundary: patch.kind.boundary,
        faces: patch.kind.faces,
        sector: patch.kind.sector,
        n,
    };
    // First dual vertex of every face.
    let mut first = Vec::with_capacity(patches.len() + 1);
    first.push(0usize);
    for &n in rates {
        first.push(first[first.len() - 1] + (n * n) as usize);
    }
    // Dual vertices, face by face, in face-local order (j outer): look up every face's
    // sections first (errors surface here), then evaluate the faces in parallel, each into its
    // own slice of the preallocated output.
    let total = first[patches.len()];
    let mut sections = Vec::with_capacity(patches.len());
    for (f, patch) in patches.iter().enumerate() {
        let n = rates[f];
        let nu = n as usize;
        let k = patch.points.len();
        let [pos, du, dv] = [
            StencilKind::Position,
            StencilKind::DerivativeU,
            StencilKind::DerivativeV,
        ]
        .map(|kind| table.weights(&section(patch, kind, n)));
        let (pos, du, dv) = (pos?, du?, dv?);
        if pos.len() != nu * nu * k || du.len() != pos.len() || dv.len() != pos.len() {
            return Err(RuntimeError::LayoutMismatch {
                key: section(patch, StencilKind::Position, n),
                table: pos.len() / (nu * nu),
                patch: k,
            });
        }
        sections.push((pos, du, dv));
    }
    out.positions = vec![[0.0; 3]; total];
    out.normals = vec![[0.0; 3]; total];
    out.sources = vec![(0, 0.0, 0.0); total];
    let mut chunks = Vec::with_capacity(patches.len());
    {
        let (mut positions, mut normals, mut sources) = (
            out.positions.as_mut_slice(),
            out.normals.as_mut_slice(),
            out.sources.as_mut_slice(),
        );
        for &n in rates {
            let size = (n * n) as usize;
            let (p, rest_p) = std::mem::take(&mut positions).split_at_mut(size);
            let (q, rest_q) = std::mem::take(&mut normals).split_at_mut(size);
            let (r, rest_r) = std::mem::take(&mut sources).split_at_mut(size);
            chunks.push((p, q, r));
            (positions, normals, sources) = (rest_p, rest_q, rest_r);
        }
    }
    chunks
        .into_par_iter()
        .enumerate()
        .for_each(|(f, (positions, normals, sources))| {
            let patch = &patches[f];
            let (pos, du, dv) = sections[f];
            let n = rates[f];
            let nu = n as usize;
            let k = patch.points.len();
            // The patch's control points, gathered once.
            let control: Vec<[f64; 3]> = patch
                .points
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect();
            let d = f64::from(2 * n);
            for j in 0..nu {
                for i in 0..nu {
                    let (pi, pj) = dual_index_in_patch(patch.corner, i, j, nu);
                    let row = (pj * nu + pi) * k;
                    let (wp, wu, wv) = (&pos[row..row + k], &du[row..row + k], &dv[row..row + k]);
                    let mut p = [[0.0f64; 3]; 3];
                    for l in 0..k {
                        let q = control[l];
                        let (a, b, c) = (f64::from(wp[l]), f64::from(wu[l]), f64::from(wv[l]));
                        for x in 0..3 {
                            p[0][x] += a * q[x];
                            p[1][x] += b * q[x];
                            p[2][x] += c * q[x];
                        }
                    }
                    let normal = cross(p[1], p[2]);
                    let length = (normal.iter().map(|x| x * x).sum::<f64>()).sqrt();
                    let at = j * nu + i;
                    positions[at] = p[0];
                    normals[at] = if length > 0.0 {
                        normal.map(|x| x / length)
                    } else {
                        [0.0; 3]
                    };
                    sources[at] = (
                        f as u32,
                        f64::from(2 * i as u32 + 1) / d,
                        f64::from(2 * j as u32 + 1) / d,
                    );
                }
            }
        });
    let rate = |f: usize| rates[f] as usize;
    let interior: usize = rates.iter().map(|&n| 2 * (n as usize - 1).pow(2)).sum();
    out.triangles
        .reserve(interior + 2 * total + 2 * mesh.face_vertices.len());
    let vertex = |f: usize, i: usize, j: usize| (first[f] + j * rate(f) + i) as u32;
    // Face interiors.
    for f in 0..patches.len() {
        let nu = rate(f);
        for j in 0..nu - 1 {
            for i in 0..nu - 1 {
                let (a, b, c, d) = (
                    vertex(f, i, j),
                    vertex(f, i + 1, j),
                    vertex(f, i + 1, j + 1),
                    vertex(f, i, j + 1),
                );
                out.triangles.push([a, b, c]);
                out.triangles.push([a, c, d]);
            }
        }
    }
    // The dual row of face f nearest its side `side`, in the side's direction.
    let row = |f: usize, side: usize| -> Vec<u32> {
        let nu = rate(f);
        (0..nu)
            .map(|t| match side {
                0 => vertex(f, t, 0),
                1 => vertex(f, nu - 1, t),
                2 => vertex(f, nu - 1 - t, nu - 1),
                _ => vertex(f, 0, nu - 1 - t),
            })
            .collect()
    };
    // Edge strips, each edge once (from its lower half-edge). Both rows run along the edge;
    // point t of a row of n points sits at (2t + 1)/2n, so comparing (2t + 1) n_other orders them.
    for h in 0..mesh.face_vertices.len() {
        let t = mesh.twin[h] as usize;
        if t < h {
            continue;
        }
        let (f, g) = (mesh.face_of[h] as usize, mesh.face_of[t] as usize);
        let a = row(f, h - mesh.face_halfedges(f).start);
        let mut b = row(g, t - mesh.face_halfedges(g).start);
        b.reverse();
        let (na, nb) = (a.len(), b.len());
        let (mut i, mut j) = (0, 0);
        while i + 1 < na || j + 1 < nb {
            let advance_a =
                j + 1 == nb || (i + 1 < na && (2 * (i + 1) + 1) * nb <= (2 * (j + 1) + 1) * na);
            if advance_a {
                out.triangles.push([b[j], a[i + 1], a[i]]);
                i += 1;
            } else {
                out.triangles.push([b[j], b[j + 1], a[i]]);
                j += 1;
            }
        }
    }
    // Vertex polygons: the corner dual points of the faces around each vertex, in fan order.
    let corner_point = |f: usize, corner: usize| {
        let last = rate(f) - 1;
        match corner {
            0 => vertex(f, 0, 0),
            1 => vertex(f, last, 0),
            2 => vertex(f, last, last),
            _ => vertex(f, 0, last),
        }
    };
    for v in 0..mesh.positions.len() {
        let polygon: Vec<u32> = mesh
            .fan(v)
            .into_iter()
            .map(|h| {
                let f = mesh.face_of[h] as usize;
                corner_point(f, h - mesh.face_halfedges(f).start)
            })
            .collect();
        for i in 1..polygon.len().saturating_sub(1) {
            out.triangles.push([polygon[0], polygon[i], polygon[i + 1]]);
        }
    }
    Ok((
        out,
        TessellationTime {
            seconds: started.elapsed().as_secs_f64(),
        },
    ))
}
