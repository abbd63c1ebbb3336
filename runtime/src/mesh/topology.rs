//! Polygon-mesh topology: a compact half-edge structure over face-vertex lists, with the
//! validation a subdivision surface needs.
//!
//! Half-edge `h` is corner `h` of the flattened face-vertex array: it runs from
//! `face_vertices[h]` to the next corner of the same face. `twin[h]` is the half-edge running
//! the other way in the neighbouring face, or [`NONE`] on the boundary. A mesh is accepted when
//! every face has at least three distinct, existing vertices, every coordinate is finite, every
//! edge has one or two faces traversing it in opposite directions, and the faces around every
//! vertex form a single fan (a disc, or a half-disc at the boundary).
//!
//! The mesh also carries its sharp features (OpenSubdiv's component tags): a sharpness per edge
//! and per vertex, and the faces that are holes. Boundary edges are infinitely sharp, and in
//! "edge and corner" mode so is a boundary vertex with one face, as OpenSubdiv makes them
//! before the first refinement (`schemes::crease`).

use schemes::crease::{is_infinite, INFINITE};
use schemes::{BoundaryMode, CreaseMethod};

use crate::mesh::face_varying::FaceVarying;
use crate::MeshError;

/// "No half-edge": the twin of a boundary half-edge.
pub const NONE: u32 = u32::MAX;

/// What separates two consecutive faces around a vertex where the tessellators sample the
/// surface ([`Mesh::cut`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cut {
    /// Nothing: the surface is smooth across the edge.
    None,
    /// An infinitely sharp edge (or a face-varying seam): one surface, two sectors.
    Sector,
    /// The boundary or a hole: separate sheets of surface.
    Sheet,
}

/// A validated polygon mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Face `f` owns half-edges `face_offsets[f]..face_offsets[f + 1]`.
    pub face_offsets: Vec<u32>,
    /// The vertex each half-edge starts at.
    pub face_vertices: Vec<u32>,
    /// The opposite half-edge, or [`NONE`].
    pub twin: Vec<u32>,
    /// The face of each half-edge.
    pub face_of: Vec<u32>,
    /// One outgoing half-edge per vertex (on the boundary: the one with no twin, so that turning
    /// from it visits the whole fan); [`NONE`] for unused vertices.
    pub vertex_halfedge: Vec<u32>,
    /// The boundary rule.
    pub boundary: BoundaryMode,
    /// The sharpness of every half-edge's edge (twins equal; boundary edges infinite).
    pub edge_sharpness: Vec<f32>,
    /// The sharpness of every vertex (a pinned boundary corner infinite).
    pub vertex_sharpness: Vec<f32>,
    /// Whether each face is a hole: it shapes its neighbours but makes no surface.
    pub holes: Vec<bool>,
    /// How semi-sharp edges decay from level to level.
    pub creasing: CreaseMethod,
    /// The input vertex of every vertex after the input ones: copies made to split non-manifold
    /// vertices, one per extra fan (empty for a manifold mesh).
    pub copies: Vec<u32>,
    /// OpenSubdiv's "smooth triangles" option (`TRI_SUB_SMOOTH`): an edge next to a triangle
    /// weighs the triangle's centroid by 0.47 instead of 0.25, for rounder triangle regions.
    pub smooth_triangles: bool,
    /// Texture coordinates: one face-varying channel over the faces ([`FaceVarying`]), `None`
    /// without (and on refined meshes: the channel has its own mesh,
    /// `scheme::catmull_clark::face_varying::channel_mesh`).
    pub face_varying: Option<FaceVarying>,
}

/// The largest coordinate magnitude an input vertex may have (docs/reliability.md): output is
/// `f32` (at most 3.4e38), and each normal is the cross product of two `f32` tangents of about
/// the surface's size, which overflows near 1.8e19 (a cube scaled by 1e19 still got unit
/// normals, by 1e25 zero ones). Refinement combines at most a few points with weights of
/// bounded sum, so every refined position of an input within the bound stays finite in `f64`.
pub const MAX_COORDINATE: f64 = 1e18;

impl Mesh {
    /// Build and validate from faces given as vertex indices. `lines` (the faces' OBJ lines)
    /// only labels errors. Every coordinate must be finite and at most [`MAX_COORDINATE`] in
    /// magnitude.
    pub fn new(
        positions: Vec<[f64; 3]>,
        faces: &[Vec<i64>],
        lines: &[usize],
        boundary: BoundaryMode,
    ) -> Result<Self, MeshError> {
        let within = |c: &f64| c.abs() <= MAX_COORDINATE;
        let beyond = |p: &[f64; 3]| !p.iter().all(within);
        if let Some((vertex, p)) = positions.iter().enumerate().find(|(_, p)| beyond(p)) {
            return Err(if p.iter().all(|c| c.is_finite()) {
                MeshError::TooLarge {
                    vertex,
                    position: *p,
                    limit: MAX_COORDINATE,
                }
            } else {
                MeshError::NonFinite {
                    vertex,
                    position: *p,
                }
            });
        }
        Self::refined(positions, faces, lines, boundary)
    }

