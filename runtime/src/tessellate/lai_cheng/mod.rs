//! Error-bounded adaptive tessellation of Catmull–Clark surfaces (S. Lai, F. Cheng,
//! "Near-optimum adaptive tessellation of general Catmull–Clark subdivision surfaces";
//! `../shared/papers/lai-cheng-adaptive-ccss.txt`). `docs/lai-cheng.md` has the method as built,
//! what is guaranteed and the results.
//!
//! * **Recursive midpoint subdivision** (section 2): each patch's `(u, v)` square is split into
//!   four until every square passes the flatness test ([`tessellate_adaptive`]).
//! * **Evaluation** (section 3): a regular patch is a bicubic; its Bézier net (converted once
//!   from the B-spline net) is split exactly by de Casteljau, and the net's corners are the
//!   limit points at the square's corners. A patch at an extraordinary vertex (EV) is descended
//!   with the local subdivision matrix `A`: at depth `k` the square `[0, 2^-k]^2` at the EV has
//!   the layout `A^k P`, and the three other quarters of it are regular bicubics `R_b A^k P`.
//! * **Flatness** (section 4, eq. 4–8): on a regular square, the guaranteed bound of
//!   [`bezier_net::flatness_bound`] (Bernstein coefficients of `S - Q` and the linear
//!   interpolation error of `Q`), the direction-free form of the two-sided test eq. (8), so
//!   that the polygon replacing the base quadrilateral meets it too (section 4.2). On the
//!   square at the EV, the counterpart of section 4.1's `m_eps` (the patch within an
//!   `eps`-sphere): with non-negative subdivision rules, the surface over `[0, 2^-k]^2`, its
//!   boundary points and so any polygon through them lie in the convex hull of `A^k P`, so
//!   `|S - L| <= diam(A^k P)`, which decays like `lambda^k` (the subdominant eigenvalue); and
//!   in the tighter hull of `ev_enclosure` (the Bézier nets of the regular quarters of three
//!   levels and the innermost layout): the bound is the smaller of the two diameters.
//! * **Globalization** (section 5): every marked point gets one id, keyed by its exact place in
//!   a shared parameterization (a mesh vertex; a canonical half-edge and the dyadic parameter
//!   along it; a face and its dyadic `(u, v)`). Each leaf square becomes the polygon through
//!   every marked point on its sides, so the output is watertight by construction.
//! * **Absolute and relative flatness** (section 6): [`AdaptiveOptions::relative`].
//! * **Sharp features** (OpenSubdiv's tags; not in the paper): hole faces get no polygons; a
//!   face with a sharp edge or vertex at its corners takes the feature-adaptive descent of
//!   `feature.rs` — local refinement until each piece is a feature-aware B-spline patch
//!   (phantom points beyond infinitely sharp edges), converted to Bézier and bounded as above,
//!   and at feature vertices the hull of the piece's one-ring (non-negative rules), the
//!   counterpart of the extraordinary sphere bound.
//!
//! ```
//! use subtess::scheme::catmull_clark::isolate::isolate_with_origins;
//! use subtess::tessellate::lai_cheng::{tessellate_adaptive, AdaptiveOptions};
//! use subtess::io::obj::parse_obj;
//! use subtess::stencil_table::StencilTable;
//! use subtess::mesh::topology::Mesh;
//! let obj = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
//!     f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n")?;
//! let (mesh, _) = Mesh::from_obj(&obj)?;
//! let iso = isolate_with_origins(&mesh)?;
//! let table = StencilTable::default_catmull_clark()?;
//! let options = AdaptiveOptions { tolerance: 0.01, ..Default::default() };
//! let (out, stats) = tessellate_adaptive(&table, &iso.mesh, &iso.patches, &options)?;
//! assert!(out.to_triangle_mesh().is_watertight());
//! assert_eq!(stats.leaves_over_tolerance, 0);
//! # Ok::<(), subtess::RuntimeError>(())
//! ```

pub mod bezier_net;
mod feature;
mod global_ids;
mod marks;
mod operators;
mod polygons;

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use serde_json::{json, Value};
use table_format::{PointSet, StencilKind};

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use crate::mesh::watertight::DirectedEdges;
use crate::scheme::catmull_clark::adaptive::{limit_of, limit_stencils, LimitQuery};
use crate::scheme::patch::{is_table_patch, FacePatch, PatchKind};
use crate::stencil_table::StencilTable;
use crate::tessellate::kernel::{for_each_dealt, prefix_sums, resize_to_overwrite};
use crate::RuntimeError;
use bezier_net::{corner_normal, corners, cross, longer_diagonal, unit, Deviation, Net, Point};
use marks::{counter_clockwise, FaceMarks, PlaceTable};
use operators::Operators;
pub use polygons::write_obj_polygons;

/// The deepest subdivision: parameters are multiples of `2^-MAX_DEPTH` of a patch side.
pub const MAX_DEPTH: u32 = 24;

/// The parameter grid every point lies on: `GRID = 2^MAX_DEPTH` steps per patch side.
const GRID: u32 = 1 << MAX_DEPTH;

/// The default [`AdaptiveOptions::max_polygons`]: 20 million. The adaptive tessellation peaked
/// at 412 MB for 986,496 polygons (the cube at tolerance 1e-5), about 420 bytes per polygon, so
/// the largest output allowed takes about 8.4 GB and a 24 GiB machine survives it.
pub const DEFAULT_MAX_POLYGONS: usize = 20_000_000;

/// How to tessellate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveOptions {
    /// The error tolerance `eps` of eq. (7)–(8): a distance in the mesh's units, or with
    /// `relative` a ratio (finite, `> 0`).
    pub tolerance: f64,
    /// Relative flatness RF (section 6): a square is flat when its bound is at most
    /// `tolerance` times the longer diagonal `max{D_1, D_2}` of its own base quadrilateral.
    /// The square at an extraordinary vertex uses the diagonal of its whole patch's base
    /// quadrilateral instead (its bound is a sphere bound, of the order of its size, so its own
    /// ratio cannot fall below a constant; see `docs/lai-cheng.md`).
    pub relative: bool,
    /// Whether the output primitives are triangles (the "T" rows of Table 1) rather than
    /// polygons; [`AdaptiveMesh`] carries both, this picks what [`AdaptiveStats`] reports as
    /// `primitives` and what a caller writes.
    pub triangulate: bool,
    /// Squares are not split below this depth (`<= MAX_DEPTH`); a square still over the
    /// tolerance there is kept and counted in [`AdaptiveStats::leaves_over_tolerance`].
    pub max_depth: u32,
    /// Squares are always split down to this depth (`<= max_depth`); 0 for the adaptive
    /// method, `= max_depth` for the uniform tessellation the A/U ratio compares with.
    pub min_depth: u32,
    /// The most polygons (leaf squares) the tessellation may make: when meeting the tolerance
    /// needs more, it stops splitting and fails with [`RuntimeError::OverBudget`] naming the
    /// tolerance it could not meet (`--max-polygons`; default [`DEFAULT_MAX_POLYGONS`]).
    pub max_polygons: usize,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        AdaptiveOptions {
            tolerance: 1e-3,
            relative: false,
            triangulate: false,
            max_depth: 16,
            min_depth: 0,
            max_polygons: DEFAULT_MAX_POLYGONS,
        }
    }
}

/// The parameter square a polygon replaces: face `face` (of the tessellated mesh) on
/// `[u0, u0 + size] x [v0, v0 + size] / denominator`, in the face's own parameters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PolygonRegion {
    /// The face.
    pub face: u32,
    /// Lower-left `u` numerator.
    pub u0: u32,
    /// Lower-left `v` numerator.
    pub v0: u32,
    /// Side numerator.
    pub size: u32,
    /// Common denominator (`2^MAX_DEPTH`).
    pub denominator: u32,
    /// Subdivision depth of the square (0: the whole face).
    pub depth: u32,
    /// Whether this square has a sphere (hull-diameter) bound: the square at an extraordinary
    /// vertex, or a hull square of the feature descent (at a feature vertex, or before a
    /// semi-sharp feature has settled).
    pub extraordinary: bool,
    /// The guaranteed bound on `|S - L|` over the square for any triangulation `L` of the
    /// polygon in parameter space ([`bezier_net::flatness_bound`] or, where a cheaper upper
    /// bound of it already met the tolerance, that bound, within 1% of it on most squares; or
    /// the EV hull diameter).
    pub bound: f64,
    /// The absolute tolerance the square had to meet (`tolerance`, or `tolerance` times a
    /// diagonal in relative mode).
    pub tolerance: f64,
    /// The longer diagonal `max{D_1, D_2}` of the square's base quadrilateral.
    pub diagonal: f64,
}

