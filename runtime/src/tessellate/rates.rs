//! Rate selection for the dual-grid tessellator (Schaefer–Warren section 5.5): per-face rates
//! from a tolerance on the deviation from the limit surface ([`tolerance_rates`]) or from a
//! camera ([`view_rates`]), and the measured deviation of a finished tessellation
//! ([`measure_deviation`]).
//!
//! # Tolerance: what is measured
//!
//! Face `f` of an isolated mesh has the limit surface `S_f(u, v)` on `[0,1]^2` (its own
//! parameters, DESIGN.md conventions). At rate `n` the tessellator places the dual points
//! `D_ij = S_f((2i+1)/2n, (2j+1)/2n)` and connects them (dual_grid.rs). Let `L_{f,n}` be the
//! part of the output of the *uniform* rate-`n` tessellation that covers face `f`, with the
//! tessellator's own triangles:
//!
//! * the face's interior quads over `[h, 1-h]^2`, `h = 1/2n`, split along `D_ij – D_{i+1,j+1}`;
//! * over each side rectangle (`[h, 1-h] x [0, h]` and its rotations) the half of the edge
//!   strip between the face's outer dual row and the neighbour's (both at rate `n`, so the
//!   strip is a row of quads split as the tessellator's merge splits them), or on a boundary
//!   edge the strip to the limit curve at `t/n`;
//! * over each corner square `[0, h]^2` (and rotations) the vertex polygon (the corner dual
//!   points of every face around the vertex, plus the vertex's limit point on the boundary,
//!   fanned from its first point), with the two ends of the adjacent strips and the face's
//!   corner cell.
//!
//! The deviation at a sample `(u, v)` is the parametric distance `|S_f(u, v) - L_{f,n}(u, v)|`
//! in the interior and the side rectangles, where `L_{f,n}` is linear in `(u, v)` on every
//! triangle (across an edge, in the chart `(s, d)`: position `s` along the edge, which both
//! faces share, and signed distance `d` from it); and in a corner square, where faces around an
//! extraordinary vertex have no common planar chart, the Euclidean distance from `S_f(u, v)` to
//! the nearest of those corner triangles. The **deviation of face `f` at rate `n`** is
//!
//! ```text
//! e_f(n) = max over (u, v) in G of deviation(u, v)
//! ```
//!
//! over the dense rational grid `G` = the table's primal and dual points at rate
//! [`SELECTION_GRID`] (`k/24` and `(2k+1)/48`: 1,201 points a face), evaluated from the table
//! (a regular face's in closed form: its patch is the bicubic B-spline, whose table stencils are
//! the same weights rounded to `f32`). Both kinds of distance are at least the distance from the sample to the output mesh,
//! so `e_f(n)` bounds the geometric error of the uniform tessellation at those samples. The
//! parametric part also counts tangential distortion (a flat patch whose parameterization is
//! not affine deviates): what texture coordinates and shading see.
//!
//! # Faces the table does not describe
//!
//! The faces the tessellator evaluates by feature-adaptive refinement (infinitely sharp
//! creases, corners and darts at their corners, the rims of holes, semi-sharp features at a
//! corner) and those whose patch the table lacks (a valence beyond it, interior valence 2) are
//! sampled at the same points from the same refinement ([`limit_points`]), so `S_f` is the true
//! surface there. `L_{f,n}` follows the tessellator's cuts: an infinitely sharp edge or a hole's
//! side is a limit curve both sides' strips meet, as a boundary is, and a vertex the cuts reach
//! closes each sector's polygon with its limit point, as a pinned vertex that no cut reaches
//! closes its whole fan (a cone's tip). Hole faces take the smallest rate and no samples.
//! A face next to a semi-sharp feature needs as many levels of refinement as the sharpness
//! everywhere on it, and the cost of a descent is its refinement, not its points: so one
//! descent makes the grids of several rates at once (`rate_chunk`), for the face and the
//! adaptive faces around it. (Until 2026-12-03 such faces were measured on the table's patch,
//! the surface without the feature, to save that cost; the output then missed the tolerance,
//! by 1.8 `T` on a cube with semi-sharp creases: `tolerance_rates_cover_valences_beyond_the_table_and_sharp_features`.)
//!
//! On a uniform grid on `z = a x^2` this is the closed form `e_f(n) = a / 4n^2` whenever `n`
//! divides 24 (the midpoints of the cells are samples); `runtime/tests/integration/rates.rs` checks it.
//!
//! The **tolerance rate** of face `f` is the smallest allowed `n` with `e_f(n) <= T`
//! ([`tolerance_rates`]: `n` in `1..=24`; [`tolerance_rates_among`]: any set, e.g. the powers of
//! two of subdivision-based tessellators). Because `e_f` depends on `f` and `n` alone (not on
//! the rates chosen elsewhere), the rates are monotone in `T` (a smaller `T` never lowers a
//! rate) and minimal (every smaller allowed rate exceeds `T` on `G`). Faces with no allowed rate
//! meeting `T` get the largest one and are listed in [`ToleranceRates::unmet`].
//!
//! # What is and is not guaranteed
//!
//! * Guaranteed on `G`: a face's interior quads depend on its own rate only, so over
//!   `[h, 1-h]^2` the output *is* `L_{f,n}` and deviates by at most `T` at every sample of `G`;
//!   where neighbours share the face's rate, so is the rest.
//! * Not guaranteed, measured: where rates differ, the tessellator's strips merge rows of
//!   different lengths and its vertex polygons join corner points at different distances from
//!   the vertex. These triangles lie between those of the uniform tessellations at the two
//!   (or more) rates, each of which meets `T` around its own face, but no bound is proved for
//!   them. [`measure_deviation`] measures the finished output; `docs/results.md` reports it next
//!   to `T` for every mesh and tolerance: at most `T` in 19 of 20 cases, 1.002 `T` once
//!   (Spot, rates 1 and 2 side by side).
//! * Between samples of `G`: `e_f` is a maximum over samples, not over the continuum; the tests
//!   measure the output again on other grids (dual points at rates 23 and 19).

use std::cell::{Cell, OnceCell, RefCell};
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;
use table_format::{PointSet, StencilKind};

use crate::mesh::topology::{Cut, Mesh};
use crate::mesh::triangle_grid::TriangleGrid;
use crate::mesh::triangle_mesh::TriangleMesh;
use crate::once::TryOnce;
use crate::scheme::catmull_clark::adaptive::{bspline, limit_points, LimitQuery};
use crate::scheme::patch::{dual_index_in_patch, FacePatch};
use crate::stencil_table::StencilTable;
use crate::tessellate::dual_grid::REGULAR_LAYOUT;
use crate::tessellate::kernel::{
    extend_weighted_sums, table_may_describe, unless_absent, weighted_sum,
};
use crate::RuntimeError;

/// The largest rate selected: the largest of the default table (`n = 1..=24`).
pub const MAX_SELECTED_RATE: u32 = 24;

/// Every rate of the default table, `1..=24`: the rational rates of Schaefer–Warren.
pub const RATIONAL_RATES: [u32; 24] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24,
];

/// The powers of two of the default table, the rates a subdivision-based tessellator can reach
/// (`1/2^k` grids).
pub const POWER_OF_TWO_RATES: [u32; 5] = [1, 2, 4, 8, 16];

/// The rate of the dense grid the deviation is measured on during selection: the table's
/// primal points `k/24` and dual points `(2k+1)/48` of every face.
pub const SELECTION_GRID: u32 = 24;

/// Per-input-face rates from the text of a rates file (`subtess tessellate --rates FILE`): one
/// integer in `1..=`[`MAX_SELECTED_RATE`] per input face, in face order, separated by any
/// whitespace (spaces or lines, as the writer likes).
///
/// A bad token is reported as [`RuntimeError::ParseFile`] at its line (path `rates`; the CLI
/// puts the file's name there) and quoted through [`crate::error::excerpt`]; so are a file with
/// fewer rates than `input_faces` (at its last line) and one with more (at the first rate too
/// many). Nothing is allocated beyond `input_faces` rates, however long the text.
pub fn parse_rates(text: &str, input_faces: usize) -> Result<Vec<u32>, RuntimeError> {
    let error = |line: usize, message: String| RuntimeError::ParseFile {
        path: "rates".to_owned(),
        line,
        message,
    };
    let mut rates = Vec::with_capacity(input_faces.min(text.len() / 2 + 1));
    let mut last_line = 0;
    for (index, line) in text.lines().enumerate() {
        last_line = index + 1;
        for word in line.split_whitespace() {
            let n = rates.len() + 1;
            if n > input_faces {
                return Err(error(
                    last_line,
                    format!("more than {input_faces} rates for a mesh of {input_faces} faces (rate {n} is `{}`)", crate::error::excerpt(word)),
                ));
            }
            match word.parse::<u32>() {
                Ok(rate) if (1..=MAX_SELECTED_RATE).contains(&rate) => rates.push(rate),
                _ => {
                    return Err(error(
                        last_line,
                        format!(
                            "rate {n} is `{}`, not an integer in 1..={MAX_SELECTED_RATE}",
                            crate::error::excerpt(word)
                        ),
                    ))
                }
            }
        }
    }
    if rates.len() != input_faces {
        return Err(error(
            last_line,
            format!("{} rates for a mesh of {input_faces} faces", rates.len()),
        ));
    }
    Ok(rates)
}

/// Per-face rates chosen for a tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct ToleranceRates {
    /// The rate of every face.
    pub rates: Vec<u32>,
    /// `e_f(rates[f])`, the deviation of the face-local tessellation at the chosen rate
    /// (module docs).
    pub deviations: Vec<f64>,
    /// Faces where no allowed rate met the tolerance (they got the largest allowed rate).
    pub unmet: Vec<usize>,
}

/// One face's limit surface at the table's grid points: from the table where it describes the
/// face exactly (the tessellator's own choice, [`table_may_describe`], and a patch the table
/// has), otherwise from feature-adaptive refinement, as the tessellator evaluates the same
/// faces.
enum PatchPoints<'a> {
    /// The face's patch: its control points and the table lookups that evaluate it.
    Table {
        table: &'a StencilTable,
        patch: &'a FacePatch,
        control: Vec<[f64; 3]>,
    },
    /// A face the tables do not describe (sharp features nearby, a valence or patch beyond
    /// the table): its grids from the adaptive refinement, computed once per grid.
    Adaptive {
        face: usize,
        grids: &'a AdaptiveGrids<'a>,
    },
}

impl<'a> PatchPoints<'a> {
    /// Face `face`: from `adaptive` if it lists the face, else from the table.
    fn of_face(
        table: &'a StencilTable,
        mesh: &Mesh,
        patch: &'a FacePatch,
        face: usize,
        adaptive: &'a AdaptiveGrids<'a>,
    ) -> Result<Self, RuntimeError> {
        if adaptive.faces.binary_search(&face).is_err() {
            return PatchPoints::new(table, mesh, patch);
        }
        Ok(PatchPoints::Adaptive {
            face,
            grids: adaptive,
        })
    }

    /// The table patch `patch`.
    fn new(
        table: &'a StencilTable,
        mesh: &Mesh,
        patch: &'a FacePatch,
    ) -> Result<Self, RuntimeError> {
        // A one-face boundary vertex is smooth in "edge only" mode and pinned in "edge and
        // corner" mode: its stencils must come from a table made for the mesh's mode.
        let corners = mesh.boundary == schemes::BoundaryMode::EdgeAndCorner;
        if patch.kind.boundary && patch.kind.faces == 1 && table.pins_corners() != corners {
            return Err(RuntimeError::BoundaryModeMismatch {
                mesh_corners: corners,
            });
        }
        // Sized first: collecting through `Result` cannot, and grew the vector by doubling
        // (1% of a bent frame's selection, which gathers a face's points for every face it
        // reads).
        let mut control = Vec::with_capacity(patch.points.len());
        for &v in &patch.points {
            control.push(mesh.positions.get(v as usize).copied().ok_or_else(|| {
                RuntimeError::Unsupported(format!("patch control point {v} is not in the mesh"))
            })?);
        }
        Ok(PatchPoints::Table {
            table,
            patch,
            control,
        })
    }

    /// The position weights of a grid (or, for an adaptive face, its positions) and its side
    /// (`n` or `n + 1` points).
    fn grid(&self, points: PointSet, n: u32) -> Result<Grid<'a>, RuntimeError> {
        let side = match points {
            PointSet::Primal => grid_side(true, n),
            PointSet::Dual => grid_side(false, n),
            _ => {
                return Err(RuntimeError::Unsupported(format!(
                    "tolerance rates on {points:?} grids: only the quad primal and dual grids"
                )))
            }
        } as usize;
        let (table, patch) = match self {
            PatchPoints::Table { table, patch, .. } => (*table, *patch),
            PatchPoints::Adaptive { face, grids } => {
                return Ok(Grid::Positions {
                    positions: grids.grid(*face, points, n)?,
                    side,
                })
            }
        };
        Ok(Grid::Weights {
            weights: position_weights(table, patch, points, n, side)?,
            side,
            corner: patch.corner,
        })
    }

    /// The 4 x 4 B-spline control net (`net[a + 1][b + 1]` at grid offset `(a, b)`, `a` along
    /// the face's `u`) of a regular interior face whose patch starts at the face's first
    /// corner: its limit surface is the tensor-product cubic B-spline, which
    /// [`Samples::new`] evaluates in closed form.
    fn bspline_net(&self) -> Option<[[[f64; 3]; 4]; 4]> {
        let PatchPoints::Table { patch, control, .. } = self else {
            return None;
        };
        if !self.is_regular() || patch.corner != 0 {
            return None;
        }
        let mut net = [[[0.0; 3]; 4]; 4];
        for (&(a, b), &q) in REGULAR_LAYOUT.iter().zip(control) {
            net[(a + 1) as usize][(b + 1) as usize] = q;
        }
        Some(net)
    }

    /// Whether the face's points come from the table.
    fn is_table(&self) -> bool {
        matches!(self, PatchPoints::Table { .. })
    }

    /// Whether the face is a table face whose patch is the bicubic B-spline of a regular
    /// interior grid (in any rotation: its stencils are that spline's weights, rounded to
    /// `f32`).
    fn is_regular(&self) -> bool {
        let PatchPoints::Table { patch, control, .. } = self else {
            return false;
        };
        let kind = &patch.kind;
        !kind.boundary
            && kind.feature == table_format::Feature::None
            && kind.faces == 4
            && control.len() == REGULAR_LAYOUT.len()
    }

    /// The control points of a table face (none for an adaptive one, whose grids hold
    /// positions).
    fn control(&self) -> &[[f64; 3]] {
        match self {
            PatchPoints::Table { control, .. } => control,
            PatchPoints::Adaptive { .. } => &[],
        }
    }

    /// The weights of grid point `(i, j)` of a weight grid, in the face's own indices.
    fn row<'g>(
        &self,
        weights: &'g [f32],
        side: usize,
        corner: usize,
        (i, j): (usize, usize),
    ) -> &'g [f32] {
        grid_row(weights, side, corner, self.control().len(), (i, j))
    }

    /// The limit position at grid point `(i, j)` of `grid`, in the face's own indices.
    fn at(&self, grid: &Grid, i: usize, j: usize) -> [f64; 3] {
        match *grid {
            Grid::Weights {
                weights,
                side,
                corner,
            } => weighted_sum(self.control(), self.row(weights, side, corner, (i, j))),
            Grid::Positions { positions, side } => positions[j * side + i],
        }
    }

    /// The limit positions at the grid points `ij` of `grid` (the face's own indices), appended
    /// to `out`, four at a time.
    fn extend(
        &self,
        grid: &Grid,
        ij: impl Iterator<Item = (usize, usize)>,
        out: &mut Vec<[f64; 3]>,
    ) {
        match *grid {
            Grid::Weights {
                weights,
                side,
                corner,
            } => extend_weighted_sums(
                self.control(),
                ij.map(|point| self.row(weights, side, corner, point)),
                out,
            ),
            Grid::Positions { positions, side } => {
                out.extend(ij.map(|(i, j)| positions[j * side + i]))
            }
        }
    }

    /// Every point of a grid, row by row (`j` outer).
    fn all(&self, points: PointSet, n: u32) -> Result<Vec<[f64; 3]>, RuntimeError> {
        let grid = self.grid(points, n)?;
        let side = grid.side();
        let mut out = Vec::with_capacity(side * side);
        self.extend(
            &grid,
            (0..side * side).map(|p| (p % side, p / side)),
            &mut out,
        );
        Ok(out)
    }
}

