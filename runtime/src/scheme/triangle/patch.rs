//! Which Loop table patch evaluates a triangle, its control points in the table's order, and
//! how the triangle's own grids map onto the patch's.
//!
//! A triangle of an isolated mesh ([`crate::mesh::triangle_topology::isolation_defect`] finds none)
//! is one patch: at a boundary corner if it has one (the irregular one if there is one), else at
//! an interior irregular corner, else the regular patch (valence 6) at corner 0. A triangle
//! whose corners are all regular but whose boundary patch lacks a point — two boundary corners
//! joined by an interior edge, as next to a one-triangle corner — is the regular patch with
//! *phantom* points ([`Phantoms`]): with the phantom `a + b - c` across every boundary edge
//! `(a, b)` of triangle `(a, b, c)`, Loop's regular rules on the extended net reproduce its
//! boundary rules, so a triangle with regular corners is the box spline of its phantom-extended
//! twelve points (the argument is in docs/algorithms/triangle-schemes.md; the boundary tables'
//! `k = 3` sections equal it exactly). The patch corner
//! `V` is at patch `(0,0)`, the next face corner counter-clockwise at `(1,0)`, the one after at
//! `(0,1)`; a patch at face corner `r` sees the face rotated: with the face's barycentric weights
//! `(w_0, w_1, w_2) = (1 - u - v, u, v)` the patch parameters are `(w_{r+1}, w_{r+2})`.
//!
//! Control points, in table order:
//!
//! * interior vertex of valence `v` (the regular patch is `v = 6`), `K = v + 6`
//!   (`schemes::triangle_local::triangle_layout`): `V, E_0, .., E_{v-1}` (counter-clockwise,
//!   `E_0` the face's corner after `V`), then `O_0 .. O_4`, the sector-0 lattice points
//!   `(2,-1), (2,0), (1,1), (0,2), (-1,2)`: the one-ring of `E_0` from `V` is
//!   `V, E_{v-1}, O_0, O_1, O_2, E_1` and that of `E_1` is `V, E_0, O_2, O_3, O_4, E_2`;
//! * boundary vertex with `k` triangles, the face its sector `s` (triangle `V, E_s, E_{s+1}`),
//!   `K = 1 + (k + 1) + 3 + [s >= 1] + [s <= k - 2]`: `V, E_0, .., E_k`, then the far vertex
//!   across `E_{s-1} E_s` (if `s >= 1`), the vertex beyond `E_s` (straight away from `V`), the
//!   far vertex across `E_s E_{s+1}`, the vertex beyond `E_{s+1}`, the far vertex across
//!   `E_{s+1} E_{s+2}` (if `s + 1 <= k - 1`).
//!
//! Grids ([`table_format`]'s triangle point sets): the primal point `(i, j)` at rate `n` is
//! `(i/n, j/n)`, row `j` of the `(n+1)(n+2)/2` points ([`primal_index`]); the dual points are the
//! centroids of the `n^2` small triangles, `up(i, j)` at `((3i+1)/3n, (3j+1)/3n)` and
//! `down(i, j)` at `((3i+2)/3n, (3j+2)/3n)`, row `j` holding
//! `up(0,j), down(0,j), .., up(n-1-j, j)` ([`dual_index`]). Rotations map primal points to
//! primal points, ups to ups and downs to downs.

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::{is_regular, neighbours, rotate_to};
use crate::scheme::patch::PatchKind;
use crate::MeshError;

/// A triangle's patch: its kind, its control points (mesh vertices in table order), and which
/// face corner is the patch's `(0,0)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TrianglePatch {
    /// The table patch (`faces`: valence for an interior vertex, triangles for a boundary one).
    pub kind: PatchKind,
    /// Mesh vertex of every layout entry.
    pub points: Vec<u32>,
    /// The face corner at the patch's `(0,0)`.
    pub corner: usize,
}

/// The phantom points of a triangle mesh: one across every boundary edge, numbered after the
/// mesh's vertices (phantom `i` is control point `vertices + i`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Phantoms {
    /// The mesh's vertex count: the index of the first phantom.
    pub vertices: u32,
    /// The phantom of every boundary half-edge (its index among the phantoms), `NONE` elsewhere.
    of_halfedge: Vec<u32>,
    /// Phantom `i` is `a + b - c` for `definitions[i] = [a, b, c]`.
    pub definitions: Vec<[u32; 3]>,
}