/// One output polygon, borrowed from its [`AdaptiveMesh`]: the base quadrilateral with every
/// marked point on its sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptivePolygon<'a> {
    /// Global vertex ids, counter-clockwise in the face's parameters (at least the square's
    /// four corners).
    pub vertices: &'a [u32],
    /// Its triangulation (ids), every triangle of positive area in parameter space: a polygon
    /// of `k` vertices has `k - 2` (no point inside the square is marked).
    pub triangles: &'a [[u32; 3]],
    /// The parameter square it replaces, with its bound.
    pub region: &'a PolygonRegion,
}

/// The adaptive tessellation: one vertex per global id, and the polygons, face by face.
///
/// The polygons lie in three flat arrays rather than in a vector each (two allocations per
/// polygon cost Spot's 109,176 polygons at `2.749e-4` about a tenth of the run, and 80 bytes
/// a polygon of heap): polygon `i`'s vertices are `vertices[starts[i]..starts[i + 1]]` and,
/// since a polygon of `k` vertices has `k - 2` triangles, its triangles are
/// `triangles[starts[i] - 2i..starts[i + 1] - 2(i + 1)]`. [`AdaptiveMesh::polygons`] hands them
/// out as [`AdaptivePolygon`]s.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveMesh {
    /// Limit positions.
    pub positions: Vec<[f64; 3]>,
    /// Unit normals (zero where the tangents are degenerate).
    pub normals: Vec<[f64; 3]>,
    /// Where each vertex was evaluated (faces of the tessellated mesh; map them to the input
    /// with [`crate::scheme::catmull_clark::isolate::Isolation::input_source`]).
    pub sources: Vec<VertexSource>,
    /// Where each polygon's vertices start in `vertices`, and their end (`polygons + 1`
    /// entries).
    starts: Vec<u32>,
    /// Every polygon's vertex ids, polygon after polygon.
    vertices: Vec<u32>,
    /// Every polygon's triangles, polygon after polygon.
    triangles: Vec<[u32; 3]>,
    /// Every polygon's parameter square.
    regions: Vec<PolygonRegion>,
    /// The passes' buffers, refilled by the next tessellation into this output.
    workspace: Workspace,
}

/// The passes' per-face (marks, ids) and per-run buffers, kept with an output that the caller
/// keeps from frame to frame ([`crate::Surface::tessellate_adaptive_into`]): each face refills
/// its own lists of the frame before, each run of pass 3 its own, so a frame of a moving mesh
/// allocates and frees almost nothing (every face's lists made and freed each frame were some
/// fifteen allocations a face, the frees on one thread at the end; docs/benchmarks.md).
///
/// Not part of the tessellation: outputs compare equal whatever their buffers hold, and a
/// clone starts without them.
#[derive(Default)]
struct Workspace {
    marks: Vec<FaceMarks>,
    ids: Vec<global_ids::FaceIds>,
    runs: Vec<PolygonRun>,
}

impl Clone for Workspace {
    fn clone(&self) -> Self {
        Workspace::default()
    }
}

impl PartialEq for Workspace {
    fn eq(&self, _: &Workspace) -> bool {
        true
    }
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Workspace")
            .field("faces", &self.marks.len())
            .field("runs", &self.runs.len())
            .finish()
    }
}

impl Default for AdaptiveMesh {
    fn default() -> Self {
        AdaptiveMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            sources: Vec::new(),
            starts: vec![0],
            vertices: Vec::new(),
            triangles: Vec::new(),
            regions: Vec::new(),
            workspace: Workspace::default(),
        }
    }
}

impl AdaptiveMesh {
    /// No vertices and no polygons, every list's memory kept.
    pub(crate) fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.sources.clear();
        self.starts.clear();
        self.starts.push(0);
        self.vertices.clear();
        self.triangles.clear();
        self.regions.clear();
    }

    /// Free the passes' buffers ([`Workspace`]): a tessellation made once keeps none for a
    /// next one.
    pub(crate) fn release_buffers(&mut self) {
        self.workspace = Workspace::default();
    }

    /// How many polygons.
    pub fn polygon_count(&self) -> usize {
        self.regions.len()
    }

    /// Polygon `i` (`< polygon_count()`), or `None`.
    pub fn polygon(&self, i: usize) -> Option<AdaptivePolygon<'_>> {
        let (start, end) = (
            *self.starts.get(i)? as usize,
            *self.starts.get(i + 1)? as usize,
        );
        Some(AdaptivePolygon {
            vertices: self.vertices.get(start..end)?,
            triangles: self.triangles.get(start - 2 * i..end - 2 * (i + 1))?,
            region: self.regions.get(i)?,
        })
    }

    /// The polygons in order (face by face).
    pub fn polygons(&self) -> impl ExactSizeIterator<Item = AdaptivePolygon<'_>> + '_ {
        self.starts
            .windows(2)
            .zip(&self.regions)
            .enumerate()
            .map(move |(i, (ends, region))| {
                let (start, end) = (ends[0] as usize, ends[1] as usize);
                AdaptivePolygon {
                    vertices: &self.vertices[start..end],
                    triangles: &self.triangles[start - 2 * i..end - 2 * (i + 1)],
                    region,
                }
            })
    }

    /// Every polygon's parameter square, in polygon order.
    pub fn regions(&self) -> &[PolygonRegion] {
        &self.regions
    }

    /// Every polygon's triangles, polygon after polygon: the triangulated output.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The triangulated output as the runtime's triangle mesh (f32).
    pub fn to_triangle_mesh(&self) -> TriangleMesh {
        let f32s = |p: &[f64; 3]| p.map(|c| c as f32);
        TriangleMesh {
            positions: self.positions.iter().map(f32s).collect(),
            normals: self.normals.iter().map(f32s).collect(),
            sources: self.sources.clone(),
            triangles: self.triangles.clone(),
            ..TriangleMesh::default()
        }
    }

    /// Number of triangles of the triangulated output.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Whether every polygon edge is shared by exactly two polygons traversing it in opposite
    /// directions (closed inputs): every directed edge used once, and its reverse once, grouped
    /// by tail with the triangle meshes' counting sort (`mesh::watertight::DirectedEdges`).
    /// `false` also when a polygon names a vertex beyond `positions`.
    pub fn is_watertight(&self) -> bool {
        let edges = || {
            self.polygons().flat_map(|p| {
                let around = p.vertices.iter().zip(p.vertices.iter().cycle().skip(1));
                around.map(|(&a, &b)| (a, b))
            })
        };
        DirectedEdges::new(self.positions.len(), edges).is_some_and(|d| d.all_paired())
    }
}

/// What a tessellation did (Table 1 of the paper: polygons, depth, A/U ratio).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// Output polygons (leaf squares).
    pub polygons: usize,
    /// Triangles of the triangulated output.
    pub triangles: usize,
    /// Output vertices (global ids).
    pub vertices: usize,
    /// Whether the primitives written are triangles.
    pub triangulated: bool,
    /// The deepest leaf, in midpoint subdivisions of the tessellated mesh's faces.
    pub max_depth: u32,
    /// The uniform depth compared with: Table 1's "Depth", the adaptive tessellation's
    /// deepest level (a uniform tessellation needs that level wherever the adaptive one
    /// reached it). Add the isolation steps for the depth below the input control mesh.
    pub uniform_depth: u32,
    /// Polygons of the uniform tessellation at `uniform_depth`: faces times `4^depth`.
    pub uniform_polygons: f64,
    /// Table 1's A/U ratio: `polygons / uniform_polygons` (or triangles over it when
    /// triangulated, as in the paper's "T" rows).
    pub au_ratio: f64,
    /// Leaves kept at `max_depth` although their bound exceeds their tolerance.
    pub leaves_over_tolerance: usize,
    /// The largest guaranteed bound over all leaves (absolute).
    pub max_bound: f64,
    /// The largest ratio of a leaf's bound to its base quadrilateral's longer diagonal (RF,
    /// section 6), over the leaves not at an extraordinary vertex (whose sphere bound is of
    /// the order of their size).
    pub max_relative_bound: f64,
    /// Leaves at extraordinary vertices.
    pub extraordinary_leaves: usize,
    /// Seconds (evaluation, flatness tests, globalization, triangulation).
    pub seconds: f64,
}