/// The position stencils of `patch`'s grid `points` at rate `n`, `side x side` points of one
/// weight per patch point, or the error that names a table whose section does not fit.
pub(super) fn position_weights<'t>(
    table: &'t StencilTable,
    patch: &FacePatch,
    points: PointSet,
    n: u32,
    side: usize,
) -> Result<&'t [f32], RuntimeError> {
    let key = patch.kind.section(StencilKind::Position, points, n);
    let weights = table.weights(&key)?;
    let k = patch.points.len();
    if weights.len() != side * side * k {
        return Err(RuntimeError::LayoutMismatch {
            key,
            table: weights.len() / (side * side).max(1),
            patch: k,
        });
    }
    Ok(weights)
}

/// The weights of point `(i, j)` (the face's own indices) of a table section of `side x side`
/// points of `k` weights each, whose patch starts at the face's corner `corner`.
pub(super) fn grid_row(
    weights: &[f32],
    side: usize,
    corner: usize,
    k: usize,
    (i, j): (usize, usize),
) -> &[f32] {
    let (pi, pj) = dual_index_in_patch(corner, i, j, side);
    &weights[(pj * side + pi) * k..][..k]
}

/// One grid of one face: a table section of its patch, with the rotation into the patch, or
/// an adaptive face's positions in its own indices (`j` outer).
#[derive(Clone, Copy)]
enum Grid<'t> {
    Weights {
        weights: &'t [f32],
        side: usize,
        corner: usize,
    },
    Positions {
        positions: &'t [[f64; 3]],
        side: usize,
    },
}

impl Grid<'_> {
    /// Points a row.
    fn side(&self) -> usize {
        match *self {
            Grid::Weights { side, .. } | Grid::Positions { side, .. } => side,
        }
    }
}

/// The grids of the faces the tables do not describe, from feature-adaptive refinement
/// ([`limit_points`]), computed the first time a face asks for one. The faces around it that
/// share a vertex with it are computed in the same descent: they share its refinement (around
/// a high-valence vertex, all of them), and they are the faces whose rows and corner points its
/// deviation reads. So are the other grids of the asked rate's *chunk* ([`rate_chunk`]), both
/// point sets: a descent's cost is its refinement (building each level's neighbourhood), not its
/// points, and the selection asks for the rates in order.
pub(crate) struct AdaptiveGrids<'a> {
    mesh: &'a Mesh,
    /// The faces evaluated adaptively, ascending.
    pub(super) faces: Vec<usize>,
    /// Per grid (`2 (n - 1)` primal, `2 (n - 1) + 1` dual), per face of `faces`: its positions
    /// once computed.
    grids: Vec<OnceLock<FaceGrids>>,
    /// Per chunk of rates, the lock one computation of its grids holds, so that faces asking
    /// at once wait for it rather than compute their common neighbours again.
    chunks: Vec<Mutex<()>>,
}

/// One grid of every adaptive face, each set once computed.
type FaceGrids = Vec<OnceLock<Vec<[f64; 3]>>>;

/// The largest rate of an adaptive face's grid: the largest the tessellators use.
const MAX_ADAPTIVE_RATE: u32 = 64;

/// The rates whose grids are computed together with rate `n`'s, and the chunk's number: `1`,
/// `2..=3`, `4..=7`, `8..=15`, `16..=23`, then [`SELECTION_GRID`] alone (every face's samples),
/// `25..=31`, `32..=63`, `64`. With doubling chunks the points made for rates a face never
/// reaches are fewer than those of the rates it does, and a face reaching rate `n` takes a
/// handful of descents instead of one per grid, up to `2 n`.
fn rate_chunk(n: u32) -> (usize, std::ops::RangeInclusive<u32>) {
    const CHUNKS: [(u32, u32); 9] = [
        (1, 1),
        (2, 3),
        (4, 7),
        (8, 15),
        (16, SELECTION_GRID - 1),
        (SELECTION_GRID, SELECTION_GRID),
        (SELECTION_GRID + 1, 31),
        (32, 63),
        (64, MAX_ADAPTIVE_RATE),
    ];
    let k = CHUNKS
        .iter()
        .position(|&(_, last)| n <= last)
        .unwrap_or(CHUNKS.len() - 1);
    (k, CHUNKS[k].0..=CHUNKS[k].1)
}

/// Where grid `(primal, n)` (`n >= 1`) is kept in [`AdaptiveGrids::grids`].
fn grid_slot(primal: bool, n: u32) -> usize {
    2 * (n as usize - 1) + usize::from(!primal)
}

impl<'a> AdaptiveGrids<'a> {
    fn new(mesh: &'a Mesh, faces: Vec<usize>) -> Self {
        let grids = (0..2 * MAX_ADAPTIVE_RATE)
            .map(|_| OnceLock::new())
            .collect();
        let chunks = (0..=rate_chunk(MAX_ADAPTIVE_RATE).0)
            .map(|_| Mutex::new(()))
            .collect();
        AdaptiveGrids {
            mesh,
            faces,
            grids,
            chunks,
        }
    }

    /// The positions of face `face`'s grid `points` at rate `n`, `j` outer.
    fn grid(&self, face: usize, points: PointSet, n: u32) -> Result<&[[f64; 3]], RuntimeError> {
        let slot = self.faces.binary_search(&face).map_err(|_| {
            RuntimeError::Unsupported(format!("face {face} is not evaluated adaptively"))
        })?;
        let primal = points == PointSet::Primal;
        if !(1..=MAX_ADAPTIVE_RATE).contains(&n) {
            return Err(RuntimeError::InvalidParameter {
                name: "rate".to_owned(),
                reason: format!("{n} (faces evaluated adaptively take 1..={MAX_ADAPTIVE_RATE})"),
            });
        }
        let cells = self.cells(primal, n);
        if cells[slot].get().is_none() {
            let (chunk, rates) = rate_chunk(n);
            // A poisoned lock only means that another computation failed; this one reports
            // its own error, if any.
            let _computing = self.chunks[chunk]
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            if cells[slot].get().is_none() {
                // The face and the adaptive faces sharing a vertex with it, not yet computed
                // (a chunk's grids are set together, so one grid tells).
                let mut around: Vec<usize> = self
                    .mesh
                    .face(face)
                    .iter()
                    .flat_map(|&v| self.mesh.fan(v as usize))
                    .filter_map(|h| {
                        self.faces
                            .binary_search(&(self.mesh.face_of[h] as usize))
                            .ok()
                    })
                    .filter(|&k| cells[k].get().is_none())
                    .collect();
                around.push(slot);
                around.sort_unstable();
                around.dedup();
                let faces: Vec<usize> = around.iter().map(|&k| self.faces[k]).collect();
                let wanted: Vec<(bool, u32)> =
                    rates.flat_map(|r| [(true, r), (false, r)]).collect();
                let computed = self.compute(&faces, &wanted)?;
                for (k, face_grids) in around.into_iter().zip(computed) {
                    for (&(primal, r), positions) in wanted.iter().zip(face_grids) {
                        let _ = self.cells(primal, r)[k].set(positions);
                    }
                }
            }
        }
        cells[slot]
            .get()
            .map(Vec::as_slice)
            .ok_or_else(|| RuntimeError::Unsupported(format!("no adaptive grid for face {face}")))
    }

    /// Grid `(primal, n)` of every adaptive face (`1 <= n <=` [`MAX_ADAPTIVE_RATE`]).
    fn cells(&self, primal: bool, n: u32) -> &FaceGrids {
        self.grids[grid_slot(primal, n)]
            .get_or_init(|| self.faces.iter().map(|_| OnceLock::new()).collect())
    }

    /// The grids `wanted` (`(primal, n)`; primal `(n + 1)^2` points, dual `n^2`) of `faces`,
    /// in order: one descent for all of them.
    fn compute(
        &self,
        faces: &[usize],
        wanted: &[(bool, u32)],
    ) -> Result<Vec<Vec<Vec<[f64; 3]>>>, RuntimeError> {
        let grid_queries = |f: usize, (primal, n): (bool, u32)| {
            let side = grid_side(primal, n);
            let at = move |k: u32| {
                if primal {
                    f64::from(k) / f64::from(n)
                } else {
                    f64::from(2 * k + 1) / f64::from(2 * n)
                }
            };
            (0..side * side).map(move |p| LimitQuery {
                face: f as u32,
                u: at(p % side),
                v: at(p / side),
            })
        };
        let queries: Vec<LimitQuery> = faces
            .iter()
            .flat_map(|&f| wanted.iter().flat_map(move |&g| grid_queries(f, g)))
            .collect();
        let points = limit_points(self.mesh, &queries)?;
        let mut points = points.iter().map(|p| p[0]);
        Ok(faces
            .iter()
            .map(|_| {
                wanted
                    .iter()
                    .map(|&(primal, n)| {
                        let side = grid_side(primal, n) as usize;
                        points.by_ref().take(side * side).collect()
                    })
                    .collect()
            })
            .collect())
    }
}

/// Points on a side of a quad's grid at rate `n`: `n + 1` primal points, `n` dual ones.
pub(super) fn grid_side(primal: bool, n: u32) -> u32 {
    if primal {
        n + 1
    } else {
        n
    }
}

/// The limit positions of face `patch` at the table's grid `points` at rate `n` (primal:
/// `(i/n, j/n)`, `(n+1)^2` points; dual: `((2i+1)/2n, (2j+1)/2n)`, `n^2` points), in the face's
/// own parameters, row by row (`j` outer): one weighted sum of the patch's control points per
/// point. ([`crate::scheme::patch::dual_positions`] is the dual case.)
pub fn table_positions(
    table: &StencilTable,
    mesh: &Mesh,
    patch: &FacePatch,
    points: PointSet,
    n: u32,
) -> Result<Vec<[f64; 3]>, RuntimeError> {
    PatchPoints::new(table, mesh, patch)?.all(points, n)
}

/// Limit-surface samples of one face: parameters and positions.
struct Samples {
    /// The rate of the sample grids ([`selection_axes`]).
    grid: u32,
    /// Grid by grid, `j` outer.
    positions: Vec<[f64; 3]>,
    /// Where the next early-stopping scan starts: the sample that refuted the last rate. The
    /// next rate's deviation peaks in the same region of the face (where it bends most), so a
    /// scan from there finds a failing rate's first sample beyond the tolerance soonest.
    start: Cell<usize>,
    /// Whether the last rate was refuted outside the interior (in a side strip or a corner
    /// square): then the next rate is scanned there first.
    outside_first: Cell<bool>,
    /// The rates refuted so far, each at its sample; and, for a table face, the kept rate's
    /// chart deviation and its fans' ([`FaceLocal::corner_chart_deviation`], the former with the
    /// scan's largest).
    refutations: RefCell<Vec<Refutation>>,
    chart: Cell<Option<(f64, Option<f64>)>>,
}

impl Samples {
    /// No samples: a hole's.
    fn none() -> Self {
        Samples {
            grid: SELECTION_GRID,
            positions: Vec::new(),
            start: Cell::new(0),
            outside_first: Cell::new(false),
            refutations: RefCell::new(Vec::new()),
            chart: Cell::new(None),
        }
    }

    /// The primal and dual points of the face at rate `grid`.
    fn new(points: &PatchPoints, grid: u32) -> Result<Self, RuntimeError> {
        let count = (grid_side(true, grid).pow(2) + grid_side(false, grid).pow(2)) as usize;
        let mut positions = Vec::with_capacity(count);
        for (set, axis) in [PointSet::Primal, PointSet::Dual]
            .into_iter()
            .zip(selection_axes(grid))
        {
            let g = points.grid(set, grid)?;
            let side = g.side();
            match points.bspline_net() {
                Some(net) => tensor_product(&net, &axis, &mut positions),
                None => points.extend(
                    &g,
                    (0..side * side).map(|p| (p % side, p / side)),
                    &mut positions,
                ),
            }
        }
        Ok(Samples {
            grid,
            positions,
            start: Cell::new(0),
            outside_first: Cell::new(false),
            refutations: RefCell::new(Vec::new()),
            chart: Cell::new(None),
        })
    }
}

impl Samples {
    /// The parameters `(u, v)` of sample `k` ([`sample_place`]).
    fn uv(&self, k: usize) -> Option<[f64; 2]> {
        sample_place(self.grid, k).map(|(_, _, uv)| uv)
    }
}

/// The parameters along either axis of the samples at rate `grid`: the primal grid's `i / grid`,
/// `i = 0..=grid`, then the dual grid's `(2i + 1) / 2 grid`, `i = 0..grid`. Each grid of samples
/// is the square of its axis.
fn selection_axes(grid: u32) -> [Vec<f64>; 2] {
    [
        (0..=grid).map(|i| axis_parameter(true, grid, i)).collect(),
        (0..grid).map(|i| axis_parameter(false, grid, i)).collect(),
    ]
}

/// Parameter `i` of [`selection_axes`]'s primal or dual axis.
fn axis_parameter(primal: bool, grid: u32, i: u32) -> f64 {
    let n = f64::from(grid);
    if primal {
        f64::from(i) / n
    } else {
        f64::from(2 * i + 1) / (2.0 * n)
    }
}

/// Sample `index` of a face at rate `grid` (the primal grid's `(grid + 1)^2` samples, then the
/// dual grid's `grid^2`, each `j` outer): its grid, its indices there and its parameters.
fn sample_place(grid: u32, index: usize) -> Option<(PointSet, (usize, usize), [f64; 2])> {
    let primal = grid_side(true, grid) as usize;
    let (set, side, k) = if index < primal * primal {
        (PointSet::Primal, primal, index)
    } else {
        (PointSet::Dual, grid as usize, index - primal * primal)
    };
    // A grid of no points (rate 0) has no samples.
    let (i, j) = (k.checked_rem(side)?, k.checked_div(side)?);
    if j >= side {
        return None;
    }
    let t = |i: usize| axis_parameter(set == PointSet::Primal, grid, i as u32);
    Some((set, (i, j), [t(i), t(j)]))
}

/// The cubic B-spline surface of `net` ([`PatchPoints::bspline_net`]) at the grid `axis x axis`
/// (`j` outer), appended to `out`: the curve of each row of the net at every `u`, then per point
/// the curve through those four, `16 side + 4 side^2` weighted sums where the table's stencils
/// take `16 side^2`.
fn tensor_product(net: &[[[f64; 3]; 4]; 4], axis: &[f64], out: &mut Vec<[f64; 3]>) {
    let basis: Vec<[f64; 4]> = axis.iter().map(|&t| bspline(t).0).collect();
    let rows: Vec<[[f64; 3]; 4]> = basis.iter().map(|w| net_rows(net, w)).collect();
    for w in &basis {
        out.extend(rows.iter().map(|row| row_curve(row, w)));
    }
}

/// The four rows of `net` (`rows[b]`: net row `b`, offset `b - 1` along `v`) at the `u` whose
/// B-spline weights are `w`.
fn net_rows(net: &[[[f64; 3]; 4]; 4], w: &[f64; 4]) -> [[f64; 3]; 4] {
    std::array::from_fn(|b| {
        let mut p = [0.0; 3];
        for (a, column) in net.iter().enumerate() {
            for c in 0..3 {
                p[c] += w[a] * column[b][c];
            }
        }
        p
    })
}

/// The curve through the four points `row` ([`net_rows`]) at the `v` whose weights are `w`.
fn row_curve(row: &[[f64; 3]; 4], w: &[f64; 4]) -> [f64; 3] {
    let mut p = [0.0; 3];
    for (b, q) in row.iter().enumerate() {
        for c in 0..3 {
            p[c] += w[b] * q[c];
        }
    }
    p
}

/// Sample `index` of a face ([`Samples::new`] at `grid`): its parameters and its position,
/// computed as [`Samples::new`] computes it (the same value to the bit).
fn sample_at(
    points: &PatchPoints,
    grid: u32,
    index: usize,
) -> Result<([f64; 2], [f64; 3]), RuntimeError> {
    let Some((set, (i, j), [u, v])) = sample_place(grid, index) else {
        let (primal, dual) = (grid_side(true, grid), grid_side(false, grid));
        return Err(RuntimeError::InvalidParameter {
            name: "sample".to_owned(),
            reason: format!(
                "{index} (a face has {} samples)",
                primal * primal + dual * dual
            ),
        });
    };
    let position = match points.bspline_net() {
        Some(net) => row_curve(&net_rows(&net, &bspline(u).0), &bspline(v).0),
        None => points.at(&points.grid(set, grid)?, i, j),
    };
    Ok(([u, v], position))
}

/// Dual-grid index `(i, j)` of point `t` of the row next to side `side` of a face at rate `n`,
/// in the side's direction (sides run counter-clockwise: 0 `v = 0`, 1 `u = 1`, 2 `v = 1`,
/// 3 `u = 0`); `t = 0` is the point nearest corner `side`.
fn row_index(side: usize, t: usize, n: usize) -> (usize, usize) {
    let last = n - 1;
    match side {
        0 => (t, 0),
        1 => (last, t),
        2 => (last - t, last),
        _ => (0, last - t),
    }
}