impl Phantoms {
    /// One phantom per boundary half-edge `a -> b` of triangle `(a, b, c)`: `a + b - c`.
    pub fn new(mesh: &Mesh) -> Self {
        let mut of_halfedge = vec![NONE; mesh.twin.len()];
        let mut definitions = Vec::new();
        for (h, &twin) in mesh.twin.iter().enumerate() {
            if twin == NONE {
                of_halfedge[h] = definitions.len() as u32;
                let (a, b) = (mesh.face_vertices[h], mesh.head(h));
                definitions.push([a, b, mesh.head(mesh.next(h))]);
            }
        }
        Phantoms {
            vertices: mesh.positions.len() as u32,
            of_halfedge,
            definitions,
        }
    }

    /// The control point of the phantom across boundary half-edge `h`.
    fn across(&self, h: usize) -> Option<u32> {
        match self.of_halfedge.get(h) {
            Some(&p) if p != NONE => Some(self.vertices + p),
            _ => None,
        }
    }

    /// `control` followed by every phantom's position.
    pub fn extend<T>(&self, control: &[[T; 3]]) -> Vec<[T; 3]>
    where
        T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T>,
    {
        let mut out = Vec::with_capacity(control.len() + self.definitions.len());
        out.extend_from_slice(control);
        for &[a, b, c] in &self.definitions {
            let (a, b, c) = (
                control[a as usize],
                control[b as usize],
                control[c as usize],
            );
            out.push(std::array::from_fn(|i| a[i] + b[i] - c[i]));
        }
        out
    }
}

/// Index of primal point `(i, j)`, `i + j <= n`, in the triangle primal grid of rate `n`.
pub fn primal_index(n: u32, i: u32, j: u32) -> usize {
    // Rows 0..j hold n + 1, n, .., n + 2 - j points.
    (j * (n + 1) - j * j.saturating_sub(1) / 2 + i) as usize
}

/// Index of dual point `up(i, j)` (`down` false) or `down(i, j)` in the triangle dual grid of
/// rate `n`.
pub fn dual_index(n: u32, i: u32, j: u32, down: bool) -> usize {
    // Row j' holds 2(n - j') - 1 points: rows 0..j hold j (2n - j).
    (j * (2 * n - j) + 2 * i + u32::from(down)) as usize
}

/// The primal point `(i, j)` of a face, at rate `n`, in the patch at face corner `corner`.
pub fn primal_in_patch(corner: usize, n: u32, i: u32, j: u32) -> (u32, u32) {
    let k = n - i - j;
    match corner {
        0 => (i, j),
        1 => (j, k),
        _ => (k, i),
    }
}

/// The dual point `up(i, j)` / `down(i, j)` of a face, at rate `n`, in the patch at face corner
/// `corner`: its centroid's numerators over `3n` rotate like primal points (and stay an up or a
/// down).
pub fn dual_in_patch(corner: usize, n: u32, i: u32, j: u32, down: bool) -> (u32, u32) {
    let shift = 1 + u32::from(down);
    let (p, q) = primal_in_patch(corner, 3 * n, 3 * i + shift, 3 * j + shift);
    ((p - shift) / 3, (q - shift) / 3)
}

/// The patch of triangle `face` of an isolated triangle mesh (`phantoms`: the mesh's,
/// [`Phantoms::new`]).
pub fn triangle_patch(
    mesh: &Mesh,
    phantoms: &Phantoms,
    face: usize,
) -> Result<TrianglePatch, MeshError> {
    let not_isolated = |reason: String| MeshError::NotIsolated { face, reason };
    let corners = mesh.face(face);
    if corners.len() != 3 {
        return Err(MeshError::NotTriangle {
            face,
            vertices: corners.len(),
        });
    }
    let boundary = |k: usize| mesh.is_boundary_vertex(corners[k] as usize);
    let regular = |k: usize| is_regular(mesh, corners[k] as usize);
    let corner = (0..3)
        .find(|&k| boundary(k) && !regular(k))
        .or_else(|| (0..3).find(|&k| boundary(k)))
        .or_else(|| (0..3).find(|&k| !regular(k)))
        .unwrap_or(0);
    let irregular = (0..3).filter(|&k| !regular(k)).count();
    if irregular > 1 {
        return Err(not_isolated(format!(
            "{irregular} of its corners are irregular"
        )));
    }
    if (0..3).any(|k| !boundary(k) && !regular(k)) && (0..3).any(boundary) {
        return Err(not_isolated(
            "an interior irregular corner and a boundary corner".to_owned(),
        ));
    }
    let h0 = mesh.face_halfedges(face).start + corner;
    let centre = corners[corner];
    if boundary(corner) {
        boundary_patch(mesh, h0, centre)
            .or_else(|reason| {
                if irregular == 0 {
                    phantom_patch(mesh, phantoms, face, corner)
                } else {
                    Err(reason)
                }
            })
            .map_err(not_isolated)
    } else {
        interior_patch(mesh, face, centre, corners[(corner + 1) % 3], corner).map_err(not_isolated)
    }
    .map(|(kind, points)| TrianglePatch {
        kind,
        points,
        corner,
    })
}

