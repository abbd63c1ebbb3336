//! The dual-grid watertight tessellator for triangle schemes (Loop), per-face rates, closed
//! meshes and meshes with boundary (Schaefer–Warren section 5.5, the paragraph on triangle
//! schemes).
//!
//! The dual of a triangle grid is a hexagonal tiling, so the hexagons are fanned at the primal
//! point they surround, evaluated on the limit surface (the paper's second option, which keeps
//! every output vertex on the surface). A triangle at rate `n` gets its `n^2` dual points (the
//! centroids of the small triangles, `crate::scheme::triangle::patch`) and its `(n-1)(n-2)/2` interior
//! primal points `(i/n, j/n)`, `i, j >= 1`, `i + j <= n - 1`, evaluated once from the table.
//! Polygons connect them:
//!
//! * triangle interiors: the hexagon of the six dual points around each interior primal point,
//!   fanned at it: `3(n-1)(n-2)` triangles;
//! * interior edges: each triangle's zigzag row along the edge (the `2n - 1` dual points of the
//!   small triangles touching it, the `t`-th at parameter `(t+1)/2n` along the edge) is merged
//!   with the neighbour's, whatever the two rates (`2n + 2m - 4` triangles), as the quad rows are
//!   ([`crate::tessellate::dual_grid`]);
//! * boundary edges: the zigzag row and the `n + 1` points `t/n` of the limit boundary curve over
//!   the edge (`3n - 2` triangles); the curve's interior points belong to the edge, its end points
//!   (the boundary vertices' limit points) to the vertices;
//! * vertices: the corner dual points of the `v` triangles around an interior vertex form a
//!   `v`-gon, fanned at the vertex's limit point (`v` triangles); on a boundary vertex with `k`
//!   triangles the fan of the limit point and the `k` corner points (`k - 1` triangles).
//!
//! The zigzag rows of two sides of a triangle share their first two points at the corner
//! between them (the corner triangle's centroid and the next one's): the segment between them
//! is used once by each side's strip, from opposite sides, so the output stays manifold.
//! Every output vertex is made exactly once and every polygon refers to it by index: the output
//! is watertight by construction, nothing is welded by distance.
//!
//! As for quads, a [`TriangleDualGrid`] plan is built once per mesh and rates (patches, table
//! sections, the rotation of every face point into its patch, connectivity), then every frame
//! evaluates all points ([`TriangleDualGrid::evaluate`]) and writes all triangles
//! ([`TriangleDualGrid::connect`]), both in parallel with rayon over disjoint output slices.

use std::collections::HashMap;
use std::ops::Range;
use std::time::Instant;

use table_format::{PointSet, SectionKey, StencilKind};

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use crate::scheme::triangle::patch::{
    dual_in_patch, dual_index, primal_in_patch, primal_index, Phantoms, TrianglePatch,
};
pub use crate::stencil_table::TriangleStencils;
use crate::tessellate::kernel::{
    append_control, for_each_range, merge_rows, patch_origin, relative, total_bytes, vec_bytes,
    Connectivity, GridPlan, PointPlan, Stencils, TessellationTime,
};
use crate::tessellate::lane_stencils::{LaneStencils, PointGroups};
use crate::tessellate::loop_quartic::{self, QuarticBasis};
use crate::RuntimeError;

/// The largest patch (control points) the evaluator takes: an interior vertex of valence `v`
/// has `v + 6`, a boundary vertex with `k` triangles at most `k + 7`; a butterfly region at
/// most 33 (`3K + 9` at valence 8); a √3 boundary patch every fan point within four edges of
/// its corners (`crate::scheme::sqrt3::boundary_patch`).
const MAX_TRIANGLE_PATCH: usize = 128;

/// The largest rate the evaluator takes.
pub const MAX_TRIANGLE_RATE: u32 = 64;

/// How one triangle's points are evaluated: its control points, and its table stencils in the
/// face's own point order ([`LaneStencils`], shared by every face of the same section, corner
/// and rate).
#[derive(Clone, Debug)]
struct FacePlan {
    lanes: u32,
    control: Range<u32>,
    corner: u8,
    /// A regular Loop patch whose rate's stencils the quartic reproduces: evaluated as one
    /// polynomial ([`crate::tessellate::loop_quartic`]).
    quartic: bool,
}

