//! The dual-grid watertight tessellator (Schaefer–Warren section 5.5), per-face rates, closed
//! meshes and meshes with boundary.
//!
//! Every face at rate `n` gets the `n x n` dual points `((2i+1)/2n, (2j+1)/2n)` of its
//! parameter domain, evaluated once from the table. Polygons connect them:
//!
//! * face interiors: the `(n-1)^2` quads of the dual grid, two triangles each;
//! * interior edges: the strip between the two faces' dual rows nearest the shared edge, merged
//!   by their parameter along the edge when the rates differ (`n_a + n_b - 2` triangles);
//! * boundary edges: the strip between the face's dual row and the `n + 1` points
//!   `t/n` of the limit boundary curve over that edge (`2n - 1` triangles); the curve's interior
//!   points belong to the edge, its end points (the limit positions of the boundary vertices) to
//!   the vertices, each made once;
//! * vertices: the polygon of the surrounding faces' dual points nearest the vertex (a v-gon),
//!   closed on a boundary vertex by the vertex's limit position.
//!
//! Every output vertex is made exactly once and every polygon refers to it by index, so the
//! output is watertight by construction; nothing is welded by distance.
//!
//! The work splits into a [`DualGrid`] plan, built once per mesh and rates (patches, table
//! sections, separable factors, connectivity records), and the per-frame work: evaluating every
//! point from the current control points ([`DualGrid::evaluate`]) and writing the triangles
//! ([`DualGrid::connect`]), both in parallel with rayon. Regular interior faces, most of any
//! isolated mesh, are evaluated as tensor products: their table stencils factor into the cubic
//! B-spline weights of the two directions (checked when the plan is built), so a point costs 12
//! multiply-adds per coordinate for position, d/du and d/dv together instead of 48, four points
//! (four columns) in each vector operation. The other faces' stencils are interleaved four
//! points a group (`tessellate::lane_stencils`).

use std::collections::HashMap;
use std::ops::Range;
use std::time::Instant;

use table_format::{PointSet, SectionKey, StencilKind};

use crate::mesh::topology::{Cut, Mesh, NONE};
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use crate::scheme::catmull_clark::adaptive::{
    limit_stencils, phantom_grid, LimitQuery, LimitStencil,
};
use crate::scheme::patch::{dual_index_in_patch, FacePatch, PatchKind};
use crate::scheme::stencil::Stencil;
use crate::stencil_table::StencilTable;
pub use crate::tessellate::kernel::TessellationTime;
use crate::tessellate::kernel::{
    append_control, for_each_range, for_each_range_with, merge_rows, patch_origin, relative,
    table_may_describe, total_bytes, unless_absent, vec_bytes, Connectivity, GridPlan, PointPlan,
    Stencils, MAX_PATCH,
};
use crate::tessellate::lane_stencils::{
    store_points, unit_cross_x4, LaneStencils, PointGroups, LANES,
};
use crate::tessellate::mirror_stencils::MirrorStencils;
use crate::tessellate::sub_patches::{SubPatchPlan, MAX_LEVEL_ONE};
use crate::RuntimeError;
use input_patches::InputPatches;
use wide::f32x4;

mod input_patches;

/// The largest rate of the tables the evaluator takes.
pub const MAX_RATE: u32 = 64;

/// The cubic B-spline factors of the regular patch at rate `n`, recovered from the table:
/// `x[a][i]` is the weight of control column `a` (`u = -1, 0, 1, 2`) at the dual point
/// `(2i+1)/2n`, `dx` its derivative; `y`, `dy` the same for rows.
#[derive(Clone, Debug)]
struct SeparableBasis {
    x: [Vec<f32>; 4],
    dx: [Vec<f32>; 4],
    y: [Vec<f32>; 4],
    dy: [Vec<f32>; 4],
    /// `x` and `dx` by groups of [`LANES`] columns: `x_lanes[g][a]` holds `x[a][g * LANES +
    /// lane]` in its lanes; the last group's unused lanes repeat the last column (evaluated, not
    /// written).
    x_lanes: Vec<[f32x4; 4]>,
    dx_lanes: Vec<[f32x4; 4]>,
    /// `y` and `dy` broadcast: `y_splat[j][b]` holds `y[b][j]` in every lane.
    y_splat: Vec<[f32x4; 4]>,
    dy_splat: Vec<[f32x4; 4]>,
    /// Rows `j` and `n - 1 - j`, for `j < n / 2`, as even and odd parts of row `j`'s weights,
    /// broadcast: `[(y0 + y3) / 2, (y1 + y2) / 2, (y0 - y3) / 2, (y1 - y2) / 2]`, then the same
    /// of `dy` ([`rows_by_pairs`]). Empty unless every row `n - 1 - j` is row `j` mirrored
    /// (`y[b]` at `n - 1 - j` equal to `y[3 - b]` at `j`, `dy` with its sign changed), as the
    /// B-spline's are at the dual points `(2j + 1) / 2n`.
    y_pairs: Vec<[f32x4; 8]>,
}

/// Grid coordinates `(a, b)` (each in -1..=2) of the regular patch's layout entries
/// `V, E_1..E_4, F_1..F_4, O_1..O_7` (docs/algorithms/extraordinary-stencils.md).
pub(crate) const REGULAR_LAYOUT: [(i32, i32); 16] = [
    (0, 0),
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, 1),
    (-1, -1),
    (1, -1),
    (2, -1),
    (2, 0),
    (2, 1),
    (2, 2),
    (1, 2),
    (0, 2),
    (-1, 2),
];

impl SeparableBasis {
    /// The factors `x`, `dx` (along `u`) and `y`, `dy` (along `v`), `n` values each.
    fn from_factors(
        x: [Vec<f32>; 4],
        dx: [Vec<f32>; 4],
        y: [Vec<f32>; 4],
        dy: [Vec<f32>; 4],
    ) -> Self {
        let n = x[0].len();
        let lanes = |f: &[Vec<f32>; 4]| {
            (0..n.div_ceil(LANES))
                .map(|g| {
                    f.each_ref()
                        .map(|w| f32x4::new(std::array::from_fn(|l| w[(g * LANES + l).min(n - 1)])))
                })
                .collect()
        };
        let splat = |f: &[Vec<f32>; 4]| {
            (0..f[0].len())
                .map(|i| f.each_ref().map(|w| f32x4::splat(w[i])))
                .collect()
        };
        let mirrored = (0..n).all(|j| {
            (0..4).all(|b| y[b][n - 1 - j] == y[3 - b][j] && dy[b][n - 1 - j] == -dy[3 - b][j])
        });
        let half = |a: f32, b: f32| f32x4::splat((a + b) * 0.5);
        let y_pairs = (0..if mirrored { n / 2 } else { 0 })
            .map(|j| {
                let (w, d) = (
                    [0, 1, 2, 3].map(|b| y[b][j]),
                    [0, 1, 2, 3].map(|b| dy[b][j]),
                );
                [
                    half(w[0], w[3]),
                    half(w[1], w[2]),
                    half(w[0], -w[3]),
                    half(w[1], -w[2]),
                    half(d[0], d[3]),
                    half(d[1], d[2]),
                    half(d[0], -d[3]),
                    half(d[1], -d[2]),
                ]
            })
            .collect();
        SeparableBasis {
            y_pairs,
            x_lanes: lanes(&x),
            dx_lanes: lanes(&dx),
            y_splat: splat(&y),
            dy_splat: splat(&dy),
            x,
            dx,
            y,
            dy,
        }
    }

    /// Factor the regular patch's stencils at rate `n`: the marginals of a tensor product are
    /// its factors (the other direction's weights sum to one, and its derivative's to zero), and
    /// the factorization is accepted only if it reproduces every weight to 1e-6.
    fn from_stencils(s: &Stencils, n: usize) -> Option<Self> {
        let k = REGULAR_LAYOUT.len();
        if s.position.len() != n * n * k {
            return None;
        }
        let marginal = |w: &[f32], point: usize, along_u: bool| -> [f32; 4] {
            let mut out = [0.0f64; 4];
            for (l, &(a, b)) in REGULAR_LAYOUT.iter().enumerate() {
                let c = if along_u { a } else { b };
                out[(c + 1) as usize] += f64::from(w[point * k + l]);
            }
            out.map(|x| x as f32)
        };
        let column = |w: &[f32], along_u: bool| -> [Vec<f32>; 4] {
            let mut out: [Vec<f32>; 4] = Default::default();
            for t in 0..n {
                let point = if along_u { t } else { t * n };
                let m = marginal(w, point, along_u);
                for a in 0..4 {
                    out[a].push(m[a]);
                }
            }
            out
        };
        let basis = SeparableBasis::from_factors(
            column(s.position, true),
            column(s.du, true),
            column(s.position, false),
            column(s.dv, false),
        );
        let check = |w: &[f32], fx: &[Vec<f32>; 4], fy: &[Vec<f32>; 4]| {
            (0..n * n).all(|p| {
                let (i, j) = (p % n, p / n);
                REGULAR_LAYOUT.iter().enumerate().all(|(l, &(a, b))| {
                    let product = fx[(a + 1) as usize][i] * fy[(b + 1) as usize][j];
                    (w[p * k + l] - product).abs() <= 1e-6
                })
            })
        };
        (check(s.position, &basis.x, &basis.y)
            && check(s.du, &basis.dx, &basis.y)
            && check(s.dv, &basis.x, &basis.dy))
        .then_some(basis)
    }
}

