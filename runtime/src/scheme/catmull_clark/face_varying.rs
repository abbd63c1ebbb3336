//! The face-varying channel (texture coordinates) of a Catmull–Clark surface: the channel's own
//! mesh as OpenSubdiv derives it ([`channel_mesh`], after
//! `Vtr::FVarLevel::completeTopologyFromFaceValues`), and that mesh refined by the same steps
//! as the positions, so that its faces and corners are the isolated mesh's, and its limit
//! values at any points of those faces.
//!
//! The values are evaluated once, when a tessellation is planned: they do not move with the
//! control points. Smooth modes take exact limit stencils by feature-adaptive refinement of the
//! channel's mesh ([`limit_stencils`]: seams and boundaries are its boundaries, pinned values
//! its corners, so every rule of the positions applies unchanged); the linear mode
//! ([`FaceVaryingMode::All`]) is the bilinear interpolation of the input face's corner values,
//! in closed form.

use rayon::prelude::*;
use schemes::crease::{is_infinite, INFINITE};
use schemes::BoundaryMode;

use crate::mesh::face_varying::{bilinear_in, FaceVarying, FaceVaryingMode};
use crate::mesh::{Mesh, VertexSource, NONE};
use crate::scheme::catmull_clark::adaptive::{limit_stencils, LimitQuery};
use crate::scheme::catmull_clark::isolate::Isolation;
use crate::scheme::catmull_clark::refine::refine;
use crate::MeshError;

/// A face-varying channel prepared for an [`Isolation`].
#[derive(Clone, Debug)]
pub struct ChannelIsolation {
    /// The channel's mesh after the isolation's steps: its face `f` is the isolated mesh's face
    /// `f`, its half-edge `h` the same corner; its vertices are the channel's (split along
    /// seams), at the refined values `(u, v, 0)`.
    pub mesh: Mesh,
    /// The input channel (for the linear mode's closed form).
    input: FaceVarying,
    /// The input mesh's [`Mesh::face_offsets`] (a face's corners, for the linear mode).
    input_faces: Vec<u32>,
}

impl ChannelIsolation {
    /// The channel of `input` (which must have one) refined `isolation.steps` times.
    pub fn new(input: &Mesh, isolation: &Isolation) -> Result<Option<Self>, MeshError> {
        let Some(fvar) = &input.face_varying else {
            return Ok(None);
        };
        let mut mesh = channel_mesh(input, fvar)?;
        for _ in 0..isolation.steps {
            mesh = refine(&mesh).mesh;
        }
        if mesh.face_vertices.len() != isolation.mesh.face_vertices.len() {
            return Err(MeshError::FaceVarying(format!(
                "the channel refined to {} corners, the positions to {}",
                mesh.face_vertices.len(),
                isolation.mesh.face_vertices.len()
            )));
        }
        Ok(Some(ChannelIsolation {
            mesh,
            input: fvar.clone(),
            input_faces: input.face_offsets.clone(),
        }))
    }

    /// The channel's mode.
    pub fn mode(&self) -> FaceVaryingMode {
        self.input.mode
    }

    /// The linear mode's values ([`FaceVaryingMode::All`]: bilinear over each input face, or
    /// over the sub-face of a non-quad) at `input_sources`, points given on their input faces,
    /// sub-faces and parameters (`Isolation::input_source`); in parallel, in the points' order.
    pub fn linear_values(&self, input_sources: &[VertexSource]) -> Vec<[f32; 2]> {
        // A face's (or sub-face's) four values are looked up once for its run of points.
        type Quad = Option<((u32, u8), [[f64; 2]; 4])>;
        input_sources
            .par_iter()
            .map_init(
                || None,
                |last: &mut Quad, s| {
                    let key = (s.face, s.subface);
                    let quad = match *last {
                        Some((k, quad)) if k == key => quad,
                        _ => {
                            let f = s.face as usize;
                            let corners =
                                self.input_faces[f] as usize..self.input_faces[f + 1] as usize;
                            let quad = self.input.quad(corners, usize::from(s.subface));
                            *last = Some((key, quad));
                            quad
                        }
                    };
                    let (u, v) = s.uv();
                    let [x, y] = bilinear_in(&quad, u, v);
                    [x as f32, y as f32]
                },
            )
            .collect()
    }

    /// The channel's limit values at `sources`, points of the isolated mesh's faces, for the
    /// modes other than the linear one (which [`ChannelIsolation::linear_values`] gives in
    /// closed form): the channel mesh's limit stencils.
    pub fn limit_values(&self, sources: &[VertexSource]) -> Result<Vec<[f32; 2]>, MeshError> {
        let queries: Vec<LimitQuery> = sources
            .iter()
            .map(|s| {
                let (u, v) = s.uv();
                LimitQuery { face: s.face, u, v }
            })
            .collect();
        let stencils = limit_stencils(&self.mesh, &queries)?;
        Ok(stencils
            .iter()
            .map(|stencil| {
                let mut out = [0.0f64; 2];
                for &(vertex, [w, _, _]) in stencil {
                    let p = self.mesh.positions[vertex as usize];
                    out[0] += w * p[0];
                    out[1] += w * p[1];
                }
                [out[0] as f32, out[1] as f32]
            })
            .collect())
    }
}

