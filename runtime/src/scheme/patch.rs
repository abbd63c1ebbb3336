//! Which table stencils and which mesh vertices evaluate one quad face.
//!
//! A face of an isolated mesh (all quads, at most one irregular corner per face) is a patch of
//! the tables (`docs/algorithms/extraordinary-stencils.md`): its irregular corner — or, on the
//! boundary, a boundary corner; or any corner of a regular face — is the patch's vertex `V` at
//! `(0,0)`, and its control points are gathered in the table's layout order
//! `V, E_1.., F_1.., O_1..O_7` by walking the half-edges:
//!
//! * `E_i`, `F_i` around `V`: the fan of `V` in order, starting at the patch face (interior) or
//!   at the boundary (boundary vertex; the patch face is then sector `s` of the fan);
//! * the outer points, in the patch face's own coordinates: across its edge `E_1-F_1` lies the
//!   cell holding `O_2 = (2,0)` and `O_3 = (2,1)`, below that cell's edge `E_1-O_2` the one with
//!   `O_1 = (2,-1)`, above its edge `F_1-O_3` the one with `O_4`, `O_5`, then `O_6`, `O_7`.
//!
//! A face at a **dart** the tables describe ([`table_dart`]) is a patch of the dart table
//! (`docs/algorithms/extraordinary-stencils.md`, "Darts"): `V` is the dart, the fan starts at
//! its sharp edge (`E_1` is that edge's other end, as `Neighbourhood::dart` lays it out), and
//! the face is sector `s` of the fan, as at a boundary vertex; the outer points are the patch
//! face's, walked as above.
//!
//! Face parameters map to patch parameters by the rotation that brings the chosen corner to
//! `(0,0)`: corner `k` of the face `(c_0, c_1, c_2, c_3)` gives
//! `(u', v') = (u, v), (v, 1-u), (1-u, 1-v), (1-v, u)` for `k = 0, 1, 2, 3`.

use schemes::local_matrices::Neighbourhood;
use table_format::{Feature, PointSet, SectionKey, StencilKind};

use crate::mesh::topology::{Mesh, NONE};
use crate::stencil_table::StencilTable;
use crate::{MeshError, RuntimeError};

/// Which table patch a face is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PatchKind {
    /// Whether the patch vertex is on the boundary.
    pub boundary: bool,
    /// The sharp feature at the patch vertex: [`Feature::Dart`] for a dart patch (interior).
    pub feature: Feature,
    /// Its valence (interior) or number of faces (boundary).
    pub faces: u32,
    /// Which of a boundary vertex's or a dart's patches (0 for a smooth interior vertex).
    pub sector: u32,
}

impl PatchKind {
    /// The table section of this patch holding `kind` on the grid `points` at rate `n`.
    pub fn section(&self, kind: StencilKind, points: PointSet, n: u32) -> SectionKey {
        SectionKey {
            kind,
            points,
            boundary: self.boundary,
            feature: self.feature,
            faces: self.faces,
            sector: self.sector,
            n,
        }
    }

    /// The neighbourhood whose local subdivision matrices make this patch, for a mesh with
    /// boundary rule `mode` (quad schemes).
    pub fn neighbourhood(&self, mode: schemes::BoundaryMode) -> Neighbourhood {
        if self.boundary {
            Neighbourhood::boundary(self.faces, mode)
        } else if self.feature == Feature::Dart {
            Neighbourhood::dart(self.faces)
        } else {
            Neighbourhood::interior(self.faces)
        }
    }
}

/// A face's patch: its kind, its control points (mesh vertices in layout order), and which face
/// corner is the patch's `(0,0)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FacePatch {
    /// The table patch.
    pub kind: PatchKind,
    /// Mesh vertex of every layout entry.
    pub points: Vec<u32>,
    /// The face corner at the patch's `(0,0)`.
    pub corner: usize,
}

/// Gather the patch of every face; the first face that is not one is an error.
pub fn gather_patches(mesh: &Mesh) -> Result<Vec<FacePatch>, MeshError> {
    (0..mesh.faces()).map(|f| face_patch(mesh, f)).collect()
}