/// How one face's dual points are evaluated.
#[derive(Clone, Debug)]
enum FaceEval {
    /// A regular interior face: the 4 x 4 control grid (`grid[a][b]`, columns along `u`) and the
    /// separable factors of its rate.
    Separable { grid: [[u32; 4]; 4] },
    /// A B-spline patch with phantom points (`adaptive::phantom_grid`: along a boundary or a
    /// straight infinitely sharp crease, at a pinned corner), a bit per such side in
    /// `phantoms`: [`FaceEval::Separable`] with the row of `grid` beyond each such side replaced
    /// by `2 P_0 - P_1` when evaluated. (A variant of its own keeps the regular faces' code as
    /// it was: a test for phantoms there cost 5% more instructions at rate 4.)
    Phantom { grid: [[u32; 4]; 4], phantoms: u8 },
    /// Any other patch: its table stencils in the face's point order, [`LANES`] points at a
    /// time (`DualGrid::lanes[lanes]`, shared by every face of the same section, corner and
    /// patch size), and its control points.
    Table { lanes: u32, control: Range<u32> },
    /// A table face of a smooth interior patch whose stencils are mirror images across the
    /// face's diagonal: its points two at a time ([`MirrorStencils`], `DualGrid::mirrors[mirror]`).
    Mirror { mirror: u32, control: Range<u32> },
    /// A table face at a rate [`splits`](crate::tessellate::sub_patches::splits) whose table stores the
    /// scaling relation's pieces: through one subdivision step
    /// ([`crate::tessellate::sub_patches`]), the quarter at the vertex from its stencils at
    /// half the rate (`DualGrid::lanes[lanes]`, the quarter's points in the face's order) and
    /// the three regular
    /// sub-patches as tensor products (`DualGrid::splits[split]`).
    Split {
        split: u32,
        lanes: u32,
        control: Range<u32>,
    },
    /// A face the tables do not describe (sharp features, a valence beyond the table's):
    /// stencils from feature-adaptive refinement ([`crate::scheme::catmull_clark::adaptive`]),
    /// in the face's own parameters, over its own control points (the union of its points'
    /// supports, any number), in lanes of their own (`DualGrid::lanes[lanes]`).
    Local { control: Range<u32>, lanes: u32 },
    /// A piece of a regular input face evaluated whole, with its other pieces, from the input
    /// points ([`input_patches`]).
    Input,
    /// A hole: no points, no triangles.
    Hole,
}

/// A row of output vertices `start + t * step`, `t = 0..len`, at parameters
/// `(offset + 2t) / denominator` along an edge.
#[derive(Clone, Copy, Debug)]
struct DualRow {
    start: u32,
    step: i32,
    len: u32,
}

impl DualRow {
    fn at(&self, t: u32) -> u32 {
        (self.start as i64 + i64::from(self.step) * i64::from(t)) as u32
    }
}

/// One edge's strip.
#[derive(Clone, Copy, Debug)]
enum Strip {
    /// Between two faces: both rows run along the edge in the same direction, the second lies to
    /// its right.
    Interior { left: DualRow, right: DualRow },
    /// Along the boundary, a hole or a crease: the face's row and the curve points
    /// `t / segments`: `tail`, the edge's own `segments - 1` points from `first` (listed
    /// from head to tail when `reversed`: the crease's other side made them), `head`.
    Boundary {
        row: DualRow,
        tail: u32,
        first: u32,
        head: u32,
        segments: u32,
        reversed: bool,
    },
}

/// The per-mesh plan of a dual-grid tessellation: build once, then [`DualGrid::evaluate`] and
/// [`DualGrid::connect`] per frame.
#[derive(Clone, Debug)]
pub struct DualGrid {
    rates: Vec<u32>,
    /// First dual vertex of every face, and the total after the last.
    first: Vec<u32>,
    /// `first[1..]` as `usize`: where each face's dual points end, the ranges a frame hands to
    /// its faces (made once, not per frame).
    face_ends: Vec<usize>,
    faces: Vec<FaceEval>,
    /// Separable factors by rate (index `n`).
    bases: Vec<Option<SeparableBasis>>,
    /// The table faces' stencils in lanes, one per section, corner and patch size met, and
    /// one per local face.
    lanes: Vec<LaneStencils>,
    /// The split faces' plans, one per section, corner and patch size met.
    splits: Vec<SubPatchPlan>,
    /// The mirrored table faces' stencils ([`FaceEval::Mirror`]), one per section, corner and
    /// patch size met.
    mirrors: Vec<MirrorStencils>,
    /// Control points of the table-evaluated patches, concatenated.
    control: Vec<u32>,
    /// Boundary-curve points (vertex limit points first, then edges' interior points), while
    /// the plan is built.
    boundary_points: Vec<PointPlan>,
    /// The boundary points' stencils, in lanes ([`PointGroups`]), and where they lie.
    boundary_groups: PointGroups,
    /// Boundary points of local faces still to be computed (index into `boundary_points`).
    local_points: Vec<(usize, LimitQuery)>,
    strips: Vec<Strip>,
    /// Vertex polygons and the triangle offsets of every face, strip and polygon.
    connectivity: Connectivity,
    vertex_count: usize,
    boundary: bool,
    /// Output vertices that repeat another's position on the other side of a face-varying
    /// seam, `[copy, original]`: the same stencil, another source.
    seam_copies: Vec<[u32; 2]>,
    /// The regular input faces evaluated whole ([`DualGrid::with_input_patches`]), and the map
    /// that makes the control points the other faces read.
    input: Option<InputPatches>,
}

fn section(patch: &FacePatch, kind: StencilKind, points: PointSet, n: u32) -> SectionKey {
    patch.kind.section(kind, points, n)
}

fn stencils<'t>(
    table: &'t StencilTable,
    patch: &FacePatch,
    points: PointSet,
    n: u32,
) -> Result<Stencils<'t>, RuntimeError> {
    kind_stencils(table, &patch.kind, patch.points.len(), points, n)
}

/// The dual stencils of the regular interior patch (valence 4, 16 points) at rate `n`: what the
/// tensor-product faces' factors come from.
fn regular_stencils(table: &StencilTable, n: u32) -> Result<Stencils<'_>, RuntimeError> {
    let regular = PatchKind {
        boundary: false,
        feature: table_format::Feature::None,
        faces: 4,
        sector: 0,
    };
    kind_stencils(table, &regular, REGULAR_LAYOUT.len(), PointSet::Dual, n)
}

/// The stencils of patch kind `kind` over `k` control points.
fn kind_stencils<'t>(
    table: &'t StencilTable,
    kind: &PatchKind,
    k: usize,
    points: PointSet,
    n: u32,
) -> Result<Stencils<'t>, RuntimeError> {
    let [position, du, dv] = [
        StencilKind::Position,
        StencilKind::DerivativeU,
        StencilKind::DerivativeV,
    ]
    .map(|stencil| table.weights(&kind.section(stencil, points, n)));
    let (position, du, dv) = (position?, du?, dv?);
    let count = points.count(n) as usize;
    if position.len() != count * k || du.len() != position.len() || dv.len() != du.len() {
        return Err(RuntimeError::LayoutMismatch {
            key: kind.section(StencilKind::Position, points, n),
            table: position.len() / count.max(1),
            patch: k,
        });
    }
    Ok(Stencils { position, du, dv })
}

/// Stencils on the mesh's vertices as dense f32 blocks over the union of their supports: the
/// control points, then the position weights of every point, its d/du weights, its d/dv
/// weights (`points x control` each).
fn dense(stencils: &[LimitStencil]) -> (Vec<u32>, Vec<f32>) {
    let mut control: Vec<u32> = stencils.iter().flatten().map(|&(v, _)| v).collect();
    control.sort_unstable();
    control.dedup();
    let k = control.len();
    let block = stencils.len() * k;
    let mut weights = vec![0.0f32; 3 * block];
    for (p, stencil) in stencils.iter().enumerate() {
        for &(v, w) in stencil {
            let l = control.partition_point(|&c| c < v);
            for (kind, &x) in w.iter().enumerate() {
                weights[kind * block + p * k + l] = x as f32;
            }
        }
    }
    (control, weights)
}

/// Triangles of a strip merging rows of `a` and `b` points.
fn strip_triangle_count(a: u32, b: u32) -> usize {
    (a + b - 2) as usize
}

impl DualGrid {
    /// Plan the tessellation of an isolated mesh (closed or with boundary) with rate `rates[f]`
    /// on face `f` (any rates the table holds, not only powers of two).
    pub fn new(
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
        rates: &[u32],
    ) -> Result<Self, RuntimeError> {
        Self::with_channel(table, mesh, patches, rates, None)
    }