/// A triangle's zigzag row along one of its sides: the `2n - 1` dual points of the small
/// triangles touching side `side` (`0`: corner 0 to 1, `1`: 1 to 2, `2`: 2 to 0), in the side's
/// direction or reversed.
#[derive(Clone, Copy, Debug)]
struct Zigzag {
    first: u32,
    n: u32,
    side: u8,
    reversed: bool,
}

impl Zigzag {
    fn len(&self) -> u32 {
        2 * self.n - 1
    }

    fn at(&self, t: u32) -> u32 {
        let t = if self.reversed { self.len() - 1 - t } else { t };
        let (i, j, down) = zigzag_cell(self.n, self.side, t);
        self.first + dual_index(self.n, i, j, down) as u32
    }
}

/// The small triangle `(i, j, down)` of point `t` of the zigzag along side `side` at rate `n`:
/// ups touch the side, downs touch it at a point.
pub(crate) fn zigzag_cell(n: u32, side: u8, t: u32) -> (u32, u32, bool) {
    let (half, down) = (t / 2, t % 2 == 1);
    match (side, down) {
        (0, _) => (half, 0, down),
        (1, false) => (n - 1 - half, half, false),
        (1, true) => (n - 2 - half, half, true),
        (_, false) => (0, n - 1 - half, false),
        (_, true) => (0, n - 2 - half, true),
    }
}

/// One edge's strip.
#[derive(Clone, Copy, Debug)]
enum TriangleStrip {
    /// Between two triangles: both rows run along the edge in the same direction, the second to
    /// its right.
    Interior { left: Zigzag, right: Zigzag },
    /// Along the boundary: the triangle's row and the curve points `t/n`: `tail`, the edge's own
    /// `n - 1` points from `first`, `head`.
    Boundary {
        row: Zigzag,
        tail: u32,
        first: u32,
        head: u32,
    },
}

impl TriangleStrip {
    fn triangles(&self) -> usize {
        match self {
            TriangleStrip::Interior { left, right } => (left.len() + right.len() - 2) as usize,
            TriangleStrip::Boundary { row, .. } => (3 * row.n - 2) as usize,
        }
    }

    fn connect(&self, out: &mut [[u32; 3]]) {
        match *self {
            TriangleStrip::Interior { left, right } => {
                // Point t of a zigzag of a rate-n triangle sits at (t + 1)/2n along the edge.
                let (n, m) = (u64::from(left.n), u64::from(right.n));
                merge_rows(
                    |i| left.at(i),
                    left.len(),
                    |i| (u64::from(i) + 1) * m,
                    |j| right.at(j),
                    right.len(),
                    |j| (u64::from(j) + 1) * n,
                    out,
                );
            }
            TriangleStrip::Boundary {
                row,
                tail,
                first,
                head,
            } => {
                let n = row.n;
                // Zigzag points at (t + 1)/2n, curve points at t/n = 2t/2n.
                merge_rows(
                    |i| row.at(i),
                    row.len(),
                    |i| u64::from(i) + 1,
                    |j| match j {
                        0 => tail,
                        j if j == n => head,
                        j => first + j - 1,
                    },
                    n + 1,
                    |j| 2 * u64::from(j),
                    out,
                );
            }
        }
    }
}

/// Interior primal points of a triangle at rate `n`.
fn interior_points(n: u32) -> u32 {
    let m = n.saturating_sub(1);
    m * m.saturating_sub(1) / 2
}

/// Index of the interior primal point `(i, j)` (`i, j >= 1`, `i + j <= n - 1`) among a
/// triangle's interior points, row by row.
fn interior_index(n: u32, i: u32, j: u32) -> u32 {
    // Row j' >= 1 holds n - 1 - j' points.
    (j - 1) * (n - 1) - (j - 1) * j / 2 + i - 1
}