/// Whether vertex `v` is irregular: interior valence other than 4, or a boundary vertex with
/// other than two faces.
pub fn is_irregular(mesh: &Mesh, v: usize) -> bool {
    let faces = mesh.fan_iter(v).count();
    if mesh.is_boundary_vertex(v) {
        faces != 2
    } else {
        faces != 4
    }
}

/// Whether the limit over face `face` is the smooth one the tables describe: no edge at its
/// corners is sharp (other than boundary edges) and no corner is sharp (other than the
/// one-face corners "edge and corner" pins). A face next to sharp features is evaluated by
/// feature-adaptive refinement instead ([`crate::scheme::catmull_clark::adaptive`]); only the
/// edges at the corners matter, since the children of the others stay outside the face's
/// refined neighbourhoods. So is a face at an interior vertex of valence 2, which has no patch
/// of the scaling relation (its neighbourhood's layout needs three faces or more: `Neighbourhood`
/// in `schemes::local_matrices`).
pub fn is_smooth_patch(mesh: &Mesh, face: usize) -> bool {
    mesh.face(face).iter().all(|&v| {
        let v = v as usize;
        if !mesh.is_boundary_vertex(v) && mesh.fan_iter(v).count() == 2 {
            return false;
        }
        let pinned = mesh.boundary == schemes::BoundaryMode::EdgeAndCorner
            && mesh.is_boundary_vertex(v)
            && mesh.fan_iter(v).count() == 1;
        (mesh.vertex_sharpness[v] == 0.0 || pinned)
            && mesh
                .vertex_edges_iter(v)
                .all(|h| mesh.twin[h] == NONE || mesh.edge_sharpness[h] == 0.0)
    })
}

/// Whether the limit over face `face` is one the tables describe: a smooth patch
/// ([`is_smooth_patch`]), a dart patch ([`table_dart`]) or a boundary patch of a crease sector
/// ([`crease_sector`]).
pub fn is_table_patch(mesh: &Mesh, face: usize) -> bool {
    is_smooth_patch(mesh, face)
        || table_dart(mesh, face).is_some()
        || crease_sector(mesh, face).is_some()
}

/// Whether the edge of half-edge `h` is infinitely sharp.
fn infinitely_sharp(mesh: &Mesh, h: usize) -> bool {
    schemes::crease::is_infinite(mesh.edge_sharpness[h])
}

/// Whether vertex `v` is an interior vertex of valence 4 with no sharp edge and no sharpness
/// of its own: a regular corner of a smooth patch.
fn smooth_regular(mesh: &Mesh, v: usize) -> bool {
    !mesh.is_boundary_vertex(v)
        && mesh.fan_iter(v).count() == 4
        && mesh.vertex_sharpness[v] == 0.0
        && mesh
            .vertex_edges_iter(v)
            .all(|h| mesh.edge_sharpness[h] == 0.0)
}

/// The sharp edge of a dart at `v`, as its position in `v`'s fan: `v` is an interior vertex
/// with no sharpness of its own and exactly one sharp edge, infinitely sharp (a settled dart:
/// the rules at it are the same at every level).
fn dart_edge(mesh: &Mesh, v: usize) -> Option<usize> {
    if mesh.is_boundary_vertex(v) || mesh.vertex_sharpness[v] != 0.0 {
        return None;
    }
    let mut sharp = mesh
        .fan_iter(v)
        .enumerate()
        .filter(|&(_, h)| mesh.edge_sharpness[h] != 0.0);
    match (sharp.next(), sharp.next()) {
        (Some((d, h)), None) if infinitely_sharp(mesh, h) => Some(d),
        _ => None,
    }
}