/// Primal index of point `t/n` along side `side` (counter-clockwise, from corner `side`).
pub(super) fn curve_index(side: usize, t: usize, n: usize) -> (usize, usize) {
    match side {
        0 => (t, 0),
        1 => (n, t),
        2 => (n - t, n),
        _ => (0, n - t),
    }
}

/// What lies beyond one side of the face in `L_{f,n}`.
enum Beyond {
    /// The neighbour's dual row at rate `n`, running along this side.
    Face(Vec<[f64; 3]>),
    /// The limit boundary curve at `t/n`, `t = 0..=n`, along this side.
    Curve(Vec<[f64; 3]>),
}

/// The uniform-rate tessellation around one face, `L_{f,n}` (module docs): the face's dual
/// points, what lies beyond each side, and the triangles around each corner.
///
/// Everything is made when a sample first reads it: a rate the selection refutes is mostly
/// refuted at the sample that refuted the last one, in one side rectangle or corner square,
/// and needs that region's rows and triangles only (on Spot at `1e-4`, 21,332 rates got past
/// the interior, and 2,928 of them were the faces' last: the others were refuted outside it).
struct FaceLocal<'p> {
    n: usize,
    /// The face's points and its dual grid at rate `n`, which `dual` is evaluated from.
    own: &'p PatchPoints<'p>,
    grid: Grid<'p>,
    /// `n x n` dual points, `j` outer, each evaluated when first read ([`FaceLocal::d`]): a rate
    /// the selection refutes is refuted at a sample or two, which read four points each, and a
    /// face that reaches rate `n` tries every smaller rate first (`n^3 / 3` points in all, where
    /// the rate it keeps reads `n^2`).
    dual: Vec<Cell<Option<[f64; 3]>>>,
    /// The mesh and every face's points: what the sides and corners are made from.
    ctx: &'p Context<'p>,
    /// The face.
    f: usize,
    /// The neighbours' dual grids at rate `n`, each looked up once: the rows beyond the sides
    /// and the corners' rings read the same few faces (a lookup in a compact table costs as
    /// much as a dozen points).
    neighbours: RefCell<Vec<(usize, Grid<'p>)>>,
    /// The face's primal grid at rate `n`: its boundary curves and the limit points that close
    /// its corners' polygons.
    primal: OnceCell<Grid<'p>>,
    /// What lies beyond each side, and the strip between it and the face's row.
    beyond: [OnceCell<Beyond>; 4],
    strips: [OnceCell<Vec<[[f64; 3]; 3]>>; 4],
    /// Per corner: the vertex polygon's triangles, the two ends of the adjacent strips, and the
    /// face's corner cell.
    corners: [OnceCell<Vec<Corner>>; 4],
    /// Per corner, the triangle nearest the last sample read there: where a corner square's
    /// search starts.
    nearest: [Cell<usize>; 4],
    /// Vectors to fill, left by an earlier `L_{f,n}` ([`Spare`]).
    spare: RefCell<Spare<'p>>,
}

/// The vectors an `L_{f,n}` leaves when dropped ([`FaceLocal::into_spare`]), for the next one to
/// fill ([`FaceLocal::new_in`]): the selection makes one per face and rate tried, each with its
/// dual points, sides' rows, strips and corners' triangles, and allocating them afresh every
/// time was about 2% of a bent frame's selection (Spot, docs/benchmarks.md).
#[derive(Default)]
struct Spare<'p> {
    dual: Vec<Cell<Option<[f64; 3]>>>,
    neighbours: Vec<(usize, Grid<'p>)>,
    points: Vec<Vec<[f64; 3]>>,
    triangles: Vec<Vec<[[f64; 3]; 3]>>,
    corners: Vec<Vec<Corner>>,
}

/// One of `spares`, emptied, or a new vector.
fn emptied<T>(spares: &mut Vec<Vec<T>>) -> Vec<T> {
    let mut spare = spares.pop().unwrap_or_default();
    spare.clear();
    spare
}

/// The [`Spare`]s of a selection's threads: a face takes one while its rates are tried and gives
/// it back after (a lock a face, against allocations a rate).
struct SparePool<'p>(Mutex<Vec<Spare<'p>>>);

impl<'p> SparePool<'p> {
    fn new() -> Self {
        SparePool(Mutex::new(Vec::new()))
    }

    fn take(&self) -> Spare<'p> {
        // A poisoned lock only means another face's selection panicked: its spares are vectors
        // still, to be cleared before use.
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .pop()
            .unwrap_or_default()
    }

    fn give(&self, spare: Spare<'p>) {
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .push(spare);
    }
}

/// A triangle around a corner, with a ball that holds it: `|p - centre| - radius` is a lower
/// bound of the distance from `p` to the triangle that costs a tenth of the distance itself;
/// and the dual vectors of its edges, which give an upper bound nearly as cheaply
/// ([`Corner::bound_within`]).
struct Corner {
    triangle: [[f64; 3]; 3],
    centre: [f64; 3],
    radius: f64,
    /// `(b - a, c - a)` and the vectors whose dot products with `p - a` are the barycentric
    /// coordinates of `p`'s projection on the plane (`None` for a triangle too thin to have
    /// them).
    edges: [[f64; 3]; 2],
    duals: Option<[[f64; 3]; 2]>,
    /// What rounding may add to a distance from this triangle: a few ulps of its coordinates.
    slack: f64,
}

impl Corner {
    fn new(triangle: [[f64; 3]; 3]) -> Self {
        let centre = combine(&[
            (1.0 / 3.0, triangle[0]),
            (1.0 / 3.0, triangle[1]),
            (1.0 / 3.0, triangle[2]),
        ]);
        // The root of the largest square: the largest distance, to the bit.
        let radius = triangle
            .iter()
            .map(|&q| {
                let d = sub(q, centre);
                dot(d, d)
            })
            .fold(0.0, f64::max)
            .sqrt();
        let [a, b, c] = triangle;
        let edges = [sub(b, a), sub(c, a)];
        let [ab, ac] = edges;
        let (bb, bc, cc) = (dot(ab, ab), dot(ab, ac), dot(ac, ac));
        let det = bb * cc - bc * bc;
        // Solving the 2 x 2 normal equations: `beta = u . (p - a)`, `gamma = w . (p - a)`.
        let duals = (det > 1e-12 * bb * cc).then(|| {
            let inverse = 1.0 / det;
            let dual = |x: f64, e: [f64; 3], y: f64, f: [f64; 3]| {
                std::array::from_fn(|k| (x * e[k] - y * f[k]) * inverse)
            };
            [dual(cc, ab, bc, ac), dual(bb, ac, bc, ab)]
        });
        // Every coordinate of the triangle is within `radius` of the centre's.
        let largest = centre.iter().fold(0.0f64, |m, &x| m.max(x.abs())) + radius;
        Corner {
            triangle,
            centre,
            radius,
            edges,
            duals,
            slack: 1e-12 * largest,
        }
    }

    /// Whether a distance from `p` to the triangle at least [`point_triangle_distance`]'s,
    /// roundings included, is at most `floor`: the distance to the point of the triangle at
    /// `p`'s projection's barycentric coordinates, clamped into it (where the projection lies
    /// inside, the distance itself), plus a margin far above both computations' rounding. About
    /// a third of the exact search's operations: a corner sample that it shows below the
    /// largest deviation so far needs nothing else.
    ///
    /// The root is taken only where the squares leave the answer open (a root's latency
    /// dominates a scan of corner samples): with `r = floor - margin` at least half of `floor`,
    /// `|off|^2 <= r^2 (1 - 1e-14)` puts the bound below `floor` by far more than its roundings,
    /// and `|off|^2 > r^2 (1 + 1e-14)` above it.
    fn bound_within(&self, p: [f64; 3], floor: f64) -> bool {
        let Some((squared, slack, rounding)) = self.bound_parts(p) else {
            return false;
        };
        let r = floor - (slack + rounding);
        if r >= 0.5 * floor {
            if squared <= r * r * (1.0 - 1e-14) {
                return true;
            }
            if squared > r * r * (1.0 + 1e-14) {
                return false;
            }
        }
        squared.sqrt() + slack + rounding <= floor
    }

    /// The bound [`Corner::bound_within`] compares with its floor.
    #[cfg(test)]
    fn upper_bound(&self, p: [f64; 3]) -> Option<f64> {
        let (squared, slack, rounding) = self.bound_parts(p)?;
        Some(squared.sqrt() + slack + rounding)
    }

    /// [`Corner::bound_within`]'s squared distance and its two margins.
    #[inline]
    fn bound_parts(&self, p: [f64; 3]) -> Option<(f64, f64, f64)> {
        let [u, w] = self.duals?;
        let ap = sub(p, self.triangle[0]);
        let (beta, gamma) = (dot(u, ap).max(0.0), dot(w, ap).max(0.0));
        let sum = beta + gamma;
        let (beta, gamma) = if sum > 1.0 {
            (beta / sum, gamma / sum)
        } else {
            (beta, gamma)
        };
        let [ab, ac] = self.edges;
        let off: [f64; 3] = std::array::from_fn(|k| ap[k] - beta * ab[k] - gamma * ac[k]);
        let largest = p.iter().fold(0.0f64, |m, &x| m.max(x.abs()));
        Some((dot(off, off), self.slack, 1e-12 * largest))
    }
}

/// The triangles of a strip merging row `a` (`na` points at `(2i+1)/2na`) with row `b` (`nb`
/// points at `(2j+1)/2nb`) along an edge, or with a boundary curve (`b` at `j/na`): the
/// tessellator's merge order (dual_grid.rs).
fn strip_triangles(
    a: &[[f64; 3]],
    b: &[[f64; 3]],
    curve: bool,
    mut out: Vec<[[f64; 3]; 3]>,
) -> Vec<[[f64; 3]; 3]> {
    let (na, nb) = (a.len(), b.len());
    let param_a = |i: usize| if curve { 2 * i + 1 } else { (2 * i + 1) * nb };
    let param_b = |j: usize| if curve { 2 * j } else { (2 * j + 1) * na };
    let (mut i, mut j) = (0, 0);
    out.clear();
    out.reserve(na + nb);
    while i + 1 < na || j + 1 < nb {
        if j + 1 == nb || (i + 1 < na && param_a(i + 1) <= param_b(j + 1)) {
            out.push([b[j], a[i + 1], a[i]]);
            i += 1;
        } else {
            out.push([b[j], b[j + 1], a[i]]);
            j += 1;
        }
    }
    out
}

impl<'p> FaceLocal<'p> {
    /// `L_{f,n}` around face `f`: the face's own dual points at rate `n` (all it needs in the
    /// interior `[h, 1-h]^2`, [`FaceLocal::is_interior`]), what lies beyond each side and the
    /// triangles around each corner, each made when first read.
    fn new(ctx: &'p Context<'p>, f: usize, n: u32) -> Result<Self, RuntimeError> {
        Self::new_in(ctx, f, n, Spare::default())
    }

    /// [`FaceLocal::new`], filling the vectors of `spare`.
    fn new_in(
        ctx: &'p Context<'p>,
        f: usize,
        n: u32,
        mut spare: Spare<'p>,
    ) -> Result<Self, RuntimeError> {
        let own = ctx.face(f)?;
        let grid = own.grid(PointSet::Dual, n)?;
        let count = grid.side() * grid.side();
        let mut dual = std::mem::take(&mut spare.dual);
        dual.clear();
        dual.resize(count, Cell::new(None));
        let mut neighbours = std::mem::take(&mut spare.neighbours);
        neighbours.clear();
        Ok(FaceLocal {
            n: n as usize,
            own,
            grid,
            dual,
            ctx,
            f,
            neighbours: RefCell::new(neighbours),
            primal: OnceCell::new(),
            beyond: Default::default(),
            strips: Default::default(),
            corners: Default::default(),
            nearest: Default::default(),
            spare: RefCell::new(spare),
        })
    }