/// Union-find over face corners.
fn root(parent: &mut [u32], mut x: usize) -> usize {
    while parent[x] as usize != x {
        parent[x] = parent[parent[x] as usize];
        x = parent[x] as usize;
    }
    x
}

/// What one of OpenSubdiv's siblings spans at a vertex (its `ValueSpan`).
#[derive(Clone, Copy, Debug, Default)]
struct Span {
    /// Corners of the sibling at the vertex.
    size: usize,
    /// Edge-connected runs of those corners (more than one: "disjoint", pinned).
    runs: usize,
    /// Infinitely sharp edges between two of its corners.
    inf_sharp_edges: usize,
}

/// OpenSubdiv's sibling index of each value around a vertex, in its face order (the leading
/// boundary face first, or the lowest-numbered face; [`Mesh::fan`]'s order), as
/// `FVarLevel::completeTopologyFromFaceValues` assigns them, shortcut included: while two
/// values are known, a value that differs from its predecessor and from the first value is
/// taken as new without comparing it with the second. So around `a, b, a, b` the two `b` faces
/// are two siblings of one face each (smooth in mode 0), while the two `a` faces are one sibling
/// over two runs (pinned); the order decides which value is `a`.
fn osd_siblings(values: impl Iterator<Item = u32>) -> Vec<usize> {
    let mut unique: Vec<u32> = Vec::new();
    let mut out: Vec<usize> = Vec::new();
    let mut previous = None;
    for value in values {
        let sibling = match previous {
            Some((p, s)) if p == value => s,
            _ if unique.len() < 2 || (unique.len() == 2 && unique[0] != value) => {
                unique.push(value);
                unique.len() - 1
            }
            _ => match unique.iter().position(|&u| u == value) {
                Some(k) => k,
                None => {
                    unique.push(value);
                    unique.len() - 1
                }
            },
        };
        out.push(sibling);
        previous = Some((value, sibling));
    }
    out
}