/// The dart corner of face `face` and the position of the dart's sharp edge in that corner's
/// fan, when the face is a patch of the dart table (`Neighbourhood::dart`): a quad with one
/// corner `V` a settled dart (`dart_edge`) and every other corner an interior valence-4
/// vertex with nothing sharp at it (`smooth_regular`), except the sharp edge's other end
/// `E_1` when it is a corner (the faces on either side of the sharp edge): the table lets the
/// crease run straight on through it, so `E_1` must be an interior valence-4 vertex without
/// sharpness whose only sharp edges are the dart's and the opposite one, both infinitely sharp
/// (a crease vertex, with the crease rule at every level). As for [`is_smooth_patch`], only
/// the corners matter: the rules of the face's refined neighbourhoods are those of its
/// corners' edges and vertices. A face the table cannot describe (a semi-sharp edge, a crease
/// that turns or ends at `E_1`, an irregular or boundary corner beside the dart) is `None` and
/// refined adaptively.
pub fn table_dart(mesh: &Mesh, face: usize) -> Option<(usize, usize)> {
    let corners = mesh.face(face);
    if corners.len() != 4 {
        return None;
    }
    let corner = (0..4).find(|&k| dart_edge(mesh, corners[k] as usize).is_some())?;
    let centre = corners[corner] as usize;
    let fan = mesh.fan(centre);
    let d = dart_edge(mesh, centre)?;
    let e1 = mesh.head(fan[d]) as usize;
    // The dart's sharp edge is one of `E_1`'s two, so a crease vertex continues it straight on.
    let others_fit = (0..4).filter(|&k| k != corner).all(|k| {
        let v = corners[k] as usize;
        if v == e1 {
            crease_vertex(mesh, v)
        } else {
            smooth_regular(mesh, v)
        }
    });
    others_fit.then_some((corner, d))
}

/// The fan positions `(a, b)`, `a < b`, of the two sharp edges at `v` when `v` is a crease
/// vertex: an interior vertex with no sharpness of its own whose only sharp edges are two, both
/// infinitely sharp. The crease rule `(1, 6, 1) / 8` then holds at every level, and the two
/// sectors of its fan (fan faces `a..b` and the rest; fan edge `i` lies between fan faces
/// `i - 1` and `i`) subdivide apart, each from its own points and the crease's only.
fn crease_edges(mesh: &Mesh, v: usize) -> Option<(usize, usize)> {
    if mesh.is_boundary_vertex(v) || mesh.vertex_sharpness[v] != 0.0 {
        return None;
    }
    let mut sharp = mesh
        .fan_iter(v)
        .enumerate()
        .filter(|&(_, h)| mesh.edge_sharpness[h] != 0.0);
    match (sharp.next(), sharp.next(), sharp.next()) {
        (Some((a, ha)), Some((b, hb)), None)
            if infinitely_sharp(mesh, ha) && infinitely_sharp(mesh, hb) =>
        {
            Some((a, b))
        }
        _ => None,
    }
}

/// Whether `v` is an interior valence-4 crease vertex ([`crease_edges`]) whose sharp edges are
/// opposite in its fan: a crease runs straight through it with two faces on either side.
fn crease_vertex(mesh: &Mesh, v: usize) -> bool {
    mesh.fan_iter(v).count() == 4 && matches!(crease_edges(mesh, v), Some((a, b)) if b == a + 2)
}

/// A face's place at a crease vertex: the sector of the vertex's fan that holds it, between the
/// two sharp edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CreaseSector {
    /// The face corner at the crease vertex.
    pub corner: usize,
    /// The fan position of the sector's first face (its first sharp edge's).
    pub start: usize,
    /// The sector's faces.
    pub faces: usize,
    /// The face's place in the sector, `0..faces`.
    pub sector: usize,
}

/// The crease sector of face `face` at its corner `k`, if that corner is a crease vertex
/// ([`crease_edges`]).
fn sector_at(mesh: &Mesh, face: usize, k: usize) -> Option<CreaseSector> {
    let h = mesh.face_halfedges(face).start + k;
    let v = mesh.face_vertices[h] as usize;
    let (a, b) = crease_edges(mesh, v)?;
    let fan = mesh.fan(v);
    let p = fan.iter().position(|&g| g == h)?;
    let (start, faces) = if (a..b).contains(&p) {
        (a, b - a)
    } else {
        (b, fan.len() - (b - a))
    };
    Some(CreaseSector {
        corner: k,
        start,
        faces,
        sector: (p + fan.len() - start) % fan.len(),
    })
}