    /// [`DualGrid::new`] with output vertices split along the seams of a face-varying channel:
    /// `channel[h]` is the channel's vertex at corner `h` of `mesh` (the face-varying channel's
    /// mesh refined as `mesh` was,
    /// [`crate::scheme::catmull_clark::face_varying::ChannelIsolation`]). A seam (an edge whose
    /// two faces disagree at an end) is sampled like an infinitely sharp crease, and each side
    /// gets its own copies of the curve's points and of the vertex limit points, one per channel
    /// vertex: same stencils, so the same position bits, but each with a source on its own side
    /// ([`GridPlan::seam_copies`]).
    pub fn with_channel(
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
        rates: &[u32],
        channel: Option<&[u32]>,
    ) -> Result<Self, RuntimeError> {
        if channel.is_some_and(|c| c.len() != mesh.face_vertices.len()) {
            return Err(RuntimeError::Unsupported(
                "a face-varying channel of another mesh".to_owned(),
            ));
        }
        if rates.len() != patches.len() || patches.len() != mesh.faces() {
            return Err(RuntimeError::Unsupported(format!(
                "{} rates and {} patches for {} faces",
                rates.len(),
                patches.len(),
                mesh.faces()
            )));
        }
        if let Some(f) = rates.iter().position(|&n| n == 0 || n > MAX_RATE) {
            return Err(RuntimeError::Unsupported(format!(
                "rate {} on face {f} (rates run from 1 to the table's largest)",
                rates[f]
            )));
        }
        // A one-face boundary vertex is smooth in "edge only" mode and pinned in "edge and
        // corner" mode: its stencils must come from a table made for the mesh's mode.
        let corners = mesh.boundary == schemes::BoundaryMode::EdgeAndCorner;
        if table.pins_corners() != corners
            && patches.iter().any(|p| p.kind.boundary && p.kind.faces == 1)
        {
            return Err(RuntimeError::BoundaryModeMismatch {
                mesh_corners: corners,
            });
        }
        let mut first = Vec::with_capacity(patches.len() + 1);
        first.push(0u32);
        for (&n, &hole) in rates.iter().zip(&mesh.holes) {
            // A hole makes no surface: no points of its own.
            first.push(first[first.len() - 1] + if hole { 0 } else { n * n });
        }
        let face_ends = first[1..].iter().map(|&x| x as usize).collect();
        let mut grid = DualGrid {
            rates: rates.to_vec(),
            first,
            face_ends,
            faces: Vec::with_capacity(patches.len()),
            bases: vec![None; MAX_RATE as usize + 1],
            lanes: Vec::new(),
            splits: Vec::new(),
            mirrors: Vec::new(),
            control: Vec::new(),
            boundary_points: Vec::new(),
            boundary_groups: PointGroups::default(),
            local_points: Vec::new(),
            strips: Vec::new(),
            connectivity: Connectivity::default(),
            vertex_count: 0,
            boundary: false,
            seam_copies: Vec::new(),
            input: None,
        };
        // A valence-4 dart is not the regular patch: its crease refines by other rules.
        let regular = |p: &FacePatch| {
            !p.kind.boundary
                && p.kind.feature == table_format::Feature::None
                && p.kind.faces == 4
                && p.corner == 0
        };
        let mut factored = vec![false; MAX_RATE as usize + 1];
        // The index in `grid.lanes` of every section, corner and patch size met.
        let mut layouts: HashMap<(SectionKey, u8, usize), u32> = HashMap::new();
        // The split of every section, corner and patch size met, if it splits: its plan's and
        // its quarter's lanes' indices.
        let mut splits: HashMap<(SectionKey, u8, usize), Option<(u32, u32)>> = HashMap::new();
        let mut mirrors: HashMap<(SectionKey, u8, usize), Option<u32>> = HashMap::new();
        // Faces the tables describe exactly (smooth patches, settled darts, crease sectors)
        // take their stencils, or the tensor product where they are B-spline patches; the
        // others (other sharp features nearby, a valence or patch beyond the table) are refined
        // adaptively below.
        let mut local_faces = Vec::new();
        let mut phantom_faces = Vec::new();
        for (f, (patch, &n)) in patches.iter().zip(rates).enumerate() {
            if mesh.holes[f] {
                grid.faces.push(FaceEval::Hole);
                continue;
            }
            let described = table_may_describe(mesh, patch, f);
            // The regular patch's factors, once per rate (every tensor-product face shares them).
            let tensor = regular(patch) || !described || patch.kind.boundary;
            if tensor {
                grid.factor(table, n, &mut factored)?;
            }
            let factors = grid.bases[n as usize].is_some();
            let s = if described {
                unless_absent(stencils(table, patch, PointSet::Dual, n))?
            } else {
                None
            };
            if regular(patch) && s.is_some() && factors {
                grid.faces.push(FaceEval::Separable {
                    grid: regular_cells(patch),
                });
                continue;
            }
            // A B-spline patch with phantom points beyond its infinitely sharp sides (a
            // boundary, a straight crease, a pinned corner): the tensor product, cheaper than
            // any stencil. A face the table does not describe stays `Local` until the plan is
            // made, so that its curve points are planned by the refinement.
            let phantom = if tensor && factors {
                phantom_grid(mesh, f)
            } else {
                None
            };
            if let Some((cells, phantoms)) = phantom {
                if s.is_some() {
                    grid.faces.push(FaceEval::Phantom {
                        grid: cells,
                        phantoms,
                    });
                } else {
                    phantom_faces.push((f, cells, phantoms));
                    grid.faces.push(FaceEval::Local {
                        control: 0..0,
                        lanes: 0,
                    });
                }
                continue;
            }
            let Some(s) = s else {
                local_faces.push(f);
                grid.faces.push(FaceEval::Local {
                    control: 0..0,
                    lanes: 0,
                });
                continue;
            };
            let k = patch.points.len();
            let key = (
                section(patch, StencilKind::Position, PointSet::Dual, n),
                patch.corner as u8,
                k,
            );
            let split = match splits.get(&key) {
                Some(&split) => split,
                None => {
                    let split = grid.plan_split(table, patch, n, &mut factored)?;
                    splits.insert(key, split);
                    split
                }
            };
            if let Some((split, lanes)) = split {
                let control = append_control(&mut grid.control, &patch.points)?;
                grid.faces.push(FaceEval::Split {
                    split,
                    lanes,
                    control,
                });
                continue;
            }
            let smooth = !patch.kind.boundary && patch.kind.feature == table_format::Feature::None;
            let mirror = match mirrors.get(&key) {
                Some(&mirror) => mirror,
                None => {
                    let plan = smooth
                        .then(|| MirrorStencils::new(&s, k, n as usize, patch.corner))
                        .flatten();
                    let mirror = plan.map(|plan| {
                        grid.mirrors.push(plan);
                        (grid.mirrors.len() - 1) as u32
                    });
                    mirrors.insert(key, mirror);
                    mirror
                }
            };
            if let Some(mirror) = mirror {
                let control = append_control(&mut grid.control, &patch.points)?;
                grid.faces.push(FaceEval::Mirror { mirror, control });
                continue;
            }
            let lanes = match layouts.get(&key) {
                Some(&lanes) => lanes,
                None => {
                    let lanes = face_lanes(&s, patch, n)?;
                    let index = grid.lanes.len() as u32;
                    grid.lanes.push(lanes);
                    layouts.insert(key, index);
                    index
                }
            };
            let control = append_control(&mut grid.control, &patch.points)?;
            grid.faces.push(FaceEval::Table { lanes, control });
        }
        grid.plan_connectivity(table, mesh, patches, channel)?;
        grid.plan_local(mesh, &local_faces)?;
        for (f, cells, phantoms) in phantom_faces {
            grid.faces[f] = FaceEval::Phantom {
                grid: cells,
                phantoms,
            };
        }
        // Copies take their original's stencil (local ones are known only now).
        let dual_total = grid.first[patches.len()];
        for &[copy, original] in &grid.seam_copies {
            let original = grid.boundary_points[(original - dual_total) as usize].clone();
            let copy = &mut grid.boundary_points[(copy - dual_total) as usize];
            (copy.weights, copy.control) = (original.weights, original.control);
        }
        grid.boundary_groups =
            PointGroups::new(&std::mem::take(&mut grid.boundary_points), &grid.control)?;
        Ok(grid)
    }

    /// The split of `patch`'s faces at rate `n` ([`FaceEval::Split`]): the indices of its plan
    /// and of its quarter's lanes (the patch's stencils at rate `n / 2`, the quarter's points in
    /// the face's order), with the regular factors of rate `n / 2`; `None` where the face does
    /// not split.
    fn plan_split(
        &mut self,
        table: &StencilTable,
        patch: &FacePatch,
        n: u32,
        factored: &mut [bool],
    ) -> Result<Option<(u32, u32)>, RuntimeError> {
        let k = patch.points.len();
        let Some(split) = SubPatchPlan::new(table, &patch.kind, k, patch.corner, n)? else {
            return Ok(None);
        };
        let m = n / 2;
        self.factor(table, m, factored)?;
        let Some(s) = unless_absent(stencils(table, patch, PointSet::Dual, m))? else {
            return Ok(None);
        };
        if self.bases[m as usize].is_none() {
            return Ok(None);
        }
        self.lanes.push(face_lanes(&s, patch, m)?);
        self.splits.push(split);
        Ok(Some((
            (self.splits.len() - 1) as u32,
            (self.lanes.len() - 1) as u32,
        )))
    }

    /// The regular patch's separable factors at rate `n` into `bases[n]`, once per rate
    /// (`factored[n]`: tried; every tensor product at that rate shares them).
    fn factor(
        &mut self,
        table: &StencilTable,
        n: u32,
        factored: &mut [bool],
    ) -> Result<(), RuntimeError> {
        let n = n as usize;
        if let (Some(done), Some(basis)) = (factored.get_mut(n), self.bases.get_mut(n)) {
            if !*done {
                *done = true;
                *basis = unless_absent(regular_stencils(table, n as u32))?
                    .and_then(|s| SeparableBasis::from_stencils(&s, n));
            }
        }
        Ok(())
    }

    fn face_vertex(&self, f: usize, i: u32, j: u32) -> u32 {
        self.first[f] + j * self.rates[f] + i
    }

    /// The dual row of face `f` nearest its side `side`, in the side's direction.
    fn row(&self, f: usize, side: usize) -> DualRow {
        let n = self.rates[f];
        let last = n - 1;
        let (start, step) = match side {
            0 => (self.face_vertex(f, 0, 0), 1),
            1 => (self.face_vertex(f, last, 0), n as i32),
            2 => (self.face_vertex(f, last, last), -1),
            _ => (self.face_vertex(f, 0, last), -(n as i32)),
        };
        DualRow {
            start,
            step,
            len: n,
        }
    }

    /// The face's dual point nearest its corner `corner`.
    fn corner_point(&self, f: usize, corner: usize) -> u32 {
        self.row(f, corner).start
    }