/// The patches of every triangle; the first triangle that is not one is an error.
pub fn gather_triangle_patches(
    mesh: &Mesh,
    phantoms: &Phantoms,
) -> Result<Vec<TrianglePatch>, MeshError> {
    (0..mesh.faces())
        .map(|f| triangle_patch(mesh, phantoms, f))
        .collect()
}

/// The one-ring of interior vertex `e` of valence 6, from `from` counter-clockwise.
fn regular_ring(mesh: &Mesh, e: u32, from: u32) -> Result<Vec<u32>, String> {
    if mesh.is_boundary_vertex(e as usize) {
        return Err(format!(
            "vertex {e} next to the patch vertex is on the boundary"
        ));
    }
    let ring = neighbours(mesh, e as usize);
    if ring.len() != 6 {
        return Err(format!(
            "vertex {e} next to the patch vertex has valence {}, not 6",
            ring.len()
        ));
    }
    rotate_to(&ring, from).ok_or_else(|| format!("vertex {from} is not a neighbour of {e}"))
}

fn interior_patch(
    mesh: &Mesh,
    face: usize,
    centre: u32,
    e0: u32,
    corner: usize,
) -> Result<(PatchKind, Vec<u32>), String> {
    let ring = rotate_to(&neighbours(mesh, centre as usize), e0)
        .ok_or_else(|| format!("face corner {corner} is not in its vertex's fan"))?;
    let valence = ring.len();
    if valence < 3 {
        return Err(format!("vertex {centre} has valence {valence}"));
    }
    let ring0 = regular_ring(mesh, ring[0], centre)?;
    let ring1 = regular_ring(mesh, ring[1], centre)?;
    // ring0 = V, E_{v-1}, O_0, O_1, O_2, E_1; ring1 = V, E_0, O_2, O_3, O_4, E_2.
    if ring0[1] != ring[valence - 1] || ring0[5] != ring[1] || ring1[2] != ring0[4] {
        return Err(format!(
            "the one-rings around face {face}'s corner {corner} do not close"
        ));
    }
    let mut points = vec![centre];
    points.extend_from_slice(&ring);
    points.extend_from_slice(&[ring0[2], ring0[3], ring0[4], ring1[3], ring1[4]]);
    Ok((
        PatchKind {
            boundary: false,
            feature: table_format::Feature::None,
            faces: valence as u32,
            sector: 0,
        },
        points,
    ))
}

/// The six neighbours of regular vertex `e`, counter-clockwise from `from`, a boundary vertex
/// (three triangles, neighbours `E_0..E_3`) completed by the phantoms across its boundary edges:
/// `E_0, E_1, E_2, E_3, E_3 + e - E_2, e + E_0 - E_1`.
fn extended_ring(mesh: &Mesh, phantoms: &Phantoms, e: u32, from: u32) -> Result<Vec<u32>, String> {
    if !mesh.is_boundary_vertex(e as usize) {
        return regular_ring(mesh, e, from);
    }
    let fan = mesh.fan(e as usize);
    let mut ring = neighbours(mesh, e as usize);
    if fan.len() != 3 {
        return Err(format!(
            "boundary vertex {e} of a regular patch has {} triangles, not 3",
            fan.len()
        ));
    }
    let entering = mesh.prev(fan[2]);
    for h in [entering, fan[0]] {
        ring.push(phantoms.across(h).ok_or_else(|| {
            format!("half-edge {h} at boundary vertex {e} is not on the boundary")
        })?);
    }
    rotate_to(&ring, from).ok_or_else(|| format!("vertex {from} is not a neighbour of {e}"))
}

/// The regular patch (valence 6) at face corner `corner`, every corner regular, the one-rings
/// of boundary corners completed by phantoms.
fn phantom_patch(
    mesh: &Mesh,
    phantoms: &Phantoms,
    face: usize,
    corner: usize,
) -> Result<(PatchKind, Vec<u32>), String> {
    let corners = mesh.face(face);
    let centre = corners[corner];
    let ring = extended_ring(mesh, phantoms, centre, corners[(corner + 1) % 3])?;
    let ring0 = extended_ring(mesh, phantoms, ring[0], centre)?;
    let ring1 = extended_ring(mesh, phantoms, ring[1], centre)?;
    // ring0 = V, E_5, O_0, O_1, O_2, E_1; ring1 = V, E_0, O_2, O_3, O_4, E_2.
    if ring0[1] != ring[5] || ring0[5] != ring[1] || ring1[2] != ring0[4] {
        return Err(format!(
            "the phantom-extended one-rings around face {face}'s corner {corner} do not close"
        ));
    }
    let mut points = vec![centre];
    points.extend_from_slice(&ring);
    points.extend_from_slice(&[ring0[2], ring0[3], ring0[4], ring1[3], ring1[4]]);
    Ok((
        PatchKind {
            boundary: false,
            feature: table_format::Feature::None,
            faces: 6,
            sector: 0,
        },
        points,
    ))
}