impl AdaptiveStats {
    /// The stats as JSON (the CLI's `--stats`).
    pub fn to_json(&self) -> Value {
        json!({
            "method": "adaptive",
            "polygons": self.polygons,
            "triangles": self.triangles,
            "vertices": self.vertices,
            "triangulated": self.triangulated,
            "max_depth": self.max_depth,
            "uniform_depth": self.uniform_depth,
            "uniform_polygons": self.uniform_polygons,
            "au_ratio": self.au_ratio,
            "leaves_over_tolerance": self.leaves_over_tolerance,
            "max_bound": self.max_bound,
            "max_relative_bound": self.max_relative_bound,
            "extraordinary_leaves": self.extraordinary_leaves,
            "seconds": self.seconds,
        })
    }
}

/// A leaf square of one face, in the face's own grid coordinates.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    u0: u32,
    v0: u32,
    size: u32,
    depth: u32,
    bound: f64,
    tolerance: f64,
    diagonal: f64,
    extraordinary: bool,
}

/// The recursion over one face (section 5's `AdaptiveMarking`).
struct FaceWork<'a> {
    options: &'a AdaptiveOptions,
    /// The face corner at the patch's `(0,0)`.
    corner: usize,
    marks: FaceMarks,
    /// The face's points by place.
    table: &'a mut PlaceTable,
    /// Why the face could not be marked (too many points), if it could not.
    error: Option<RuntimeError>,
    /// Leaves made so far by all faces together, as far as they have been told
    /// ([`FaceWork::count_leaf`]).
    polygons: &'a AtomicUsize,
    /// This face's leaves not yet added to `polygons`.
    unpublished: usize,
    /// `polygons` when this face last added to it.
    seen: usize,
}

/// How many leaves a face makes between its additions to the shared count: one atomic addition
/// a leaf, on a cache line that both threads write, made the squares of the marking pass up to
/// twice as slow on two threads as on one (the issue's cage, docs/benchmarks.md). The budget may
/// then be exceeded by this many leaves a thread before a face sees it, which changes no result:
/// the pass fails once the total is over, and a total under it was never seen over.
const LEAVES_PER_COUNT: usize = 256;

impl<'a> FaceWork<'a> {
    /// The work on a face whose patch has its `(0,0)` at face corner `corner`, refilling its
    /// leaves and marks in `marks` (the face's lists of the frame before) and its points in
    /// `table`.
    fn new(
        options: &'a AdaptiveOptions,
        corner: usize,
        (mut marks, table): (FaceMarks, &'a mut PlaceTable),
        polygons: &'a AtomicUsize,
    ) -> Self {
        table.reset(marks.places.capacity());
        marks.clear();
        FaceWork {
            options,
            corner,
            marks,
            table,
            error: None,
            polygons,
            unpublished: 0,
            seen: polygons.load(Ordering::Relaxed),
        }
    }

    /// Count one more leaf, adding the face's leaves to the shared count every
    /// [`LEAVES_PER_COUNT`] of them.
    fn count_leaf(&mut self) {
        self.unpublished += 1;
        if self.unpublished >= LEAVES_PER_COUNT {
            self.publish();
        }
    }

    /// Add the face's uncounted leaves to the shared count.
    fn publish(&mut self) {
        self.seen = (self.polygons)
            .fetch_add(self.unpublished, Ordering::Relaxed)
            .saturating_add(self.unpublished);
        self.unpublished = 0;
    }

    /// Mark a face whose patch has its `(0,0)` at face corner `corner` by `body` into
    /// `marks`, with the thread's `table`.
    fn run(
        options: &AdaptiveOptions,
        corner: usize,
        (marks, table): (&mut FaceMarks, &mut PlaceTable),
        polygons: &AtomicUsize,
        body: &mut dyn FnMut(&mut FaceWork),
    ) -> Result<(), RuntimeError> {
        let mut face = FaceWork::new(options, corner, (std::mem::take(marks), table), polygons);
        body(&mut face);
        let result;
        (result, *marks) = face.finish();
        result
    }

    /// The face's leaves and marks with the leaves' side points (none when the polygon budget
    /// is spent), or why the face could not be marked.
    fn finish(mut self) -> (Result<(), RuntimeError>, FaceMarks) {
        self.publish();
        if let Some(error) = self.error {
            return (Err(error), self.marks);
        }
        if self.over_budget() {
            self.marks.clear();
            return (Ok(()), self.marks);
        }
        let sides = self.marks.sides(self.table);
        (sides, self.marks)
    }
}

impl FaceWork<'_> {
    /// Face grid coordinates of patch grid coordinates (the inverse of [`crate::scheme::patch::to_patch`]).
    fn to_face(&self, p: u32, q: u32) -> (u32, u32) {
        match self.corner {
            0 => (p, q),
            1 => (GRID - q, p),
            2 => (GRID - p, GRID - q),
            _ => (q, GRID - p),
        }
    }

    fn tolerance(&self, diagonal: f64) -> f64 {
        if self.options.relative {
            self.options.tolerance * diagonal
        } else {
            self.options.tolerance
        }
    }

    /// Whether a square is a leaf: flat enough (or at `max_depth`), or the polygon budget is
    /// spent (then the whole tessellation fails once every face has stopped).
    fn done(&self, depth: u32, bound: f64, tolerance: f64) -> bool {
        self.over_budget()
            || depth >= self.options.min_depth
                && (bound <= tolerance || depth >= self.options.max_depth)
    }

    /// Whether the leaves counted so far, as far as this face knows them, exceed the budget
    /// (or the face cannot be marked: then it stops as soon).
    fn over_budget(&self) -> bool {
        self.seen.saturating_add(self.unpublished) > self.options.max_polygons
            || self.error.is_some()
    }

    /// Whether a square at `depth` may still be split (below `max_depth`, budget left): then
    /// whether its bound exceeds the tolerance is all [`FaceWork::done`] asks of it, and a
    /// lower bound above the tolerance answers that.
    fn may_split(&self, depth: u32) -> bool {
        depth < self.options.max_depth && !self.over_budget()
    }

    /// The `floor` of [`diameter_above`] for a square at `depth`: the tolerance where the
    /// square may be split (a first distance above it settles the split), else none.
    fn diameter_floor(&self, depth: u32, tolerance: f64) -> f64 {
        if self.may_split(depth) {
            tolerance
        } else {
            f64::INFINITY
        }
    }

    /// Mark the face grid point `(u, v)` ([`FaceMarks::mark`]), its point returned; on an
    /// error `NONE`, the first error kept.
    fn mark(
        &mut self,
        place: (u32, u32),
        position: Option<Point>,
        normal: impl FnOnce() -> Point,
    ) -> u32 {
        self.marks
            .mark(self.table, place, position, normal)
            .unwrap_or_else(|error| {
                self.error.get_or_insert(error);
                NONE
            })
    }

    /// Record a leaf with face corners `places` (a square's, in any cyclic order) after
    /// marking them, `mark(k)` marking corner `k` and returning its point.
    fn push_leaf(
        &mut self,
        places: &[(u32, u32); 4],
        mut mark: impl FnMut(&mut Self, usize) -> u32,
        leaf: Leaf,
    ) {
        let mut corners = [NONE; 4];
        for (k, &place) in places.iter().enumerate() {
            corners[counter_clockwise(place, (leaf.u0, leaf.v0))] = mark(self, k);
        }
        self.marks.corners.push(corners);
        self.marks.leaves.push(leaf);
    }

    /// Record the leaf `[p0, p0 + size] x [q0, q0 + size]` (patch coordinates) and mark its
    /// corners (`MarkBlack`): their positions `points` (whose [`longer_diagonal`] is
    /// `diagonal`) and their normals `normal(k)`, made only for a point not marked before.
    fn leaf(
        &mut self,
        (p0, q0, depth): (u32, u32, u32),
        (points, diagonal): ([Point; 4], f64),
        normal: impl Fn(usize) -> Point,
        bound: f64,
        tolerance: f64,
        extraordinary: bool,
    ) {
        self.count_leaf();
        let size = GRID >> depth;
        let patch_corners = [
            (p0, q0),
            (p0 + size, q0),
            (p0 + size, q0 + size),
            (p0, q0 + size),
        ];
        let places = patch_corners.map(|(p, q)| self.to_face(p, q));
        let leaf = Leaf {
            u0: places.iter().map(|p| p.0).min().unwrap_or(0),
            v0: places.iter().map(|p| p.1).min().unwrap_or(0),
            size,
            depth,
            bound,
            tolerance,
            diagonal,
            extraordinary,
        };
        let mark = |face: &mut Self, k: usize| face.mark(places[k], Some(points[k]), || normal(k));
        self.push_leaf(&places, mark, leaf);
    }

