//! Face-varying data (texture coordinates): values per face corner, and the topology of the
//! channel as OpenSubdiv derives it (`Vtr::FVarLevel::completeTopologyFromFaceValues`).
//!
//! A face-varying channel assigns every face corner a value index. Where two faces sharing an
//! edge use different values at either end of it, the edge is *discontinuous* (a seam): the
//! channel's surface is cut there. The channel is then a subdivision surface of its own mesh,
//! [`channel_mesh`]: one vertex per *sibling* (a value at a vertex, over an edge-connected run
//! of its faces), the same faces, seams and the mesh's boundary as boundaries, the mesh's edge
//! and vertex sharpness inherited, and the vertices that the [`FaceVaryingMode`] makes linear
//! pinned as infinitely sharp corners. The Catmull–Clark rules applied to that mesh give
//! OpenSubdiv's face-varying limit surface (docs/algorithms/face-varying.md).

use schemes::crease::{is_infinite, INFINITE};
use schemes::BoundaryMode;

use crate::mesh::topology::{Mesh, NONE};
use crate::MeshError;

/// Where the face-varying surface is linear instead of smooth: OpenSubdiv's
/// `Sdc::Options::FVarLinearInterpolation`, in the order of the OBJ tag
/// `t facevaryinginterpolateboundary k` (k = 0..=5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FaceVaryingMode {
    /// 0, `FVAR_LINEAR_NONE`: smooth everywhere; a seam or boundary is a smooth crease, a
    /// one-face corner follows it ("edge only").
    None,
    /// 1, `FVAR_LINEAR_CORNERS_ONLY`: one-face corners of the channel pinned.
    CornersOnly,
    /// 2, `FVAR_LINEAR_CORNERS_PLUS1`: corners pinned, and vertices where three or more
    /// values meet, or two with a sharp edge or a further seam inside either.
    CornersPlus1,
    /// 3, `FVAR_LINEAR_CORNERS_PLUS2`: as `CornersPlus1`, and both values of a two-value
    /// vertex pinned when either is a corner, and the ends of seams (darts) pinned.
    CornersPlus2,
    /// 4, `FVAR_LINEAR_BOUNDARIES`: every vertex on a seam or boundary pinned, so the channel
    /// is linear along them; smooth inside.
    Boundaries,
    /// 5, `FVAR_LINEAR_ALL`: bilinear on every face (OpenSubdiv's default).
    #[default]
    All,
}

impl FaceVaryingMode {
    /// The mode of `t facevaryinginterpolateboundary k`.
    pub fn from_tag(k: i64) -> Option<Self> {
        Some(match k {
            0 => Self::None,
            1 => Self::CornersOnly,
            2 => Self::CornersPlus1,
            3 => Self::CornersPlus2,
            4 => Self::Boundaries,
            5 => Self::All,
            _ => return None,
        })
    }

    /// The tag value `k` of this mode.
    pub fn tag(self) -> u8 {
        self as u8
    }

    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::CornersOnly => "corners-only",
            Self::CornersPlus1 => "corners-plus1",
            Self::CornersPlus2 => "corners-plus2",
            Self::Boundaries => "boundaries",
            Self::All => "all",
        }
    }

    /// Every mode, in tag order.
    pub const ALL: [FaceVaryingMode; 6] = [
        Self::None,
        Self::CornersOnly,
        Self::CornersPlus1,
        Self::CornersPlus2,
        Self::Boundaries,
        Self::All,
    ];

    /// The mode named `name` ([`FaceVaryingMode::name`]) or numbered `0`..`5`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name || m.tag().to_string() == name)
    }

    /// Whether seams and boundaries are linear (every value on them pinned).
    fn linear_boundaries(self) -> bool {
        matches!(self, Self::Boundaries | Self::All)
    }
}

/// One face-varying channel of a mesh: the values and the value of every face corner.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceVarying {
    /// The values (texture coordinates).
    pub values: Vec<[f64; 2]>,
    /// The value index of every half-edge's corner (the corner at the half-edge's tail, in
    /// the mesh's face order).
    pub corners: Vec<u32>,
    /// Where the channel is linear.
    pub mode: FaceVaryingMode,
}