/// The crease sector whose boundary patch describes face `face`, when the face lies at an
/// infinitely sharp crease the tables describe as a boundary: a crease vertex's sectors
/// subdivide apart (`crease_edges`), each exactly as a boundary vertex with as many faces
/// (the crease rule is the boundary rule, a crease edge's rule the boundary edge's midpoint),
/// so the table's boundary patch of `faces` faces, sector `sector`, gathered on the face's side
/// of the crease, is the face's limit.
///
/// The corners must be what that patch assumes, as for [`is_smooth_patch`] only the corners
/// and their edges mattering: the patch vertex `V` a crease vertex (the one whose sector is not
/// two faces, if any), the face's sides at `V` sharp exactly where the sector ends, its two
/// other sides smooth, a corner on the crease a crease vertex with two faces on the face's side
/// (the crease goes on as a regular boundary), any other corner an interior valence-4 vertex
/// with nothing sharp at it (`smooth_regular`). A one-face sector takes the crease rule, so
/// in "edge and corner" mode, whose table pins one-face boundary vertices, it is not one.
pub fn crease_sector(mesh: &Mesh, face: usize) -> Option<CreaseSector> {
    if mesh.face(face).len() != 4 {
        return None;
    }
    let sectors: [Option<CreaseSector>; 4] = std::array::from_fn(|k| sector_at(mesh, face, k));
    let irregular = || sectors.iter().flatten().filter(|s| s.faces != 2);
    if irregular().count() > 1 {
        return None;
    }
    let at = irregular()
        .next()
        .or_else(|| sectors.iter().flatten().next())
        .copied()?;
    if at.faces == 1 && mesh.boundary == schemes::BoundaryMode::EdgeAndCorner {
        return None;
    }
    let c = at.corner;
    // Side `c` leaves V, side `c - 1` enters it; corner `c + 1` ends side `c`.
    let first = at.sector == 0;
    let last = at.sector + 1 == at.faces;
    let halfedges = mesh.face_halfedges(face);
    let sides_fit = (0..4).all(|side| {
        let sharp = mesh.edge_sharpness[halfedges.start + side] != 0.0;
        sharp == ((side == c && first) || (side == (c + 3) % 4 && last))
    });
    let corners = mesh.face(face);
    let corners_fit = (1..4).all(|d| {
        let k = (c + d) % 4;
        let on_crease = (d == 1 && first) || (d == 3 && last);
        if on_crease {
            matches!(sectors[k], Some(s) if s.faces == 2)
        } else {
            smooth_regular(mesh, corners[k] as usize)
        }
    });
    (sides_fit && corners_fit).then_some(at)
}

/// The patch corner of a quad face by its topology alone: its irregular corner if any, else a
/// boundary corner, else corner 0; an error for a face that is no patch (two irregular
/// corners, an interior irregular corner beside a boundary one).
fn topological_corner(mesh: &Mesh, face: usize) -> Result<usize, MeshError> {
    let not_isolated = |reason: String| MeshError::NotIsolated { face, reason };
    let corners = mesh.face(face);
    let irregular: Vec<usize> = (0..corners.len())
        .filter(|&k| is_irregular(mesh, corners[k] as usize))
        .collect();
    if irregular.len() > 1 {
        return Err(not_isolated(format!(
            "{} of its corners are irregular",
            irregular.len()
        )));
    }
    let boundary = |k: usize| mesh.is_boundary_vertex(corners[k] as usize);
    let corner = irregular
        .first()
        .copied()
        .or_else(|| (0..corners.len()).find(|&k| boundary(k)))
        .unwrap_or(0);
    if !boundary(corner) && (0..corners.len()).any(boundary) {
        return Err(not_isolated(
            "an interior irregular corner and a boundary corner".to_owned(),
        ));
    }
    Ok(corner)
}