    /// Record a hull square (at a feature, [`feature`]) with face frame `frame`; its corners are
    /// evaluated after the marking, its diagonal then.
    fn pending_leaf(&mut self, frame: &feature::Frame, depth: u32, bound: f64, tolerance: f64) {
        self.count_leaf();
        let leaf = Leaf {
            u0: frame.iter().map(|p| p.0).min().unwrap_or(0),
            v0: frame.iter().map(|p| p.1).min().unwrap_or(0),
            size: GRID >> depth,
            depth,
            bound,
            tolerance,
            diagonal: 0.0,
            extraordinary: true,
        };
        let mark = |face: &mut Self, k: usize| face.mark(frame[k], None, || [0.0; 3]);
        self.push_leaf(frame, mark, leaf);
    }

    /// A regular square with Bézier net `net` at patch coordinates `(p0, q0)`, depth `depth`.
    fn regular(&mut self, net: &Net, p0: u32, q0: u32, depth: u32) {
        self.regular_below(net, (p0, q0, depth), f64::INFINITY);
    }

    /// [`FaceWork::regular`] for a square whose parent's bound was at least `parent` (a lower
    /// bound of it, or the bound itself).
    ///
    /// A square that is split needs no exact bound (only leaves record theirs): where the
    /// corner pairs' lower bound ([`Deviation::corner_bound`]) already exceeds the tolerance,
    /// `done` would say no whatever the other pairs give, and the square is split after 28 of
    /// the bound's 182 pairs. That lower bound is only tried where the square is likely to be
    /// split, its parent's bound above four times the tolerance (a bound falls about fourfold
    /// per level on a smooth patch): most squares are leaves, for which it would be wasted.
    /// A square not split by it is first tested with the cheap upper bound
    /// ([`Deviation::upper_bound`], 28 lengths): within the tolerance, the square is a leaf by
    /// the full test too and records that upper bound; else the full bound decides. Either
    /// way the leaves and every split are the full test's; a leaf's bound is the full one or
    /// the upper bound, both valid.
    fn regular_below(&mut self, net: &Net, (p0, q0, depth): (u32, u32, u32), parent: f64) {
        let points = corners(net);
        let deviation = Deviation::new(net);
        let diagonal = longer_diagonal(&points);
        let tolerance = self.tolerance(diagonal);
        let may_split = self.may_split(depth);
        let mut lower = if may_split && parent > 4.0 * tolerance {
            deviation.corner_bound()
        } else {
            0.0
        };
        let split = may_split && (depth < self.options.min_depth || lower > tolerance);
        if !split {
            // A leaf by the cheap upper bound is a leaf by the full one: it records the cheap
            // one (a valid bound, within 1% of the full one on 99% of leaves).
            let quick = deviation.upper_bound();
            let bound = if quick <= tolerance {
                quick
            } else {
                deviation.bound()
            };
            lower = bound;
            if self.done(depth, bound, tolerance) {
                self.leaf(
                    (p0, q0, depth),
                    (points, diagonal),
                    |k| corner_normal(net, k),
                    bound,
                    tolerance,
                    false,
                );
                return;
            }
        }
        let half = (GRID >> depth) / 2;
        let origins = [(0, 0), (half, 0), (half, half), (0, half)];
        for (child, (dp, dq)) in bezier_net::split(net).iter().zip(origins) {
            self.regular_below(child, (p0 + dp, q0 + dq, depth + 1), lower);
        }
    }

    /// The patch at an extraordinary vertex with layout `points`: descend with `A` (section
    /// 4.1), the three regular quarters of each level as Bézier squares.
    ///
    /// The levels `k..=k + EV_ENCLOSURE_LEVELS` that the enclosure of level `k` needs are kept
    /// in a ring and each is made once (the next level's enclosure shares all but one), in
    /// place: level `k + 1 + EV_ENCLOSURE_LEVELS` takes the slot and the lists of level `k`
    /// (moving whole levels through a window and allocating two lists a level were a sixth
    /// of the descent, docs/benchmarks.md).
    fn extraordinary(&mut self, ops: &Operators, points: &[Point], vertex_normal: Point) {
        const SLOTS: usize = EV_ENCLOSURE_LEVELS + 1;
        let mut depth = 0;
        let mut root_diagonal = 0.0;
        let mut ring: [EvLevel; SLOTS] = Default::default();
        let mut rows = Vec::new();
        ring[0].points.extend_from_slice(points);
        ring[0].make(ops, &mut rows);
        // Levels made from `depth` on; without non-negative rules there is no enclosure, only
        // the level itself.
        let mut made = 1;
        let wanted = if ops.nonnegative { SLOTS } else { 1 };
        loop {
            // Level `depth + i`'s slot.
            let slot = |i: usize| (depth as usize + i) % SLOTS;
            while made < wanted {
                let (last, slot) = (slot(made + SLOTS - 1), slot(made));
                let next = std::mem::take(&mut ring[last].next);
                let level = &mut ring[slot];
                level.next = std::mem::replace(&mut level.points, next);
                level.make(ops, &mut rows);
                made += 1;
            }
            let level = &ring[slot(0)];
            let nets = &level.nets;
            let corner_points = [
                ops.vertex_position(&level.points),
                nets[0][3],
                nets[1][15],
                nets[2][12],
            ];
            let diagonal = longer_diagonal(&corner_points);
            if depth == 0 {
                root_diagonal = diagonal;
            }
            let tolerance = self.tolerance(root_diagonal);
            // A level that may be split needs to know only whether both diameters exceed the
            // tolerance, which its regular corners often show ([`corners_apart`]), else their
            // first pairs ([`diameter_above`]); where one of them does not, it is exact and
            // below the other, so the smaller is exact too, as the leaf records it.
            let floor = self.diameter_floor(depth, tolerance);
            let bound = if !ops.nonnegative {
                f64::INFINITY
            } else if let Some(lower) = corners_apart(&corner_points[1..], &level.points, floor) {
                lower
            } else {
                let levels = (0..made).map(|i| &ring[slot(i)]);
                diameter_above(&level.points, floor)
                    .min(diameter_above(&ev_enclosure(levels), floor))
            };
            if self.done(depth, bound, tolerance) {
                let normal = |k: usize| match k {
                    0 => vertex_normal,
                    k => corner_normal(&nets[k - 1], k),
                };
                let square = (corner_points, diagonal);
                self.leaf((0, 0, depth), square, normal, bound, tolerance, true);
                return;
            }
            let half = (GRID >> depth) / 2;
            self.regular(&nets[0], half, 0, depth + 1);
            self.regular(&nets[1], half, half, depth + 1);
            self.regular(&nets[2], 0, half, depth + 1);
            depth += 1;
            made -= 1;
        }
    }
}

/// A thread's buffers for pass 3, kept from polygon to polygon.
#[derive(Default)]
struct PolygonBuffers {
    ring: Vec<((u32, u32), u32)>,
    params: Vec<(i64, i64)>,
    positions: Vec<Point>,
    corners: Vec<usize>,
    triangles: Vec<[usize; 3]>,
}

/// The polygons of a run of leaves, flat as in [`AdaptiveMesh`]: each polygon's vertex count,
/// then all their vertices and all their triangles; and the leaves' statistics.
#[derive(Default)]
struct PolygonRun {
    counts: Vec<u32>,
    vertices: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    leaves: LeafStats,
}

impl PolygonRun {
    /// No polygons, the lists' memory kept.
    fn clear(&mut self) {
        self.counts.clear();
        self.vertices.clear();
        self.triangles.clear();
        self.leaves = LeafStats::default();
    }
}

/// The statistics of [`AdaptiveStats`] read from the leaves' regions, gathered per run of
/// leaves in pass 3 (a serial pass over the regions after it took 1 ms of Spot's frame).
#[derive(Clone, Copy, Default)]
struct LeafStats {
    max_depth: u32,
    over_tolerance: usize,
    max_bound: f64,
    max_relative_bound: f64,
    extraordinary: usize,
}

impl LeafStats {
    fn add(&mut self, r: &PolygonRegion) {
        self.max_depth = self.max_depth.max(r.depth);
        self.over_tolerance += usize::from(r.bound > r.tolerance);
        self.max_bound = self.max_bound.max(r.bound);
        if r.extraordinary {
            self.extraordinary += 1;
        } else {
            self.max_relative_bound = self.max_relative_bound.max(r.bound / r.diagonal);
        }
    }