    /// A point on the boundary curve: the primal point `(i, j)` of face `f` at rate `n`, in the
    /// face's own indices.
    fn boundary_point(
        &mut self,
        table: &StencilTable,
        patch: &FacePatch,
        f: usize,
        n: u32,
        (i, j): (u32, u32),
    ) -> Result<(), RuntimeError> {
        let source = VertexSource {
            face: f as u32,
            u: i,
            v: j,
            denominator: n,
            subface: 0,
        };
        if let FaceEval::Local { .. } = self.faces[f] {
            let (u, v) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            let query = LimitQuery {
                face: f as u32,
                u,
                v,
            };
            self.local_points.push((self.boundary_points.len(), query));
            self.boundary_points.push(PointPlan {
                weights: Vec::new(),
                control: 0..0,
                source,
            });
            return Ok(());
        }
        let s = stencils(table, patch, PointSet::Primal, n)?;
        // The primal grid's rotation into the patch: as for dual points, with n + 1 points a row.
        let (pi, pj) = dual_index_in_patch(patch.corner, i as usize, j as usize, n as usize + 1);
        let k = patch.points.len();
        let control = append_control(&mut self.control, &patch.points)?;
        let row = pj * (n as usize + 1) + pi;
        self.boundary_points
            .push(PointPlan::from_row(&s, row, k, control, source));
        Ok(())
    }

    /// The stencils of the local faces' dual points and of the boundary points on them, all
    /// in one feature-adaptive refinement.
    fn plan_local(&mut self, mesh: &Mesh, local_faces: &[usize]) -> Result<(), RuntimeError> {
        let mut queries = Vec::new();
        for &f in local_faces {
            let n = self.rates[f];
            let d = f64::from(2 * n);
            for j in 0..n {
                for i in 0..n {
                    queries.push(LimitQuery {
                        face: f as u32,
                        u: f64::from(2 * i + 1) / d,
                        v: f64::from(2 * j + 1) / d,
                    });
                }
            }
        }
        queries.extend(self.local_points.iter().map(|&(_, q)| q));
        if queries.is_empty() {
            return Ok(());
        }
        let stencils = limit_stencils(mesh, &queries)?;
        let mut at = 0;
        for &f in local_faces {
            let n = self.rates[f] as usize;
            let points = &stencils[at..at + n * n];
            at += n * n;
            let (control, weights) = dense(points);
            let block = n * n * control.len();
            let s = Stencils {
                position: &weights[..block],
                du: &weights[block..2 * block],
                dv: &weights[2 * block..],
            };
            // `None` only for a face without points (rate 0, refused before the plan).
            let lanes = LaneStencils::new(control.len(), n * n, |t| (&s, t)).ok_or_else(|| {
                RuntimeError::Unsupported(format!("face {f} has no points at rate {n}"))
            })?;
            let control = append_control(&mut self.control, &control)?;
            self.faces[f] = FaceEval::Local {
                control,
                lanes: self.lanes.len() as u32,
            };
            self.lanes.push(lanes);
        }
        for (&(plan, _), stencil) in std::mem::take(&mut self.local_points)
            .iter()
            .zip(&stencils[at..])
        {
            let (control, weights) = dense(std::slice::from_ref(stencil));
            self.boundary_points[plan].control = append_control(&mut self.control, &control)?;
            self.boundary_points[plan].weights = weights;
        }
        Ok(())
    }

    /// A copy of output vertex `original` (a boundary point) at `source`.
    fn seam_copy(&mut self, original: u32, source: VertexSource) -> u32 {
        let dual_total = self.first[self.rates.len()];
        let copy = dual_total + self.boundary_points.len() as u32;
        self.boundary_points.push(PointPlan {
            weights: Vec::new(),
            control: 0..0,
            source,
        });
        self.seam_copies.push([copy, original]);
        copy
    }

    fn plan_connectivity(
        &mut self,
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
        channel: Option<&[u32]>,
    ) -> Result<(), RuntimeError> {
        let dual_total = self.first[patches.len()];
        let hole = |f: usize| mesh.holes[f];
        // A face-varying seam: the faces on either side use different channel vertices at an
        // end of the edge.
        let seam = |h: usize| {
            let t = mesh.twin[h];
            channel.is_some_and(|c| {
                t != NONE && (c[h] != c[mesh.next(t as usize)] || c[mesh.next(h)] != c[t as usize])
            })
        };
        // An infinitely sharp edge between two surface faces is tessellated like a boundary
        // on both sides: the crease curve is sampled, and shared by the two sides' strips. A
        // seam is sampled too, each side with its own copies of the points.
        // Around every vertex, the fan is cut by the boundary and holes (separate surface
        // sheets, each with its own limit point) and by sharp edges (sectors of one sheet,
        // sharing its limit point). A smooth interior vertex makes one closed polygon of
        // corner points; every sector otherwise is closed by its sheet's limit point,
        // evaluated at the corner of the sheet's first face. `limit_at[h]`: the limit point
        // of half-edge h's corner.
        let mut limit_at = vec![NONE; mesh.face_vertices.len()];
        for v in 0..mesh.positions.len() {
            let fan = mesh.fan(v);
            let n = fan.len();
            // The cut before fan face i, across the edge of fan[i].
            let cut = |i: usize| mesh.cut(fan[i], seam(fan[i]));
            let start = (0..n)
                .find(|&i| cut(i) == Cut::Sheet)
                .or_else(|| (0..n).find(|&i| cut(i) == Cut::Sector));
            // A pinned vertex no cut reaches is a cone's tip: a wheel of corner points around
            // its limit point, the one sector of a fan that closes on itself.
            let wheel = start.is_none() && mesh.is_cone_tip(v);
            let Some(start) = start.or(wheel.then_some(0)) else {
                for &h in &fan {
                    let f = mesh.face_of[h] as usize;
                    let corner = self.corner_point(f, h - mesh.face_halfedges(f).start);
                    self.connectivity.polygons.push(corner);
                }
                if n > 0 {
                    self.connectivity
                        .polygon_offsets
                        .push(self.connectivity.polygons.len() as u32);
                }
                continue;
            };
            let mut limit = NONE;
            // The sheet's limit point for each channel vertex met so far.
            let mut siblings: Vec<(u32, u32)> = Vec::new();
            let mut polygon: Vec<u32> = Vec::new();
            for k in 0..=n {
                let i = (start + k) % n;
                let c = if k == n { Cut::Sheet } else { cut(i) };
                if k == 0 || c != Cut::None {
                    if !polygon.is_empty() {
                        if wheel {
                            polygon.push(polygon[0]);
                        }
                        self.connectivity.polygons.push(limit);
                        self.connectivity.polygons.append(&mut polygon);
                        self.connectivity
                            .polygon_offsets
                            .push(self.connectivity.polygons.len() as u32);
                    }
                    if k == n {
                        break;
                    }
                }
                if k == 0 || c == Cut::Sheet {
                    limit = NONE;
                    siblings.clear();
                }
                let h = fan[i];
                let f = mesh.face_of[h] as usize;
                if hole(f) {
                    continue;
                }
                let corner = h - mesh.face_halfedges(f).start;
                // The corner of the primal grid at the face's own rate (present in any table
                // that has the face's dual grid).
                let rate = self.rates[f];
                let (i, j) = [(0, 0), (rate, 0), (rate, rate), (0, rate)][corner];
                let sibling = channel.map_or(0, |c| c[h]);
                if limit == NONE {
                    self.boundary = true;
                    limit = dual_total + self.boundary_points.len() as u32;
                    self.boundary_point(table, &patches[f], f, rate, (i, j))?;
                    siblings.push((sibling, limit));
                } else if let Some(&(_, known)) = siblings.iter().find(|s| s.0 == sibling) {
                    limit = known;
                } else {
                    let source = VertexSource {
                        face: f as u32,
                        u: i,
                        v: j,
                        denominator: rate,
                        subface: 0,
                    };
                    limit = self.seam_copy(siblings[0].1, source);
                    siblings.push((sibling, limit));
                }
                limit_at[h] = limit;
                polygon.push(self.corner_point(f, corner));
            }
        }
        // Edges, each once: between two surface faces from their lower half-edge; along the
        // boundary, a hole or a crease from each surface face's half-edge, the curve points
        // made once (by the crease's lower half-edge) and shared.
        let mut curve_of = vec![(0u32, 0u32); mesh.face_vertices.len()];
        // At most a strip a half-edge: reserved, not grown (each doubling copied the strips into
        // fresh pages, faulted in every plan; untouched, the reserve costs no pages).
        self.strips.reserve(mesh.face_vertices.len());
        for h in 0..mesh.face_vertices.len() {
            let t = mesh.twin[h];
            let f = mesh.face_of[h] as usize;
            if hole(f) {
                continue;
            }
            let side = h - mesh.face_halfedges(f).start;
            let row = self.row(f, side);
            let cut = mesh.cut(h, seam(h));
            if cut != Cut::None {
                let (tail, head) = (limit_at[h], limit_at[mesh.next(h)]);
                if cut == Cut::Sector && (t as usize) < h {
                    let (mut first, segments) = curve_of[t as usize];
                    if seam(h) {
                        // This side's copies, in the other side's order: its point s lies at
                        // (segments - s) / segments along h.
                        let copies = first;
                        for s in 1..segments {
                            let a = segments - s;
                            let (u, v) = match side {
                                0 => (a, 0),
                                1 => (segments, a),
                                2 => (segments - a, segments),
                                _ => (0, segments - a),
                            };
                            let source = VertexSource {
                                face: f as u32,
                                u,
                                v,
                                denominator: segments,
                                subface: 0,
                            };
                            let copy = self.seam_copy(copies + s - 1, source);
                            if s == 1 {
                                first = copy;
                            }
                        }
                    }
                    self.strips.push(Strip::Boundary {
                        row,
                        tail,
                        first,
                        head,
                        segments,
                        reversed: true,
                    });
                    continue;
                }
                let n = self.rates[f];
                let first = dual_total + self.boundary_points.len() as u32;
                for s in 1..n {
                    let ij = match side {
                        0 => (s, 0),
                        1 => (n, s),
                        2 => (n - s, n),
                        _ => (0, n - s),
                    };
                    self.boundary_point(table, &patches[f], f, n, ij)?;
                }
                curve_of[h] = (first, n);
                self.strips.push(Strip::Boundary {
                    row,
                    tail,
                    first,
                    head,
                    segments: n,
                    reversed: false,
                });
            } else if (t as usize) > h {
                let t = t as usize;
                let g = mesh.face_of[t] as usize;
                let other = self.row(g, t - mesh.face_halfedges(g).start);
                // Reversed, so that both rows run along h.
                let right = DualRow {
                    start: other.at(other.len - 1),
                    step: -other.step,
                    len: other.len,
                };
                self.strips.push(Strip::Interior { left: row, right });
            }
        }
        self.vertex_count = (dual_total as usize) + self.boundary_points.len();
        let strip_count = |s: &Strip| match *s {
            Strip::Interior { left, right } => strip_triangle_count(left.len, right.len),
            Strip::Boundary { row, segments, .. } => strip_triangle_count(row.len, segments + 1),
        };
        self.connectivity.count(
            self.rates.iter().zip(&mesh.holes).map(|(&n, &hole)| {
                if hole {
                    0
                } else {
                    2 * (n as usize - 1).pow(2)
                }
            }),
            self.strips.iter().map(strip_count),
        );
        Ok(())
    }