/// The per-mesh plan of a triangle dual-grid tessellation: build once, then
/// [`TriangleDualGrid::evaluate`] and [`TriangleDualGrid::connect`] per frame.
#[derive(Clone, Debug)]
pub struct TriangleDualGrid {
    rates: Vec<u32>,
    /// First output vertex of every triangle (its dual points, then its interior primal
    /// points), and the total after the last.
    first: Vec<u32>,
    /// `first[1..]`, as [`for_each_range`] takes it (kept so that a frame allocates nothing).
    ends: Vec<usize>,
    faces: Vec<FacePlan>,
    /// The faces' stencils in their point order, one per table section, corner and rate.
    lanes: Vec<LaneStencils>,
    /// By rate: the parameters `k / 3n`, `k = 0..=3n`, of the quartic faces' rows, and whether
    /// the quartic reproduces the rate's regular stencils (`None`: not checked yet).
    params: Vec<Vec<f32>>,
    quartic_rates: Vec<Option<bool>>,
    /// The regular Loop patch's quartics (`None` when the closed form is unavailable).
    quartic: Option<&'static QuarticBasis>,
    /// Control points of every patch, concatenated.
    control: Vec<u32>,
    /// Points evaluated on their own: every vertex's limit point, then the boundary curves'
    /// interior points, while the plan is built.
    points: Vec<PointPlan>,
    /// Those points' stencils, in lanes ([`PointGroups`]), and where they lie.
    point_groups: PointGroups,
    strips: Vec<TriangleStrip>,
    /// The output vertex of every mesh vertex's limit point ([`NONE`] for unused vertices).
    limit_points: Vec<u32>,
    /// Vertex polygons and the triangle offsets of every face, strip and polygon.
    connectivity: Connectivity,
    vertex_count: usize,
    boundary: bool,
    /// The mesh's phantom points, appended to the control points when a patch reads one.
    phantoms: Option<Phantoms>,
}

fn section(patch: &TrianglePatch, kind: StencilKind, points: PointSet, n: u32) -> SectionKey {
    patch.kind.section(kind, points, n)
}

fn stencils<'t>(
    table: &'t dyn TriangleStencils,
    patch: &TrianglePatch,
    grid: PointSet,
    n: u32,
) -> Result<Stencils<'t>, RuntimeError> {
    let [position, du, dv] = [
        StencilKind::Position,
        StencilKind::DerivativeU,
        StencilKind::DerivativeV,
    ]
    .map(|kind| table.triangle_weights(&section(patch, kind, grid, n)));
    let (position, du, dv) = (position?, du?, dv?);
    let k = patch.points.len();
    let count = grid.count(n) as usize;
    if position.len() != count * k || du.len() != position.len() || dv.len() != du.len() {
        return Err(RuntimeError::LayoutMismatch {
            key: section(patch, StencilKind::Position, grid, n),
            table: position.len() / count.max(1),
            patch: k,
        });
    }
    Ok(Stencils { position, du, dv })
}

/// The patch rows of a triangle's points at rate `n`, for a patch at face corner `corner`.
fn point_map(n: u32, corner: usize) -> Vec<u32> {
    let mut map = Vec::with_capacity((n * n + interior_points(n)) as usize);
    for j in 0..n {
        for i in 0..n - j {
            for down in [false, true] {
                if down && i + j + 1 == n {
                    continue;
                }
                let (pi, pj) = dual_in_patch(corner, n, i, j, down);
                map.push(dual_index(n, pi, pj, down) as u32);
            }
        }
    }
    for j in 1..n {
        for i in 1..n - j {
            let (pi, pj) = primal_in_patch(corner, n, i, j);
            map.push(primal_index(n, pi, pj) as u32);
        }
    }
    map
}