/// The far vertex of the triangle across the edge of half-edge `h`.
fn across(mesh: &Mesh, h: usize) -> Result<u32, String> {
    match mesh.twin[h] {
        NONE => Err(format!(
            "edge ({}, {}) of its neighbourhood is on the boundary",
            mesh.face_vertices[h],
            mesh.head(h)
        )),
        t => Ok(mesh.head(mesh.next(t as usize))),
    }
}

/// The vertex beyond `e` straight away from its neighbour `v`: opposite `v` in `e`'s ring
/// (interior valence 6), or `e`'s other boundary neighbour (`e` on the boundary with three
/// triangles, `v` one of its boundary neighbours).
fn beyond(mesh: &Mesh, e: u32, v: u32) -> Result<u32, String> {
    let ring = neighbours(mesh, e as usize);
    if mesh.is_boundary_vertex(e as usize) {
        match (ring.len(), ring.first(), ring.last()) {
            (4, Some(&a), Some(&b)) if a == v => Ok(b),
            (4, Some(&a), Some(&b)) if b == v => Ok(a),
            (4, _, _) => Err(format!(
                "its boundary corners {v} and {e} are joined by an interior edge, a neighbourhood no Loop table layout covers"
            )),
            (faces, _, _) => Err(format!(
                "boundary vertex {e} next to the patch vertex has {} triangles, not 3",
                faces.saturating_sub(1)
            )),
        }
    } else {
        Ok(regular_ring(mesh, e, v)?[3])
    }
}

fn boundary_patch(mesh: &Mesh, h0: usize, centre: u32) -> Result<(PatchKind, Vec<u32>), String> {
    let fan = mesh.fan(centre as usize);
    let k = fan.len();
    let s = fan
        .iter()
        .position(|&h| h == h0)
        .ok_or_else(|| "the face is not in its corner's fan".to_owned())?;
    let ring = neighbours(mesh, centre as usize);
    let mut points = vec![centre];
    points.extend_from_slice(&ring);
    if s >= 1 {
        points.push(across(mesh, mesh.next(fan[s - 1]))?);
    }
    points.push(beyond(mesh, ring[s], centre)?);
    points.push(across(mesh, mesh.next(h0))?);
    points.push(beyond(mesh, ring[s + 1], centre)?);
    if s + 1 < k {
        points.push(across(mesh, mesh.next(fan[s + 1]))?);
    }
    Ok((
        PatchKind {
            boundary: true,
            feature: table_format::Feature::None,
            faces: k as u32,
            sector: s as u32,
        },
        points,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_indices_count_rows_in_the_table_order() {
        let n = 4;
        let mut at = 0;
        for j in 0..=n {
            for i in 0..=n - j {
                assert_eq!(primal_index(n, i, j), at);
                at += 1;
            }
        }
        assert_eq!(at, ((n + 1) * (n + 2) / 2) as usize);
        let mut at = 0;
        for j in 0..n {
            for i in 0..n - j {
                assert_eq!(dual_index(n, i, j, false), at);
                at += 1;
                if i + 1 < n - j {
                    assert_eq!(dual_index(n, i, j, true), at);
                    at += 1;
                }
            }
        }
        assert_eq!(at, (n * n) as usize);
    }

    #[test]
    fn rotations_move_corners_and_centroids() {
        let n = 5;
        // Corner r of the face is the patch's (0,0); the face's corner r + 1 its (1,0).
        assert_eq!(primal_in_patch(1, n, n, 0), (0, 0));
        assert_eq!(primal_in_patch(1, n, 0, n), (n, 0));
        assert_eq!(primal_in_patch(2, n, 0, n), (0, 0));
        assert_eq!(primal_in_patch(2, n, 0, 0), (n, 0));
        // The face's corner triangle at (1,0) is the patch's corner triangle at (0,0).
        assert_eq!(dual_in_patch(1, n, n - 1, 0, false), (0, 0));
        assert_eq!(dual_in_patch(2, n, 0, n - 1, false), (0, 0));
        // down(0,0) of the face at corner 1: centroid (2,2)/3n; w = (3n - 4, 2, 2) -> patch
        // (w_2, w_0) = (2, 3n - 4): down(0, n - 2).
        assert_eq!(dual_in_patch(1, n, 0, 0, true), (0, n - 2));
    }
}