    /// Whether the mesh has a boundary (its output then has boundary loops).
    pub fn has_boundary(&self) -> bool {
        self.boundary
    }

    /// Every dual point of face `f`, from its control points relative to one of them
    /// ([`relative`]).
    fn evaluate_face(
        &self,
        f: usize,
        control: &[[f64; 3]],
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        let n = self.rates[f] as usize;
        match &self.faces[f] {
            FaceEval::Separable { grid } => {
                // The face's corner at (0, 0) is the origin.
                let origin = control[grid[1][1] as usize];
                let g = grid.map(|column| column.map(|v| relative(control[v as usize], origin)));
                if let Some(basis) = &self.bases[n] {
                    let origin = origin.map(|c| c as f32);
                    evaluate_separable_at_rate(&g, origin, basis, n, n, positions, normals);
                }
            }
            FaceEval::Phantom { grid, phantoms } => {
                let origin = control[grid[1][1] as usize];
                let mut g =
                    grid.map(|column| column.map(|v| relative(control[v as usize], origin)));
                reflect_phantoms(&mut g, *phantoms);
                if let Some(basis) = &self.bases[n] {
                    let origin = origin.map(|c| c as f32);
                    evaluate_separable_at_rate(&g, origin, basis, n, n, positions, normals);
                }
            }
            FaceEval::Table {
                lanes,
                control: range,
            }
            | FaceEval::Local {
                lanes,
                control: range,
            } => {
                let points = &self.control[range.start as usize..range.end as usize];
                if let Some(lanes) = self.lanes.get(*lanes as usize) {
                    lanes.evaluate_patch(points, control, positions, normals);
                }
            }
            FaceEval::Mirror {
                mirror,
                control: range,
            } => {
                let points = &self.control[range.start as usize..range.end as usize];
                if let Some(mirror) = self.mirrors.get(*mirror as usize) {
                    mirror.evaluate_patch(points, control, positions, normals);
                }
            }
            FaceEval::Split {
                split,
                lanes,
                control: range,
            } => {
                let points = &self.control[range.start as usize..range.end as usize];
                if let (Some(split), Some(lanes)) = (
                    self.splits.get(*split as usize),
                    self.lanes.get(*lanes as usize),
                ) {
                    if let Some(basis) = &self.bases[split.m] {
                        evaluate_split(split, lanes, basis, points, control, positions, normals);
                    }
                }
            }
            FaceEval::Input | FaceEval::Hole => {}
        }
    }

    fn connect_face(&self, f: usize, out: &mut [[u32; 3]]) {
        if let FaceEval::Hole = self.faces[f] {
            return;
        }
        let n = self.rates[f];
        let mut k = 0;
        for j in 0..n.saturating_sub(1) {
            let row = self.first[f] + j * n;
            for i in 0..n - 1 {
                let (a, b, c, d) = (row + i, row + i + 1, row + n + i + 1, row + n + i);
                out[k] = [a, b, c];
                out[k + 1] = [a, c, d];
                k += 2;
            }
        }
    }
}

impl GridPlan for DualGrid {
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
        // The separable bases, a few rows of `n + 1` weights per rate, are left out.
        let deep = [
            total_bytes(self.lanes.iter().map(LaneStencils::heap_bytes)),
            total_bytes(self.splits.iter().map(SubPatchPlan::heap_bytes)),
            total_bytes(self.mirrors.iter().map(MirrorStencils::heap_bytes)),
            total_bytes(self.boundary_points.iter().map(PointPlan::heap_bytes)),
            self.boundary_groups.heap_bytes(),
            self.connectivity.heap_bytes(),
            self.input.as_ref().map_or(0, InputPatches::heap_bytes),
        ];
        let shallow = [
            vec_bytes(&self.rates),
            vec_bytes(&self.first),
            vec_bytes(&self.face_ends),
            vec_bytes(&self.faces),
            vec_bytes(&self.bases),
            vec_bytes(&self.lanes),
            vec_bytes(&self.splits),
            vec_bytes(&self.mirrors),
            vec_bytes(&self.control),
            vec_bytes(&self.boundary_points),
            vec_bytes(&self.local_points),
            vec_bytes(&self.strips),
            vec_bytes(&self.seam_copies),
        ];
        total_bytes(deep.into_iter().chain(shallow))
    }

    /// Where every output vertex is evaluated, in output order.
    fn sources_into(&self, out: &mut Vec<VertexSource>) {
        out.clear();
        out.reserve(self.vertex_count);
        for (f, &n) in self.rates.iter().enumerate() {
            if let FaceEval::Hole = self.faces[f] {
                continue;
            }
            for j in 0..n {
                for i in 0..n {
                    out.push(VertexSource {
                        face: f as u32,
                        u: 2 * i + 1,
                        v: 2 * j + 1,
                        denominator: 2 * n,
                        subface: 0,
                    });
                }
            }
        }
        out.extend_from_slice(self.boundary_groups.sources());
    }

    /// Evaluate every output vertex from the control points `control` (the mesh's vertex
    /// positions): limit positions and unit normals, `vertex_count()` each.
    fn evaluate(&self, control: &[[f64; 3]], positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]) {
        let dual = self.first[self.rates.len()] as usize;
        let (face_positions, curve_positions) = positions.split_at_mut(dual);
        let (face_normals, curve_normals) = normals.split_at_mut(dual);
        match &self.input {
            Some(input) => for_each_range_with(
                input.unit_ends(),
                (face_positions, face_normals),
                InputPatches::scratch,
                |scratch, u, out| input.evaluate_unit(self, u, control, out, scratch),
            ),
            None => for_each_range(
                &self.face_ends,
                (face_positions, face_normals),
                |f, (p, q)| self.evaluate_face(f, control, p, q),
            ),
        }
        self.boundary_groups
            .evaluate(&self.control, control, curve_positions, curve_normals);
    }

    /// Write every triangle (`triangle_count()` of them).
    fn connect(&self, triangles: &mut [[u32; 3]]) {
        self.connectivity.connect(
            triangles,
            |f, out| self.connect_face(f, out),
            |s, out| connect_strip(&self.strips[s], out),
        );
    }

    fn seam_copies(&self) -> &[[u32; 2]] {
        &self.seam_copies
    }

    fn control_map(&self) -> Option<&Stencil<f64>> {
        self.input.as_ref().map(InputPatches::map)
    }

    /// How many faces take the separable (tensor-product) path.
    fn separable_faces(&self) -> usize {
        self.faces
            .iter()
            .filter(|f| {
                matches!(
                    f,
                    FaceEval::Separable { .. } | FaceEval::Phantom { .. } | FaceEval::Input
                )
            })
            .count()
    }

    fn refined_faces(&self) -> usize {
        self.faces
            .iter()
            .filter(|f| matches!(f, FaceEval::Local { .. }))
            .count()
    }
}

fn connect_strip(strip: &Strip, out: &mut [[u32; 3]]) {
    match *strip {
        Strip::Interior { left, right } => {
            // Point t of a row of n sits at (2t + 1)/2n: compare (2t + 1) n_other.
            let (na, nb) = (u64::from(left.len), u64::from(right.len));
            merge_rows(
                |i| left.at(i),
                left.len,
                |i| (2 * u64::from(i) + 1) * nb,
                |j| right.at(j),
                right.len,
                |j| (2 * u64::from(j) + 1) * na,
                out,
            );
        }
        Strip::Boundary {
            row,
            tail,
            first,
            head,
            segments: m,
            reversed,
        } => {
            let n = row.len;
            // Dual points at (2i + 1)/2n, curve points at j/m: compare (2i + 1) m with 2 j n.
            merge_rows(
                |i| row.at(i),
                n,
                |i| (2 * u64::from(i) + 1) * u64::from(m),
                |j| match j {
                    0 => tail,
                    j if j == m => head,
                    j if reversed => first + (m - j) - 1,
                    j => first + j - 1,
                },
                m + 1,
                |j| 2 * u64::from(j) * u64::from(n),
                out,
            );
        }
    }
}

/// A patch's stencils `s` at rate `n` in lanes, in the order of a face whose corner
/// `patch.corner` is the patch's vertex (point `t` of the face is the patch's grid point
/// [`dual_index_in_patch`]).
fn face_lanes(s: &Stencils, patch: &FacePatch, n: u32) -> Result<LaneStencils, RuntimeError> {
    let (k, corner, n) = (patch.points.len(), patch.corner, n as usize);
    LaneStencils::new(k, n * n, |t| {
        let (pi, pj) = dual_index_in_patch(corner, t % n, t / n, n);
        (s, pj * n + pi)
    })
    .ok_or_else(|| RuntimeError::LayoutMismatch {
        key: section(patch, StencilKind::Position, PointSet::Dual, n as u32),
        table: s.position.len() / (n * n).max(1),
        patch: k,
    })
}