impl TriangleDualGrid {
    /// Plan the tessellation of an isolated triangle mesh (closed or with boundary) with rate
    /// `rates[f]` on triangle `f`.
    pub fn new(
        table: &dyn TriangleStencils,
        mesh: &Mesh,
        patches: &[TrianglePatch],
        rates: &[u32],
    ) -> Result<Self, RuntimeError> {
        if rates.len() != patches.len() || patches.len() != mesh.faces() {
            return Err(RuntimeError::Unsupported(format!(
                "{} rates and {} patches for {} triangles",
                rates.len(),
                patches.len(),
                mesh.faces()
            )));
        }
        if let Some(f) = rates.iter().position(|&n| n == 0 || n > MAX_TRIANGLE_RATE) {
            return Err(RuntimeError::Unsupported(format!(
                "rate {} on triangle {f} (rates run from 1 to the table's largest)",
                rates[f]
            )));
        }
        let mut first = Vec::with_capacity(rates.len() + 1);
        first.push(0u32);
        for &n in rates {
            first.push(first[first.len() - 1] + n * n + interior_points(n));
        }
        let mut grid = TriangleDualGrid {
            rates: rates.to_vec(),
            first,
            ends: Vec::new(),
            faces: Vec::with_capacity(patches.len()),
            lanes: Vec::new(),
            params: vec![Vec::new(); MAX_TRIANGLE_RATE as usize + 1],
            quartic_rates: vec![None; MAX_TRIANGLE_RATE as usize + 1],
            quartic: None,
            control: Vec::new(),
            points: Vec::new(),
            point_groups: PointGroups::default(),
            strips: Vec::new(),
            limit_points: Vec::new(),
            connectivity: Connectivity::default(),
            vertex_count: 0,
            boundary: false,
            phantoms: None,
        };
        grid.ends = grid.first[1..].iter().map(|&x| x as usize).collect();
        // By rate, then by patch corner: the patch row of every point of a triangle (the dual
        // grid's rows for its dual points, then the primal grid's for its interior points).
        let mut maps: Vec<Option<[Vec<u32>; 3]>> = vec![None; MAX_TRIANGLE_RATE as usize + 1];
        // The index in `grid.lanes` of every section, corner and patch size met.
        let mut layouts: HashMap<(SectionKey, u8, usize), u32> = HashMap::new();
        let vertices = mesh.positions.len() as u32;
        if patches
            .iter()
            .any(|p| p.points.iter().any(|&c| c >= vertices))
        {
            grid.phantoms = Some(Phantoms::new(mesh));
        }
        for (patch, &n) in patches.iter().zip(rates) {
            if patch.points.len() > MAX_TRIANGLE_PATCH {
                return Err(RuntimeError::Unsupported(format!(
                    "a triangle patch of {} control points (valence {}); at most {MAX_TRIANGLE_PATCH}",
                    patch.points.len(),
                    patch.kind.faces
                )));
            }
            let k = patch.points.len();
            let key = (
                section(patch, StencilKind::Position, PointSet::TriangleDual, n),
                patch.corner as u8,
                k,
            );
            let (lanes, quartic) = match layouts.get(&key) {
                // The section, corner and size of an earlier face: its stencils were read and
                // checked then, and whether the quartic reproduces them is known for the rate.
                Some(&lanes) => (
                    lanes,
                    is_loop_regular(patch)
                        && n >= MIN_QUARTIC_RATE
                        && grid.quartic_rates[n as usize] == Some(true),
                ),
                None => {
                    // A valence beyond the table's is refused here, by the table naming its
                    // coverage.
                    let dual = stencils(table, patch, PointSet::TriangleDual, n)?;
                    let primal = stencils(table, patch, PointSet::TrianglePrimal, n)?;
                    let quartic = is_loop_regular(patch)
                        && n >= MIN_QUARTIC_RATE
                        && grid.reproduces(&dual, &primal, n);
                    let map = &maps[n as usize]
                        .get_or_insert_with(|| [0, 1, 2].map(|corner| point_map(n, corner)))
                        [patch.corner % 3];
                    let dual_points = (n * n) as usize;
                    let lanes = LaneStencils::new(k, map.len(), |t| {
                        let s = if t < dual_points { &dual } else { &primal };
                        (s, map[t] as usize)
                    })
                    .ok_or_else(|| RuntimeError::LayoutMismatch {
                        key: key.0,
                        table: dual.position.len() / dual_points.max(1),
                        patch: k,
                    })?;
                    let index = grid.lanes.len() as u32;
                    grid.lanes.push(lanes);
                    layouts.insert(key, index);
                    (index, quartic)
                }
            };
            let control = append_control(&mut grid.control, &patch.points)?;
            grid.faces.push(FacePlan {
                lanes,
                control,
                corner: patch.corner as u8,
                quartic,
            });
        }
        grid.plan_connectivity(table, mesh, patches)?;
        grid.point_groups = PointGroups::new(&std::mem::take(&mut grid.points), &grid.control)?;
        Ok(grid)
    }