/// The channel's own mesh: one vertex per sibling (a value at a vertex over one edge-connected
/// run of faces), the faces of `mesh` in order (so half-edge `h` is the same corner in both),
/// positions `(u, v, 0)`, seams and boundaries as boundaries, the edge sharpness and holes of
/// `mesh`, and the vertex sharpness OpenSubdiv's rules give the values: infinite where the mode
/// makes a value linear (a pinned corner), the vertex's own elsewhere.
///
/// Which values are pinned, at a vertex whose channel topology differs from the mesh's (a seam
/// ends there, several values meet, or the mode changes a boundary vertex), as in
/// `FVarLevel::completeTopologyFromFaceValues`: every value when the mode makes boundaries
/// linear, the vertex is infinitely sharp or non-manifold, three or more values meet (modes
/// 2, 3), or a seam ends at an interior vertex with one value (modes 3, 4, 5); with two values
/// in modes 2 and 3, both when either has an infinitely sharp edge inside, or (mode 3) either
/// is a one-face corner; and a value used over several runs, one with an infinitely sharp edge
/// inside (three sharp edges make a corner), or a one-face corner (every mode but 0). Not
/// modelled: OpenSubdiv's "dependent" sharpness (a two-value vertex of modes 2 and 3 where one
/// value has a semi-sharp edge inside and the other none, pinned until that sharpness decays).
pub fn channel_mesh(mesh: &Mesh, fvar: &FaceVarying) -> Result<Mesh, MeshError> {
    let corners = mesh.face_vertices.len();
    let mut parent: Vec<u32> = (0..corners as u32).collect();
    let seam: Vec<bool> = (0..corners).map(|h| mesh.is_seam(h)).collect();
    for (h, &t) in mesh.twin.iter().enumerate() {
        if t == NONE || seam[h] {
            continue;
        }
        // Across a continuous edge the corners at each end are one sibling.
        for (a, b) in [(h, mesh.next(t as usize)), (mesh.next(h), t as usize)] {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra.max(rb)] = ra.min(rb) as u32;
        }
    }
    // Sibling ids in order of their first corner.
    let mut id = vec![NONE; corners];
    let mut sibling_of_corner = vec![0u32; corners];
    let mut first_corner = Vec::new();
    for (h, sibling) in sibling_of_corner.iter_mut().enumerate() {
        let r = root(&mut parent, h);
        if id[r] == NONE {
            id[r] = first_corner.len() as u32;
            first_corner.push(h);
        }
        *sibling = id[r];
    }
    let mut sharpness: Vec<f32> = first_corner
        .iter()
        .map(|&h| mesh.vertex_sharpness[mesh.face_vertices[h] as usize])
        .collect();
    let mode = fvar.mode;
    let corners_sharp = mode != FaceVaryingMode::None;
    let smooth_geometry_corners = mesh.boundary != BoundaryMode::EdgeAndCorner;
    let dependent = matches!(
        mode,
        FaceVaryingMode::CornersPlus1 | FaceVaryingMode::CornersPlus2
    );
    let sharpen_darts = mode == FaceVaryingMode::CornersPlus2 || mode.linear_boundaries();
    // A vertex split for being non-manifold (OpenSubdiv pins all its values).
    let mut split = vec![false; mesh.positions.len()];
    for (i, &origin) in mesh.copies.iter().enumerate() {
        split[origin as usize] = true;
        split[mesh.input_vertices() + i] = true;
    }
    for (v, &non_manifold) in split.iter().enumerate() {
        let fan = mesh.fan(v);
        if fan.is_empty() {
            continue;
        }
        let boundary = mesh.is_boundary_vertex(v);
        // The corners at v are the fan's half-edges; the edges at v are each fan half-edge's
        // own and the one into v of the fan's last face.
        let discontinuous = fan.iter().any(|&h| seam[h] || seam[mesh.prev(h)]);
        let siblings = osd_siblings(fan.iter().map(|&h| fvar.corners[h]));
        let mut spans = vec![Span::default(); siblings.iter().max().map_or(0, |&s| s + 1)];
        let mut runs: Vec<u32> = Vec::new();
        for (&h, &at) in fan.iter().zip(&siblings) {
            spans[at].size += 1;
            let run = sibling_of_corner[h];
            if !runs.contains(&run) {
                runs.push(run);
                spans[at].runs += 1;
            }
            // The edge h leaves v by is inside the span when continuous.
            if mesh.twin[h] != NONE && !seam[h] && is_infinite(mesh.edge_sharpness[h]) {
                spans[at].inf_sharp_edges += 1;
            }
        }
        let mismatched = discontinuous
            || spans.len() > 1
            || (boundary && mode.linear_boundaries())
            || (boundary && fan.len() == 1 && smooth_geometry_corners && corners_sharp);
        if !mismatched {
            continue;
        }
        let mut all = mode.linear_boundaries()
            || is_infinite(mesh.vertex_sharpness[v])
            || non_manifold
            || (dependent && spans.len() > 2)
            || (sharpen_darts && spans.len() == 1 && !boundary);
        if !all && dependent && spans.len() == 2 {
            all = spans.iter().any(|s| s.inf_sharp_edges > 0 || s.runs > 1)
                || (mode == FaceVaryingMode::CornersPlus2 && spans.iter().any(|s| s.size == 1));
        }
        for (&h, &at) in fan.iter().zip(&siblings) {
            let span = spans[at];
            let pinned = all
                || span.runs > 1
                || span.inf_sharp_edges > 0
                || (span.size == 1 && corners_sharp);
            if pinned {
                sharpness[sibling_of_corner[h] as usize] = INFINITE;
            }
        }
    }
    let positions: Vec<[f64; 3]> = first_corner
        .iter()
        .map(|&h| {
            let [u, v] = fvar.values[fvar.corners[h] as usize];
            [u, v, 0.0]
        })
        .collect();
    let faces: Vec<Vec<i64>> = (0..mesh.faces())
        .map(|f| {
            mesh.face_halfedges(f)
                .map(|h| i64::from(sibling_of_corner[h]))
                .collect()
        })
        .collect();
    let mut channel = Mesh::refined(positions, &faces, &[], BoundaryMode::EdgeOnly)?;
    for h in 0..corners {
        if channel.twin[h] != NONE {
            channel.edge_sharpness[h] = mesh.edge_sharpness[h];
        }
    }
    for (s, &p) in channel.vertex_sharpness.iter_mut().zip(&sharpness) {
        *s = s.max(p);
    }
    channel.holes.clone_from(&mesh.holes);
    channel.creasing = mesh.creasing;
    channel.smooth_triangles = mesh.smooth_triangles;
    Ok(channel)
}

#[cfg(test)]
mod tests {
    use super::osd_siblings;

    /// OpenSubdiv's assignment, worked by hand from `completeTopologyFromFaceValues`: runs of
    /// one value share a sibling; a third value, or a return to a known one, is searched for,
    /// except the second value met again right after the first, which is taken as new.
    #[test]
    fn siblings_follow_opensubdivs_assignment() {
        let of = |v: &[u32]| osd_siblings(v.iter().copied());
        assert_eq!(of(&[7, 7, 7]), [0, 0, 0]);
        assert_eq!(of(&[1, 2, 2, 1]), [0, 1, 1, 0]);
        assert_eq!(of(&[1, 2, 1, 2]), [0, 1, 0, 2]);
        assert_eq!(of(&[1, 2, 3, 2]), [0, 1, 2, 1]);
        assert_eq!(of(&[1, 2, 3, 1, 3]), [0, 1, 2, 0, 2]);
    }
}