/// The 4 x 4 control grid of a regular interior patch at corner 0, `cells[a][b]` at layout
/// position `(a - 1, b - 1)` (columns along `u`).
fn regular_cells(patch: &FacePatch) -> [[u32; 4]; 4] {
    let mut cells = [[0u32; 4]; 4];
    for (&(a, b), &v) in REGULAR_LAYOUT.iter().zip(&patch.points) {
        cells[(a + 1) as usize][(b + 1) as usize] = v;
    }
    cells
}

/// A [`FaceEval::Split`] face's points from its control points `control[points[l]]`
/// ([`crate::tessellate::sub_patches`]): the level-1 points, relative to the patch's origin as
/// the control points are; the quarter at the vertex through `lanes` (the patch's stencils at
/// rate `m`, in the face's order) and the three sub-patches as rate-`m` tensor products, each
/// into its block of the face's grid.
fn evaluate_split(
    split: &SubPatchPlan,
    lanes: &LaneStencils,
    basis: &SeparableBasis,
    points: &[u32],
    control: &[[f64; 3]],
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let k = points.len();
    if k > MAX_PATCH {
        return;
    }
    let origin = patch_origin(points, control);
    let mut local = [f32x4::ZERO; MAX_PATCH];
    for (l, &v) in local.iter_mut().zip(points) {
        let [x, y, z] = relative(control[v as usize], origin);
        *l = f32x4::new([x, y, z, 0.0]);
    }
    let mut level = [f32x4::ZERO; MAX_LEVEL_ONE];
    split.level_one(&local[..k], &mut level);
    let point = |r: u8| -> [f32; 3] {
        let [x, y, z, _] = level[usize::from(r)].to_array();
        [x, y, z]
    };
    let origin = origin.map(|c| c as f32);
    let m = split.m;
    let n = 2 * m;
    let quarter_at = split.quarter_at;
    lanes.evaluate_with(
        |l| point(split.quarter[l]),
        origin,
        |t| quarter_at + (t / m) * n + t % m,
        positions,
        normals,
    );
    for (net, at) in &split.nets {
        let g = net.map(|column| column.map(point));
        evaluate_separable_at_rate(
            &g,
            origin,
            basis,
            m,
            n,
            &mut positions[*at..],
            &mut normals[*at..],
        );
    }
}

/// Replace the row of `g` beyond every side in `phantoms` (side 0: `v = 0`, 1: `u = 1`,
/// 2: `v = 1`, 3: `u = 0`) by the reflection `2 P_0 - P_1` of the next two rows through the
/// side's row; rows after columns, so that a corner beyond two sides becomes
/// `4 P_00 - 2 P_10 - 2 P_01 + P_11` (`adaptive::phantom_grid`).
fn reflect_phantoms(g: &mut [[[f32; 3]; 4]; 4], phantoms: u8) {
    let reflect = |p0: [f32; 3], p1: [f32; 3]| std::array::from_fn(|c| 2.0 * p0[c] - p1[c]);
    for column in g.iter_mut() {
        if phantoms & 1 != 0 {
            column[0] = reflect(column[1], column[2]);
        }
        if phantoms & 4 != 0 {
            column[3] = reflect(column[2], column[1]);
        }
    }
    if phantoms & 2 != 0 {
        g[3] = std::array::from_fn(|t| reflect(g[2][t], g[1][t]));
    }
    if phantoms & 8 != 0 {
        g[0] = std::array::from_fn(|t| reflect(g[1][t], g[2][t]));
    }
}

/// [`evaluate_separable`] at rate `n`, with the loops of rates 4 and 8 known when compiled.
///
/// Why: with `n` a constant the compiler unrolls the rows and keeps the group's contractions in
/// registers across them; a frame at rate 8 took 6–7% fewer instructions and less time that
/// way, at rate 4 4–7% fewer instructions and 2–4% less time (docs/benchmarks.md); at rate 16
/// it made no difference. The sums are the same, in the same order. At rate 4 the rows go by
/// pairs ([`rows_by_pairs`]) when the basis has them (the B-spline's factors are mirrored; a
/// basis that is not takes the general path, which needs no pairs).
#[inline(always)]
fn evaluate_separable_at_rate(
    g: &[[[f32; 3]; 4]; 4],
    origin: [f32; 3],
    basis: &SeparableBasis,
    n: usize,
    stride: usize,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    let out = (positions, normals);
    match (n, stride) {
        (4, 4) if basis.y_pairs.len() == 2 => evaluate_separable(g, origin, basis, 4, 4, true, out),
        (8, 8) => evaluate_separable(g, origin, basis, 8, 8, false, out),
        (8, 16) => evaluate_separable(g, origin, basis, 8, 16, false, out),
        _ => evaluate_separable(g, origin, basis, n, stride, false, out),
    }
}

/// The tensor-product evaluation of a regular face, a group of [`LANES`] columns at a time: the
/// 4 x 4 grid contracted along `u` with the group's weights into four points `q[b]` per
/// control row (and `dq[b]` with the derivative's weights), the group's columns in the lanes;
/// then every row `j` of the group is a 4-term combination of those with the row's weights
/// (broadcast in the basis). `g` is relative to `origin`
/// ([`relative`]), where every position's sum
/// starts.
///
/// Why this order: the contraction along `u` is made once per group of columns and serves
/// every row, where contracting along `v` first (once per row) needed its four results
/// broadcast into 24 vectors that spilled: a rate-4 frame took 14% more instructions that way
/// (docs/benchmarks.md).
///
/// Every lane makes its sums in the order of the scalar formulas (`q[b] = sum_a x_a g[a][b]`,
/// `q'[b] = sum_a x'_a g[a][b]`, then `P = O + sum_b y_b q[b]`, `P_u = sum_b y_b q'[b]`,
/// `P_v = sum_b y'_b q[b]`, each over `a, b = 0..4`: `q` and `q'` from zero, `P` from `O`,
/// `P_u` and `P_v` from their first term), so the output is bit-identical to one point at a time
/// (`separable_lanes_are_the_scalar_sums_bit_for_bit`); except where `paired`, which
/// [`evaluate_separable_at_rate`] sets at rate 4 when the rows' factors are mirrored: then the
/// rows are made two at a time by [`rows_by_pairs`], whose sums differ in their rounding.
///
/// Inlined, through [`evaluate_separable_at_rate`], into both of its callers (regular faces and
/// those with phantom rows): called, it cost a rate-4 frame 5% more instructions.
#[inline(always)]
fn evaluate_separable(
    g: &[[[f32; 3]; 4]; 4],
    origin: [f32; 3],
    basis: &SeparableBasis,
    n: usize,
    stride: usize,
    paired: bool,
    (positions, normals): (&mut [[f32; 3]], &mut [[f32; 3]]),
) {
    let end = n.saturating_sub(1) * stride + n;
    let (positions, normals) = (&mut positions[..end], &mut normals[..end]);
    let groups = n.div_ceil(LANES);
    let (Some(xs), Some(dxs), Some(ys), Some(dys)) = (
        basis.x_lanes.get(..groups),
        basis.dx_lanes.get(..groups),
        basis.y_splat.get(..n),
        basis.dy_splat.get(..n),
    ) else {
        return;
    };
    let origin = origin.map(f32x4::splat);
    for (k, (x, dx)) in xs.iter().zip(dxs).enumerate() {
        let (q, dq) = contract_columns(g, x, dx);
        let at = k * LANES;
        let end = n.min(at + LANES);
        // Rows by pairs (`paired`: the caller found them) only at rate 4, where a face's block
        // is a few cache lines: at rates 8 and 16 the rows written alternately from both ends
        // of the block (straight to memory) made the frame slower, though it took fewer
        // instructions (docs/benchmarks.md).
        let (pairs, rows) = if paired {
            (n / 2, n / 2..n - n / 2)
        } else {
            (0, 0..n)
        };
        let pairs = basis.y_pairs.iter().take(pairs);
        rows_by_pairs(
            &q,
            &dq,
            origin,
            pairs,
            n,
            stride,
            at..end,
            (positions, normals),
        );
        for j in rows {
            let (p, normal) = row_points(&q, &dq, &ys[j], &dys[j], origin);
            let row = j * stride;
            store_points(p, &mut positions[row + at..row + end]);
            store_points(normal, &mut normals[row + at..row + end]);
        }
    }
}

/// A group of columns' contraction along `u` ([`evaluate_separable`]): `q[b][c] = sum_a x_a
/// g[a][b][c]`, `dq` the same with `dx`, the group's columns in the lanes.
#[inline(always)]
fn contract_columns(
    g: &[[[f32; 3]; 4]; 4],
    x: &[f32x4; 4],
    dx: &[f32x4; 4],
) -> ([[f32x4; 3]; 4], [[f32x4; 3]; 4]) {
    let mut q = [[f32x4::ZERO; 3]; 4];
    let mut dq = [[f32x4::ZERO; 3]; 4];
    for b in 0..4 {
        for c in 0..3 {
            for a in 0..4 {
                let point = f32x4::splat(g[a][b][c]);
                q[b][c] += x[a] * point;
                dq[b][c] += dx[a] * point;
            }
        }
    }
    (q, dq)
}

/// One row of a group of columns ([`evaluate_separable`]): the positions `O + sum_b y_b q[b]`
/// and the unit normals of `P_u = sum_b y_b q'[b]` and `P_v = sum_b y'_b q[b]`, every sum from
/// its first term in the order of `b`.
#[inline(always)]
fn row_points(
    q: &[[f32x4; 3]; 4],
    dq: &[[f32x4; 3]; 4],
    y: &[f32x4; 4],
    dy: &[f32x4; 4],
    origin: [f32x4; 3],
) -> ([f32x4; 3], [f32x4; 3]) {
    let mut p = origin;
    let mut du: [f32x4; 3] = std::array::from_fn(|c| y[0] * dq[0][c]);
    let mut dv: [f32x4; 3] = std::array::from_fn(|c| dy[0] * q[0][c]);
    for c in 0..3 {
        p[c] += y[0] * q[0][c];
    }
    for b in 1..4 {
        for c in 0..3 {
            p[c] += y[b] * q[b][c];
            du[c] += y[b] * dq[b][c];
            dv[c] += dy[b] * q[b][c];
        }
    }
    (p, unit_cross_x4(du, dv))
}