    /// Whether the regular patch's quartic reproduces its table stencils `dual`, `primal` at
    /// rate `n` (checked once per rate; every regular face of a rate reads the same section).
    fn reproduces(&mut self, dual: &Stencils, primal: &Stencils, n: u32) -> bool {
        let n_index = n as usize;
        if let Some(known) = self.quartic_rates[n_index] {
            return known;
        }
        if self.quartic.is_none() {
            self.quartic = QuarticBasis::get();
        }
        let ok = self
            .quartic
            .is_some_and(|basis| basis.reproduces(dual, primal, n));
        self.quartic_rates[n_index] = Some(ok);
        if ok {
            let d = (3 * n) as f32;
            self.params[n_index] = (0..=3 * n).map(|k| k as f32 / d).collect();
        }
        ok
    }

    /// The same plan with every face evaluated from its table stencils: the reference the
    /// quartic path is checked against (tests, benchmarks).
    pub fn without_quartics(mut self) -> Self {
        for face in &mut self.faces {
            face.quartic = false;
        }
        self
    }

    /// The zigzag row of triangle `f` along its side `side`.
    fn zigzag(&self, f: usize, side: usize, reversed: bool) -> Zigzag {
        Zigzag {
            first: self.first[f],
            n: self.rates[f],
            side: side as u8,
            reversed,
        }
    }

    /// A point evaluated on its own: the primal point `(i, j)` of triangle `f` at its rate, in
    /// the triangle's own indices.
    fn point(
        &mut self,
        table: &dyn TriangleStencils,
        patch: &TrianglePatch,
        f: usize,
        (i, j): (u32, u32),
    ) -> Result<u32, RuntimeError> {
        let n = self.rates[f];
        let s = stencils(table, patch, PointSet::TrianglePrimal, n)?;
        let (pi, pj) = primal_in_patch(patch.corner, n, i, j);
        let k = patch.points.len();
        let at = primal_index(n, pi, pj);
        let control = append_control(&mut self.control, &patch.points)?;
        let index = self.first[self.rates.len()] + self.points.len() as u32;
        let source = VertexSource {
            face: f as u32,
            u: i,
            v: j,
            denominator: n,
            subface: 0,
        };
        self.points
            .push(PointPlan::from_row(&s, at, k, control, source));
        Ok(index)
    }