impl FaceVarying {
    /// A channel over `mesh`, checked: one value per corner, every index in range, every
    /// value finite.
    pub fn new(
        mesh: &Mesh,
        values: Vec<[f64; 2]>,
        corners: Vec<u32>,
        mode: FaceVaryingMode,
    ) -> Result<Self, MeshError> {
        if corners.len() != mesh.face_vertices.len() {
            return Err(MeshError::FaceVarying(format!(
                "{} face-varying corners for {} face corners",
                corners.len(),
                mesh.face_vertices.len()
            )));
        }
        if let Some(h) = corners.iter().position(|&c| c as usize >= values.len()) {
            return Err(MeshError::FaceVarying(format!(
                "corner {} of face {} names value {} of {}",
                h - mesh.face_halfedges(mesh.face_of[h] as usize).start,
                mesh.face_of[h],
                corners[h],
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(MeshError::FaceVarying(format!(
                "value {i} {:?} is not finite",
                values[i]
            )));
        }
        Ok(FaceVarying {
            values,
            corners,
            mode,
        })
    }

    /// Whether the edge of half-edge `h` is a seam: the faces on its two sides use different
    /// values at one of its ends. A boundary edge is not a seam.
    pub fn is_seam(&self, mesh: &Mesh, h: usize) -> bool {
        let t = mesh.twin[h];
        if t == NONE {
            return false;
        }
        let t = t as usize;
        self.corners[h] != self.corners[mesh.next(t)]
            || self.corners[mesh.next(h)] != self.corners[t]
    }

    /// The bilinear value at `(u, v)` of face `f` (quads), or of the quad at corner `subface`
    /// of an n-gon's first bilinear step (corner, next edge's midpoint, centroid, previous
    /// edge's midpoint, the Ptex convention of [`crate::VertexSource`]): the channel under
    /// [`FaceVaryingMode::All`].
    pub fn bilinear(&self, mesh: &Mesh, f: usize, subface: usize, u: f64, v: f64) -> [f64; 2] {
        let corners = mesh.face_halfedges(f);
        let value = |h: usize| self.values[self.corners[h] as usize];
        let quad: [[f64; 2]; 4] = if corners.len() == 4 {
            [0, 1, 2, 3].map(|k| value(corners.start + k))
        } else {
            let n = corners.len();
            let at = |k: usize| value(corners.start + k % n);
            let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
            let mut centroid = [0.0; 2];
            for k in 0..n {
                centroid[0] += at(k)[0] / n as f64;
                centroid[1] += at(k)[1] / n as f64;
            }
            let k = subface % n;
            [
                at(k),
                mid(at(k), at(k + 1)),
                centroid,
                mid(at(k + n - 1), at(k)),
            ]
        };
        let w = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
        let mut out = [0.0; 2];
        for (p, w) in quad.iter().zip(w) {
            out[0] += w * p[0];
            out[1] += w * p[1];
        }
        out
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

/// What one value contributes at a vertex (OpenSubdiv's `ValueSpan`).
#[derive(Clone, Copy, Debug, Default)]
struct Span {
    value: u32,
    /// Corners using the value at the vertex.
    size: usize,
    /// Edge-connected runs of those corners (more than one: "disjoint", pinned).
    runs: usize,
    /// Infinitely sharp edges between two of its corners.
    inf_sharp_edges: usize,
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
    let seam: Vec<bool> = (0..corners).map(|h| fvar.is_seam(mesh, h)).collect();
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
        let mut spans: Vec<Span> = Vec::new();
        let mut runs: Vec<u32> = Vec::new();
        for &h in &fan {
            let value = fvar.corners[h];
            let at = match spans.iter().position(|s| s.value == value) {
                Some(i) => i,
                None => {
                    spans.push(Span {
                        value,
                        ..Span::default()
                    });
                    spans.len() - 1
                }
            };
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
        for &h in &fan {
            let span = spans
                .iter()
                .find(|s| s.value == fvar.corners[h])
                .copied()
                .unwrap_or_default();
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