    /// Every vector this `L_{f,n}` made, for the next one ([`FaceLocal::new_in`]).
    fn into_spare(self) -> Spare<'p> {
        let mut spare = self.spare.into_inner();
        spare.dual = self.dual;
        spare.neighbours = self.neighbours.into_inner();
        for beyond in self.beyond {
            if let Some(Beyond::Face(points) | Beyond::Curve(points)) = beyond.into_inner() {
                spare.points.push(points);
            }
        }
        spare
            .triangles
            .extend(self.strips.into_iter().filter_map(OnceCell::into_inner));
        spare
            .corners
            .extend(self.corners.into_iter().filter_map(OnceCell::into_inner));
        spare
    }

    /// An empty vector of points, a spare one if there is one.
    fn points_vec(&self) -> Vec<[f64; 3]> {
        emptied(&mut self.spare.borrow_mut().points)
    }

    /// An empty vector of triangles, a spare one if there is one.
    fn triangles_vec(&self) -> Vec<[[f64; 3]; 3]> {
        emptied(&mut self.spare.borrow_mut().triangles)
    }

    /// A vector of points made here and no longer read, for the next to fill.
    fn give_points(&self, points: Vec<[f64; 3]>) {
        self.spare.borrow_mut().points.push(points);
    }

    /// Every dual point, those not read yet evaluated four at a time ([`PatchPoints::extend`]):
    /// what a scan that is not refuted at once reads anyway. (Give the vector back with
    /// [`FaceLocal::give_points`].)
    fn filled(&self) -> Vec<[f64; 3]> {
        let mut missing = self.points_vec();
        self.own.extend(
            &self.grid,
            (0..self.dual.len())
                .filter(|&k| self.dual[k].get().is_none())
                .map(|k| (k % self.n, k / self.n)),
            &mut missing,
        );
        // The cells still empty, in the same order.
        let mut fresh = missing.iter().copied();
        let mut all = self.points_vec();
        all.extend(self.dual.iter().map(|cell| {
            cell.get().unwrap_or_else(|| {
                let p = fresh.next().unwrap_or_default();
                cell.set(Some(p));
                p
            })
        }));
        self.give_points(missing);
        all
    }

    /// The dual grid of face `g` at rate `n`.
    fn neighbour_grid(&self, g: usize) -> Result<Grid<'p>, RuntimeError> {
        if let Some(&(_, grid)) = self.neighbours.borrow().iter().find(|(h, _)| *h == g) {
            return Ok(grid);
        }
        let grid = self.ctx.face(g)?.grid(PointSet::Dual, self.n as u32)?;
        self.neighbours.borrow_mut().push((g, grid));
        Ok(grid)
    }

    /// The face's primal grid at rate `n`, looked up once for all its sides and corners.
    fn primal(&self) -> Result<Grid<'p>, RuntimeError> {
        self.primal
            .get_or_try(|| self.own.grid(PointSet::Primal, self.n as u32))
            .copied()
    }

    /// What lies beyond side `side`: the neighbour's row, or the boundary curve.
    fn beyond(&self, side: usize) -> Result<&Beyond, RuntimeError> {
        self.beyond[side].get_or_try(|| self.make_beyond(side))
    }

    /// [`FaceLocal::beyond`], made (apart, so that the scans' loops stay small).
    #[inline(never)]
    fn make_beyond(&self, side: usize) -> Result<Beyond, RuntimeError> {
        let (ctx, f) = (self.ctx, self.f);
        let m = self.n;
        let Some((g, other)) = across(ctx.mesh, f, side) else {
            let primal = self.primal()?;
            let mut curve = self.points_vec();
            self.own.extend(
                &primal,
                (0..=m).map(|t| curve_index(side, t, m)),
                &mut curve,
            );
            return Ok(Beyond::Curve(curve));
        };
        let grid = self.neighbour_grid(g)?;
        let mut row = self.points_vec();
        ctx.face(g)?
            .extend(&grid, (0..m).map(|t| beyond_index(other, t, m)), &mut row);
        Ok(Beyond::Face(row))
    }

    /// The strip along side `side`, in the tessellator's merge order.
    fn strip(&self, side: usize) -> Result<&[[[f64; 3]; 3]], RuntimeError> {
        self.strips[side]
            .get_or_try(|| {
                let mut row = self.points_vec();
                row.extend((0..self.n).map(|t| self.row(side, t)));
                let beyond = self.beyond(side)?;
                let (Beyond::Face(other) | Beyond::Curve(other)) = beyond;
                let curve = matches!(beyond, Beyond::Curve(_));
                let strip = strip_triangles(&row, other, curve, self.triangles_vec());
                self.give_points(row);
                Ok(strip)
            })
            .map(Vec::as_slice)
    }

    /// The triangles around corner `corner`.
    fn corner(&self, corner: usize) -> Result<&[Corner], RuntimeError> {
        self.corners[corner]
            .get_or_try(|| self.make_corner(corner))
            .map(Vec::as_slice)
    }

    /// [`FaceLocal::corner`], made (apart, so that the scans' loops stay small).
    #[inline(never)]
    fn make_corner(&self, corner: usize) -> Result<Vec<Corner>, RuntimeError> {
        let (ctx, f) = (self.ctx, self.f);
        let m = self.n;
        let mesh = ctx.mesh;
        let (fan, closed) = sector(mesh, mesh.face_halfedges(f).start + corner);
        let mut ring = self.points_vec();
        if !closed {
            let primal = self.primal()?;
            let (i, j) = curve_index(corner, 0, m);
            ring.push(self.own.at(&primal, i, j));
        }
        for h in fan {
            let g = mesh.face_of[h] as usize;
            let (i, j) = row_index(h - mesh.face_halfedges(g).start, 0, m);
            ring.push(if g == f {
                self.d(i, j)
            } else {
                ctx.face(g)?.at(&self.neighbour_grid(g)?, i, j)
            });
        }
        // The polygon's fan, two triangles of each strip and the corner cell's two.
        let mut triangles = self.triangles_vec();
        triangles
            .extend((1..ring.len().saturating_sub(1)).map(|i| [ring[0], ring[i], ring[i + 1]]));
        // Side `corner` starts at this corner, side `corner - 1` ends at it.
        triangles.extend(self.strip(corner)?.iter().take(2));
        triangles.extend(self.strip((corner + 3) % 4)?.iter().rev().take(2));
        if m >= 2 {
            let (i, j) = row_index(corner, 0, m);
            let (i1, j1) = (i.min(m - 2), j.min(m - 2));
            let (p, q, r, s) = (
                self.d(i1, j1),
                self.d(i1 + 1, j1),
                self.d(i1 + 1, j1 + 1),
                self.d(i1, j1 + 1),
            );
            triangles.extend([[p, q, r], [p, r, s]]);
        }
        let mut corners = emptied(&mut self.spare.borrow_mut().corners);
        corners.extend(triangles.iter().copied().map(Corner::new));
        self.give_points(ring);
        self.spare.borrow_mut().triangles.push(triangles);
        Ok(corners)
    }

    /// Dual point `(i, j)`, evaluated the first time it is read.
    fn d(&self, i: usize, j: usize) -> [f64; 3] {
        let cell = &self.dual[j * self.n + i];
        cell.get().unwrap_or_else(|| {
            let p = self.own.at(&self.grid, i, j);
            cell.set(Some(p));
            p
        })
    }

    /// Dual point `t` of the row next to side `side`, in the side's direction.
    fn row(&self, side: usize, t: usize) -> [f64; 3] {
        let (i, j) = row_index(side, t, self.n);
        self.d(i, j)
    }

    /// The deviation at one sample: `|S - L_{f,n}(u, v)|` in the interior and the side
    /// rectangles, the distance to the nearest triangle around the corner in a corner square;
    /// or, where that is at most `floor`, any value at most `floor` (a scan after the largest
    /// deviation needs no more: a corner square's search stops at the first triangle that
    /// near).
    fn deviation_at(&self, u: f64, v: f64, p: [f64; 3], floor: f64) -> Result<f64, RuntimeError> {
        let (u, v) = (AxisPlace::new(u, self.n), AxisPlace::new(v, self.n));
        match u.corner_with(&v) {
            Some(corner) => Ok(self.corner_deviation(corner, self.corner(corner)?, p, floor)),
            None => Ok(distance(p, self.at(&u, &v)?)),
        }
    }

    /// The distance from `p` to the nearest of corner `corner`'s `triangles`, or any value at
    /// most `floor` where that is at most `floor` ([`FaceLocal::deviation_at`]). Most samples of
    /// a scan lie nearer the last sample's triangle than the largest deviation so far, which its
    /// bound shows without the exact search; most of the others nearer another triangle, whose
    /// bound, a third of an exact distance, shows it (a sample crossing into the next triangle
    /// of a fan: at rate 1, whose samples are all in corner squares, the exact searches were
    /// 7% of a bent frame's selection on Spot).
    #[inline(always)]
    fn corner_deviation(
        &self,
        corner: usize,
        triangles: &[Corner],
        p: [f64; 3],
        floor: f64,
    ) -> f64 {
        let first = self.nearest[corner]
            .get()
            .min(triangles.len().saturating_sub(1));
        let Some(t) = triangles.get(first) else {
            return f64::INFINITY;
        };
        if floor > 0.0 {
            if t.bound_within(p, floor) {
                return floor;
            }
            // `first` again among them: one bound, against a branch per triangle.
            if let Some(k) = triangles.iter().position(|t| t.bound_within(p, floor)) {
                self.nearest[corner].set(k);
                return floor;
            }
        }
        self.nearest_triangle(corner, triangles, first, p, floor)
    }

    /// The exact search of [`FaceLocal::corner_deviation`], from triangle `first` (the one nearest
    /// the last sample here: the next sample is mostly nearest it too, and then bounds the rest
    /// tightest): one whose ball is farther than the nearest so far cannot be nearer (the margin
    /// keeps rounding in the bound from skipping a tie).
    #[inline(never)]
    fn nearest_triangle(
        &self,
        corner: usize,
        triangles: &[Corner],
        first: usize,
        p: [f64; 3],
        floor: f64,
    ) -> f64 {
        let mut nearest = triangles
            .get(first)
            .map_or(f64::INFINITY, |t| point_triangle_distance(p, &t.triangle));
        for (k, t) in triangles.iter().enumerate() {
            if nearest <= floor {
                break;
            }
            let centre = distance(p, t.centre);
            if k != first && centre - t.radius - 1e-12 * (centre + t.radius) <= nearest {
                let d = point_triangle_distance(p, &t.triangle);
                if d < nearest {
                    nearest = d;
                    self.nearest[corner].set(k);
                }
            }
        }
        nearest
    }

    /// Whether `(u, v)` lies in the interior `[h, 1-h]^2`, outside the corner squares: there
    /// `L_{f,n}` is made of the face's own dual points alone.
    fn is_interior(&self, u: f64, v: f64) -> bool {
        AxisPlace::new(u, self.n).interior_with(&AxisPlace::new(v, self.n), self.n)
    }

    /// `L_{f,n}` outside the corner squares at the sample with places `u` and `v`
    /// ([`linear_terms`]): in a side strip, what lies beyond the side looked up once.
    #[inline]
    fn at(&self, u: &AxisPlace, v: &AxisPlace) -> Result<[f64; 3], RuntimeError> {
        if self.n >= 2 && !(u.inside && v.inside) {
            let (side, along, across) = strip_of(u, v);
            let beyond = self.beyond(side)?;
            let (Beyond::Face(points) | Beyond::Curve(points)) = beyond;
            let curve = matches!(beyond, Beyond::Curve(_));
            let terms = strip_terms(along, across.depth, self.n, curve);
            return Ok(combine(&terms.map(|(w, point)| {
                (
                    w,
                    match point {
                        StripPoint::Row(t) => self.row(side, t),
                        StripPoint::Beyond(t) => points[t],
                    },
                )
            })));
        }
        Ok(combine(
            &dual_terms(u, v, self.n).map(|(w, (i, j))| (w, self.d(i, j))),
        ))
    }

    /// The largest distance from a corner square's sample to the point of `L_{f,n}` at its own
    /// parameters in the regular chart ([`FaceLocal::chart_point`]) over the corners that have
    /// one ([`chart_corner`]), and the largest deviation (to the nearest triangle) over those
    /// that do not (`None` where all have one); `None` as soon as either exceeds `stop` (the
    /// bound is of no use then).
    fn corner_chart_deviation(
        &self,
        samples: &Samples,
        stop: f64,
    ) -> Result<Option<(f64, Option<f64>)>, RuntimeError> {
        let charts = self.corner_charts()?;
        // The corner squares' samples: rows and columns within `h` of a side. The largest
        // squares, their roots taken where they grow (the root of the largest square is the
        // largest distance, to the bit).
        let (mut squared, mut largest, mut fans) = (0.0f64, 0.0f64, None::<f64>);
        let mut offset = 0;
        for axis in placed_axes(self.n)? {
            let side = axis.places.len();
            let near: Vec<usize> = (0..side).filter(|&i| axis.places[i].near_side()).collect();
            for &j in &near {
                for &i in &near {
                    let (u, v) = (&axis.places[i], &axis.places[j]);
                    let (Some(&p), Some(corner)) = (
                        samples.positions.get(offset + j * side + i),
                        u.corner_with(v),
                    ) else {
                        continue;
                    };
                    match self.chart_point(&charts, u.t, v.t) {
                        Some(x) => {
                            let d = sub(p, x);
                            if dot(d, d) > squared {
                                squared = dot(d, d);
                                largest = squared.sqrt();
                            }
                        }
                        None => {
                            // The largest so far as the floor: a sample below it leaves the
                            // largest as it is, whatever value stands for it.
                            let triangles = self.corner(corner)?;
                            let floor = fans.unwrap_or(0.0);
                            let d = self.corner_deviation(corner, triangles, p, floor);
                            fans = Some(floor.max(d));
                        }
                    }
                    if largest.max(fans.unwrap_or(0.0)) > stop {
                        return Ok(None);
                    }
                }
            }
            offset += side * side;
        }
        Ok(Some((largest, fans)))
    }

    /// Per corner with a regular chart ([`chart_corner`]), the fan's diagonal and the four
    /// faces' corner points in the order of [`chart_corner_terms`].
    fn corner_charts(&self) -> Result<[Option<CornerChart>; 4], RuntimeError> {
        let mut charts = [None; 4];
        for (corner, chart) in charts.iter_mut().enumerate() {
            let Some(ChartCorner {
                through_face,
                points,
            }) = chart_corner(self.ctx.mesh, self.f, corner, self.n)
            else {
                continue;
            };
            let mut at = [[0.0; 3]; 4];
            for (x, (g, (i, j))) in at.iter_mut().zip(points) {
                *x = if g == self.f {
                    self.d(i, j)
                } else {
                    self.ctx.face(g)?.at(&self.neighbour_grid(g)?, i, j)
                };
            }
            *chart = Some((through_face, at));
        }
        Ok(charts)
    }

    /// The point of `L_{f,n}` at `(u, v)` in a corner square whose corner has a chart in
    /// `charts` ([`chart_corner_terms`]); `None` elsewhere.
    fn chart_point(&self, charts: &[Option<CornerChart>; 4], u: f64, v: f64) -> Option<[f64; 3]> {
        let (corner, a, b) = corner_square(u, v, self.n)?;
        let (through_face, points) = charts[corner]?;
        let terms = chart_corner_terms(a, b, 0.5 / self.n as f64, through_face);
        Some(combine(&terms.map(|(w, k)| (w, points[k as usize]))))
    }

    /// `e_f(n)` over the samples.
    fn deviation(&self, samples: &Samples) -> Result<f64, RuntimeError> {
        self.deviation_up_to(samples, f64::INFINITY, |_| true)
    }

    /// The largest deviation over the samples whose region passes `keep(is_interior)`, or, as
    /// soon as one sample deviates by more than `stop`, that sample's deviation (a lower bound
    /// of `e_f(n)`, enough to reject the rate: the selection tries rates that mostly fail, and
    /// a failing rate usually fails at its first samples).
    ///
    /// The sample that refuted the last rate is read first; then the samples grid by grid, row
    /// by row, with each row's and column's place in the dual grid found once (where the
    /// interior's samples, most of them, cost one interpolation each).
    fn deviation_up_to(
        &self,
        samples: &Samples,
        stop: f64,
        keep: impl Fn(bool) -> bool,
    ) -> Result<f64, RuntimeError> {
        let first = samples.start.get();
        let mut worst = 0.0f64;
        if let (Some([u, v]), Some(&p)) = (samples.uv(first), samples.positions.get(first)) {
            if keep(self.is_interior(u, v)) {
                worst = self.deviation_at(u, v, p, 0.0)?;
                if worst > stop {
                    return Ok(worst);
                }
            }
        }
        let n = self.n;
        let wants_interior = n >= 2 && keep(true);
        let dual = if wants_interior {
            self.filled()
        } else {
            self.points_vec()
        };
        let scanned = self.scan_rows(samples, stop, &keep, &dual, worst);
        self.give_points(dual);
        scanned
    }

    /// [`FaceLocal::deviation_up_to`] after its first sample (`worst`): every sample row by row,
    /// the interior's read from `dual` (every dual point, or none where the interior is not
    /// scanned).
    fn scan_rows(
        &self,
        samples: &Samples,
        stop: f64,
        keep: &impl Fn(bool) -> bool,
        dual: &[[f64; 3]],
        worst: f64,
    ) -> Result<f64, RuntimeError> {
        let n = self.n;
        let wants_interior = n >= 2 && keep(true);
        let mut largest = Largest::new(worst);
        let mut offset = 0;
        for axis in placed_axes(n)? {
            let side = axis.places.len();
            for (j, row) in axis.places.iter().enumerate() {
                let row_samples = offset + j * side..offset + (j + 1) * side;
                let Some(positions) = samples.positions.get(row_samples) else {
                    break;
                };
                let interior = axis.interior_columns(row, n);
                if wants_interior {
                    for i in interior.clone() {
                        // The square root only where the sample may be the largest so far:
                        // `distance` is the root of the same sum.
                        let d = sub(
                            positions[i],
                            in_cell(|i, j| dual[j * n + i], &axis.places[i], row),
                        );
                        let squared = dot(d, d);
                        if squared > largest.below
                            && largest.raise(squared.sqrt())
                            && largest.value > stop
                        {
                            samples.start.set(offset + j * side + i);
                            return Ok(largest.value);
                        }
                    }
                }
                if keep(false) {
                    for columns in [0..interior.start, interior.end..side] {
                        let places = axis.places.get(columns.clone()).unwrap_or_default();
                        let points = positions.get(columns.clone()).unwrap_or_default();
                        for ((place, &p), i) in places.iter().zip(points).zip(columns) {
                            let raised = match place.corner_with(row) {
                                Some(corner) => {
                                    let triangles = self.corner(corner)?;
                                    let floor = largest.value;
                                    largest
                                        .raise(self.corner_deviation(corner, triangles, p, floor))
                                }
                                // As in the interior: the root only where it may be the largest.
                                None => {
                                    let d = sub(p, self.at(place, row)?);
                                    let squared = dot(d, d);
                                    squared > largest.below && largest.raise(squared.sqrt())
                                }
                            };
                            if raised && largest.value > stop {
                                samples.start.set(offset + j * side + i);
                                return Ok(largest.value);
                            }
                        }
                    }
                }
            }
            offset += side * side;
        }
        Ok(largest.value)
    }
}

/// The largest deviation of a scan so far, and the squared distances certainly below it.
struct Largest {
    value: f64,
    /// `value^2` less a margin of a few ulps of its rounding: a square at most this has a root
    /// at most `value`.
    below: f64,
}

impl Largest {
    fn new(value: f64) -> Self {
        Largest {
            value,
            below: value * value * (1.0 - 1e-14),
        }
    }

    /// Keep `deviation` if it is larger (a NaN is not: it leaves the value as `f64::max`
    /// would), and say whether it was.
    fn raise(&mut self, deviation: f64) -> bool {
        let larger = deviation > self.value;
        if larger {
            *self = Largest::new(deviation);
        }
        larger
    }
}

/// `L_{f,n}` in the interior: the dual grid's cell that holds the sample with places `u` and `v`,
/// split along `a = b` (the tessellator's diagonal), the dual point `(i, j)` read by `at`.
fn in_cell(at: impl Fn(usize, usize) -> [f64; 3], u: &AxisPlace, v: &AxisPlace) -> [f64; 3] {
    let [(x, p), (y, q), (z, r)] = cell_terms(u, v);
    combine(&[(x, at(p.0, p.1)), (y, at(q.0, q.1)), (z, at(r.0, r.1))])
}

/// [`in_cell`]'s weights and dual points.
fn cell_terms(u: &AxisPlace, v: &AxisPlace) -> [(f64, (usize, usize)); 3] {
    let ((i, a), (j, b)) = ((u.cell, u.fraction), (v.cell, v.fraction));
    if a >= b {
        [(1.0 - a, (i, j)), (a - b, (i + 1, j)), (b, (i + 1, j + 1))]
    } else {
        [(1.0 - b, (i, j)), (b - a, (i, j + 1)), (a, (i + 1, j + 1))]
    }
}

/// A corner's fan in the regular chart: whether its diagonal runs through the face, and the
/// points of [`chart_corner_terms`].
type CornerChart = (bool, [[f64; 3]; 4]);

/// A vertex of `L_{f,n}` outside the corner squares: the face's dual point `(i, j)`, or point
/// `t` of what lies beyond side `side` ([`Beyond`]: the neighbour's row or the boundary curve).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Vertex {
    Dual(usize, usize),
    Beyond(usize, usize),
}