/// The patch of quad face `face`.
pub fn face_patch(mesh: &Mesh, face: usize) -> Result<FacePatch, MeshError> {
    let not_isolated = |reason: String| MeshError::NotIsolated { face, reason };
    let corners = mesh.face(face);
    if corners.len() != 4 {
        return Err(not_isolated(format!(
            "it has {} sides; patches are quads",
            corners.len()
        )));
    }
    // A crease sector or a dart the table describes; else the irregular corner if any, else a
    // boundary corner, else corner 0.
    let crease = crease_sector(mesh, face);
    let dart = table_dart(mesh, face);
    let corner = match (crease, dart) {
        (Some(c), _) => c.corner,
        (None, Some((k, _))) => k,
        (None, None) => topological_corner(mesh, face)?,
    };
    let h0 = mesh.face_halfedges(face).start + corner;
    let centre = mesh.face_vertices[h0] as usize;
    let fan = mesh.fan(centre);
    let boundary = crease.is_some() || mesh.is_boundary_vertex(centre);
    let position = fan
        .iter()
        .position(|&h| h == h0)
        .ok_or_else(|| not_isolated("the face is not in its corner's fan".to_owned()))?;
    // Interior: the fan starts at the patch face. Boundary: at the boundary, the face is sector
    // s. Crease: the sector's faces from its first sharp edge, as if the crease were the
    // boundary. Dart: at the sharp edge, the face is sector s.
    let (fan, sector) = if let Some(c) = crease {
        let sector = (0..c.faces)
            .map(|i| fan[(c.start + i) % fan.len()])
            .collect();
        (sector, c.sector)
    } else if boundary {
        (fan, position)
    } else if let Some((_, d)) = dart {
        let mut rotated = fan[d..].to_vec();
        rotated.extend_from_slice(&fan[..d]);
        (rotated, (position + fan.len() - d) % fan.len())
    } else {
        let mut rotated = fan[position..].to_vec();
        rotated.extend_from_slice(&fan[..position]);
        (rotated, 0)
    };
    let quad = |h: usize| -> Result<usize, MeshError> {
        let f = mesh.face_of[h] as usize;
        if mesh.face(f).len() == 4 {
            Ok(h)
        } else {
            Err(not_isolated(format!("face {f} next to it is not a quad")))
        }
    };
    // The layout's 2N + 8 points (one more on a boundary), in one allocation.
    let mut points = Vec::with_capacity(2 * fan.len() + 9);
    points.push(centre as u32);
    for &h in &fan {
        points.push(mesh.head(quad(h)?));
    }
    if boundary {
        // E_{f+1}: the start of the last face's edge into the centre.
        let last = *fan
            .last()
            .ok_or_else(|| not_isolated("isolated vertex".to_owned()))?;
        points.push(mesh.face_vertices[mesh.prev(last)]);
    }
    for &h in &fan {
        points.push(mesh.head(mesh.next(h)));
    }
    // Outer points, walking cells from the patch face. `across(h)` is the twin, if any.
    // A crease patch's side of the crease ends at it, as a boundary patch's at the boundary.
    let across = |h: usize| -> Result<Option<usize>, MeshError> {
        match mesh.twin[h] {
            NONE => Ok(None),
            _ if crease.is_some() && infinitely_sharp(mesh, h) => Ok(None),
            t => quad(t as usize).map(Some),
        }
    };
    let (next, head) = (|h: usize| mesh.next(h), |h: usize| mesh.head(h));
    // g1 = F_1 -> E_1 in the cell [1,2] x [0,1].
    let g1 = across(next(h0))?;
    let mut outer: [Option<u32>; 7] = [None; 7];
    if let Some(g1) = g1 {
        outer[1] = Some(head(next(g1)));
        outer[2] = Some(head(next(next(g1))));
        // Below the edge E_1 -> O_2: the cell [1,2] x [-1,0], where O_1 -> O_2 precedes O_2 -> E_1.
        if let Some(g0) = across(next(g1))? {
            outer[0] = Some(mesh.face_vertices[mesh.prev(g0)]);
        }
        // Above the edge O_3 -> F_1: the cell [1,2] x [1,2] = (F_1, O_3, O_4, O_5).
        if let Some(g2) = across(next(next(next(g1))))? {
            outer[3] = Some(head(next(g2)));
            outer[4] = Some(head(next(next(g2))));
            // Left of O_5 -> F_1: the cell [0,1] x [1,2] = (E_2, F_1, O_5, O_6).
            if let Some(g3) = across(next(next(next(g2))))? {
                outer[5] = Some(head(next(g3)));
                // Left of O_6 -> E_2: the cell [-1,0] x [1,2] = (F_2, E_2, O_6, O_7).
                if let Some(g4) = across(next(next(g3)))? {
                    outer[6] = Some(head(next(g4)));
                }
            }
        }
    }
    // A boundary patch lacks exactly O_1 in sector 0 and O_7 in the last sector; all else exists.
    let faces = fan.len() as u32;
    for (i, point) in outer.iter().enumerate() {
        let absent = boundary && ((i == 0 && sector == 0) || (i == 6 && sector + 1 == fan.len()));
        match (point, absent) {
            (Some(p), false) => points.push(*p),
            (None, true) => {}
            (Some(_), true) => {
                return Err(not_isolated(format!(
                    "outer point O{} exists beyond the boundary",
                    i + 1
                )))
            }
            (None, false) => {
                return Err(not_isolated(format!(
                    "outer point O{} is missing (a boundary too close)",
                    i + 1
                )))
            }
        }
    }
    Ok(FacePatch {
        kind: PatchKind {
            boundary,
            feature: if dart.is_some() {
                Feature::Dart
            } else {
                Feature::None
            },
            faces,
            sector: sector as u32,
        },
        points,
        corner,
    })
}