    fn plan_connectivity(
        &mut self,
        table: &dyn TriangleStencils,
        mesh: &Mesh,
        patches: &[TrianglePatch],
    ) -> Result<(), RuntimeError> {
        // Every vertex's limit point, from a triangle whose patch sits at the vertex if there is
        // one (its primal (0,0), where the derivative rows are the tangent masks), else from
        // the first triangle of its fan at the matching corner.
        let mut limit_point = vec![NONE; mesh.positions.len()];
        for (v, limit) in limit_point.iter_mut().enumerate() {
            let fan = mesh.fan(v);
            let Some(&h0) = fan.first() else { continue };
            let corner_of = |h: usize| {
                let f = mesh.face_of[h] as usize;
                (f, h - mesh.face_halfedges(f).start)
            };
            let h = fan
                .iter()
                .copied()
                .find(|&h| {
                    let (f, c) = corner_of(h);
                    patches[f].corner == c
                })
                .unwrap_or(h0);
            let (f, c) = corner_of(h);
            let n = self.rates[f];
            let ij = [(0, 0), (n, 0), (0, n)][c];
            *limit = self.point(table, &patches[f], f, ij)?;
        }
        // Edges, each once: interior ones from their lower half-edge, boundary ones from theirs.
        for h in 0..mesh.face_vertices.len() {
            let t = mesh.twin[h];
            let f = mesh.face_of[h] as usize;
            let side = h - mesh.face_halfedges(f).start;
            let row = self.zigzag(f, side, false);
            if t == NONE {
                self.boundary = true;
                let n = self.rates[f];
                let first = self.first[self.rates.len()] + self.points.len() as u32;
                for s in 1..n {
                    let ij = match side {
                        0 => (s, 0),
                        1 => (n - s, s),
                        _ => (0, n - s),
                    };
                    self.point(table, &patches[f], f, ij)?;
                }
                self.strips.push(TriangleStrip::Boundary {
                    row,
                    tail: limit_point[mesh.face_vertices[h] as usize],
                    first,
                    head: limit_point[mesh.head(h) as usize],
                });
            } else if (t as usize) > h {
                let t = t as usize;
                let g = mesh.face_of[t] as usize;
                // Reversed, so that both rows run along h.
                let right = self.zigzag(g, t - mesh.face_halfedges(g).start, true);
                self.strips
                    .push(TriangleStrip::Interior { left: row, right });
            }
        }
        // Vertex polygons: the limit point, then the corner dual points in fan order, closed
        // around an interior vertex.
        for (v, &limit) in limit_point.iter().enumerate() {
            let fan = mesh.fan(v);
            if fan.is_empty() {
                self.connectivity
                    .polygon_offsets
                    .push(self.connectivity.polygons.len() as u32);
                continue;
            }
            self.connectivity.polygons.push(limit);
            let start = self.connectivity.polygons.len();
            for &h in &fan {
                let f = mesh.face_of[h] as usize;
                let corner = h - mesh.face_halfedges(f).start;
                let point = self.zigzag(f, corner, false).at(0);
                self.connectivity.polygons.push(point);
            }
            if !mesh.is_boundary_vertex(v) {
                self.connectivity
                    .polygons
                    .push(self.connectivity.polygons[start]);
            }
            self.connectivity
                .polygon_offsets
                .push(self.connectivity.polygons.len() as u32);
        }
        self.vertex_count = self.first[self.rates.len()] as usize + self.points.len();
        self.limit_points = limit_point;
        self.connectivity.count(
            self.rates.iter().map(|&n| 6 * interior_points(n) as usize),
            self.strips.iter().map(TriangleStrip::triangles),
        );
        Ok(())
    }

    /// The output vertex holding mesh vertex `vertex`'s limit point (`None` for a vertex no
    /// triangle uses).
    pub fn limit_point(&self, vertex: usize) -> Option<u32> {
        self.limit_points
            .get(vertex)
            .copied()
            .filter(|&v| v != NONE)
    }

    /// Whether the mesh has a boundary (its output then has boundary loops).
    pub fn has_boundary(&self) -> bool {
        self.boundary
    }

    /// Every point of face `f`, from its control points relative to the first of them
    /// ([`relative`]).
    fn evaluate_face(
        &self,
        f: usize,
        control: &[[f64; 3]],
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        let n = self.rates[f] as usize;
        let plan = &self.faces[f];
        let points = &self.control[plan.control.start as usize..plan.control.end as usize];
        // The relative points are made as they are read (no buffer of MAX_TRIANGLE_PATCH
        // points cleared per face).
        let first = patch_origin(points, control);
        let point = |l: usize| relative(control[points[l] as usize], first);
        let origin = first.map(|c| c as f32);
        if plan.quartic && points.len() >= loop_quartic::POINTS {
            let params = self.params.get(n).filter(|p| p.len() == 3 * n + 1);
            if let (Some(basis), Some(params)) = (self.quartic, params) {
                let net: [[f32; 3]; loop_quartic::POINTS] = std::array::from_fn(point);
                let frame = &basis.frame[plan.corner as usize % 3];
                return loop_quartic::evaluate_face(
                    frame, &net, origin, n, params, positions, normals,
                );
            }
        }
        // Every other face (the regular patches of the butterfly and √3, Loop's below
        // MIN_QUARTIC_RATE, the patches at extraordinary vertices): its stencils, `LANES`
        // points at a time.
        if let Some(lanes) = self.lanes.get(plan.lanes as usize) {
            if lanes.control_points() == points.len() {
                lanes.evaluate_with(point, origin, |t| t, positions, normals);
            }
        }
    }