/// Which corner square of the rate-`n` tessellation holds `(u, v)`, if any, with the sample's
/// distances from the corner along the corner's two sides: `a` along side `corner` (which
/// starts there), `b` back along side `corner - 1` (which ends there). The squares are
/// `[0, h]^2` and its rotations, `h = 1/2n`; a sample on the line `u = h` at rate 1 belongs to
/// the lower corner.
pub(super) fn corner_square(u: f64, v: f64, n: usize) -> Option<(usize, f64, f64)> {
    let h = 0.5 / n as f64;
    let corner = corner_of([u <= h, u >= 1.0 - h], [v <= h, v >= 1.0 - h])?;
    Some(match corner {
        0 => (0, u, v),
        1 => (1, v, 1.0 - u),
        2 => (2, 1.0 - u, 1.0 - v),
        _ => (3, 1.0 - v, u),
    })
}

/// The corner square of a sample whose `u` lies within `h` of 0 or of 1 (`[low, high]`), and
/// its `v` likewise; `None` unless both do. Corner `c` is where side `c` starts.
fn corner_of([low_u, high_u]: [bool; 2], [low_v, high_v]: [bool; 2]) -> Option<usize> {
    if !((low_u || high_u) && (low_v || high_v)) {
        return None;
    }
    Some(match (low_u, low_v) {
        (true, true) => 0,
        (false, true) => 1,
        (false, false) => 2,
        (true, false) => 3,
    })
}

/// `L_{f,n}(u, v)` outside the corner squares as an affine combination of three of its
/// vertices (`is_curve(side)`: whether a boundary curve lies beyond side `side`): in the
/// interior `[h, 1-h]^2` the dual grid's cell split along `D_ij - D_{i+1,j+1}` ([`in_cell`]);
/// in a side rectangle the strip to the neighbour's row (the rows' quads split as the
/// tessellator's merge splits them) or to the boundary curve, in scaled side coordinates: the
/// face's row point `t` at `(2t + 1, 1)`, the curve point `t` at `(2t, 0)`, the neighbour's row
/// point `t` at `(2t + 1, -1)`.
pub(super) fn linear_terms(
    u: &AxisPlace,
    v: &AxisPlace,
    n: usize,
    is_curve: impl FnOnce(usize) -> Result<bool, RuntimeError>,
) -> Result<[(f64, Vertex); 3], RuntimeError> {
    if n == 1 || (u.inside && v.inside) {
        return Ok(dual_terms(u, v, n).map(|(w, (i, j))| (w, Vertex::Dual(i, j))));
    }
    let (side, along, across) = strip_of(u, v);
    let terms = strip_terms(along, across.depth, n, is_curve(side)?);
    Ok(terms.map(|(w, point)| {
        (
            w,
            match point {
                StripPoint::Row(t) => {
                    let (i, j) = row_index(side, t, n);
                    Vertex::Dual(i, j)
                }
                StripPoint::Beyond(t) => Vertex::Beyond(side, t),
            },
        )
    }))
}

/// [`linear_terms`] at rate 1 (the face's one dual point) or in the interior ([`cell_terms`]),
/// where `L_{f,n}` is the face's own dual points alone.
fn dual_terms(u: &AxisPlace, v: &AxisPlace, n: usize) -> [(f64, (usize, usize)); 3] {
    if n == 1 {
        [(1.0, (0, 0)), (0.0, (0, 0)), (0.0, (0, 0))]
    } else {
        cell_terms(u, v)
    }
}

/// A vertex of a side strip of `L_{f,n}`: point `t` of the face's row next to the side
/// ([`row_index`]), or point `t` of what lies beyond the side ([`Beyond`]).
#[derive(Clone, Copy)]
enum StripPoint {
    Row(usize),
    Beyond(usize),
}

/// The side strip that holds a sample outside the interior and the corner squares (one of its
/// parameters alone lies within `h` of an end), with the sample's places along and across it:
/// side 0 runs with `u`, 1 with `v`, 2 and 3 against them.
fn strip_of<'p>(u: &'p AxisPlace, v: &'p AxisPlace) -> (usize, &'p Along, &'p AxisPlace) {
    if v.low {
        (0, &u.along[0], v)
    } else if u.high {
        (1, &v.along[0], u)
    } else if v.high {
        (2, &u.along[1], v)
    } else {
        (3, &v.along[1], u)
    }
}

/// `L_{f,n}` in a side strip ([`linear_terms`]) at `along`, `delta = across.depth`: to the
/// neighbour's row, or to the boundary curve (`curve`).
fn strip_terms(along: &Along, delta: f64, n: usize, curve: bool) -> [(f64, StripPoint); 3] {
    use StripPoint::{Beyond, Row};
    let sigma = along.sigma;
    if !curve {
        // Cell i between the rows: quad (F_i, F_i+1, G_i+1, G_i) split as
        // [G_i, F_i+1, F_i], [G_i, G_i+1, F_i+1]; alpha along, beta from G (0) to F (1).
        let (i, alpha) = (along.cell, along.alpha);
        let beta = (1.0 + delta) / 2.0;
        if beta >= alpha {
            [
                (1.0 - beta, Beyond(i)),
                (alpha, Row(i + 1)),
                (beta - alpha, Row(i)),
            ]
        } else {
            [
                (1.0 - alpha, Beyond(i)),
                (alpha - beta, Beyond(i + 1)),
                (beta, Row(i + 1)),
            ]
        }
    } else {
        let j = ((sigma / 2.0) as usize).min(n - 1);
        let centre = (2 * j + 1) as f64;
        if (sigma - centre).abs() <= 1.0 - delta {
            // [C_j, C_{j+1}, D_j].
            let w1 = (sigma - 2.0 * j as f64 - delta) / 2.0;
            [
                (1.0 - delta - w1, Beyond(j)),
                (w1, Beyond(j + 1)),
                (delta, Row(j)),
            ]
        } else {
            // [C_k, D_k, D_{k-1}], k = 1..n-1 the curve point nearest sigma.
            let k = if sigma < centre { j } else { j + 1 }.clamp(1, n - 1);
            let x = sigma - 2.0 * k as f64;
            [
                (1.0 - delta, Beyond(k)),
                ((delta + x) / 2.0, Row(k)),
                ((delta - x) / 2.0, Row(k - 1)),
            ]
        }
    }
}

/// The point of a corner square's fan at the sample's own parameters, for an interior vertex of
/// four faces: in the chart of the corner (`a` along side `corner`, `b` back along side
/// `corner - 1`, [`corner_square`]) the four faces' corner dual points lie at `(h, h)` (the
/// face's own, `0`), `(h, -h)` (beyond side `corner`, `1`), `(-h, h)` (beyond side
/// `corner - 1`, `2`) and `(-h, -h)` (the face opposite, `3`), and the fan splits their square
/// along the diagonal through the face (`through_face`) or along the other one. The weights
/// (barycentric in the triangle that holds `(a, b)`) and the points' numbers.
pub(super) fn chart_corner_terms(a: f64, b: f64, h: f64, through_face: bool) -> [(f64, u8); 3] {
    let (a, b) = (a / h, b / h);
    if !through_face {
        // The triangle (own, beyond `corner`, beyond `corner - 1`) holds the whole square.
        let own = (a + b) / 2.0;
        let along = (1.0 - own + (a - b) / 2.0) / 2.0;
        return [(own, 0), (along, 1), (1.0 - own - along, 2)];
    }
    if a >= b {
        [
            ((1.0 + b) / 2.0, 0),
            ((a - b) / 2.0, 1),
            ((1.0 - a) / 2.0, 3),
        ]
    } else {
        [
            ((1.0 + a) / 2.0, 0),
            ((b - a) / 2.0, 2),
            ((1.0 - b) / 2.0, 3),
        ]
    }
}

/// A sample parameter `t` (along `u` or `v`) against the dual grid at rate `n`: the cell (of
/// cells `0..n-1` between dual points `(2i+1)/2n`) that [`in_cell`] interpolates in, and the
/// fraction in it; and where `t` lies in the side strips' scaled coordinates ([`linear_terms`]).
/// A scan computes it once per row and column of samples.
pub(super) struct AxisPlace {
    /// The parameter.
    pub(super) t: f64,
    cell: usize,
    fraction: f64,
    /// Whether `t` lies in `[h, 1-h]` (`h = 1/2n`), in `[0, h]`, in `[1-h, 1]`.
    inside: bool,
    low: bool,
    high: bool,
    /// `delta = 2n d` clamped to `[0, 1]`, `d` the distance from `t` to the nearer end: how far
    /// into a side strip a sample `d` from that side lies.
    depth: f64,
    /// Along a side that runs with `t` (`s = t`) and against it (`s = 1 - t`).
    along: [Along; 2],
}

/// A sample's place along a side strip at rate `n`: `sigma = 2ns` clamped to `[1, 2n-1]`, and
/// the strip's cell `i` (between the rows' points `i` and `i+1`, at `2i+1` and `2i+3`) with the
/// fraction `alpha` in it.
struct Along {
    sigma: f64,
    cell: usize,
    alpha: f64,
}

impl Along {
    fn new(s: f64, n: usize) -> Self {
        let nf = n as f64;
        let sigma = (2.0 * nf * s).clamp(1.0, 2.0 * nf - 1.0);
        let x = (sigma - 1.0) / 2.0;
        // `x >= 0`: truncation is the floor.
        let cell = (x as usize).min(n.saturating_sub(2));
        Along {
            sigma,
            cell,
            alpha: x - cell as f64,
        }
    }
}

impl AxisPlace {
    fn new(t: f64, n: usize) -> Self {
        let nf = n as f64;
        let x = (t * nf - 0.5).clamp(0.0, nf - 1.0);
        // `x >= 0`: truncation is the floor.
        let cell = (x as usize).min(n.saturating_sub(2));
        let h = 0.5 / nf;
        let nearer = if t <= 0.5 { t } else { 1.0 - t };
        AxisPlace {
            t,
            cell,
            fraction: x - cell as f64,
            inside: t >= h && 1.0 - t >= h,
            low: t <= h,
            high: t >= 1.0 - h,
            depth: (2.0 * nf * nearer).clamp(0.0, 1.0),
            along: [Along::new(t, n), Along::new(1.0 - t, n)],
        }
    }

    /// Whether `t` lies within `h` of either end.
    fn near_side(&self) -> bool {
        self.low || self.high
    }

    /// Whether the sample at places `self` (along `u`) and `v` lies in the interior of the rate-`n`
    /// tessellation, `[h, 1-h]^2` with `h = 1/2n`, outside the corner squares (n >= 2).
    fn interior_with(&self, v: &AxisPlace, n: usize) -> bool {
        n >= 2 && self.inside && v.inside && !(self.near_side() && v.near_side())
    }

    /// The corner square that holds the sample at places `self` (along `u`) and `v`, if any
    /// ([`corner_square`]).
    pub(super) fn corner_with(&self, v: &AxisPlace) -> Option<usize> {
        corner_of([self.low, self.high], [v.low, v.high])
    }
}

/// The samples' parameters along either axis ([`selection_axes`]) placed against the dual grid
/// at one rate, with the columns whose samples may lie in the interior: the same for every face.
pub(super) struct AxisPlaces {
    pub(super) places: Vec<AxisPlace>,
    /// The columns whose parameter lies in `[h, 1-h]`, and those in `(h, 1-h)`: contiguous,
    /// the parameters ascending.
    inside: std::ops::Range<usize>,
    strictly_inside: std::ops::Range<usize>,
}

impl AxisPlaces {
    fn new(axis: &[f64], n: usize) -> Self {
        let places: Vec<AxisPlace> = axis.iter().map(|&t| AxisPlace::new(t, n)).collect();
        let range = |keep: &dyn Fn(&AxisPlace) -> bool| {
            let start = places.iter().take_while(|p| !keep(p)).count();
            let end = places.len()
                - places[start..]
                    .iter()
                    .rev()
                    .take_while(|p| !keep(p))
                    .count();
            start..end
        };
        let inside = range(&|p| p.inside);
        let strictly_inside = range(&|p| p.inside && !p.near_side());
        AxisPlaces {
            places,
            inside,
            strictly_inside,
        }
    }

    /// The columns whose samples in row `row` lie in the interior ([`AxisPlace::interior_with`]):
    /// beside a corner square (the row within `h` of a side) only those strictly inside.
    fn interior_columns(&self, row: &AxisPlace, n: usize) -> std::ops::Range<usize> {
        if n < 2 || !row.inside {
            0..0
        } else if row.near_side() {
            self.strictly_inside.clone()
        } else {
            self.inside.clone()
        }
    }
}

/// The sample grids' axes placed at rate `n`: the same for every face and selection, made
/// once per process.
pub(super) fn placed_axes(n: usize) -> Result<&'static [AxisPlaces; 2], RuntimeError> {
    static PLACES: OnceLock<Vec<[AxisPlaces; 2]>> = OnceLock::new();
    let places = PLACES.get_or_init(|| {
        (1..=MAX_SELECTED_RATE as usize)
            .map(|n| selection_axes(SELECTION_GRID).map(|axis| AxisPlaces::new(&axis, n)))
            .collect()
    });
    n.checked_sub(1)
        .and_then(|k| places.get(k))
        .ok_or_else(|| RuntimeError::InvalidParameter {
            name: "rate".to_owned(),
            reason: format!("{n} (the selection measures rates 1..={MAX_SELECTED_RATE})"),
        })
}

/// The mesh and every face's patch points: what evaluates any face.
struct Context<'a> {
    mesh: &'a Mesh,
    table: &'a StencilTable,
    patches: &'a [FacePatch],
    adaptive: &'a AdaptiveGrids<'a>,
    /// Per face, its points, gathered when the selection first reads the face: a selection kept
    /// across frames resamples a few faces, and reads those and their neighbours only.
    points: Vec<OnceLock<PatchPoints<'a>>>,
}

impl<'a> Context<'a> {
    /// Every face from the table, except those in `adaptive` ([`adaptive_faces`]).
    fn new(
        table: &'a StencilTable,
        mesh: &'a Mesh,
        patches: &'a [FacePatch],
        adaptive: &'a AdaptiveGrids<'a>,
    ) -> Result<Self, RuntimeError> {
        check_faces(mesh, patches)?;
        Ok(Context {
            mesh,
            table,
            patches,
            adaptive,
            points: (0..patches.len()).map(|_| OnceLock::new()).collect(),
        })
    }

    /// Whether face `f` and every face sharing a vertex with it are regular interior B-spline
    /// patches ([`PatchPoints::is_regular`]) around vertices of four faces: then its samples
    /// and `L_{f,n}` are stencils on one regular grid of control points ([`chart_norm`]).
    fn regular(&self, f: usize) -> bool {
        let mesh = self.mesh;
        let patch = |g: usize| !mesh.holes[g] && self.face(g).is_ok_and(|p| p.is_regular());
        patch(f)
            && mesh.face_halfedges(f).all(|h| {
                let v = mesh.face_vertices[h] as usize;
                let mut faces = 0;
                let all = mesh.fan_iter(v).all(|e| {
                    faces += 1;
                    mesh.cut(e, false) == Cut::None && patch(mesh.face_of[e] as usize)
                });
                all && faces == 4 && !mesh.is_cone_tip(v)
            })
    }

    /// Face `f`'s points, or the error that names a face the mesh does not have.
    fn face(&self, f: usize) -> Result<&PatchPoints<'a>, RuntimeError> {
        let (Some(cell), Some(patch)) = (self.points.get(f), self.patches.get(f)) else {
            return Err(RuntimeError::InvalidParameter {
                name: "face".to_owned(),
                reason: format!("{f} (the mesh has {} faces)", self.points.len()),
            });
        };
        cell.get_or_try(|| PatchPoints::of_face(self.table, self.mesh, patch, f, self.adaptive))
    }

    /// Whether face `f` is a hole: it has no surface, no samples and no deviation.
    fn hole(&self, f: usize) -> bool {
        self.mesh.holes[f]
    }
}

/// The grids of the faces of [`adaptive_face_list`], computed when first read.
pub(crate) fn adaptive_faces<'a>(
    table: &StencilTable,
    mesh: &'a Mesh,
    patches: &[FacePatch],
) -> Result<AdaptiveGrids<'a>, RuntimeError> {
    Ok(AdaptiveGrids::new(
        mesh,
        adaptive_face_list(table, mesh, patches)?,
    ))
}

/// [`adaptive_faces`] over faces already found ([`adaptive_face_list`]: the table and the
/// topology decide them, so a surface finds them once).
pub(crate) fn adaptive_grids<'a>(mesh: &'a Mesh, faces: &[usize]) -> AdaptiveGrids<'a> {
    AdaptiveGrids::new(mesh, faces.to_vec())
}