/// The patch parameters of face parameters `(u, v)` for a patch at face corner `corner`.
pub fn to_patch(corner: usize, u: f64, v: f64) -> (f64, f64) {
    match corner {
        0 => (u, v),
        1 => (v, 1.0 - u),
        2 => (1.0 - u, 1.0 - v),
        _ => (1.0 - v, u),
    }
}

/// The patch indices of the face's dual point `(i, j)` at rate `n` (the rotation of
/// [`to_patch`] on the dual grid).
pub fn dual_index_in_patch(corner: usize, i: usize, j: usize, n: usize) -> (usize, usize) {
    let last = n - 1;
    match corner {
        0 => (i, j),
        1 => (j, last - i),
        2 => (last - i, last - j),
        _ => (last - j, i),
    }
}

/// The limit positions at the dual points `((2i+1)/2n, (2j+1)/2n)` of the face, in the face's
/// own parameters, row by row (`j` outer): a direct table evaluation, one weighted sum of the
/// patch's control points per point.
pub fn dual_positions(
    table: &StencilTable,
    mesh: &Mesh,
    patch: &FacePatch,
    n: u32,
) -> Result<Vec<[f64; 3]>, RuntimeError> {
    let key = patch.kind.section(StencilKind::Position, PointSet::Dual, n);
    // A one-face boundary vertex is smooth in "edge only" mode and pinned in "edge and corner"
    // mode: its stencils must come from a table made for the mesh's mode.
    let corners = mesh.boundary == schemes::BoundaryMode::EdgeAndCorner;
    if patch.kind.boundary && patch.kind.faces == 1 && table.pins_corners() != corners {
        return Err(RuntimeError::BoundaryModeMismatch {
            mesh_corners: corners,
        });
    }
    let weights = table.weights(&key)?;
    let k = patch.points.len();
    let nu = n as usize;
    if weights.len() != nu * nu * k {
        return Err(RuntimeError::LayoutMismatch {
            key,
            table: weights.len() / (nu * nu).max(1),
            patch: k,
        });
    }
    let mut out = Vec::with_capacity(nu * nu);
    for j in 0..nu {
        for i in 0..nu {
            let (pi, pj) = dual_index_in_patch(patch.corner, i, j, nu);
            let row = &weights[(pj * nu + pi) * k..][..k];
            let mut p = [0.0; 3];
            for (w, &v) in row.iter().zip(&patch.points) {
                let q = mesh.positions[v as usize];
                for c in 0..3 {
                    p[c] += f64::from(*w) * q[c];
                }
            }
            out.push(p);
        }
    }
    Ok(out)
}