    /// Both runs' statistics (maxima and counts: the order of the runs does not matter).
    fn merge(self, other: LeafStats) -> LeafStats {
        LeafStats {
            max_depth: self.max_depth.max(other.max_depth),
            over_tolerance: self.over_tolerance + other.over_tolerance,
            max_bound: self.max_bound.max(other.max_bound),
            max_relative_bound: self.max_relative_bound.max(other.max_relative_bound),
            extraordinary: self.extraordinary + other.extraordinary,
        }
    }
}

/// The leaves of `work` from leaf `index` of face `face` on, in face order, each with its
/// face's marks: `(marks, (face, index, leaf))`.
fn leaves_from(
    work: &[FaceMarks],
    face: usize,
    index: usize,
) -> impl Iterator<Item = (&FaceMarks, (usize, usize, &Leaf))> {
    work.get(face..)
        .unwrap_or(&[])
        .iter()
        .zip(face..)
        .flat_map(|(marks, f)| {
            let leaves = marks.leaves.iter().enumerate();
            leaves.map(move |(i, l)| (marks, (f, i, l)))
        })
        .skip(index)
}

/// Leaves per job of pass 3: enough that a job's three vectors grow a few times only, few
/// enough that Spot's 109,176 polygons at `2.749e-4` make about a hundred jobs for two threads.
const LEAVES_PER_RUN: usize = 1024;

impl PolygonBuffers {
    /// Append to `run` the polygon of `leaf` of `face` (whose marks are `marks`): its ring of
    /// marked points (section 5) and the ring's triangulation (`k - 2` triangles for `k`
    /// points).
    fn polygon(
        &mut self,
        (ids, marks): (&global_ids::GlobalIds, &FaceMarks),
        positions: &[Point],
        leaf: (usize, usize, &Leaf),
        run: &mut PolygonRun,
    ) -> Result<(), RuntimeError> {
        ids.leaf_ring(leaf, marks, &mut self.ring)?;
        let count = u32::try_from(self.ring.len())
            .map_err(|_| RuntimeError::Unsupported("a polygon of 2^32 vertices".to_owned()))?;
        self.params.clear();
        self.positions.clear();
        for &((u, v), i) in &self.ring {
            self.params.push((i64::from(u), i64::from(v)));
            let p = positions
                .get(i as usize)
                .ok_or_else(|| RuntimeError::Unsupported(format!("vertex {i} has no position")))?;
            self.positions.push(*p);
        }
        polygons::triangulate(
            &self.params,
            &self.positions,
            &mut self.corners,
            &mut self.triangles,
        );
        // The flat arrays place a polygon's triangles by this count (`AdaptiveMesh`).
        if self.triangles.len() + 2 != self.ring.len() {
            return Err(RuntimeError::Unsupported(format!(
                "internal: a polygon of {} vertices triangulated into {} triangles",
                self.ring.len(),
                self.triangles.len()
            )));
        }
        let first = run.vertices.len();
        run.counts.push(count);
        run.vertices.extend(self.ring.iter().map(|&(_, id)| id));
        let vertices = &run.vertices[first..];
        run.triangles
            .extend(self.triangles.iter().map(|t| t.map(|k| vertices[k])));
        Ok(())
    }
}

impl Leaf {
    /// The square's corners on the face's grid, counter-clockwise from `(u0, v0)`.
    fn corners(&self) -> [(u32, u32); 4] {
        let (u0, v0) = (self.u0, self.v0);
        let (u1, v1) = (u0 + self.size, v0 + self.size);
        [(u0, v0), (u1, v0), (u1, v1), (u0, v1)]
    }

    /// Per side `s` (from corner `s` to corner `s + 1`), where it lies on side `s` of the face
    /// (the only face side it can lie on), its ends in that side's own parameter (counter-
    /// clockwise around the face); `None` for a side inside the face.
    fn on_face_side(&self) -> [Option<(u32, u32)>; 4] {
        let (u0, v0) = (self.u0, self.v0);
        let (u1, v1) = (u0 + self.size, v0 + self.size);
        [
            (v0 == 0).then_some((u0, u1)),
            (u1 == GRID).then_some((v0, v1)),
            (v1 == GRID).then_some((GRID - u1, GRID - u0)),
            (u0 == 0).then_some((GRID - v1, GRID - v0)),
        ]
    }

    /// The parameter square of this leaf of `face`, with its bound.
    fn region(&self, face: usize) -> PolygonRegion {
        PolygonRegion {
            face: face as u32,
            u0: self.u0,
            v0: self.v0,
            size: self.size,
            denominator: GRID,
            depth: self.depth,
            extraordinary: self.extraordinary,
            bound: self.bound,
            tolerance: self.tolerance,
            diagonal: self.diagonal,
        }
    }
}

/// One level `k` of the extraordinary descent: the layout `A^k P` of the square
/// `[0, 2^-k]^2` at the vertex, the Bézier nets `R_b A^k P` of its three regular quarters, and
/// the next level's layout `A^{k+1} P` (until the next level takes it).
#[derive(Default)]
struct EvLevel {
    points: Vec<Point>,
    nets: [Net; 3],
    next: Vec<Point>,
}

impl EvLevel {
    /// The nets and the next layout of the level's layout `points`, into the level's lists
    /// (`rows`: the product's, kept by the caller).
    fn make(&mut self, ops: &Operators, rows: &mut Vec<Point>) {
        ops.level(&self.points, rows, &mut self.next, &mut self.nets);
    }
}

/// How a face is tessellated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Path {
    /// A hole: no surface.
    Hole,
    /// Its table patch (regular, or the extraordinary descent).
    Table,
    /// The feature-adaptive descent ([`feature`]).
    Feature,
}

/// Levels of the extraordinary enclosure ([`ev_enclosure`]).
const EV_ENCLOSURE_LEVELS: usize = 3;

/// Points whose convex hull contains the surface over the extraordinary square of
/// `levels[0]` (`levels`: that level and the next [`EV_ENCLOSURE_LEVELS`]): the Bézier nets
/// of the regular quarters of [`EV_ENCLOSURE_LEVELS`] levels and the layout `A^levels P` of the
/// innermost square. Each regular quarter lies in the hull of its own Bézier net (Bernstein
/// polynomials are non-negative and sum to one), the innermost square in the hull of its layout
/// (`A >= 0`, the extraordinary bound's condition), and the squares tile the extraordinary one.
/// The hull is inside that of `points` when the quarters' operators are non-negative too, and
/// shrinks towards the surface piece itself as the levels grow.
fn ev_enclosure<'a>(levels: impl Iterator<Item = &'a EvLevel>) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::with_capacity(EV_ENCLOSURE_LEVELS * 48 + 64);
    for (k, level) in levels.enumerate().take(EV_ENCLOSURE_LEVELS + 1) {
        if k < EV_ENCLOSURE_LEVELS {
            out.extend(level.nets.iter().flat_map(|n| n.iter().copied()));
        } else {
            out.extend_from_slice(&level.points);
        }
    }
    out
}

/// The largest distance between the extraordinary square's three regular corners `corners`
/// (the corners of its quarters' Bézier nets), where it exceeds `floor` by a rounding margin:
/// a lower bound of both of [`FaceWork::extraordinary`]'s diameters above `floor`, which settles
/// a split (most levels of the descent) without them. `None` otherwise.
///
/// Why it bounds both: the corners are points of the surface over the square, so they lie in
/// the hull of its layout `layout` (non-negative rules) and are points of its enclosure
/// ([`ev_enclosure`]: their nets are in it). Computed from `layout` they may stray from that
/// hull by rounding, a few units in the last place of the layout's coordinates, far below the
/// margin of `1e-12` of their size; so where the corners are more than `floor` plus the margin
/// apart, both diameters as [`diameter_above`] computes them are above `floor`, and the split
/// is the one they give.
fn corners_apart(corners: &[Point], layout: &[Point], floor: f64) -> Option<f64> {
    if !floor.is_finite() {
        return None;
    }
    let mut apart: f64 = 0.0;
    for (i, &a) in corners.iter().enumerate() {
        for &b in &corners[i + 1..] {
            apart = apart.max(bezier_net::norm(bezier_net::sub(a, b)));
        }
    }
    let scale = layout.iter().flatten().fold(0.0f64, |s, &c| s.max(c.abs()));
    (apart > floor + 1e-12 * scale).then_some(apart)
}