    /// [`Mesh::new`] for a mesh made by refining a valid one: its positions, combinations of
    /// input positions within [`MAX_COORDINATE`], may exceed it by a small factor (the
    /// butterfly's weights are not all positive) but are finite.
    pub(crate) fn refined(
        positions: Vec<[f64; 3]>,
        faces: &[Vec<i64>],
        lines: &[usize],
        boundary: BoundaryMode,
    ) -> Result<Self, MeshError> {
        if faces.is_empty() {
            return Err(MeshError::Empty);
        }
        if let Some((vertex, p)) = positions
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(MeshError::NonFinite {
                vertex,
                position: *p,
            });
        }
        let mut face_offsets = vec![0u32];
        let mut face_vertices = Vec::new();
        let mut face_of = Vec::new();
        for (f, face) in faces.iter().enumerate() {
            let bad = |reason: String| MeshError::BadFace {
                face: f,
                line: lines.get(f).copied().unwrap_or(0),
                reason,
            };
            if face.len() < 3 {
                return Err(bad(format!(
                    "it has {} vertices; a face needs at least 3",
                    face.len()
                )));
            }
            for &v in face {
                if v < 0 || v as usize >= positions.len() {
                    return Err(bad(format!(
                        "vertex index {} is out of range (the mesh has {} vertices)",
                        v + 1,
                        positions.len()
                    )));
                }
                face_vertices.push(v as u32);
                face_of.push(f as u32);
            }
            face_offsets.push(face_vertices.len() as u32);
        }
        let mut mesh = Mesh {
            vertex_halfedge: vec![NONE; positions.len()],
            vertex_sharpness: vec![0.0; positions.len()],
            positions,
            holes: vec![false; faces.len()],
            face_offsets,
            twin: vec![NONE; face_vertices.len()],
            edge_sharpness: vec![0.0; face_vertices.len()],
            face_vertices,
            face_of,
            boundary,
            creasing: CreaseMethod::Uniform,
            smooth_triangles: false,
            copies: Vec::new(),
            face_varying: None,
        };
        let non_manifold = mesh.link_twins()?;
        mesh.split_non_manifold(&non_manifold);
        mesh.refuse_repeats_in_one_fan(lines)?;
        mesh.sharpen_boundary();
        Ok(mesh)
    }

    /// A face that repeats a vertex is accepted when splitting the vertex into one copy per
    /// fan ([`Mesh::copies`]) leaves the face's corners different vertices (the doubled corner
    /// of `catmark_nonman_quadpole8`, whose degenerate edge is non-manifold). Corners that
    /// stay one vertex, because the faces around it join them into one fan, would make a
    /// face pass through one point twice inside a disc: refused, naming the face.
    fn refuse_repeats_in_one_fan(&self, lines: &[usize]) -> Result<(), MeshError> {
        let mut seen_in = vec![u32::MAX; self.positions.len()];
        for f in 0..self.faces() {
            for &v in self.face(f) {
                if seen_in[v as usize] == f as u32 {
                    let v = self.origin(v as usize);
                    return Err(MeshError::BadFace {
                        face: f,
                        line: lines.get(f).copied().unwrap_or(0),
                        reason: format!(
                            "vertex {} appears twice, and the faces around it join both \
                             corners into one fan (a face that repeats a vertex is accepted \
                             where its corners lie in different fans, as at a doubled corner)",
                            v + 1
                        ),
                    });
                }
                seen_in[v as usize] = f as u32;
            }
        }
        Ok(())
    }

    /// Make boundary edges infinitely sharp, and one-face boundary corners too in "edge and
    /// corner" mode (OpenSubdiv's `Crease::SharpenBoundaryEdge` and `SharpenBoundaryVertex`).
    pub(crate) fn sharpen_boundary(&mut self) {
        for h in 0..self.twin.len() {
            if self.twin[h] == NONE {
                self.edge_sharpness[h] = INFINITE;
            }
        }
        if self.boundary == BoundaryMode::EdgeAndCorner {
            for v in 0..self.positions.len() {
                if self.is_boundary_vertex(v) && self.fan_iter(v).count() == 1 {
                    self.vertex_sharpness[v] = INFINITE;
                }
            }
        }
    }

    /// Input vertex `v` and its copies ([`Mesh::copies`]).
    fn with_copies(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        let inputs = self.input_vertices();
        std::iter::once(v).chain(
            self.copies
                .iter()
                .enumerate()
                .filter(move |&(_, &o)| o as usize == v)
                .map(move |(i, _)| inputs + i),
        )
    }

    /// The half-edges between input vertices `a` and `b` (either way, any of their copies).
    pub fn find_halfedges(&self, a: usize, b: usize) -> Vec<usize> {
        if a >= self.input_vertices() || b >= self.input_vertices() {
            return Vec::new();
        }
        let mut out = Vec::new();
        for x in self.with_copies(a) {
            for h in self.vertex_edges(x) {
                if self.origin(self.opposite(h, x) as usize) == b {
                    out.push(h);
                }
            }
        }
        out
    }

    /// Set the sharpness of edge `(a, b)` of the input (all its half-edges); a boundary edge
    /// (a non-manifold one among them) stays infinitely sharp. Negative values count as 0, as
    /// in OpenSubdiv.
    pub fn set_edge_sharpness(&mut self, a: usize, b: usize, s: f32) -> Result<(), MeshError> {
        let halfedges = self.find_halfedges(a, b);
        if halfedges.is_empty() {
            return Err(MeshError::NoSuchEdge { a, b });
        }
        for h in halfedges {
            if self.twin[h] != NONE {
                let s = s.max(0.0);
                self.edge_sharpness[h] = s;
                self.edge_sharpness[self.twin[h] as usize] = s;
            }
        }
        Ok(())
    }

    /// Set the sharpness of input vertex `v` (and its copies); a corner pinned by the boundary
    /// rule or by non-manifold topology stays pinned.
    pub fn set_vertex_sharpness(&mut self, v: usize, s: f32) -> Result<(), MeshError> {
        if v >= self.input_vertices() {
            return Err(MeshError::NoSuchVertex { vertex: v });
        }
        let all: Vec<usize> = self.with_copies(v).collect();
        for w in all {
            if self.vertex_sharpness[w] < INFINITE {
                self.vertex_sharpness[w] = s.max(0.0);
            }
        }
        Ok(())
    }

    /// Whether any edge or vertex is sharp beyond what the boundary rule makes sharp, or any
    /// face is a hole: whether the mesh has features the smooth rules do not describe.
    pub fn has_sharp_features(&self) -> bool {
        let interior_sharp =
            (0..self.twin.len()).any(|h| self.twin[h] != NONE && self.edge_sharpness[h] > 0.0);
        let pinned = |v: usize| {
            self.boundary == BoundaryMode::EdgeAndCorner
                && self.is_boundary_vertex(v)
                && self.fan_iter(v).count() == 1
        };
        let sharp_vertex =
            (0..self.positions.len()).any(|v| self.vertex_sharpness[v] > 0.0 && !pinned(v));
        interior_sharp || sharp_vertex || self.holes.iter().any(|&h| h)
    }

    /// OpenSubdiv's "no boundary interpolation" (`interpolateboundary 0`): every face at an
    /// input vertex with a boundary edge that is not infinitely sharp by a tag becomes a hole
    /// (`sharp_boundary`: the edges so tagged, as sorted input vertex pairs).
    ///
    /// The test is on the input's topology, as `Far::TopologyRefinerFactory` makes it before
    /// any sharpening: an edge is on the boundary when one face uses it, and a vertex with
    /// such an edge loses every face around it, all its copies' ([`Mesh::copies`]) included.
    /// A doubled corner's degenerate edge (from a vertex to itself) is such an edge, as many
    /// faces as double the vertex (`catmark_nonman_quadpole8` under mode 0 has no surface).
    /// The edges a non-manifold split leaves with one face each on the split mesh (an edge
    /// of three or more faces) are not boundary edges there, and a non-manifold vertex with a
    /// true boundary edge loses its closed fans too (`catmark_val2_nonman` under
    /// `interpolateboundary 0` has no surface at all in OpenSubdiv).
    pub fn exclude_boundary_faces(&mut self, sharp_boundary: &[(usize, usize)]) {
        let mut sharp_boundary = sharp_boundary.to_vec();
        sharp_boundary.sort_unstable();
        let mut edges: Vec<(usize, usize)> = (0..self.faces())
            .flat_map(|f| {
                let corners = self.face(f);
                (0..corners.len()).map(move |k| (corners[k], corners[(k + 1) % corners.len()]))
            })
            .map(|(a, b)| (self.origin(a as usize), self.origin(b as usize)))
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        edges.sort_unstable();
        let mut excluded = vec![false; self.input_vertices()];
        for run in edges.chunk_by(|x, y| x == y) {
            let edge = run[0];
            // Vtr gives each degenerate edge of a face its own edge, whatever the faces.
            let one_face = run.len() == 1 || edge.0 == edge.1;
            if one_face && sharp_boundary.binary_search(&edge).is_err() {
                excluded[edge.0] = true;
                excluded[edge.1] = true;
            }
        }
        for f in 0..self.faces() {
            if self
                .face(f)
                .iter()
                .any(|&v| excluded[self.origin(v as usize)])
            {
                self.holes[f] = true;
            }
        }
    }

    /// The edges at vertex `v`, one half-edge each, in fan order: the fan's outgoing
    /// half-edges, then on the boundary the incoming boundary half-edge of the last face.
    pub fn vertex_edges(&self, v: usize) -> Vec<usize> {
        let mut edges = Vec::with_capacity(8);
        edges.extend(self.vertex_edges_iter(v));
        edges
    }

    /// [`Mesh::vertex_edges`] without allocating (the plan tests every face's corners with it
    /// each time it is made: a vector per corner was 7% of Spot's plan at `1e-3`).
    pub fn vertex_edges_iter(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        let closing = match self.is_boundary_vertex(v) {
            true => self.fan_iter(v).last().map(|last| self.prev(last)),
            false => None,
        };
        self.fan_iter(v).chain(closing)
    }

    /// The other end of half-edge `h`'s edge, seen from its end vertex `v`.
    pub fn opposite(&self, h: usize, v: usize) -> u32 {
        let tail = self.face_vertices[h];
        if tail as usize == v {
            self.head(h)
        } else {
            tail
        }
    }

    /// The input vertices' positions as the f32 control points a frame takes
    /// ([`crate::Tessellator::evaluate`]); copies of split vertices are not among them.
    pub fn positions_f32(&self) -> Vec<[f32; 3]> {
        self.positions[..self.input_vertices()]
            .iter()
            .map(|p| p.map(|c| c as f32))
            .collect()
    }

    /// Number of faces.
    pub fn faces(&self) -> usize {
        self.face_offsets.len() - 1
    }

    /// The half-edges of face `f`.
    pub fn face_halfedges(&self, f: usize) -> std::ops::Range<usize> {
        self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize
    }

    /// The vertices of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_halfedges(f)]
    }

    /// The next half-edge in the same face.
    pub fn next(&self, h: usize) -> usize {
        let f = self.face_of[h] as usize;
        if h + 1 == self.face_offsets[f + 1] as usize {
            self.face_offsets[f] as usize
        } else {
            h + 1
        }
    }

    /// The previous half-edge in the same face.
    pub fn prev(&self, h: usize) -> usize {
        let f = self.face_of[h] as usize;
        if h == self.face_offsets[f] as usize {
            self.face_offsets[f + 1] as usize - 1
        } else {
            h - 1
        }
    }

    /// Whether the edge of half-edge `h` is a seam of the texture coordinates
    /// ([`Mesh::face_varying`]): the faces on its two sides use different values at one of its
    /// ends. A boundary edge is not a seam, nor is any edge of a mesh without texture
    /// coordinates.
    pub fn is_seam(&self, h: usize) -> bool {
        let (Some(fvar), t) = (&self.face_varying, self.twin[h]) else {
            return false;
        };
        if t == NONE {
            return false;
        }
        let (c, t) = (&fvar.corners, t as usize);
        c[h] != c[self.next(t)] || c[self.next(h)] != c[t]
    }

    /// The vertex half-edge `h` ends at.
    pub fn head(&self, h: usize) -> u32 {
        self.face_vertices[self.next(h)]
    }

    /// Outgoing half-edges of vertex `v` in fan order (counter-clockwise for faces listed
    /// counter-clockwise), starting at [`Mesh::vertex_halfedge`]; empty for unused vertices.
    pub fn fan(&self, v: usize) -> Vec<usize> {
        // Sized for the common valences at once: collected from the iterator, whose length is
        // unknown, the vector grew twice for a valence of 6 (two allocations and a copy, about
        // a seventh of Loop's isolation of the triangulated Spot).
        let mut fan = Vec::with_capacity(8);
        fan.extend(self.fan_iter(v));
        fan
    }

    /// [`Mesh::fan`] without allocating.
    pub fn fan_iter(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        let start = self.vertex_halfedge[v];
        let mut next = (start != NONE).then_some(start as usize);
        std::iter::from_fn(move || {
            let h = next?;
            // The half-edge into v in this face, then across to the next face's outgoing one.
            let t = self.twin[self.prev(h)];
            next = (t != NONE && t != start).then_some(t as usize);
            Some(h)
        })
    }

    /// The number of faces around every vertex (`fan(v).len()`, 0 for unused vertices), in
    /// one pass over the faces: validation made the faces around a vertex one fan, so they are
    /// the faces it appears in.
    pub fn valences(&self) -> Vec<usize> {
        let mut valence = vec![0; self.positions.len()];
        for &v in &self.face_vertices {
            valence[v as usize] += 1;
        }
        valence
    }

    /// What the tessellators' sampling separates across the edge of half-edge `h`: the
    /// boundary and a hole's side part separate sheets of surface, an infinitely sharp edge
    /// (or a face-varying seam, `seam`) two sectors of one sheet, each sampled as a limit curve
    /// that both sides' strips meet. Around a vertex, the edge of fan face `i` lies between it
    /// and fan face `i - 1`, so this is the cut before fan face `i` (the boundary before the
    /// first face of an open fan, whose first half-edge has no twin).
    pub(crate) fn cut(&self, h: usize, seam: bool) -> Cut {
        let t = self.twin[h];
        if t == NONE
            || self.holes[self.face_of[h] as usize]
            || self.holes[self.face_of[t as usize] as usize]
        {
            Cut::Sheet
        } else if is_infinite(self.edge_sharpness[h]) || seam {
            Cut::Sector
        } else {
            Cut::None
        }
    }

    /// Whether vertex `v` is the tip of a cone: pinned (infinitely sharp: a `corner` tag, a
    /// non-manifold vertex's copy), with at least three faces around it and no `Mesh::cut`
    /// (boundary, hole, infinitely sharp edge) reaching it. Its limit point is the vertex
    /// itself, where the surface has no tangent plane (a normal there is a choice: those of
    /// points approaching it converge like `e^0.07`, docs/results.md). The corner points of the
    /// faces around would cut the tip off by a distance of the order of the sampling step, not
    /// its square as at a smooth vertex, so the tessellators close the fan around the limit
    /// point, as a wheel. A pinned vertex of two faces has no polygon to close (the strips across
    /// its two edges meet).
    pub fn is_cone_tip(&self, v: usize) -> bool {
        if !is_infinite(self.vertex_sharpness[v]) {
            return false;
        }
        let fan = self.fan(v);
        fan.len() >= 3 && fan.iter().all(|&h| self.cut(h, false) == Cut::None)
    }

    /// Whether vertex `v` is on the boundary.
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        let h = self.vertex_halfedge[v];
        h != NONE && self.twin[h as usize] == NONE
    }

    fn link_twins(&mut self) -> Result<Vec<usize>, MeshError> {
        // Half-edges grouped by tail (counting sort): a twin is found among its head's few
        // outgoing half-edges, without hashing every directed edge.
        let halfedges = self.face_vertices.len();
        let mut start = vec![0u32; self.positions.len() + 1];
        for &v in &self.face_vertices {
            start[v as usize + 1] += 1;
        }
        for v in 0..self.positions.len() {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut outgoing = vec![0u32; halfedges];
        for (h, &v) in self.face_vertices.iter().enumerate() {
            outgoing[fill[v as usize] as usize] = h as u32;
            fill[v as usize] += 1;
        }
        let leaving =
            |v: u32| &outgoing[start[v as usize] as usize..start[v as usize + 1] as usize];
        // An edge is manifold when exactly two half-edges of two different faces use it, one
        // each way; any other use (three faces or more, two the same way, both ways in one
        // face, or a degenerate edge from a vertex to itself in a face that repeats it) leaves
        // all its half-edges unlinked, to be split apart with their vertices
        // (`split_non_manifold`), as OpenSubdiv's Vtr makes each such edge non-manifold.
        let mut non_manifold = Vec::new();
        for h in 0..halfedges {
            let (a, b) = (self.face_vertices[h], self.head(h));
            let same = leaving(a)
                .iter()
                .filter(|&&g| self.head(g as usize) == b)
                .count();
            let mut reverse = leaving(b).iter().filter(|&&g| self.head(g as usize) == a);
            match (same, reverse.next(), reverse.next()) {
                (1, Some(&t), None) if a != b && self.face_of[t as usize] != self.face_of[h] => {
                    self.twin[h] = t
                }
                (1, None, None) => {}
                _ => non_manifold.push(h),
            }
        }
        Ok(non_manifold)
    }

    /// One outgoing half-edge per vertex, a boundary one where there is one, so that turning
    /// from it visits the whole fan.
    fn pick_vertex_halfedges(&mut self) {
        self.vertex_halfedge = vec![NONE; self.positions.len()];
        for (h, &v) in self.face_vertices.iter().enumerate() {
            let current = self.vertex_halfedge[v as usize];
            if current == NONE || (self.twin[h] == NONE && self.twin[current as usize] != NONE) {
                self.vertex_halfedge[v as usize] = h as u32;
            }
        }
    }

    /// Split non-manifold vertices as OpenSubdiv's surfaces split there: a vertex whose faces
    /// form several fans (a bowtie, or the ends of a non-manifold edge, whose half-edges
    /// `non_manifold` were left unlinked) gets one vertex per fan, the copies appended and
    /// recorded in [`Mesh::copies`]. The vertex and its copies are made infinitely sharp
    /// corners (OpenSubdiv's sharpening of non-manifold vertices), except along a non-manifold
    /// crease: exactly two non-manifold edges and no boundary edge, where every copy follows
    /// the crease rule along them.
    fn split_non_manifold(&mut self, non_manifold: &[usize]) {
        self.pick_vertex_halfedges();
        let original = self.positions.len();
        let mut outgoing: Vec<Vec<usize>> = vec![Vec::new(); original];
        for (h, &v) in self.face_vertices.iter().enumerate() {
            outgoing[v as usize].push(h);
        }
        let mut sharpen: Vec<usize> = Vec::new();
        for (v, all) in outgoing.iter().enumerate() {
            if all.is_empty() || self.fan_iter(v).count() == all.len() {
                continue;
            }
            // Group the outgoing half-edges into fans: back to a fan's start, then forward.
            let mut fan_of = vec![usize::MAX; all.len()];
            let mut fans: Vec<Vec<usize>> = Vec::new();
            for (i, &h) in all.iter().enumerate() {
                if fan_of[i] != usize::MAX {
                    continue;
                }
                let mut start = h;
                loop {
                    let t = self.twin[start];
                    if t == NONE {
                        break;
                    }
                    let back = self.next(t as usize);
                    if back == h {
                        break;
                    }
                    start = back;
                }
                let mut fan = vec![start];
                let mut g = start;
                loop {
                    let t = self.twin[self.prev(g)];
                    if t == NONE || t as usize == start {
                        break;
                    }
                    g = t as usize;
                    fan.push(g);
                }
                for &g in &fan {
                    // `all` lists the half-edges in increasing order.
                    if let Ok(j) = all.binary_search(&g) {
                        fan_of[j] = fans.len();
                    }
                }
                fans.push(fan);
            }
            for fan in fans.iter().skip(1) {
                let copy = self.positions.len() as u32;
                self.positions.push(self.positions[v]);
                self.copies.push(v as u32);
                for &h in fan {
                    self.face_vertices[h] = copy;
                }
            }
            sharpen.push(v);
        }
        // Ends of non-manifold edges whose faces still form one fan are non-manifold too.
        let mut is_sharpened = vec![false; original];
        for &v in &sharpen {
            is_sharpened[v] = true;
        }
        let mut non_manifold_edges: Vec<Vec<(usize, usize)>> = vec![Vec::new(); original];
        // Ends of an edge that only one face uses, degenerate (from a vertex to itself) or
        // run both ways in one face: OpenSubdiv gives each such use its own one-face edge, a
        // boundary edge, which rules out the non-manifold crease at its ends.
        let mut lone_edge = vec![false; original];
        for &h in non_manifold {
            let origin = |g: usize| self.origin(self.face_vertices[g] as usize);
            let (a, b) = (origin(h), self.origin(self.head(h) as usize));
            let lone = a == b
                || self
                    .face_halfedges(self.face_of[h] as usize)
                    .any(|g| origin(g) == b && origin(self.next(g)) == a);
            for v in [a, b] {
                is_sharpened[v] = true;
                lone_edge[v] |= lone;
                non_manifold_edges[v].push((a.min(b), a.max(b)));
            }
        }
        let mut manifold_boundary = lone_edge;
        for h in 0..self.twin.len() {
            if self.twin[h] == NONE && non_manifold.binary_search(&h).is_err() {
                manifold_boundary[self.origin(self.face_vertices[h] as usize)] = true;
                manifold_boundary[self.origin(self.head(h) as usize)] = true;
            }
        }
        self.vertex_sharpness.resize(self.positions.len(), 0.0);
        for w in 0..self.positions.len() {
            let v = self.origin(w);
            if !is_sharpened[v] {
                continue;
            }
            let edges = &mut non_manifold_edges[v];
            edges.sort_unstable();
            edges.dedup();
            let crease = edges.len() == 2 && !manifold_boundary[v];
            if !crease {
                self.vertex_sharpness[w] = INFINITE;
            }
        }
        self.pick_vertex_halfedges();
    }

    /// The input vertex vertex `v` stands for: itself, or the vertex it is a copy of.
    pub fn origin(&self, v: usize) -> usize {
        let inputs = self.positions.len() - self.copies.len();
        if v < inputs {
            v
        } else {
            self.copies[v - inputs] as usize
        }
    }

    /// Number of input vertices: the mesh's vertices without the copies that split
    /// non-manifold vertices.
    pub fn input_vertices(&self) -> usize {
        self.positions.len() - self.copies.len()
    }

    /// Number of loops of the surface's boundary: the boundary edges of faces that are not
    /// holes, and the edges between such faces and holes. Each is followed to the next one
    /// leaving its head, turning through the surface faces around the head.
    pub fn boundary_loops(&self) -> usize {
        let surface = |h: usize| !self.holes[self.face_of[h] as usize];
        let rim =
            |h: usize| surface(h) && (self.twin[h] == NONE || !surface(self.twin[h] as usize));
        let mut seen = vec![false; self.face_vertices.len()];
        let mut loops = 0;
        for h in 0..self.face_vertices.len() {
            if !rim(h) || seen[h] {
                continue;
            }
            loops += 1;
            let mut e = h;
            while !seen[e] {
                seen[e] = true;
                let mut g = self.next(e);
                while !rim(g) {
                    g = self.next(self.twin[g] as usize);
                }
                e = g;
            }
        }
        loops
    }

    /// Euler characteristic V - E + F of the surface the tessellators make: the faces that
    /// are not holes, the edges they use, and every vertex once per run of such faces around
    /// it (holes that leave a vertex two separate runs of faces make it two surface points).
    /// Without holes: every used vertex, every edge, every face.
    pub fn euler_characteristic(&self) -> i64 {
        let surface = |h: usize| !self.holes[self.face_of[h] as usize];
        let mut edges = 0i64;
        for h in (0..self.face_vertices.len()).filter(|&h| surface(h)) {
            let t = self.twin[h];
            if t == NONE || !surface(t as usize) || h < t as usize {
                edges += 1;
            }
        }
        let points: i64 = (0..self.positions.len())
            .map(|v| {
                let fan = self.fan(v);
                let kept: Vec<bool> = fan.iter().map(|&h| surface(h)).collect();
                // Runs start where a kept face follows a dropped one (or the boundary).
                let starts = (0..kept.len())
                    .filter(|&i| {
                        let before = if i == 0 {
                            (!self.is_boundary_vertex(v)).then(|| kept[kept.len() - 1])
                        } else {
                            Some(kept[i - 1])
                        };
                        kept[i] && before != Some(true)
                    })
                    .count();
                // A closed fan kept whole is one run without a start.
                let whole = !kept.is_empty() && kept.iter().all(|&k| k) && starts == 0;
                (starts + usize::from(whole)) as i64
            })
            .sum();
        let faces = self.holes.iter().filter(|&&hole| !hole).count() as i64;
        points - edges + faces
    }
}