/// The faces around the corner at half-edge `h` whose corner points make its vertex polygon in
/// the tessellator (dual_grid.rs), as their half-edges at the vertex in fan order, and whether
/// the polygon closes on itself: the whole fan of a smooth vertex no cut reaches ([`Mesh::cut`]);
/// around a cone's tip ([`Mesh::is_cone_tip`]), the whole fan with its first face again, a wheel
/// around the limit point; otherwise the sector between the cuts before and after `h`'s face,
/// which the vertex's limit point closes.
fn sector(mesh: &Mesh, h: usize) -> (Vec<usize>, bool) {
    let v = mesh.face_vertices[h] as usize;
    let fan = mesh.fan(v);
    let n = fan.len();
    let cut = |i: usize| mesh.cut(fan[i], false) != Cut::None;
    let Some(me) = fan.iter().position(|&e| e == h) else {
        return (vec![h], false);
    };
    if !(0..n).any(cut) {
        if mesh.is_cone_tip(v) {
            // The wheel around the limit point.
            let mut wheel = fan;
            wheel.push(wheel[0]);
            return (wheel, false);
        }
        return (fan, true);
    }
    let start = (0..n)
        .map(|back| (me + n - back) % n)
        .find(|&i| cut(i))
        .unwrap_or(me);
    let len = (1..n).find(|&d| cut((start + d) % n)).unwrap_or(n);
    ((0..len).map(|d| fan[(start + d) % n]).collect(), false)
}

/// The face across side `side` of face `f` and that side's number in it, or `None` where the
/// side is cut (a boundary or an infinitely sharp edge: a limit curve lies beyond it in
/// `L_{f,n}`).
pub(super) fn across(mesh: &Mesh, f: usize, side: usize) -> Option<(usize, usize)> {
    let h = mesh.face_halfedges(f).start + side;
    if mesh.cut(h, false) != Cut::None {
        return None;
    }
    let t = *mesh.twin.get(h)? as usize;
    let g = *mesh.face_of.get(t)? as usize;
    Some((g, t.checked_sub(mesh.face_halfedges(g).start)?))
}

/// Dual-grid index (in the neighbour's own indices) of point `t` of the row beyond a side, in
/// the side's direction, the neighbour's side being its side `other`: the neighbour's row runs
/// the other way along the shared edge.
pub(super) fn beyond_index(other: usize, t: usize, n: usize) -> (usize, usize) {
    row_index(other, n - 1 - t, n)
}

/// A corner's regular chart at rate `n` ([`chart_corner_terms`]): whether the fan's diagonal runs
/// through the face, and the four faces' corner dual points (face, dual index in its own
/// indices): the face's own, beyond side `corner`, beyond side `corner - 1`, the face opposite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ChartCorner {
    pub(super) through_face: bool,
    pub(super) points: [(usize, (usize, usize)); 4],
}

/// Corner `corner` of face `f`'s chart at rate `n`, where the corner is an interior vertex of four
/// faces and the two sides at it have neighbours' rows beyond them; `None` elsewhere (an
/// extraordinary vertex, a boundary or a cut): there the fan has no planar chart.
pub(super) fn chart_corner(mesh: &Mesh, f: usize, corner: usize, n: usize) -> Option<ChartCorner> {
    let own = mesh.face_halfedges(f).start + corner;
    let (fan, closed) = sector(mesh, own);
    let me = fan.iter().position(|&h| h == own)?;
    if !closed || fan.len() != 4 {
        return None;
    }
    let (next, next_side) = across(mesh, f, corner)?;
    let (previous, previous_side) = across(mesh, f, (corner + 3) % 4)?;
    let h = fan[(me + 2) % 4];
    let g = mesh.face_of[h] as usize;
    Some(ChartCorner {
        through_face: me % 2 == 0,
        points: [
            (f, row_index(corner, 0, n)),
            (next, beyond_index(next_side, 0, n)),
            (previous, beyond_index(previous_side, n - 1, n)),
            (g, row_index(h - mesh.face_halfedges(g).start, 0, n)),
        ],
    })
}

fn combine(terms: &[(f64, [f64; 3])]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (w, p) in terms {
        for c in 0..3 {
            out[c] += w * p[c];
        }
    }
    out
}

fn check_faces(mesh: &Mesh, patches: &[FacePatch]) -> Result<(), RuntimeError> {
    if patches.len() != mesh.faces() {
        return Err(RuntimeError::Unsupported(format!(
            "{} patches for {} faces",
            patches.len(),
            mesh.faces()
        )));
    }
    Ok(())
}

/// `e_f(n)` of face `face` (module docs): the deviation, over the table's primal and dual
/// points at rate [`SELECTION_GRID`], of the limit surface from the tessellation of the face's
/// neighbourhood with every face at rate `n`.
pub fn face_deviation(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    face: usize,
    n: u32,
) -> Result<f64, RuntimeError> {
    let adaptive = adaptive_faces(table, mesh, patches)?;
    let ctx = Context::new(table, mesh, patches, &adaptive)?;
    let points = ctx.face(face)?;
    if ctx.hole(face) {
        return Ok(0.0);
    }
    let samples = Samples::new(points, SELECTION_GRID)?;
    FaceLocal::new(&ctx, face, n)?.deviation(&samples)
}

/// Per face the smallest rate `n` in `1..=24` with `e_f(n) <= tolerance` (module docs):
/// [`tolerance_rates_among`] with [`RATIONAL_RATES`].
pub fn tolerance_rates(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    tolerance: f64,
) -> Result<ToleranceRates, RuntimeError> {
    tolerance_rates_among(table, mesh, patches, tolerance, &RATIONAL_RATES)
}

/// Per face the smallest rate `n` of `candidates` with `e_f(n) <= tolerance` (module docs), or
/// the largest candidate (and the face listed in [`ToleranceRates::unmet`]) when none meets it.
/// `tolerance` is in the mesh's units; `candidates` must be non-empty, each in `1..=24`.
///
/// Cost: per face, the 1,201 samples once (a regular face's in closed form, the tensor-product
/// B-spline), then for each candidate tried the dual points its scan reads (four for a rate
/// refuted at its first sample, `n^2 + 4(n + 1)` table points for the rate kept), the rows and
/// triangles of the side rectangles and corner squares it reads (one region for a rate refuted
/// there at its first sample, all of them for the rate kept) and one interpolation per sample
/// read (in a corner square, mostly one bound on one triangle's distance: the search starts
/// at the last sample's nearest triangle, whose upper bound, when below the largest deviation
/// so far, ends it, and stops below that deviation); faces run in parallel.
/// Faces evaluated adaptively ([module docs](self)) cost a descent per grid, shared by the faces
/// around one vertex.
pub fn tolerance_rates_among(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    tolerance: f64,
    candidates: &[u32],
) -> Result<ToleranceRates, RuntimeError> {
    let adaptive = adaptive_faces(table, mesh, patches)?;
    with_selection(
        table,
        mesh,
        patches,
        &adaptive,
        tolerance,
        candidates,
        |choose| {
            let choices = (0..patches.len())
                .into_par_iter()
                .map(|f| choose(f, &[]))
                .collect::<Result<Vec<_>, _>>()?;
            Ok(ToleranceRates::from_choices(&choices))
        },
    )
}

/// Runs `body` with the selection of [`tolerance_rates_among`] for one face at a time
/// (`choose(f, hints)`, from the mesh's current positions; `hints`: the face's refutations when
/// it was last sampled, where each rate's scan starts, or none): what a full selection and a
/// partial one ([`super::rate_memory`]) share. The hints change where a refuted rate is found
/// refuted, never whether.
pub(crate) fn with_selection<R>(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    adaptive: &AdaptiveGrids,
    tolerance: f64,
    candidates: &[u32],
    body: impl FnOnce(
        &(dyn Fn(usize, &[Refutation]) -> Result<FaceChoice, RuntimeError> + Sync),
    ) -> Result<R, RuntimeError>,
) -> Result<R, RuntimeError> {
    check_tolerance(tolerance)?;
    let sorted = sorted_candidates(candidates, &RATIONAL_RATES)?;
    let ctx = Context::new(table, mesh, patches, adaptive)?;
    // A rate below the largest is only compared with the tolerance; the largest's deviation is
    // reported when no rate meets it, so it is measured in full.
    let largest = sorted.last().copied().unwrap_or(0);
    let pool = SparePool::new();
    let choose = |f: usize, hints: &[Refutation]| {
        let regular = ctx.regular(f);
        let spare = RefCell::new(pool.take());
        let (mut choice, samples) = choose_rate(
            f,
            tolerance,
            &sorted,
            |f| {
                if ctx.hole(f) {
                    return Ok(Samples::none());
                }
                Samples::new(ctx.face(f)?, SELECTION_GRID)
            },
            |f, samples, n| {
                if ctx.hole(f) {
                    return Ok(0.0);
                }
                let stop = if n == largest {
                    f64::INFINITY
                } else {
                    tolerance
                };
                let local = FaceLocal::new_in(&ctx, f, n, spare.take())?;
                // A rate refuted when the face was last sampled is mostly refuted at the same
                // sample again: scanned from there, it costs one sample.
                if let Some(hint) = hints.iter().find(|r| r.rate == n) {
                    if let Some([u, v]) = samples.uv(hint.sample) {
                        samples.start.set(hint.sample);
                        samples.outside_first.set(!local.is_interior(u, v));
                    }
                }
                let worst = scan(&local, samples, stop)?;
                if worst > stop {
                    // The scan stopped at the refuting sample.
                    samples.refutations.borrow_mut().push(Refutation {
                        rate: n,
                        sample: samples.start.get(),
                        deviation: worst,
                    });
                } else if worst <= tolerance && ctx.face(f)?.is_table() {
                    if let Some((charted, fans)) =
                        local.corner_chart_deviation(samples, tolerance)?
                    {
                        samples.chart.set(Some((worst.max(charted), fans)));
                    }
                }
                spare.replace(local.into_spare());
                Ok(worst)
            },
        )?;
        pool.give(spare.into_inner());
        choice.refutations = samples.refutations.take();
        if let (true, Some((deviation, fans))) = (choice.met, samples.chart.get()) {
            choice.chart = Some(ChartBound {
                deviation,
                fans,
                norm: if regular {
                    Some(chart_norm(choice.rate)?)
                } else {
                    None
                },
            });
        }
        Ok(choice)
    };
    body(&choose)
}

/// `e_f(n)` of `local`'s face over `samples`, or a sample's deviation beyond `stop`
/// ([`FaceLocal::deviation_up_to`]). Most samples are interior, where the face's own dual
/// points are all of `L_{f,n}`: a failing rate is refuted there before its neighbours' rows and
/// its corners' polygons are evaluated, unless the last rate failed only outside.
fn scan(local: &FaceLocal, samples: &Samples, stop: f64) -> Result<f64, RuntimeError> {
    let mut worst = 0.0f64;
    if !samples.outside_first.get() {
        worst = local.deviation_up_to(samples, stop, |interior| interior)?;
        if worst > stop {
            return Ok(worst);
        }
    }
    worst = worst.max(local.deviation_up_to(samples, stop, |interior| !interior)?);
    if worst > stop {
        samples.outside_first.set(true);
        return Ok(worst);
    }
    if samples.outside_first.get() {
        samples.outside_first.set(false);
        worst = worst.max(local.deviation_up_to(samples, stop, |interior| interior)?);
    }
    Ok(worst)
}

/// The deviation of each `(face, rate, sample)` of `checks` at the mesh's current positions:
/// what [`FaceLocal::deviation_at`] measures there in full (a later frame's look at the samples
/// that refuted its rates, [`super::rate_memory`]).
pub(crate) fn sample_deviations(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    adaptive: &AdaptiveGrids,
    checks: &[(usize, u32, usize)],
) -> Result<Vec<f64>, RuntimeError> {
    let ctx = Context::new(table, mesh, patches, adaptive)?;
    checks
        .par_iter()
        .map_init(Spare::default, |spare, &(f, n, sample)| {
            let ([u, v], p) = sample_at(ctx.face(f)?, SELECTION_GRID, sample)?;
            let local = FaceLocal::new_in(&ctx, f, n, std::mem::take(spare))?;
            let deviation = local.deviation_at(u, v, p, 0.0);
            *spare = local.into_spare();
            deviation
        })
        .collect()
}

/// The faces the selection samples by feature-adaptive refinement, ascending ([module
/// docs](self)): the surface faces the table does not describe exactly, those the tessellator
/// evaluates by feature-adaptive refinement ([`table_may_describe`]: sharp and semi-sharp
/// features at a corner) and those whose patch the table lacks (a valence beyond it).
pub(crate) fn adaptive_face_list(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
) -> Result<Vec<usize>, RuntimeError> {
    check_faces(mesh, patches)?;
    let faces: Vec<Option<usize>> = patches
        .par_iter()
        .enumerate()
        .map(|(f, patch)| {
            let key = patch
                .kind
                .section(StencilKind::Position, PointSet::Dual, SELECTION_GRID);
            let described = table_may_describe(mesh, patch, f);
            let from_table = described && unless_absent(table.weights(&key))?.is_some();
            Ok((!mesh.holes[f] && !from_table).then_some(f))
        })
        .collect::<Result<_, RuntimeError>>()?;
    Ok(faces.into_iter().flatten().collect())
}

/// A tolerance is a positive, finite distance.
pub(crate) fn check_tolerance(tolerance: f64) -> Result<(), RuntimeError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(RuntimeError::InvalidParameter {
            name: "tolerance".to_owned(),
            reason: format!("{tolerance} (it must be a positive distance)"),
        })
    }
}

/// `candidates` sorted and deduplicated: at least one, each one of `allowed` (sorted).
pub(crate) fn sorted_candidates(
    candidates: &[u32],
    allowed: &[u32],
) -> Result<Vec<u32>, RuntimeError> {
    let mut sorted = candidates.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    if sorted.is_empty() || sorted.iter().any(|n| allowed.binary_search(n).is_err()) {
        let (first, last) = (allowed.first(), allowed.last());
        let contiguous =
            matches!((first, last), (Some(&a), Some(&b)) if (b - a) as usize + 1 == allowed.len());
        let range = match (first, last) {
            (Some(a), Some(b)) if contiguous => format!("{a}..={b}"),
            _ => format!("{allowed:?}"),
        };
        return Err(RuntimeError::InvalidParameter {
            name: "candidate rates".to_owned(),
            reason: format!("{candidates:?} (they must be {range}, at least one)"),
        });
    }
    Ok(sorted)
}

/// One face's rate from the selection ([`choose_rate`]).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FaceChoice {
    /// The smallest candidate meeting the tolerance, or the largest.
    pub(crate) rate: u32,
    /// `e_f(rate)`.
    pub(crate) deviation: f64,
    /// Whether `rate` meets the tolerance.
    pub(crate) met: bool,
    /// The least of the values that refuted the smaller candidates: each is one sample's
    /// deviation at that rate, beyond the tolerance (infinity when no smaller candidate was
    /// tried). What lets a later frame keep `rate` ([`super::rate_memory`]).
    pub(crate) refuted: f64,
    /// Each smaller candidate's refutation, in order, where the selection recorded them (the
    /// quad one does): what lets a later frame look at those samples alone.
    pub(crate) refutations: Vec<Refutation>,
    /// Where the face is a table face and `rate` met the tolerance, the chart's bound of
    /// `e_f(rate)` ([`ChartBound`]).
    pub(crate) chart: Option<ChartBound>,
}

/// A candidate rate the selection refuted, at the sample (its index in the face's samples, the
/// primal grid at [`SELECTION_GRID`] then the dual one) that deviated by `deviation`, beyond the
/// tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Refutation {
    pub(crate) rate: u32,
    pub(crate) sample: usize,
    pub(crate) deviation: f64,
}

/// A bound of a table face's deviation at its rate that motion moves little: the largest
/// distance from a sample to the point of `L_{f,n}` at the sample's own parameters
/// (`deviation`, at least those samples' deviations: the points lie on `L_{f,n}`; in a corner
/// square the fan's point in the corner's regular chart, [`chart_corner_terms`]) over the
/// samples outside the corner squares of corners without a chart ([`chart_corner`]:
/// extraordinary vertices, boundaries), the largest deviation in those (`fans`, `None` where
/// every corner has a chart), and the norm of the stencils of the differences: [`chart_norm`] where
/// the face's neighbourhood is regular (the same for every such face), `None` where it is the
/// face's own ([`super::difference_norm`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ChartBound {
    pub(crate) deviation: f64,
    pub(crate) fans: Option<f64>,
    pub(crate) norm: Option<f64>,
}

impl ToleranceRates {
    /// The rates of `choices`, face by face.
    pub(crate) fn from_choices(choices: &[FaceChoice]) -> Self {
        ToleranceRates {
            rates: choices.iter().map(|c| c.rate).collect(),
            deviations: choices.iter().map(|c| c.deviation).collect(),
            unmet: choices
                .iter()
                .enumerate()
                .filter(|(_, c)| !c.met)
                .map(|(f, _)| f)
                .collect(),
        }
    }
}