/// The largest distance between two of the points (the diameter of their convex hull), to the
/// last bit the largest `norm(a - b)` over all pairs (but see `floor` below).
///
/// A pair is at most `r_a + r_b` apart (`r` the distance from the centroid, the triangle
/// inequality), with a margin of `1e-12` of the coordinates' and radii's size, far above the
/// rounding of either side. The farthest point from the outermost one gives a first distance
/// `d_0`; a point with `r + r_max` below it is in no pair that beats it and is dropped before
/// the sort (an enclosure, `ev_enclosure`, is about 170 points clustered near a surface piece);
/// the rest are visited by decreasing `r`, a pair skipped when `r_a + r_b` is below the best
/// distance found. A skipped pair's computed distance cannot be the largest, so the result is
/// the full double loop's, and most of the `n^2 / 2` pairs are never computed.
///
/// Except when `d_0` (a pair's distance, so at most the diameter) is above `floor`: then it is
/// returned, enough for a caller that only asks whether the diameter exceeds `floor` (the sort
/// and the pairs, most of the cost, are skipped). `floor = f64::INFINITY` always gets the
/// diameter.
fn diameter_above(points: &[Point], floor: f64) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let mut centroid = [0.0; 3];
    let mut scale: f64 = 0.0;
    for p in points {
        for c in 0..3 {
            centroid[c] += p[c];
            scale = scale.max(p[c].abs());
        }
    }
    let centroid = centroid.map(|c| c / points.len() as f64);
    let radius = |p: Point| bezier_net::norm(bezier_net::sub(p, centroid));
    let (mut outermost, mut r_max) = (points[0], radius(points[0]));
    for &p in &points[1..] {
        let r = radius(p);
        if r > r_max {
            (outermost, r_max) = (p, r);
        }
    }
    let margin = 1e-12 * (scale + 2.0 * r_max);
    // `norm` is the root of the square, and `sqrt` is monotone: the largest square's root is
    // the largest `norm` exactly.
    let squared = |a: Point, b: Point| {
        let d = bezier_net::sub(a, b);
        bezier_net::dot(d, d)
    };
    let mut best_squared = points
        .iter()
        .map(|&p| squared(outermost, p))
        .fold(0.0, f64::max);
    let mut best = best_squared.sqrt();
    if best > floor {
        return best;
    }
    let mut by_radius: Vec<(f64, Point)> = points
        .iter()
        .map(|&p| (radius(p), p))
        .filter(|&(r, _)| r + r_max + margin >= best)
        .collect();
    by_radius.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    for (i, &(ra, a)) in by_radius.iter().enumerate() {
        if 2.0 * ra + margin < best {
            break;
        }
        for &(rb, b) in &by_radius[i + 1..] {
            if ra + rb + margin < best {
                break;
            }
            let d = squared(a, b);
            if d > best_squared {
                best_squared = d;
                best = d.sqrt();
            }
        }
    }
    best
}

/// The normal at the patch's extraordinary vertex from the table's tangent stencils at
/// `(0,0)` (primal grid, `n = 1`), in patch coordinates (a rotation of the face's).
fn vertex_normal(table: &StencilTable, patch: &FacePatch, points: &[Point]) -> Option<Point> {
    let tangent = |kind| -> Option<Point> {
        let key = patch.kind.section(kind, PointSet::Primal, 1);
        let weights = table.weights(&key).ok()?;
        let row = weights.get(..points.len())?;
        let mut t = [0.0; 3];
        for (w, q) in row.iter().zip(points) {
            for c in 0..3 {
                t[c] += f64::from(*w) * q[c];
            }
        }
        Some(t)
    };
    Some(unit(cross(
        tangent(StencilKind::DerivativeU)?,
        tangent(StencilKind::DerivativeV)?,
    )))
}

fn check_options(options: &AdaptiveOptions) -> Result<(), RuntimeError> {
    let bad = |name: &str, reason: String| RuntimeError::InvalidParameter {
        name: name.to_owned(),
        reason,
    };
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(bad(
            "tolerance",
            format!(
                "{} (it must be a positive {})",
                options.tolerance,
                if options.relative {
                    "ratio"
                } else {
                    "distance"
                }
            ),
        ));
    }
    if options.max_depth > MAX_DEPTH {
        return Err(bad(
            "max_depth",
            format!("{} (it must be at most {MAX_DEPTH})", options.max_depth),
        ));
    }
    if options.min_depth > options.max_depth {
        return Err(bad(
            "min_depth",
            format!(
                "{} (it must be at most max_depth = {})",
                options.min_depth, options.max_depth
            ),
        ));
    }
    Ok(())
}

/// Tessellate an isolated mesh (every face a table patch, [`crate::scheme::catmull_clark::isolate`]) adaptively with
/// the guaranteed error of Lai–Cheng (sections 2, 4, 5, 6; module documentation): every leaf
/// square passes the flatness test (eq. 7–8 in the bound of [`bezier_net::flatness_bound`], or
/// the extraordinary vertex's hull bound) unless `max_depth` stops it (then it is counted in
/// [`AdaptiveStats::leaves_over_tolerance`]); the polygons share one vertex per marked point.
///
/// `table` supplies the tangent stencils for the normals at extraordinary vertices.
/// Cost: one Bézier subdivision and one 16-point bound per square, faces in parallel.
pub fn tessellate_adaptive(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    options: &AdaptiveOptions,
) -> Result<(AdaptiveMesh, AdaptiveStats), RuntimeError> {
    let started = Instant::now();
    check_input(mesh, patches, options)?;
    let operators = PatchOperators::new(mesh, patches)?;
    let mut out = AdaptiveMesh::default();
    let stats =
        tessellate_adaptive_with(table, mesh, patches, options, &operators, started, &mut out)?;
    out.release_buffers();
    Ok((out, stats))
}

/// The options valid and a patch per face: what [`tessellate_adaptive_with`] assumes, checked
/// before the operators are made.
pub(crate) fn check_input(
    mesh: &Mesh,
    patches: &[FacePatch],
    options: &AdaptiveOptions,
) -> Result<(), RuntimeError> {
    check_options(options)?;
    if patches.len() != mesh.faces() {
        return Err(RuntimeError::Unsupported(format!(
            "{} patches for {} faces",
            patches.len(),
            mesh.faces()
        )));
    }
    Ok(())
}

/// Which faces take which path: a hole has no surface; a face the tables describe (no sharp
/// feature on its support, a settled dart the dart patches describe, a crease vertex's sector
/// as a boundary patch) its table patch; any other the feature descent.
fn face_paths(mesh: &Mesh) -> Vec<Path> {
    (0..mesh.faces())
        .map(|f| {
            if mesh.holes[f] {
                Path::Hole
            } else if is_table_patch(mesh, f) {
                Path::Table
            } else {
                Path::Feature
            }
        })
        .collect()
}

/// The local subdivision operators of every patch kind that an isolated mesh's table faces
/// take, built once per topology: they depend on the patches' kinds and the mesh's boundary
/// rule, not on its positions, so a [`crate::Surface`] keeps them from frame to frame.
#[derive(Debug)]
pub(crate) struct PatchOperators(HashMap<PatchKind, Operators>);

impl PatchOperators {
    /// The operators of the kinds of `patches` on the table path, built in parallel.
    pub(crate) fn new(mesh: &Mesh, patches: &[FacePatch]) -> Result<Self, RuntimeError> {
        let mut kinds: Vec<PatchKind> = patches
            .iter()
            .zip(face_paths(mesh))
            .filter(|(_, p)| *p == Path::Table)
            .map(|(p, _)| p.kind)
            .collect();
        kinds.sort_by_key(|k| (k.boundary, k.feature, k.faces, k.sector));
        kinds.dedup();
        kinds
            .par_iter()
            .map(|&kind| Ok((kind, Operators::new(mesh, kind)?)))
            .collect::<Result<_, RuntimeError>>()
            .map(PatchOperators)
    }
}

/// [`tessellate_adaptive`] with the patch kinds' operators given (those of `mesh` and
/// `patches`, [`PatchOperators::new`]), its statistics' seconds counted from `started`, into
/// `out` (every list resized in place and overwritten, its capacity kept; emptied on an error);
/// the input passed [`check_input`].
pub(crate) fn tessellate_adaptive_with(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    options: &AdaptiveOptions,
    operators: &PatchOperators,
    started: Instant,
    out: &mut AdaptiveMesh,
) -> Result<AdaptiveStats, RuntimeError> {
    let result = passes(table, mesh, patches, options, &operators.0, out);
    if result.is_err() {
        out.clear();
    }
    Ok(statistics(out, result?, mesh.faces(), options, started))
}