    /// The hexagon around every interior primal point, fanned at it.
    fn connect_face(&self, f: usize, out: &mut [[u32; 3]]) {
        let n = self.rates[f];
        let base = self.first[f];
        let centres = base + n * n;
        let dual = |i: u32, j: u32, down: bool| base + dual_index(n, i, j, down) as u32;
        let mut k = 0;
        for j in 1..n {
            for i in 1..n - j {
                let c = centres + interior_index(n, i, j);
                // Counter-clockwise around (i, j), from the triangle between +u and +v.
                let ring = [
                    dual(i, j, false),
                    dual(i - 1, j, true),
                    dual(i - 1, j, false),
                    dual(i - 1, j - 1, true),
                    dual(i, j - 1, false),
                    dual(i, j - 1, true),
                ];
                for r in 0..6 {
                    out[k] = [c, ring[r], ring[(r + 1) % 6]];
                    k += 1;
                }
            }
        }
    }
}

impl GridPlan for TriangleDualGrid {
    /// Output vertices per frame.
    fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Output triangles per frame.
    fn triangle_count(&self) -> usize {
        self.connectivity.triangle_count()
    }

    /// About the plan's heap memory: its vectors' capacities, the stencils' weights included.
    fn heap_bytes(&self) -> usize {
        let deep = [
            total_bytes(self.lanes.iter().map(LaneStencils::heap_bytes)),
            total_bytes(self.params.iter().map(vec_bytes)),
            total_bytes(self.points.iter().map(PointPlan::heap_bytes)),
            self.point_groups.heap_bytes(),
            self.connectivity.heap_bytes(),
        ];
        let shallow = [
            vec_bytes(&self.rates),
            vec_bytes(&self.first),
            vec_bytes(&self.ends),
            vec_bytes(&self.faces),
            vec_bytes(&self.lanes),
            vec_bytes(&self.params),
            vec_bytes(&self.quartic_rates),
            vec_bytes(&self.control),
            vec_bytes(&self.points),
            vec_bytes(&self.strips),
            vec_bytes(&self.limit_points),
        ];
        total_bytes(deep.into_iter().chain(shallow))
    }

    /// Where every output vertex is evaluated, in output order, in the tessellated mesh's
    /// triangles: dual points over `3n`, primal points over `n`.
    fn sources_into(&self, out: &mut Vec<VertexSource>) {
        out.clear();
        out.reserve(self.vertex_count);
        for (f, &n) in self.rates.iter().enumerate() {
            let source = |u, v, denominator| VertexSource {
                face: f as u32,
                u,
                v,
                denominator,
                subface: 0,
            };
            for j in 0..n {
                for i in 0..n - j {
                    out.push(source(3 * i + 1, 3 * j + 1, 3 * n));
                    if i + j + 1 < n {
                        out.push(source(3 * i + 2, 3 * j + 2, 3 * n));
                    }
                }
            }
            for j in 1..n {
                for i in 1..n - j {
                    out.push(source(i, j, n));
                }
            }
        }
        out.extend_from_slice(self.point_groups.sources());
    }

    /// Evaluate every output vertex from the control points `control` (the mesh's vertex
    /// positions): limit positions and unit normals, `vertex_count()` each.
    fn evaluate(&self, control: &[[f64; 3]], positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        let extended;
        let control = match &self.phantoms {
            Some(phantoms) => {
                extended = phantoms.extend(control);
                extended.as_slice()
            }
            None => control,
        };
        let owned = self.first[self.rates.len()] as usize;
        let (face_positions, point_positions) = positions.split_at_mut(owned);
        let (face_normals, point_normals) = normals.split_at_mut(owned);
        rayon::join(
            || {
                for_each_range(&self.ends, (face_positions, face_normals), |f, (p, q)| {
                    self.evaluate_face(f, control, p, q)
                })
            },
            || {
                self.point_groups
                    .evaluate(&self.control, control, point_positions, point_normals)
            },
        );
    }

    /// Write every triangle (`triangle_count()` of them).
    fn connect(&self, triangles: &mut [[u32; 3]]) {
        self.connectivity.connect(
            triangles,
            |f, out| self.connect_face(f, out),
            |s, out| self.strips[s].connect(out),
        );
    }