/// The largest `|c|_1` at rate `n` over the samples, `c` the stencil of `S(u, v) - x(u, v)` on a
/// regular grid of control points, where `S` is the bicubic B-spline and `x` the point of
/// `L_{f,n}` at the sample's parameters (what [`linear_terms`] combines, or in a corner square
/// the fan's point under either diagonal, [`chart_corner_terms`]), plus `2^-20` for the table's
/// `f32` rounding of the dual points' stencils (at most `2^-24` each, weights of norm one).
///
/// Why it is small: `c` annihilates every control net that is an affine function of the grid
/// (the spline reproduces it, and so does linear interpolation between its points), so
/// `|c|_1` is second order in the spacing `1/n`: 0.50 at rate 1, 0.18 at 2, 0.047 at 4, where
/// `|w|_1 + |l|_1` of the two ends is 2. If every control point lies within `delta` of its image
/// under an affine map, the distance moves by at most `|c|_1 delta` from the map's image of it
/// ([`super::rate_memory`]).
pub(crate) fn chart_norm(n: u32) -> Result<f64, RuntimeError> {
    static NORMS: [OnceLock<f64>; MAX_SELECTED_RATE as usize] =
        [const { OnceLock::new() }; MAX_SELECTED_RATE as usize];
    let slot = (n as usize)
        .checked_sub(1)
        .and_then(|k| NORMS.get(k))
        .ok_or_else(|| RuntimeError::InvalidParameter {
            name: "rate".to_owned(),
            reason: format!("{n} (the selection measures rates 1..={MAX_SELECTED_RATE})"),
        })?;
    Ok(*slot.get_or_init(|| measured_chart_norm(n as usize) + 2f64.powi(-20)))
}

/// The B-spline surface of the regular grid at `(x, y)` (the face `[0, 1]^2`, `x, y` in
/// `[-1/2, 3/2]`) as weights on the control points `-2..=3` along each axis (`x` inner).
fn chart_stencil(x: f64, y: f64) -> [f64; 36] {
    let cell = |t: f64| (t.floor() as i64).clamp(-1, 1);
    let (kx, ky) = (cell(x), cell(y));
    let (wx, wy) = (bspline(x - kx as f64).0, bspline(y - ky as f64).0);
    let mut w = [0.0; 36];
    for (b, &y_weight) in wy.iter().enumerate() {
        for (a, &x_weight) in wx.iter().enumerate() {
            let (i, j) = ((kx + 1) as usize + a, (ky + 1) as usize + b);
            w[j * 6 + i] = x_weight * y_weight;
        }
    }
    w
}

/// [`chart_norm`] without the rounding allowance.
fn measured_chart_norm(n: usize) -> f64 {
    let h = 0.5 / n as f64;
    let dual = |t: usize| (2 * t + 1) as f64 * h;
    // Where a vertex of `L_{f,n}` lies in the face's chart.
    let place = |vertex: Vertex| match vertex {
        Vertex::Dual(i, j) => (dual(i), dual(j)),
        Vertex::Beyond(side, t) => {
            let (along, across) = (dual(t), -h);
            match side {
                0 => (along, across),
                1 => (1.0 - across, along),
                2 => (1.0 - along, 1.0 - across),
                _ => (across, 1.0 - along),
            }
        }
    };
    let norm = |sample: [f64; 36], terms: &[(f64, (f64, f64))]| {
        let mut c = sample;
        for &(weight, (x, y)) in terms {
            for (c, w) in c.iter_mut().zip(chart_stencil(x, y)) {
                *c -= weight * w;
            }
        }
        c.iter().map(|x| x.abs()).sum::<f64>()
    };
    let [primal, dual_axis] = selection_axes(SELECTION_GRID);
    let mut largest = 0.0f64;
    for axis in [primal, dual_axis] {
        for &v in &axis {
            for &u in &axis {
                let sample = chart_stencil(u, v);
                if let Some((corner, a, b)) = corner_square(u, v, n) {
                    // The corner's chart back to the face's: `(a, b)` from the vertex.
                    let to_face = |(a, b): (f64, f64)| match corner {
                        0 => (a, b),
                        1 => (1.0 - b, a),
                        2 => (1.0 - a, 1.0 - b),
                        _ => (b, 1.0 - a),
                    };
                    let points = [(h, h), (h, -h), (-h, h), (-h, -h)].map(to_face);
                    for through_face in [true, false] {
                        let terms = chart_corner_terms(a, b, h, through_face)
                            .map(|(w, k)| (w, points[k as usize]));
                        largest = largest.max(norm(sample, &terms));
                    }
                    continue;
                }
                // Never an error here (no side is a curve); were it one, no bound.
                let places = (AxisPlace::new(u, n), AxisPlace::new(v, n));
                largest = match linear_terms(&places.0, &places.1, n, |_| Ok(false)) {
                    Ok(terms) => largest.max(norm(sample, &terms.map(|(w, x)| (w, place(x))))),
                    Err(_) => f64::INFINITY,
                };
            }
        }
    }
    largest
}

/// The selection of face `f` shared by the quad and triangle tolerance rates: the smallest `n`
/// of `sorted` (ascending, non-empty) with `deviation(f, &prepare(f), n) <= tolerance`, trying
/// them in order, or the largest (not met). `prepare` is what every rate reuses (the face's
/// samples); `deviation` may stop at the first sample beyond the tolerance for a rate below the
/// largest, and returns that sample's deviation then. The choice, with what `prepare` made.
pub(crate) fn choose_rate<S>(
    f: usize,
    tolerance: f64,
    sorted: &[u32],
    prepare: impl Fn(usize) -> Result<S, RuntimeError>,
    deviation: impl Fn(usize, &S, u32) -> Result<f64, RuntimeError>,
) -> Result<(FaceChoice, S), RuntimeError> {
    let largest = *sorted
        .last()
        .ok_or_else(|| RuntimeError::InvalidParameter {
            name: "candidate rates".to_owned(),
            reason: "none given".to_owned(),
        })?;
    let prepared = prepare(f)?;
    let mut refuted = f64::INFINITY;
    let mut last = 0.0;
    let choice = |rate, deviation, met, refuted| FaceChoice {
        rate,
        deviation,
        met,
        refuted,
        refutations: Vec::new(),
        chart: None,
    };
    for &n in sorted {
        last = deviation(f, &prepared, n)?;
        if last <= tolerance {
            return Ok((choice(n, last, true, refuted), prepared));
        }
        refuted = refuted.min(last);
    }
    Ok((choice(largest, last, false, refuted), prepared))
}

/// The measured deviation of a finished tessellation: the largest Euclidean distance from the
/// limit surface, sampled at the table's primal and dual points at rate `grid` of every face
/// (`(grid+1)^2 + grid^2` a face), to the nearest triangle of `tessellation` (the one-sided
/// Hausdorff distance from the surface to the mesh, at those samples).
///
/// This is the error a viewer sees, measured independently of how the rates were chosen (no
/// parametric correspondence, the whole output, edge strips and vertex polygons included); it
/// is at most the parametric deviation at the same samples. The nearest triangle is found with
/// a uniform grid of cells about twice the mean triangle size, searched in growing shells.
pub fn measure_deviation(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    tessellation: &TriangleMesh,
    grid: u32,
) -> Result<f64, RuntimeError> {
    check_faces(mesh, patches)?;
    if tessellation.triangles.is_empty() {
        return Err(RuntimeError::InvalidParameter {
            name: "tessellation".to_owned(),
            reason: "it has no triangles".to_owned(),
        });
    }
    let cells = TriangleGrid::from_mesh(tessellation);
    let adaptive = adaptive_faces(table, mesh, patches)?;
    let ctx = Context::new(table, mesh, patches, &adaptive)?;
    let per_face = (0..patches.len())
        .into_par_iter()
        .filter(|&f| !ctx.hole(f))
        .map(|f| -> Result<f64, RuntimeError> {
            let samples = Samples::new(ctx.face(f)?, grid)?;
            Ok(samples
                .positions
                .iter()
                .map(|&p| cells.nearest_distance(p))
                .fold(0.0, f64::max))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_face.into_iter().fold(0.0, f64::max))
}

pub use crate::mesh::geometry::point_triangle_distance;
use crate::mesh::geometry::{cross, distance, dot, sub};

/// A pinhole camera for view-dependent rates (Schaefer–Warren section 5.5: "projecting each quad
/// from the base subdivision surface onto the screen, computing its maximal edge length and
/// dividing by the maximal number of pixels we would like edges on the adaptively tessellated
/// surface to be").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewCamera {
    /// The eye.
    pub position: [f64; 3],
    /// The point looked at (the view direction is `target - position`).
    pub target: [f64; 3],
    /// The full vertical field of view, degrees, in `(0, 180)`.
    pub vertical_fov_degrees: f64,
    /// The image height in pixels.
    pub image_height_px: f64,
    /// The longest edge wanted in the output, in pixels.
    pub target_edge_px: f64,
}

impl ViewCamera {
    fn check(&self) -> Result<(), RuntimeError> {
        let bad = |reason: String| {
            Err(RuntimeError::InvalidParameter {
                name: "camera".to_owned(),
                reason,
            })
        };
        let axis = sub(self.target, self.position);
        if self
            .position
            .iter()
            .chain(&self.target)
            .any(|c| !c.is_finite())
            || dot(axis, axis) == 0.0
        {
            return bad(format!(
                "position {:?} and target {:?} must be finite and distinct",
                self.position, self.target
            ));
        }
        if !(self.vertical_fov_degrees > 0.0 && self.vertical_fov_degrees < 180.0) {
            return bad(format!(
                "vertical field of view {} degrees (it must be in (0, 180))",
                self.vertical_fov_degrees
            ));
        }
        if !(self.image_height_px.is_finite() && self.image_height_px > 0.0) {
            return bad(format!("image height {} px", self.image_height_px));
        }
        if !(self.target_edge_px.is_finite() && self.target_edge_px > 0.0) {
            return bad(format!("target edge length {} px", self.target_edge_px));
        }
        Ok(())
    }

    /// The focal length in pixels, `F = (H / 2) / tan(fov / 2)`.
    pub fn focal_px(&self) -> f64 {
        0.5 * self.image_height_px / (0.5 * self.vertical_fov_degrees.to_radians()).tan()
    }