/// The marking, the global ids and the polygons of [`tessellate_adaptive_with`], into `out`,
/// whose lists hold the frame before's (each is resized and every entry written: ids and
/// positions in `global_ids::assign`, regions below, polygons in [`gather_polygons`]).
fn passes(
    stencils: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    options: &AdaptiveOptions,
    operators: &HashMap<PatchKind, Operators>,
    out: &mut AdaptiveMesh,
) -> Result<LeafStats, RuntimeError> {
    let path = face_paths(mesh);
    // The whole feature face's diagonal, for relative flatness at its hull squares (as the
    // extraordinary square uses its whole patch's).
    let feature_faces: Vec<usize> = (0..mesh.faces())
        .filter(|&f| path[f] == Path::Feature)
        .collect();
    let corner_queries: Vec<LimitQuery> = feature_faces
        .iter()
        .flat_map(|&f| {
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| LimitQuery {
                face: f as u32,
                u,
                v,
            })
        })
        .collect();
    let corner_points = limit_stencils(mesh, &corner_queries)?;
    let mut root_diagonal = vec![0.0; mesh.faces()];
    for (k, &f) in feature_faces.iter().enumerate() {
        let p: [Point; 4] = std::array::from_fn(|c| limit_of(&corner_points[4 * k + c], mesh)[0]);
        root_diagonal[f] = longer_diagonal(&p);
    }
    // Pass 1 (parallel): the adaptive marking of every face, within the polygon budget.
    // The faces are dealt to the threads one at a time, most leaves first by the frame
    // before's count (a kept workspace; else in face order): a face's cost goes with its
    // leaves, so the faces left when a thread runs dry are cheap and the threads end together.
    // In face order, in halves, the issue's cage's 16 extraordinary faces (20–40 µs each,
    // against 0.5–4 µs for the others) left one thread waiting, and a thread that waits
    // sleeps, which on the development host costs some 100 µs to wake (docs/benchmarks.md).
    let polygons = AtomicUsize::new(0);
    let mut work = std::mem::take(&mut out.workspace.marks);
    work.truncate(patches.len());
    work.resize_with(patches.len(), FaceMarks::default);
    let mut order: Vec<(usize, &mut FaceMarks)> = work.iter_mut().enumerate().collect();
    order.sort_by_key(|(_, marks)| std::cmp::Reverse(marks.leaves.len()));
    for_each_dealt(
        &mut order,
        PlaceTable::default,
        |table, (f, marks)| -> Result<(), RuntimeError> {
            let (f, patch) = (*f, &patches[*f]);
            let mut run = |corner, body: &mut dyn FnMut(&mut FaceWork)| {
                FaceWork::run(options, corner, (&mut *marks, &mut *table), &polygons, body)
            };
            match path[f] {
                Path::Hole => {
                    marks.clear();
                    return Ok(());
                }
                Path::Feature => {
                    let (level, g) = feature::root(mesh, f);
                    let frame = [(0, 0), (GRID, 0), (GRID, GRID), (0, GRID)];
                    return run(0, &mut |face| {
                        face.feature(&level, g, frame, 0, true, root_diagonal[f]);
                    });
                }
                Path::Table => {}
            }
            let ops = operators.get(&patch.kind).ok_or_else(|| {
                RuntimeError::Unsupported(format!("no operators for {:?}", patch.kind))
            })?;
            if ops.size != patch.points.len() {
                return Err(RuntimeError::Unsupported(format!(
                    "a patch {:?} has {} control points, its layout {}",
                    patch.kind,
                    patch.points.len(),
                    ops.size
                )));
            }
            let points: Vec<Point> = patch
                .points
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect();
            match ops.regular_patch(&points) {
                Some(net) => run(patch.corner, &mut |face| {
                    face.regular(&net, 0, 0, 0);
                }),
                None => {
                    let normal = vertex_normal(stencils, patch, &points).unwrap_or([0.0; 3]);
                    run(patch.corner, &mut |face| {
                        face.extraordinary(ops, &points, normal);
                    })
                }
            }
        },
    )?;
    if polygons.load(Ordering::Relaxed) > options.max_polygons {
        return Err(RuntimeError::OverBudget {
            what: format!(
                "the adaptive tessellation meeting the {} tolerance {}",
                if options.relative {
                    "relative"
                } else {
                    "distance"
                },
                options.tolerance
            ),
            estimate: format!(
                "{} polygons over {} faces when it stopped, squares still over the tolerance",
                polygons.load(Ordering::Relaxed),
                mesh.faces()
            ),
            limit: format!("{} polygons", options.max_polygons),
            raise: "--max-polygons N raises it, a larger --tolerance needs fewer".to_owned(),
        });
    }
    // Pass 1b: the corners of the hull squares, by feature-adaptive limit stencils (one batch),
    // and those squares' diagonals.
    // Only the feature descent leaves points pending, each once.
    let pending: Vec<(usize, u32)> = feature_faces
        .iter()
        .flat_map(|&f| work[f].pending.iter().map(move |&p| (f, p)))
        .collect();
    let queries: Vec<LimitQuery> = pending
        .iter()
        .map(|&(f, p)| {
            let (u, v) = work[f].places[p as usize];
            LimitQuery {
                face: f as u32,
                u: f64::from(u) / f64::from(GRID),
                v: f64::from(v) / f64::from(GRID),
            }
        })
        .collect();
    let stencils = limit_stencils(mesh, &queries)?;
    for (&(f, p), stencil) in pending.iter().zip(&stencils) {
        let [position, du, dv] = limit_of(stencil, mesh);
        work[f].positions[p as usize] = position;
        work[f].normals[p as usize] = unit(cross(du, dv));
    }
    for &f in &feature_faces {
        let marks = &mut work[f];
        marks.pending.clear();
        for (leaf, corners) in marks.leaves.iter_mut().zip(&marks.corners) {
            if leaf.extraordinary && leaf.diagonal == 0.0 {
                let mut p = [[0.0; 3]; 4];
                for (p, &c) in p.iter_mut().zip(corners) {
                    *p = *marks.positions.get(c as usize).ok_or_else(|| {
                        global_ids::internal(format!("face {f}: a leaf's corner is not marked"))
                    })?;
                }
                leaf.diagonal = longer_diagonal(&p);
            }
        }
    }
    // Pass 2 (parallel): global ids (section 5), first evaluation wins, in face order.
    let ids = global_ids::assign(
        mesh,
        &work,
        std::mem::take(&mut out.workspace.ids),
        &mut out.positions,
        &mut out.normals,
        &mut out.sources,
    )?;
    // Pass 3 (parallel): the polygons (base quadrilateral replacement) and their triangles,
    // in runs of leaves, then copied into the output's flat arrays run by run in parallel
    // (gathering them on one thread was a serial copy of 36 MB, 23 ms for Spot's 356,467
    // polygons at `8.248e-5`).
    // Each run's leaves are found from the faces' leaf counts (a list of every leaf, made on
    // one thread, took a twentieth of the issue's cage's frame on two).
    let leaf_ends = prefix_sums(work.iter().map(|marks| marks.leaves.len()));
    let leaf_count = leaf_ends.last().copied().unwrap_or(0);
    resize_to_overwrite(&mut out.regions, leaf_count, PolygonRegion::default());
    let positions = &out.positions;
    let mut runs = std::mem::take(&mut out.workspace.runs);
    let chunks = leaf_count.div_ceil(LEAVES_PER_RUN);
    runs.truncate(chunks);
    runs.resize_with(chunks, PolygonRun::default);
    out.regions
        .par_chunks_mut(LEAVES_PER_RUN)
        .zip(runs.par_iter_mut())
        .enumerate()
        .map_init(
            PolygonBuffers::default,
            |buffers, (chunk, (regions, kept))| {
                let first = chunk * LEAVES_PER_RUN;
                let face = leaf_ends.partition_point(|&end| end <= first);
                // Filled where it lives on this thread's stack: the runs are neighbours in
                // `runs`, and each push writing a list's length into a cache line that the
                // other thread writes too made both runs 2.5 times slower (false sharing).
                let mut run = std::mem::take(kept);
                run.clear();
                let leaves = leaves_from(&work, face, first - global_ids::start(&leaf_ends, face));
                let result =
                    regions
                        .iter_mut()
                        .zip(leaves)
                        .try_for_each(|(region, (marks, leaf))| {
                            *region = leaf.2.region(leaf.0);
                            run.leaves.add(region);
                            buffers.polygon((&ids, marks), positions, leaf, &mut run)
                        });
                *kept = run;
                result
            },
        )
        .collect::<Result<(), RuntimeError>>()?;
    gather_polygons(&runs, out)?;
    let stats = runs
        .iter()
        .fold(LeafStats::default(), |all, run| all.merge(run.leaves));
    out.workspace = Workspace {
        marks: work,
        ids: ids.faces,
        runs,
    };
    Ok(stats)
}