/// Rows `j` and `n - 1 - j` of a group ([`evaluate_separable`]) for every `j` of `pairs`
/// ([`SeparableBasis::y_pairs`]), columns `columns`: with `s_0 = q_0 + q_3`, `s_1 = q_1 + q_2`,
/// `d_0 = q_0 - q_3`, `d_1 = q_1 - q_2` and row `j`'s even and odd weights `e_b`, `o_b`, the sum
/// `sum_b y_b q_b` is `E + O` on row `j` and `E - O` on its mirror, `E = e_0 s_0 + e_1 s_1`,
/// `O = o_0 d_0 + o_1 d_1` (for `P_v`, whose weights change sign under the mirror, `O - E`):
/// 4 products for two rows' sums where they took 8 (the sums of `s` and `d`, made once, serve
/// every pair).
///
/// Why: at rate 4, 5% off a frame of the torus (docs/benchmarks.md). The sums differ from
/// [`evaluate_separable`]'s row by row in their rounding only
/// (`paired_rows_are_the_row_sums_to_rounding`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn rows_by_pairs<'a>(
    q: &[[f32x4; 3]; 4],
    dq: &[[f32x4; 3]; 4],
    origin: [f32x4; 3],
    pairs: impl Iterator<Item = &'a [f32x4; 8]>,
    n: usize,
    stride: usize,
    columns: std::ops::Range<usize>,
    (positions, normals): (&mut [[f32; 3]], &mut [[f32; 3]]),
) {
    let (sq, sdq) = (even_odd(q), even_odd(dq));
    for (j, w) in pairs.enumerate() {
        let (p, normal) = pair_points(&sq, &sdq, w, origin);
        for (r, row) in [j, n - 1 - j].into_iter().enumerate() {
            let row = row * stride;
            let out = row + columns.start..row + columns.end;
            store_points(p[r], &mut positions[out.clone()]);
            store_points(normal[r], &mut normals[out]);
        }
    }
}

/// A group's even and odd sums `q_0 + q_3`, `q_1 + q_2`, `q_0 - q_3`, `q_1 - q_2`
/// ([`rows_by_pairs`]).
#[inline(always)]
fn even_odd(q: &[[f32x4; 3]; 4]) -> [[f32x4; 3]; 4] {
    [
        std::array::from_fn(|c| q[0][c] + q[3][c]),
        std::array::from_fn(|c| q[1][c] + q[2][c]),
        std::array::from_fn(|c| q[0][c] - q[3][c]),
        std::array::from_fn(|c| q[1][c] - q[2][c]),
    ]
}

/// A row `j` and its mirror `n - 1 - j` from the group's even and odd sums and the row's pair
/// of weights ([`rows_by_pairs`]): their positions and unit normals.
#[inline(always)]
fn pair_points(
    sq: &[[f32x4; 3]; 4],
    sdq: &[[f32x4; 3]; 4],
    w: &[f32x4; 8],
    origin: [f32x4; 3],
) -> ([[f32x4; 3]; 2], [[f32x4; 3]; 2]) {
    let mut p = [[f32x4::ZERO; 3]; 2];
    let mut du = [[f32x4::ZERO; 3]; 2];
    let mut dv = [[f32x4::ZERO; 3]; 2];
    for c in 0..3 {
        let e = origin[c] + w[0] * sq[0][c] + w[1] * sq[1][c];
        let o = w[2] * sq[2][c] + w[3] * sq[3][c];
        p[0][c] = e + o;
        p[1][c] = e - o;
        let e = w[0] * sdq[0][c] + w[1] * sdq[1][c];
        let o = w[2] * sdq[2][c] + w[3] * sdq[3][c];
        du[0][c] = e + o;
        du[1][c] = e - o;
        let e = w[4] * sq[0][c] + w[5] * sq[1][c];
        let o = w[6] * sq[2][c] + w[7] * sq[3][c];
        dv[0][c] = e + o;
        dv[1][c] = o - e;
    }
    (
        p,
        [unit_cross_x4(du[0], dv[0]), unit_cross_x4(du[1], dv[1])],
    )
}

/// Tessellate an isolated mesh at rate `n` on every face.
pub fn tessellate_uniform(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    n: u32,
) -> Result<(TriangleMesh, TessellationTime), RuntimeError> {
    tessellate(table, mesh, patches, &vec![n; patches.len()])
}