    /// How many triangles are evaluated as one quartic polynomial (the regular Loop patches).
    fn separable_faces(&self) -> usize {
        self.faces.iter().filter(|f| f.quartic).count()
    }
}

/// Control points of Loop's regular patch (valence 6): `V`, six neighbours, five outer points.
const LOOP_REGULAR_POINTS: usize = loop_quartic::POINTS;

/// The smallest rate at which a regular Loop face is evaluated as a quartic: below it the
/// per-face work (contracting the control points into 15 coefficients, the rows' polynomials)
/// outweighs what the points save. Against the lane stencils (`tessellate/lane_stencils.rs`)
/// the quartic costs about the same at rate 8 (289 M against 277 M instructions a frame on
/// Spot, callgrind) and 17% less at rate 16 (767 M against 919 M), break-even near rate 9
/// (docs/benchmarks.md); the bound stays at 5, where it was set against the scalar stencils, so
/// that every rate's output is unchanged (moving it would move rates 5..9 from the quartic's
/// rounding to the stencils', within `quartic_against_stencils`' bounds).
pub const MIN_QUARTIC_RATE: u32 = 5;

/// Whether `patch` has the layout of Loop's regular patch (interior, valence 6, twelve points);
/// whether its table section *is* the quartic box spline is checked against the table.
pub(crate) fn is_loop_regular(patch: &TrianglePatch) -> bool {
    !patch.kind.boundary && patch.kind.faces == 6 && patch.points.len() == LOOP_REGULAR_POINTS
}

/// Tessellate an isolated triangle mesh (closed or with boundary) with rate `rates[f]` on
/// triangle `f`.
pub fn tessellate_triangles(
    table: &dyn TriangleStencils,
    mesh: &Mesh,
    patches: &[TrianglePatch],
    rates: &[u32],
) -> Result<(TriangleMesh, TessellationTime), RuntimeError> {
    let started = Instant::now();
    let grid = TriangleDualGrid::new(table, mesh, patches, rates)?;
    let planned = Instant::now();
    let out = grid.tessellate(mesh);
    Ok((
        out,
        TessellationTime {
            plan_seconds: (planned - started).as_secs_f64(),
            seconds: planned.elapsed().as_secs_f64(),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzags_run_along_their_sides() {
        let n = 4;
        // Side 0 from corner 0: up(0,0), down(0,0), up(1,0), ..
        assert_eq!(zigzag_cell(n, 0, 0), (0, 0, false));
        assert_eq!(zigzag_cell(n, 0, 1), (0, 0, true));
        assert_eq!(zigzag_cell(n, 0, 6), (3, 0, false));
        // Side 1 from corner 1 to corner 2.
        assert_eq!(zigzag_cell(n, 1, 0), (3, 0, false));
        assert_eq!(zigzag_cell(n, 1, 1), (2, 0, true));
        assert_eq!(zigzag_cell(n, 1, 6), (0, 3, false));
        // Side 2 from corner 2 to corner 0.
        assert_eq!(zigzag_cell(n, 2, 0), (0, 3, false));
        assert_eq!(zigzag_cell(n, 2, 1), (0, 2, true));
        assert_eq!(zigzag_cell(n, 2, 6), (0, 0, false));
        // Every zigzag point's small triangle touches its side.
        for side in 0..3u8 {
            for t in 0..2 * n - 1 {
                let (i, j, down) = zigzag_cell(n, side, t);
                let corners = if down {
                    [(i + 1, j), (i, j + 1), (i + 1, j + 1)]
                } else {
                    [(i, j), (i + 1, j), (i, j + 1)]
                };
                let on = |&(a, b): &(u32, u32)| match side {
                    0 => b == 0,
                    1 => a + b == n,
                    _ => a == 0,
                };
                assert!(corners.iter().any(on), "side {side} t {t}");
            }
        }
    }

    #[test]
    fn interior_points_are_numbered_densely() {
        for n in 1..8 {
            let mut at = 0;
            for j in 1..n {
                for i in 1..n - j {
                    assert_eq!(interior_index(n, i, j), at);
                    at += 1;
                }
            }
            assert_eq!(at, interior_points(n));
        }
    }
}