/// Give every vertex whose faces (in `faces`) form several edge-connected fans one vertex per
/// fan: the extra copies are appended, and `origin` (the source vertex of every vertex, one
/// entry per vertex already) grows with them. A fan here is a maximal set of faces around the
/// vertex joined through edges at it.
pub fn split_fans(faces: &mut [Vec<i64>], origin: &mut Vec<u32>) {
    use std::collections::HashMap;
    // Corners, numbered in face order; corners at one vertex sharing an edge are joined.
    let mut corner_of: Vec<(usize, usize)> = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        corner_of.extend((0..face.len()).map(|i| (f, i)));
    }
    let mut parent: Vec<usize> = (0..corner_of.len()).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut by_edge: HashMap<(i64, i64), usize> = HashMap::new();
    for (c, &(f, i)) in corner_of.iter().enumerate() {
        let face = &faces[f];
        let v = face[i];
        for w in [
            face[(i + 1) % face.len()],
            face[(i + face.len() - 1) % face.len()],
        ] {
            match by_edge.get(&(v, w)) {
                Some(&other) => {
                    let (a, b) = (root(&mut parent, c), root(&mut parent, other));
                    parent[a] = b;
                }
                None => {
                    by_edge.insert((v, w), c);
                }
            }
        }
    }
    // The first fan of a vertex keeps it; each further fan gets a copy.
    let mut copy_of_root: HashMap<usize, i64> = HashMap::new();
    let mut first_root: HashMap<i64, usize> = HashMap::new();
    for (c, &(f, i)) in corner_of.iter().enumerate() {
        let v = faces[f][i];
        let r = root(&mut parent, c);
        let kept = *first_root.entry(v).or_insert(r);
        if kept != r {
            let copy = *copy_of_root.entry(r).or_insert_with(|| {
                origin.push(origin[v as usize]);
                origin.len() as i64 - 1
            });
            faces[f][i] = copy;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `interpolateboundary 0` on a non-manifold edge: a pillow (two quads back to back) with
    /// two flaps on its edge 1-2, so that the edge has four faces and vertices 1 and 2 have the
    /// flaps' boundary edges. OpenSubdiv (`Far::TopologyRefinerFactory`) takes every face at a
    /// vertex with an untagged boundary edge out, the pillow's included (the shape
    /// `catmark_val2_nonman` under mode 0 has no patch in OpenSubdiv). On this mesh the rule
    /// decided after the split takes every face out too; what tells the two apart is the second
    /// case: with the flaps' boundary edges tagged infinitely sharp, no face goes here, while
    /// the split's own boundary edges took every face before (checked by swapping the old rule
    /// back in; `catmark_val2_nonman` shows the other difference, closed fans kept).
    #[test]
    fn no_boundary_interpolation_decides_on_the_input_edges() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.5],
            [2.0, 1.0, 0.5],
            [2.0, 0.0, -0.5],
            [2.0, 1.0, -0.5],
        ];
        let faces = [
            vec![0, 1, 2, 3],
            vec![3, 2, 1, 0],
            vec![1, 4, 5, 2],
            vec![2, 7, 6, 1],
        ];
        let mesh = Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a mesh");
        assert!(!mesh.copies.is_empty(), "edge 1-2 is non-manifold");
        let mut none = mesh.clone();
        none.exclude_boundary_faces(&[]);
        assert_eq!(none.holes, vec![true; 4]);
        let mut tagged = mesh.clone();
        tagged.exclude_boundary_faces(&[(1, 4), (4, 5), (2, 5), (1, 6), (6, 7), (2, 7)]);
        assert_eq!(tagged.holes, vec![false; 4]);
    }

    /// `interpolateboundary 0` at doubled corners (`catmark_nonman_quadpole8`'s pole, made
    /// small): a ring of quads `r_i r_i+1 h h` around `h` inside a strip whose outer ring is the
    /// boundary. Every inner vertex `r_i` is interior, so only `h`'s degenerate edges can take
    /// the pole's faces out: Vtr gives each its own edge of one face, a boundary edge, and
    /// OpenSubdiv has no patch there (measured on the shape under mode 0).
    #[test]
    fn no_boundary_interpolation_takes_the_faces_at_a_doubled_corner() {
        let ring = |r: f64, z: f64| [[r, 0.0, z], [0.0, r, z], [-r, 0.0, z], [0.0, -r, z]];
        let mut positions: Vec<[f64; 3]> = ring(2.0, 0.0).into_iter().collect();
        positions.extend(ring(1.0, 0.2));
        positions.push([0.0, 0.0, 0.5]);
        let (outer, inner, hub) = (|i: i64| i % 4, |i: i64| 4 + i % 4, 8);
        let mut faces: Vec<Vec<i64>> = (0..4)
            .map(|i| vec![outer(i), outer(i + 1), inner(i + 1), inner(i)])
            .collect();
        faces.extend((0..4).map(|i| vec![inner(i), inner(i + 1), hub, hub]));
        let mut mesh = Mesh::new(positions, &faces, &[], BoundaryMode::EdgeOnly).expect("a pole");
        mesh.exclude_boundary_faces(&[]);
        assert_eq!(mesh.holes, vec![true; 8]);
    }

    /// A cone's tip: pinned, three faces or more, no cut around it. A sharp edge, a hole or the
    /// boundary at the vertex, or a vertex sharpness short of infinite, makes it none.
    #[test]
    fn a_cone_tip_is_a_pinned_vertex_no_cut_reaches() {
        let octahedron = crate::mesh::test_meshes::octahedron;
        let mut m = octahedron();
        assert!(!m.is_cone_tip(4));
        m.set_vertex_sharpness(4, 9.5).expect("a vertex");
        assert!(!m.is_cone_tip(4), "semi-sharp: smooth in the limit");
        m.set_vertex_sharpness(4, INFINITE).expect("a vertex");
        assert!(m.is_cone_tip(4));
        assert!(!m.is_cone_tip(0), "not pinned");
        let mut creased = m.clone();
        creased.set_edge_sharpness(4, 0, INFINITE).expect("an edge");
        assert!(!creased.is_cone_tip(4), "a sharp edge cuts the fan");
        let mut holed = m.clone();
        holed.holes[0] = true;
        assert!(!holed.is_cone_tip(4), "a hole cuts the fan");
        // The 2 x 2 grid without its last face: its middle vertex has three faces and the
        // boundary.
        let (p, mut f) = grid(2);
        f.pop();
        let mut open = Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("an L of quads");
        open.set_vertex_sharpness(4, INFINITE).expect("a vertex");
        assert_eq!(open.fan(4).len(), 3);
        assert!(!open.is_cone_tip(4), "the boundary cuts the fan");
    }

    fn grid(n: i64) -> (Vec<[f64; 3]>, Vec<Vec<i64>>) {
        let positions = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| [i as f64, j as f64, 0.0]))
            .collect();
        let faces = (0..n)
            .flat_map(|j| {
                (0..n).map(move |i| {
                    let v = j * (n + 1) + i;
                    vec![v, v + 1, v + n + 2, v + n + 1]
                })
            })
            .collect();
        (positions, faces)
    }

    #[test]
    fn a_grid_has_boundary_fans_and_euler_characteristic_one() {
        let (p, f) = grid(3);
        let m = Mesh::new(p, &f, &[], BoundaryMode::EdgeOnly).expect("valid");
        assert_eq!(m.euler_characteristic(), 1);
        assert_eq!(m.fan(5).len(), 4); // interior
        assert_eq!(m.fan(1).len(), 2); // boundary edge vertex
        assert_eq!(m.fan(0).len(), 1); // corner
        assert!(m.is_boundary_vertex(1) && !m.is_boundary_vertex(5));
    }

    #[test]
    fn each_defect_is_named() {
        let (p, f) = grid(1);
        assert_eq!(
            Mesh::new(p.clone(), &[], &[], BoundaryMode::EdgeOnly),
            Err(MeshError::Empty)
        );
        let mut bad = p.clone();
        bad[2][1] = f64::NAN;
        assert!(matches!(
            Mesh::new(bad, &f, &[], BoundaryMode::EdgeOnly),
            Err(MeshError::NonFinite { vertex: 2, .. })
        ));
        for c in [1.5e18, -1e30, 1e308, f64::MAX] {
            let mut far = p.clone();
            far[1][0] = c;
            let e = Mesh::new(far, &f, &[], BoundaryMode::EdgeOnly).expect_err("beyond the bound");
            assert!(matches!(e, MeshError::TooLarge { vertex: 1, .. }), "{e}");
            assert!(e.to_string().contains("OBJ `v` number 2"), "{e}");
        }
        let mut inf = p.clone();
        inf[1][0] = f64::INFINITY;
        assert!(matches!(
            Mesh::new(inf, &f, &[], BoundaryMode::EdgeOnly),
            Err(MeshError::NonFinite { vertex: 1, .. })
        ));
        let mut edge = p.clone();
        edge[1][0] = -MAX_COORDINATE;
        Mesh::new(edge, &f, &[], BoundaryMode::EdgeOnly).expect("at the bound");
        let e = Mesh::new(p.clone(), &[vec![0, 1]], &[7], BoundaryMode::EdgeOnly)
            .expect_err("two vertices");
        assert!(matches!(
            e,
            MeshError::BadFace {
                face: 0,
                line: 7,
                ..
            }
        ));
        let e = Mesh::new(p.clone(), &[vec![0, 1, 9]], &[], BoundaryMode::EdgeOnly)
            .expect_err("out of range");
        assert!(e.to_string().contains("out of range"), "{e}");
    }

    /// A doubled corner (`catmark_nonman_quadpole8`'s quads) is OpenSubdiv's degenerate edge:
    /// non-manifold, so infinitely sharp, and its vertex pinned; splitting the vertex per fan
    /// leaves the face with two corners at one position.
    #[test]
    fn a_doubled_corner_is_a_degenerate_pinned_edge() {
        let (p, _) = grid(1);
        let m = Mesh::new(p, &[vec![0, 1, 1, 2]], &[], BoundaryMode::EdgeOnly).expect("accepted");
        assert_eq!(m.copies, vec![1]);
        assert_eq!(m.face(0), &[0, 1, 4, 2]);
        assert_eq!(m.positions[4], m.positions[1]);
        assert!(m.twin.iter().all(|&t| t == NONE));
        assert!(m.edge_sharpness.iter().all(|&s| s == INFINITE));
        assert_eq!(m.vertex_sharpness[1], INFINITE);
        assert_eq!(m.vertex_sharpness[4], INFINITE);
        assert_eq!(m.vertex_sharpness[0], 0.0);
        assert_eq!(m.boundary_loops(), 1);
    }

    /// A face that passes twice through a vertex whose other faces join both corners into one
    /// fan (here a closed, pinched sphere: `(v, 1, 2, v, 3, 4)` with two triangles filling the
    /// gaps) cannot be split per fan: refused, naming the face and the vertex.
    #[test]
    fn corners_of_one_face_in_one_fan_are_refused() {
        let p = vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
        ];
        let faces = vec![vec![0, 1, 2, 0, 3, 4], vec![0, 4, 3], vec![0, 2, 1]];
        let e = Mesh::new(p, &faces, &[11, 12, 13], BoundaryMode::EdgeOnly).expect_err("pinched");
        assert!(
            matches!(
                e,
                MeshError::BadFace {
                    face: 0,
                    line: 11,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("vertex 1 appears twice"), "{e}");
    }

    /// Non-manifold input is split as OpenSubdiv's surfaces split: a non-manifold edge leaves
    /// every face its own copy of the edge (infinitely sharp), its ends one vertex per fan, all
    /// pinned corners; a bowtie vertex one vertex per fan, pinned.
    #[test]
    fn non_manifold_vertices_split_into_pinned_copies() {
        let (p, _) = grid(1);
        // Three faces on edge (0, 1).
        let mut p3 = p.clone();
        p3.push([0.5, -1.0, 0.0]);
        p3.push([0.5, 0.0, 1.0]);
        let faces = vec![vec![0, 1, 3, 2], vec![1, 0, 4], vec![0, 1, 5]];
        let m = Mesh::new(p3, &faces, &[], BoundaryMode::EdgeOnly).expect("split");
        assert_eq!(m.input_vertices(), 6);
        assert_eq!(m.copies, vec![0, 0, 1, 1]);
        assert!(m.twin.iter().all(|&t| t == NONE));
        for v in 0..m.positions.len() {
            let expected = if m.origin(v) <= 1 { INFINITE } else { 0.0 };
            assert_eq!(m.vertex_sharpness[v], expected, "vertex {v}");
            // Every vertex is one fan now.
            assert_eq!(
                m.fan(v).len(),
                m.face_vertices.iter().filter(|&&w| w as usize == v).count()
            );
        }
        assert_eq!(m.euler_characteristic(), 3);
        // Two triangles touching at one vertex only.
        let p2 = vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        let m = Mesh::new(
            p2,
            &[vec![0, 1, 2], vec![0, 3, 4]],
            &[],
            BoundaryMode::EdgeOnly,
        )
        .expect("split");
        assert_eq!(m.copies, vec![0]);
        assert_eq!(m.vertex_sharpness[0], INFINITE);
        assert_eq!(m.vertex_sharpness[5], INFINITE);
        assert_eq!(m.boundary_loops(), 2);
    }
}