/// Tessellate an isolated mesh (closed or with boundary) with rate `rates[f]` on face `f`.
pub fn tessellate(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    rates: &[u32],
) -> Result<(TriangleMesh, TessellationTime), RuntimeError> {
    let started = Instant::now();
    let grid = DualGrid::new(table, mesh, patches, rates)?;
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
    #[cfg(feature = "catmull-clark")]
    use crate::mesh::test_meshes::cube;
    #[cfg(feature = "catmull-clark")]
    use crate::scheme::catmull_clark::isolate::isolate;
    use crate::tessellate::kernel::{cross, unit};
    use crate::tessellate::lane_stencils::test_numbers;

    /// The pentagonal bipyramid: poles of valence 5 over a ring of five triangles each.
    #[cfg(feature = "catmull-clark")]
    fn bipyramid() -> Mesh {
        bipyramid_of(5)
    }

    /// The bipyramid over a ring of `sides` vertices: poles of valence `sides`.
    #[cfg(feature = "catmull-clark")]
    fn bipyramid_of(sides: i64) -> Mesh {
        let mut p: Vec<[f64; 3]> = (0..sides)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / sides as f64;
                [a.cos(), a.sin(), 0.1 * k as f64]
            })
            .collect();
        p.extend([[0.0, 0.0, 1.3], [0.1, 0.0, -0.9]]);
        let (top, bottom) = (sides, sides + 1);
        let f: Vec<Vec<i64>> = (0..sides)
            .flat_map(|k| {
                [
                    vec![k, (k + 1) % sides, top],
                    vec![(k + 1) % sides, k, bottom],
                ]
            })
            .collect();
        Mesh::new(p, &f, &[], schemes::BoundaryMode::EdgeOnly).expect("a valid bipyramid")
    }

    /// `mesh` with face `f`'s corners turned by `(f + f / 4) % 4` (isolation puts every extraordinary
    /// vertex at its faces' corner 0), its sharp edges kept; and its patches.
    #[cfg(feature = "catmull-clark")]
    fn rotated(mesh: &Mesh) -> (Mesh, Vec<FacePatch>) {
        let faces: Vec<Vec<i64>> = (0..mesh.faces())
            .map(|f| {
                let mut corners: Vec<i64> = mesh.face(f).iter().map(|&v| i64::from(v)).collect();
                let turn = (f + f / 4) % corners.len();
                corners.rotate_left(turn);
                corners
            })
            .collect();
        let mut out = Mesh::new(mesh.positions.clone(), &faces, &[], mesh.boundary)
            .expect("the same faces, turned");
        for f in 0..mesh.faces() {
            let corners = mesh.face(f);
            for (k, h) in mesh.face_halfedges(f).enumerate() {
                let s = mesh.edge_sharpness[h];
                if s > 0.0 && mesh.twin[h] != NONE {
                    let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                    out.set_edge_sharpness(a as usize, b as usize, s)
                        .expect("an edge of the mesh");
                }
            }
        }
        let patches = crate::scheme::patch::gather_patches(&out).expect("isolated patches");
        (out, patches)
    }

    /// The largest distance and normal angle between the points of `meshes`' isolated faces
    /// that `which` picks, evaluated at each of `rates` with every face's corners turned
    /// ([`rotated`]), and their table stencils summed in f64 (every point a weighted sum of the
    /// patch's control points); such faces must come from three corners at least.
    #[cfg(feature = "catmull-clark")]
    fn table_stencil_errors(
        meshes: &[(&str, Mesh)],
        rates: &[u32],
        which: impl Fn(&FaceEval) -> bool,
    ) -> (f64, f64) {
        let table = StencilTable::default_catmull_clark().expect("the embedded table");
        let (mut worst_position, mut worst_angle) = (0.0f64, 0.0f64);
        for (label, input) in meshes {
            let (isolated, _, _) = isolate(input).expect("isolated");
            let (mesh, patches) = rotated(&isolated);
            for &n in rates {
                let rates = vec![n; patches.len()];
                let grid = DualGrid::new(&table, &mesh, &patches, &rates).expect("a plan");
                let mut positions = vec![[0.0f32; 3]; grid.vertex_count()];
                let mut normals = positions.clone();
                grid.evaluate(&mesh.positions, &mut positions, &mut normals);
                let mut corners = [false; 4];
                for (f, patch) in patches.iter().enumerate() {
                    if !which(&grid.faces[f]) {
                        continue;
                    }
                    corners[patch.corner] = true;
                    let s = stencils(&table, patch, PointSet::Dual, n).expect("stencils");
                    let (n, k) = (n as usize, patch.points.len());
                    for t in 0..n * n {
                        let (pi, pj) = dual_index_in_patch(patch.corner, t % n, t / n, n);
                        let row = (pj * n + pi) * k..(pj * n + pi + 1) * k;
                        let sum = |w: &[f32]| -> [f64; 3] {
                            let mut out = [0.0; 3];
                            for (&w, &v) in w.iter().zip(&patch.points) {
                                let q = mesh.positions[v as usize];
                                for (o, q) in out.iter_mut().zip(q) {
                                    *o += f64::from(w) * q;
                                }
                            }
                            out
                        };
                        let p = sum(&s.position[row.clone()]);
                        let (du, dv) = (sum(&s.du[row.clone()]), sum(&s.dv[row]));
                        let cross64 = |a: [f64; 3], b: [f64; 3]| {
                            [
                                a[1] * b[2] - a[2] * b[1],
                                a[2] * b[0] - a[0] * b[2],
                                a[0] * b[1] - a[1] * b[0],
                            ]
                        };
                        let normal = cross64(du, dv);
                        let at = grid.first[f] as usize + t;
                        let got = positions[at].map(f64::from);
                        let distance = (0..3).map(|c| (got[c] - p[c]).powi(2)).sum::<f64>();
                        worst_position = worst_position.max(distance.sqrt());
                        let q = normals[at].map(f64::from);
                        let along = (0..3).map(|c| q[c] * normal[c]).sum::<f64>();
                        let across = cross64(q, normal);
                        let sine = (0..3).map(|c| across[c].powi(2)).sum::<f64>().sqrt();
                        worst_angle = worst_angle.max(sine.atan2(along));
                    }
                }
                assert!(
                    corners.iter().filter(|&&c| c).count() >= 3,
                    "{label} at rate {n}: faces of the kind at corners {corners:?}"
                );
            }
        }
        (worst_position, worst_angle)
    }

    /// A split face's points ([`FaceEval::Split`]: one subdivision step, the tensor products of
    /// the sub-patches and the quarter at half the rate) are its table stencils' (the other
    /// path, independent: every point a weighted sum of the patch's control points), summed in
    /// f64: at interior vertices of valences 3 and 5, at boundary vertices with two faces, at
    /// darts, each from every face corner, at rates 16 and 24. Measured: positions within
    /// 2.7e-7 (the meshes are about 1 across), normals within 3.8e-7 rad; with the sub-patches'
    /// nets left unturned, 0.26 and 0.64.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn split_faces_are_their_table_stencils() {
        let mut open_box = cube();
        let top = (0..open_box.faces()).position(|f| open_box.face(f).iter().all(|&v| v >= 4));
        let mut darts = cube();
        darts
            .set_edge_sharpness(0, 1, schemes::crease::INFINITE)
            .expect("an edge of the cube");
        let boxed = top.map(|top| {
            let faces: Vec<Vec<i64>> = (0..open_box.faces())
                .filter(|&f| f != top)
                .map(|f| open_box.face(f).iter().map(|&v| i64::from(v)).collect())
                .collect();
            Mesh::new(
                open_box.positions.clone(),
                &faces,
                &[],
                schemes::BoundaryMode::EdgeOnly,
            )
            .expect("a cube without its top")
        });
        open_box = boxed.expect("the cube has a top face");
        let meshes = [
            ("cube", cube()),
            ("bipyramid", bipyramid()),
            ("open box", open_box),
            ("darts", darts),
        ];
        let (worst_position, worst_angle) = table_stencil_errors(&meshes, &[16, 24], |face| {
            matches!(face, FaceEval::Split { .. })
        });
        assert!(worst_position < 2e-6, "positions off by {worst_position:e}");
        assert!(worst_angle < 1e-5, "normals off by {worst_angle:e} rad");
    }

    /// A mirrored face's points ([`FaceEval::Mirror`]: a point and its mirror across the face's
    /// diagonal from one set of even and odd sums) are its table stencils', summed in f64: at
    /// interior vertices of valences 3, 5 and 6 (the patch sizes 14, 18 and 20), from every
    /// face corner, at rates 5, 6, 7 and 8. Measured: positions within 2.4e-7 (the meshes are
    /// about 1 across), normals within 3.4e-7 rad; with the mirror's tangents swapped, pi.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn mirrored_faces_are_their_table_stencils() {
        let meshes = [
            ("cube", cube()),
            ("bipyramid", bipyramid()),
            ("hexagonal bipyramid", bipyramid_of(6)),
        ];
        let (worst_position, worst_angle) = table_stencil_errors(&meshes, &[5, 6, 7, 8], |face| {
            matches!(face, FaceEval::Mirror { .. })
        });
        assert!(worst_position < 2e-6, "positions off by {worst_position:e}");
        assert!(worst_angle < 1e-5, "normals off by {worst_angle:e} rad");
    }

    /// At rate 4 the rows are made by pairs ([`rows_by_pairs`]): the embedded table's factors
    /// at that rate are mirrored (so the frame takes that path), and for mirrored factors the
    /// pairs give the rows' sums of [`evaluate_separable`] one row at a time to the rounding of
    /// `f32` sums of terms below 8 in size: positions within 4e-6, normals within 1e-5 rad, on
    /// random nets; factors that are not mirrored have no pairs.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn paired_rows_are_the_row_sums_to_rounding() {
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let s = regular_stencils(&table, 4).expect("rate-4 regular stencils");
        let real = SeparableBasis::from_stencils(&s, 4).expect("the regular patch factors");
        assert_eq!(
            real.y_pairs.len(),
            2,
            "the table's rate-4 factors are mirrored"
        );
        let mut next = test_numbers(0x5eed_1234);
        let mut mirrored = |odd: bool| -> [Vec<f32>; 4] {
            let mut f: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; 4]);
            for j in 0..2 {
                for b in 0..4 {
                    let w = next();
                    f[b][j] = w;
                    f[3 - b][3 - j] = if odd { -w } else { w };
                }
            }
            f
        };
        let (x, dx, y, dy) = (
            mirrored(false),
            mirrored(true),
            mirrored(false),
            mirrored(true),
        );
        let basis = SeparableBasis::from_factors(x.clone(), dx, y.clone(), dy);
        assert_eq!(basis.y_pairs.len(), 2);
        let mut skewed = y.clone();
        skewed[0][3] += 0.25;
        let lopsided = SeparableBasis::from_factors(x.clone(), x.clone(), skewed, y);
        assert!(
            lopsided.y_pairs.is_empty(),
            "rows that are not mirrored have no pairs"
        );
        for _ in 0..50 {
            let g: [[[f32; 3]; 4]; 4] = std::array::from_fn(|_| {
                std::array::from_fn(|_| [next() * 4.0, next() * 4.0, next() * 4.0])
            });
            let origin = [next(), next() * 8.0, 2.0];
            let by = |paired: bool| {
                let mut out = (vec![[0.0f32; 3]; 16], vec![[0.0f32; 3]; 16]);
                let rows = (&mut out.0[..], &mut out.1[..]);
                evaluate_separable(&g, origin, &basis, 4, 4, paired, rows);
                out
            };
            let ((p, n), (p1, n1)) = (by(true), by(false));
            for k in 0..16 {
                let d = (0..3)
                    .map(|c| (p[k][c] - p1[k][c]).abs())
                    .fold(0.0, f32::max);
                assert!(d < 4e-6, "point {k}: {:?} != {:?}", p[k], p1[k]);
                // The angle between two unit normals: its sine small, its cosine positive.
                let sine = crate::mesh::geometry::norm(cross(n[k], n1[k]));
                let cosine: f32 = (0..3).map(|c| n[k][c] * n1[k][c]).sum();
                assert!(
                    sine < 1e-5 && cosine > 0.0,
                    "normal {k}: {:?} != {:?}",
                    n[k],
                    n1[k]
                );
            }
        }
    }

    /// The lanes give the scalar tensor-product sums (the formulas of [`evaluate_separable`]'s
    /// doc, one point at a time, as the evaluator computed them before the lanes) bit for bit,
    /// for rates whose last group of rows is full or short.
    #[test]
    fn separable_lanes_are_the_scalar_sums_bit_for_bit() {
        let mut next = test_numbers(0x9e37_79b9);
        for n in [1usize, 2, 3, 4, 5, 7, 8, 16, 24, 33, 40] {
            let mut factor =
                || -> [Vec<f32>; 4] { std::array::from_fn(|_| (0..n).map(|_| next()).collect()) };
            let (x, dx, y, dy) = (factor(), factor(), factor(), factor());
            let basis = SeparableBasis::from_factors(x.clone(), dx.clone(), y.clone(), dy.clone());
            let g: [[[f32; 3]; 4]; 4] =
                std::array::from_fn(|_| std::array::from_fn(|_| [next(), next(), next()]));
            let origin = [next() * 100.0, next(), -3.0];
            let mut positions = vec![[0.0f32; 3]; n * n];
            let mut normals = vec![[0.0f32; 3]; n * n];
            evaluate_separable_at_rate(&g, origin, &basis, n, n, &mut positions, &mut normals);
            for j in 0..n {
                for i in 0..n {
                    // The derivatives' last sums from their first term, as the lanes make them
                    // (a sum from zero differs where every term is -0).
                    let q: [[f32; 3]; 4] = std::array::from_fn(|b| {
                        std::array::from_fn(|c| (0..4).fold(0.0, |s, a| s + x[a][i] * g[a][b][c]))
                    });
                    let dq: [[f32; 3]; 4] = std::array::from_fn(|b| {
                        std::array::from_fn(|c| (0..4).fold(0.0, |s, a| s + dx[a][i] * g[a][b][c]))
                    });
                    let p: [f32; 3] = std::array::from_fn(|c| {
                        (0..4).fold(origin[c], |s, b| s + y[b][j] * q[b][c])
                    });
                    let du: [f32; 3] = std::array::from_fn(|c| {
                        (1..4).fold(y[0][j] * dq[0][c], |s, b| s + y[b][j] * dq[b][c])
                    });
                    let dv: [f32; 3] = std::array::from_fn(|c| {
                        (1..4).fold(dy[0][j] * q[0][c], |s, b| s + dy[b][j] * q[b][c])
                    });
                    let at = j * n + i;
                    assert_eq!(
                        positions[at].map(f32::to_bits),
                        p.map(f32::to_bits),
                        "n {n} ({i}, {j})"
                    );
                    assert_eq!(
                        normals[at].map(f32::to_bits),
                        unit(cross(du, dv)).map(f32::to_bits),
                        "n {n} ({i}, {j})"
                    );
                }
            }
        }
    }
}