    /// The view frame: unit forward `w`, and two unit vectors `r`, `s` across it (any pair: the
    /// projected lengths do not depend on the roll).
    fn frame(&self) -> [[f64; 3]; 3] {
        let w = sub(self.target, self.position);
        let w = w.map(|x| x / dot(w, w).sqrt());
        let helper = if w[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let r = cross(w, helper);
        let r = r.map(|x| x / dot(r, r).sqrt());
        [w, r, cross(w, r)]
    }

    /// The depth `w . (p - eye)` and the image position in pixels from the image centre,
    /// `F (r . (p - eye), s . (p - eye)) / depth` (defined for depth > 0).
    fn project(&self, frame: &[[f64; 3]; 3], p: [f64; 3]) -> (f64, [f64; 2]) {
        let d = sub(p, self.position);
        let depth = dot(frame[0], d);
        let f = self.focal_px() / depth;
        (depth, [f * dot(frame[1], d), f * dot(frame[2], d)])
    }
}

/// The view-dependent rate of every face (Schaefer–Warren section 5.5): the face's control
/// polygon is projected through `camera` and
///
/// ```text
/// rate_f = clamp(ceil(L_f / E), 1, 24),   L_f = max over the face's edges of |x(a) - x(b)|,
/// x(p) = F (r . (p - eye), s . (p - eye)) / (w . (p - eye)),   F = (H / 2) / tan(fov / 2),
/// ```
///
/// with `w` the unit view direction, `r`, `s` unit vectors across it, `H` the image height and
/// `E` the target edge length in pixels. A face wholly behind the camera (every corner at depth
/// `<= 0`) gets rate 1; a face crossing the camera's plane (some corners in front, some not)
/// projects to an unbounded polygon and gets 24. Faces outside the image are not culled.
pub fn view_rates(mesh: &Mesh, camera: &ViewCamera) -> Result<Vec<u32>, RuntimeError> {
    camera.check()?;
    let frame = camera.frame();
    Ok((0..mesh.faces())
        .map(|f| {
            let corners = mesh.face(f);
            let projected: Vec<(f64, [f64; 2])> = corners
                .iter()
                .map(|&v| camera.project(&frame, mesh.positions[v as usize]))
                .collect();
            let in_front = projected.iter().filter(|(depth, _)| *depth > 0.0).count();
            if in_front == 0 {
                return 1;
            }
            if in_front < projected.len() {
                return MAX_SELECTED_RATE;
            }
            let longest = (0..projected.len())
                .map(|k| {
                    let (a, b) = (projected[k].1, projected[(k + 1) % projected.len()].1);
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
                })
                .fold(0.0, f64::max);
            let rate = (longest / camera.target_edge_px).ceil();
            if rate >= f64::from(MAX_SELECTED_RATE) {
                MAX_SELECTED_RATE
            } else {
                (rate as u32).max(1)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample looked at again ([`sample_at`]) is the selection's sample to the bit: on a
    /// regular torus (closed form) and around extraordinary vertices (table stencils).
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn a_sample_alone_is_the_selections_sample() {
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let torus = crate::mesh::test_meshes::quad_torus(6, 5);
        let torus_patches = crate::scheme::patch::gather_patches(&torus).expect("patches");
        let (octahedron, octahedron_patches, _) =
            crate::scheme::catmull_clark::isolate::isolate(&crate::mesh::test_meshes::octahedron())
                .expect("isolates");
        for (mesh, patches) in [(&torus, &torus_patches), (&octahedron, &octahedron_patches)] {
            for patch in patches.iter().step_by(7) {
                let points = PatchPoints::new(&table, mesh, patch).expect("table patch");
                let samples = Samples::new(&points, SELECTION_GRID).expect("samples");
                for (k, p) in samples.positions.iter().enumerate() {
                    let alone = sample_at(&points, SELECTION_GRID, k).expect("a sample");
                    let uv = samples.uv(k).expect("parameters");
                    assert_eq!(alone, (uv, *p), "sample {k}");
                }
                // The parameters in the order the samples were evaluated in.
                let order = selection_axes(SELECTION_GRID).into_iter().flat_map(|axis| {
                    let rows = axis.clone();
                    rows.into_iter()
                        .flat_map(move |v| axis.clone().into_iter().map(move |u| [u, v]))
                });
                for (k, uv) in order.enumerate() {
                    assert_eq!(samples.uv(k), Some(uv), "sample {k}");
                }
                let count = samples.positions.len();
                assert!(sample_at(&points, SELECTION_GRID, count).is_err());
                assert!(samples.uv(count).is_none());
            }
        }
    }

    /// [`super::super::difference_norm`] against the scans' own evaluation: `S_f(s) - x_s` is
    /// linear in the control points, so with unit control points (three at a time, one per
    /// coordinate, the others at the origin) the position path gives the difference stencil's
    /// weights one by one; its largest norm over the samples outside the uncharted corners is
    /// the stencils' (up to the closed-form regular samples' `f32` rounding). On an isolated
    /// octahedron (valence-3 vertices), an isolated open box (boundary curves) and a cube whose
    /// lid is split in two triangles (faces of many shapes).
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn difference_norms_are_the_position_paths() {
        use crate::scheme::catmull_clark::isolate::isolate;
        use crate::tessellate::difference_norm::{difference_norm, Norms};
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let cube = crate::mesh::test_meshes::cube();
        let lid = [4, 5, 6, 7];
        let box_faces: Vec<Vec<i64>> = (0..cube.faces())
            .map(|f| cube.face(f).iter().map(|&v| i64::from(v)).collect())
            .filter(|corners: &Vec<i64>| corners.as_slice() != lid)
            .collect();
        let on_cube = |faces: &[Vec<i64>]| {
            Mesh::new(
                cube.positions.clone(),
                faces,
                &[],
                schemes::BoundaryMode::EdgeOnly,
            )
            .expect("a mesh on the cube's vertices")
        };
        let open = on_cube(&box_faces);
        // The cube with its lid split into two triangles: valences 3 and 4 next to each other,
        // no symmetry that turns every face into every other.
        let split_faces: Vec<Vec<i64>> = box_faces
            .iter()
            .cloned()
            .chain([vec![4, 5, 6], vec![4, 6, 7]])
            .collect();
        let split = on_cube(&split_faces);
        let (mut with_curves, mut with_fans) = (0, 0);
        for input in [crate::mesh::test_meshes::octahedron(), open, split] {
            let (mesh, patches, _) = isolate(&input).expect("isolates");
            let adaptive = adaptive_face_list(&table, &mesh, &patches).expect("adaptive faces");
            // Shared by every face: most take the norm of an alike face measured before, and
            // must match their own position path all the same.
            let (norms, mut made) = (Norms::default(), 0);
            for f in 0..patches.len() {
                for n in 1..=3 {
                    let Some(norm) =
                        difference_norm(&table, &mesh, &patches, &adaptive, f, n, &norms)
                            .expect("norm")
                    else {
                        continue;
                    };
                    // Every point of the faces sharing a vertex with `f`: more than it reads.
                    let mut points: Vec<u32> = mesh
                        .face(f)
                        .iter()
                        .flat_map(|&v| mesh.fan_iter(v as usize).map(|h| mesh.face_of[h]))
                        .flat_map(|g| patches[g as usize].points.iter().copied())
                        .collect();
                    points.sort_unstable();
                    points.dedup();
                    let mut sums: Vec<f64> = Vec::new();
                    for three in points.chunks(3) {
                        let mut unit = mesh.clone();
                        unit.positions.fill([0.0; 3]);
                        for (c, &p) in three.iter().enumerate() {
                            unit.positions[p as usize][c] = 1.0;
                        }
                        let grids = adaptive_grids(&unit, &adaptive);
                        let ctx = Context::new(&table, &unit, &patches, &grids).expect("context");
                        let samples = Samples::new(ctx.face(f).expect("points"), SELECTION_GRID)
                            .expect("samples");
                        let local = FaceLocal::new(&ctx, f, n).expect("local tessellation");
                        let charts = local.corner_charts().expect("charts");
                        sums.resize(samples.positions.len(), 0.0);
                        for (k, &p) in samples.positions.iter().enumerate() {
                            let [u, v] = samples.uv(k).expect("parameters");
                            let x = match corner_square(u, v, n as usize) {
                                Some(_) => local.chart_point(&charts, u, v),
                                None => {
                                    let m = n as usize;
                                    let at = local.at(&AxisPlace::new(u, m), &AxisPlace::new(v, m));
                                    Some(at.expect("a point of L"))
                                }
                            };
                            if let Some(x) = x {
                                sums[k] += sub(p, x).iter().map(|c| c.abs()).sum::<f64>();
                            }
                        }
                    }
                    let expected = sums.iter().fold(0.0f64, |m, &x| m.max(x));
                    let measured = norm - 2f64.powi(-20);
                    assert!(
                        (measured - expected).abs() <= 1e-6,
                        "face {f}, rate {n}: {measured} against {expected}"
                    );
                    assert!(expected > 0.0, "face {f}, rate {n}: no difference");
                    made += 1;
                    with_curves += usize::from((0..4).any(|side| across(&mesh, f, side).is_none()));
                    with_fans += usize::from(
                        (0..4).any(|c| chart_corner(&mesh, f, c, n as usize).is_none()),
                    );
                }
            }
            assert!(
                norms.shapes() < made,
                "{} shapes for {made} norms",
                norms.shapes()
            );
        }
        assert!(
            with_curves > 0 && with_fans > 0,
            "{with_curves} with curves, {with_fans} with fans"
        );
    }

    /// A face the mesh does not have is an error, not a panic.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn a_face_beyond_the_mesh_is_refused() {
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let mesh = crate::mesh::test_meshes::quad_torus(6, 5);
        let patches = crate::scheme::patch::gather_patches(&mesh).expect("patches");
        assert!(face_deviation(&table, &mesh, &patches, 29, 3).is_ok());
        let error = face_deviation(&table, &mesh, &patches, 30, 3).expect_err("face 30 of 30");
        assert!(
            error.to_string().contains("30 (the mesh has 30 faces)"),
            "{error}"
        );
    }

    /// [`chart_norm`] against the same norms computed independently (numpy, from the cubic
    /// B-spline basis and the tessellation's triangles written out again).
    #[test]
    fn chart_norms_are_the_splines_interpolation_errors() {
        let expected = [
            (1, 0.5008680555555557),
            (2, 0.1802300347222222),
            (3, 0.08061247332723678),
            (4, 0.04709455702039919),
            (8, 0.011940492524041061),
            (24, 0.0013352088168015067),
        ];
        for (n, norm) in expected {
            let measured = chart_norm(n).expect("a rate of the table") - 2f64.powi(-20);
            assert!(
                (measured - norm).abs() < 1e-12,
                "rate {n}: {measured} against {norm}"
            );
        }
        assert!(chart_norm(0).is_err() && chart_norm(25).is_err());
    }

    /// The distance from `p` to the nearest of `local`'s triangles around `corner`, found by
    /// trying them all.
    #[allow(dead_code)] // without the Catmull–Clark feature
    fn nearest_corner_triangle(local: &FaceLocal, corner: usize, p: [f64; 3]) -> f64 {
        local
            .corner(corner)
            .expect("corner triangles")
            .iter()
            .map(|t| point_triangle_distance(p, &t.triangle))
            .fold(f64::INFINITY, f64::min)
    }

    /// The corner squares' chart points ([`FaceLocal::chart_point`]) are points of `L_{f,n}`:
    /// on one of the corner's triangles, and so no nearer to a sample than its nearest one; on
    /// regular tori and at the valence-4 vertices of an isolated octahedron and cube (next to
    /// valence-3 ones). Where a torus's control points are an affine image of the grid they are
    /// the limit surface itself (every vertex of the fan in its place: a wrong one moves the
    /// point off the plane of the grid).
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn chart_points_lie_on_the_local_tessellation() {
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let m = 10;
        let mut bent = crate::mesh::test_meshes::quad_torus(m, m);
        for (k, p) in bent.positions.iter_mut().enumerate() {
            p[2] += 0.3 * ((k * 7919 % 13) as f64 / 13.0 - 0.5);
        }
        let mut flat = bent.clone();
        for (k, p) in flat.positions.iter_mut().enumerate() {
            let (i, j) = ((k % m) as f64, (k / m) as f64);
            *p = [i + 0.3 * j, 0.5 * j - 0.2 * i, 0.2 * i - 0.1 * j];
        }
        // Per mesh: its patches, and for a torus whether it is the affine image of the grid.
        let torus = |mesh: Mesh, affine: bool| {
            let patches = crate::scheme::patch::gather_patches(&mesh).expect("patches");
            (mesh, patches, Some(affine))
        };
        let isolated = |input: Mesh| {
            let (mesh, patches, _) =
                crate::scheme::catmull_clark::isolate::isolate(&input).expect("isolates");
            (mesh, patches, None)
        };
        let meshes = [
            torus(bent, false),
            torus(flat, true),
            isolated(crate::mesh::test_meshes::octahedron()),
            isolated(crate::mesh::test_meshes::cube()),
        ];
        for (mesh, patches, torus) in &meshes {
            let affine = *torus == Some(true);
            let adaptive = adaptive_faces(&table, mesh, patches).expect("adaptive faces");
            let ctx = Context::new(&table, mesh, patches, &adaptive).expect("context");
            let mut checked = 0;
            for f in 0..patches.len() {
                assert!(
                    torus.is_none() || ctx.regular(f),
                    "face {f} of a regular torus"
                );
                // Faces whose neighbourhood does not reach across the seam of `flat`.
                let corner = mesh.face(f)[0] as usize;
                let (i, j) = (corner % m, corner / m);
                if affine && !((2..m - 3).contains(&i) && (2..m - 3).contains(&j)) {
                    continue;
                }
                let samples =
                    Samples::new(ctx.face(f).expect("points"), SELECTION_GRID).expect("samples");
                for n in 1..=5 {
                    let local = FaceLocal::new(&ctx, f, n).expect("local tessellation");
                    let charts = local.corner_charts().expect("charts");
                    assert!(
                        torus.is_none() || charts.iter().all(Option::is_some),
                        "face {f}: a corner without a chart"
                    );
                    for (k, &p) in samples.positions.iter().enumerate() {
                        let [u, v] = samples.uv(k).expect("parameters");
                        let Some(x) = local.chart_point(&charts, u, v) else {
                            continue;
                        };
                        let (corner, _, _) = corner_square(u, v, n as usize).expect("a corner");
                        let on = nearest_corner_triangle(&local, corner, x);
                        assert!(on < 1e-12, "face {f}, rate {n}, ({u}, {v}): {on} off L");
                        let nearest = local.deviation_at(u, v, p, 0.0).expect("deviation");
                        let chart = distance(p, x);
                        assert!(
                            chart >= nearest - 1e-12,
                            "face {f}, rate {n}, ({u}, {v}): chart {chart} below {nearest}"
                        );
                        assert!(!affine || chart < 1e-5, "face {f}, rate {n}: {chart}");
                        checked += 1;
                    }
                }
            }
            assert!(checked > 1000, "{checked} corner samples");
        }
    }

    fn message(text: &str, faces: usize) -> String {
        match parse_rates(text, faces) {
            Ok(rates) => panic!("{text:?} parsed as {rates:?}"),
            Err(e) => e.to_string(),
        }
    }

    /// On a torus of regular quads, the samples of every face in closed form
    /// ([`tensor_product`]) are the table's stencils applied to the same control points, to the
    /// table's `f32` rounding.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn regular_samples_in_closed_form_are_the_tables() {
        let mesh = crate::mesh::test_meshes::quad_torus(6, 5);
        let patches = crate::scheme::patch::gather_patches(&mesh).expect("patches");
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let mut closed_form = 0;
        for patch in &patches {
            let points = PatchPoints::new(&table, &mesh, patch).expect("table patch");
            closed_form += usize::from(points.bspline_net().is_some());
            let samples = Samples::new(&points, SELECTION_GRID).expect("samples");
            let mut stencils = points
                .all(PointSet::Primal, SELECTION_GRID)
                .expect("primal");
            stencils.extend(points.all(PointSet::Dual, SELECTION_GRID).expect("dual"));
            assert_eq!(samples.positions.len(), 1201);
            assert_eq!(stencils.len(), 1201);
            for (a, b) in samples.positions.iter().zip(&stencils) {
                assert!(distance(*a, *b) < 2e-6, "{a:?} != {b:?}");
            }
        }
        // Most patches start at the face's first corner; those take the closed form.
        assert!(closed_form > 0, "no face took the closed form");
    }

    /// The scan's shortcuts (squares before roots, a corner's search from the last nearest
    /// triangle, stopped once below the largest deviation so far) change no deviation: on the
    /// Catmull–Clark octahedron (valence-3 and valence-4 corners) and a torus of regular quads
    /// (whose largest deviations lie in the interior), every corner sample's deviation is the
    /// nearest of all its triangles by a plain search, below a floor it stays below it, and a
    /// face's `e_f(n)` is the largest of the samples' deviations one by one.
    #[test]
    #[cfg(feature = "catmull-clark")]
    fn scans_are_the_largest_plain_sample_deviation() {
        use crate::mesh::test_meshes::{octahedron, quad_torus};
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        let (octahedron, octahedron_patches, _) =
            crate::scheme::catmull_clark::isolate::isolate(&octahedron()).expect("isolates");
        let torus = quad_torus(6, 5);
        let torus_patches = crate::scheme::patch::gather_patches(&torus).expect("patches");
        let mut corner_samples = 0;
        for (mesh, patches) in [(&octahedron, &octahedron_patches), (&torus, &torus_patches)] {
            let adaptive = adaptive_faces(&table, mesh, patches).expect("adaptive faces");
            let ctx = Context::new(&table, mesh, patches, &adaptive).expect("context");
            for f in [0, 5, 17] {
                let samples =
                    Samples::new(ctx.face(f).expect("points"), SELECTION_GRID).expect("samples");
                for n in [1, 2, 3, 7, 16] {
                    let local = FaceLocal::new(&ctx, f, n).expect("local");
                    let mut largest = 0.0f64;
                    for (k, &p) in samples.positions.iter().enumerate() {
                        let [u, v] = samples.uv(k).expect("parameters");
                        let deviation = local.deviation_at(u, v, p, 0.0).expect("deviation");
                        largest = largest.max(deviation);
                        let h = 0.5 / f64::from(n);
                        let near = |t: f64| t <= h || t >= 1.0 - h;
                        if !(near(u) && near(v)) {
                            continue;
                        }
                        corner_samples += 1;
                        let corner = match (u <= h, v <= h) {
                            (true, true) => 0,
                            (false, true) => 1,
                            (false, false) => 2,
                            (true, false) => 3,
                        };
                        let plain = nearest_corner_triangle(&local, corner, p);
                        assert_eq!(deviation, plain, "face {f} n = {n} at ({u}, {v})");
                        for floor in [0.5 * plain, plain, 2.0 * plain] {
                            let d = local.deviation_at(u, v, p, floor).expect("deviation");
                            if plain <= floor {
                                assert!(d <= floor, "face {f} n = {n}: {d} above {floor}");
                            } else {
                                assert_eq!(d, plain, "face {f} n = {n} floor {floor}");
                            }
                        }
                    }
                    let scanned = FaceLocal::new(&ctx, f, n)
                        .expect("local")
                        .deviation(&samples)
                        .expect("scan");
                    assert_eq!(scanned, largest, "face {f} n = {n}");
                }
            }
        }
        assert!(corner_samples > 1000, "{corner_samples} corner samples");
    }

    proptest::proptest! {
        /// A corner triangle's upper bound is at least the exact search's distance, to the
        /// bit, and no more than the margin above it where the point lies over the triangle
        /// (its projection inside): triangles and points of any scale and place, thin ones too.
        #[test]
        fn corner_upper_bounds_hold(
            corners in proptest::array::uniform9(-1.0f64..1.0),
            point in proptest::array::uniform3(-2.0f64..2.0),
            scale in -8i32..8,
            offset in -1e3f64..1e3,
            thin in proptest::bool::ANY,
        ) {
            let size = 10f64.powi(scale);
            let at = |k: usize| std::array::from_fn(|c| offset + size * corners[3 * k + c]);
            let mut triangle: [[f64; 3]; 3] = [at(0), at(1), at(2)];
            if thin {
                // The third corner nearly on the first edge.
                triangle[2] = std::array::from_fn(|c| {
                    0.5 * (triangle[0][c] + triangle[1][c]) + 1e-9 * size * corners[c]
                });
            }
            let p: [f64; 3] = std::array::from_fn(|c| offset + size * point[c]);
            let corner = Corner::new(triangle);
            let exact = point_triangle_distance(p, &triangle);
            if let Some(bound) = corner.upper_bound(p) {
                proptest::prop_assert!(bound >= exact, "{bound} below {exact}");
                // The comparison through squares is the comparison of the bound, near it too.
                for floor in [
                    bound,
                    // The neighbours of a positive bound.
                    f64::from_bits(bound.to_bits() + 1),
                    f64::from_bits(bound.to_bits() - 1),
                    bound * (1.0 + 1e-15),
                    bound * (1.0 - 1e-15),
                    bound * (1.0 + 1e-13),
                    bound * (1.0 - 1e-13),
                    bound * 1.5,
                    bound * 0.75,
                    exact,
                ] {
                    proptest::prop_assert_eq!(
                        corner.bound_within(p, floor),
                        bound <= floor,
                        "floor {} against the bound {}",
                        floor,
                        bound
                    );
                }
                use crate::mesh::geometry::{closest_point_on_segment, closest_point_on_triangle};
                let [a, b, c] = triangle;
                let closest = closest_point_on_triangle(p, a, b, c);
                // Over the triangle: the nearest point off its three edges.
                let interior = [(a, b), (b, c), (c, a)].iter().all(|&(x, y)| {
                    distance(closest, closest_point_on_segment(closest, x, y)) > 1e-3 * size
                });
                let slack = 4e-12 * (offset.abs() + 4.0 * size);
                if interior {
                    proptest::prop_assert!(
                        bound <= exact * (1.0 + 1e-9) + slack,
                        "{bound} far above {exact}"
                    );
                }
            }
        }
    }

    #[test]
    fn rates_are_read_in_face_order_across_lines() {
        let rates = parse_rates("1 2\r\n\t3\n\n24 5 6\n", 6).expect("valid rates");
        assert_eq!(rates, [1, 2, 3, 24, 5, 6]);
        assert_eq!(
            parse_rates("", 0).expect("no faces, no rates"),
            Vec::<u32>::new()
        );
    }

    #[test]
    fn bad_rates_name_their_line() {
        assert_eq!(
            message("1 2\n3 x 5 6", 6),
            "rates:2: rate 4 is `x`, not an integer in 1..=24"
        );
        assert_eq!(
            message("1 2 3 4 5 25", 6),
            "rates:1: rate 6 is `25`, not an integer in 1..=24"
        );
        assert_eq!(
            message("0", 1),
            "rates:1: rate 1 is `0`, not an integer in 1..=24"
        );
        assert_eq!(
            message("-1", 1),
            "rates:1: rate 1 is `-1`, not an integer in 1..=24"
        );
        assert_eq!(
            message("1 2\n3\n", 6),
            "rates:2: 3 rates for a mesh of 6 faces"
        );
        assert_eq!(
            message("1 1\n1 1", 3),
            "rates:2: more than 3 rates for a mesh of 3 faces (rate 4 is `1`)"
        );
        assert_eq!(message("", 2), "rates:0: 0 rates for a mesh of 2 faces");
        let long = "9".repeat(1000);
        assert!(message(&long, 1).len() < 200);
    }
}