/// Copy the runs of pass 3 into `out`'s flat arrays, each run into its own ranges, in parallel.
fn gather_polygons(runs: &[PolygonRun], out: &mut AdaptiveMesh) -> Result<(), RuntimeError> {
    let too_many = || RuntimeError::Unsupported("more than 2^32 polygon vertices".to_owned());
    let polygons: usize = runs.iter().map(|r| r.counts.len()).sum();
    let vertices: usize = runs.iter().map(|r| r.vertices.len()).sum();
    let triangles: usize = runs.iter().map(|r| r.triangles.len()).sum();
    u32::try_from(vertices).map_err(|_| too_many())?;
    // Sized in place, every entry written below (pages written before, where the caller keeps
    // `out`).
    resize_to_overwrite(&mut out.starts, polygons + 1, 0);
    out.starts[0] = 0;
    resize_to_overwrite(&mut out.vertices, vertices, 0);
    resize_to_overwrite(&mut out.triangles, triangles, [0; 3]);
    // Each run's ranges of the three arrays, split off in order.
    let mut pieces = Vec::with_capacity(runs.len());
    let (mut starts, mut ids, mut triples) = (
        &mut out.starts[1..],
        &mut out.vertices[..],
        &mut out.triangles[..],
    );
    let mut first = 0u32;
    for run in runs {
        let (s, s_rest) = std::mem::take(&mut starts).split_at_mut(run.counts.len());
        let (v, v_rest) = std::mem::take(&mut ids).split_at_mut(run.vertices.len());
        let (t, t_rest) = std::mem::take(&mut triples).split_at_mut(run.triangles.len());
        (starts, ids, triples) = (s_rest, v_rest, t_rest);
        pieces.push((run, first, s, v, t));
        // In range: the total was checked above.
        first += run.vertices.len() as u32;
    }
    // A run is some 50 KB to copy (a few µs): a job of fewer than four costs more to hand to
    // the other thread than it saves.
    pieces
        .into_par_iter()
        .with_min_len(4)
        .for_each(|(run, first, starts, vertices, triangles)| {
            let mut end = first;
            for (start, &count) in starts.iter_mut().zip(&run.counts) {
                end += count;
                *start = end;
            }
            vertices.copy_from_slice(&run.vertices);
            triangles.copy_from_slice(&run.triangles);
        });
    Ok(())
}

/// The tessellation's statistics: `out`'s counts, the leaves' (gathered in pass 3), the
/// uniform tessellation compared with, and the seconds since `started`.
fn statistics(
    out: &AdaptiveMesh,
    leaves: LeafStats,
    faces: usize,
    options: &AdaptiveOptions,
    started: Instant,
) -> AdaptiveStats {
    let mut stats = AdaptiveStats {
        polygons: out.polygon_count(),
        vertices: out.positions.len(),
        triangles: out.triangle_count(),
        triangulated: options.triangulate,
        max_depth: leaves.max_depth,
        leaves_over_tolerance: leaves.over_tolerance,
        max_bound: leaves.max_bound,
        max_relative_bound: leaves.max_relative_bound,
        extraordinary_leaves: leaves.extraordinary,
        ..AdaptiveStats::default()
    };
    stats.uniform_depth = stats.max_depth;
    stats.uniform_polygons = faces as f64 * 4f64.powi(stats.max_depth as i32);
    let primitives = if options.triangulate {
        stats.triangles
    } else {
        stats.polygons
    };
    stats.au_ratio = primitives as f64 / stats.uniform_polygons;
    stats.seconds = started.elapsed().as_secs_f64();
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh of the quads `faces` over 8 vertices (positions unused by the check).
    fn quads(faces: &[[u32; 4]]) -> AdaptiveMesh {
        let region = PolygonRegion {
            face: 0,
            u0: 0,
            v0: 0,
            size: 1,
            denominator: 1,
            depth: 0,
            extraordinary: false,
            bound: 0.0,
            tolerance: 0.0,
            diagonal: 0.0,
        };
        // Each quad's two triangles (unused by the check), to keep the arrays' invariant.
        let mut starts = vec![0];
        starts.extend((1..=faces.len()).map(|i| 4 * i as u32));
        AdaptiveMesh {
            positions: vec![[0.0; 3]; 8],
            starts,
            vertices: faces.concat(),
            triangles: faces
                .iter()
                .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
                .collect(),
            regions: vec![region; faces.len()],
            ..AdaptiveMesh::default()
        }
    }

    /// The polygons' check against the definition on a cube (vertex `x + 2y + 4z`, faces
    /// outward): closed; a face missing, reversed or doubled, or a vertex beyond the positions,
    /// is not.
    #[test]
    fn polygon_watertightness_is_every_edge_once_each_way() {
        let cube = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        assert!(quads(&cube).is_watertight());
        assert!(!quads(&cube[1..]).is_watertight(), "a face missing");
        let mut reversed = cube;
        reversed[2].reverse();
        assert!(!quads(&reversed).is_watertight(), "a face reversed");
        let doubled: Vec<[u32; 4]> = cube.iter().chain(&cube[..1]).copied().collect();
        assert!(!quads(&doubled).is_watertight(), "a face twice");
        let mut beyond = quads(&cube);
        beyond.positions.truncate(7);
        assert!(!beyond.is_watertight(), "vertex 7 beyond the positions");
    }

    /// Every pair's distance, the largest: what `diameter` must return to the bit.
    fn all_pairs(points: &[Point]) -> f64 {
        let mut best = 0.0f64;
        for (i, &a) in points.iter().enumerate() {
            for &b in &points[i + 1..] {
                best = best.max(bezier_net::norm(bezier_net::sub(a, b)));
            }
        }
        best
    }

    /// The corners settle a split only beyond the floor and its margin, which grows with the
    /// layout's coordinates; the lower bound they give is their largest distance, never above
    /// the diameter of any cloud holding them.
    #[test]
    fn corners_apart_only_beyond_the_floor_and_its_margin() {
        let corners = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 4.0, 0.0]];
        let layout = [[-1.0, -1.0, 0.0], [4.0, 5.0, 1.0]];
        assert_eq!(corners_apart(&corners, &layout, 4.9), Some(5.0));
        assert_eq!(corners_apart(&corners, &layout, 5.0), None);
        assert_eq!(corners_apart(&corners, &layout, f64::INFINITY), None);
        // Far from the origin the margin (1e-12 of the coordinates) hides a small excess.
        let far = [[1e11, 0.0, 0.0]];
        assert_eq!(corners_apart(&corners, &far, 4.95), None);
        assert_eq!(corners_apart(&corners, &far, 4.8), Some(5.0));
        let cloud: Vec<Point> = corners.iter().chain(&layout).copied().collect();
        assert!(diameter_above(&cloud, f64::INFINITY) >= 5.0);
    }

    #[test]
    fn diameter_is_the_largest_distance_of_all_pairs() {
        // A fixed linear congruential sequence in [0, 1).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..200 {
            let count = 1 + case % 170;
            // Clouds of every shape the bound meets: isotropic, flat, a thin needle, and a
            // cluster far from the origin (large coordinates, small extent).
            let (scale, offset) = match case % 4 {
                0 => ([1.0, 1.0, 1.0], 0.0),
                1 => ([1.0, 1.0, 1e-6], 0.0),
                2 => ([1.0, 1e-3, 1e-3], 0.0),
                _ => ([1e-4, 1e-4, 1e-4], 1e3),
            };
            let mut points: Vec<Point> = (0..count)
                .map(|_| std::array::from_fn(|c| offset + scale[c] * (next() - 0.5)))
                .collect();
            if case % 5 == 0 {
                // Repeated points (a net's corners are shared).
                let copy = points[0];
                points.push(copy);
            }
            let exact = all_pairs(&points);
            assert_eq!(
                diameter_above(&points, f64::INFINITY).to_bits(),
                exact.to_bits(),
                "case {case}"
            );
            // Below a floor under the diameter a caller learns only that it is above; at or
            // over it, the diameter itself.
            for floor in [0.0, 0.5 * exact, 0.999 * exact, exact] {
                let d = diameter_above(&points, floor);
                assert!(d <= exact, "case {case}");
                assert_eq!(d > floor, exact > floor, "case {case}, floor {floor}");
                if d <= floor {
                    assert_eq!(d.to_bits(), exact.to_bits(), "case {case}, floor {floor}");
                }
            }
        }
        assert_eq!(diameter_above(&[], f64::INFINITY), 0.0);
        assert_eq!(diameter_above(&[[1.0, 2.0, 3.0]], f64::INFINITY), 0.0);
    }
}
