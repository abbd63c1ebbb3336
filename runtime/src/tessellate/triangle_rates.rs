//! Tolerance rates for the triangle dual grid (Loop, the butterfly, √3): per triangle the smallest
//! rate whose tessellation deviates from the limit surface by at most a tolerance `T`
//! ([`triangle_tolerance_rates`]), and the measured deviation of a finished tessellation
//! ([`measure_triangle_deviation`]). The quad analogue is [`crate::tessellate::rates`]; the selection loop
//! and the nearest-triangle search are shared with it, and so is the memory that keeps a moving
//! mesh's rates from frame to frame (`TriangleSelection`, `tessellate/rate_memory.rs`).
//!
//! # What is measured
//!
//! Triangle `f` of an isolated mesh has the limit surface `S_f(u, v)` on its barycentric domain
//! `u, v >= 0, u + v <= 1` (corner 0 at `(0,0)`, corner 1 at `(1,0)`, corner 2 at `(0,1)`). Let
//! `L_{f,n}` be the part of the *uniform* rate-`n` tessellation ([`crate::tessellate::triangle_dual_grid`])
//! that covers `f`, with the tessellator's own triangles:
//!
//! * the hexagons around `f`'s interior primal points `(i/n, j/n)`, fanned at them;
//! * the strip along each side: `f`'s zigzag row merged with the neighbour's (both at rate
//!   `n`, as the tessellator merges them), or on a boundary side with the limit curve at `t/n`;
//! * at each corner the triangles of the vertex polygon that hold `f`'s corner dual point: the
//!   vertex's limit point, `f`'s corner point and the corner point of the neighbour across each
//!   interior side through the corner.
//!
//! Every one of these triangles has its corners in `f` or in a triangle `g` across one of `f`'s
//! sides (the vertex polygon is fanned at the limit point, so each of its triangles joins two
//! triangles sharing a side), and `g` continues `f`'s domain affinely across the side: the two
//! form a parallelogram, `g`'s corner opposite the side at `C_s + C_{s+1} - C_{s+2}` in `f`'s
//! parameters. At a uniform rate `g`'s points are the mirror images of `f`'s through the side's
//! midpoint. So `L_{f,n}` is linear on each of its triangles in `f`'s own parameters, whatever the
//! valences, and the deviation at a sample `(u, v)` is the parametric distance
//! `|S_f(u, v) - L_{f,n}(u, v)|`. The **deviation of triangle `f` at rate `n`** is
//!
//! ```text
//! e_f(n) = max over (u, v) in G of |S_f(u, v) - L_{f,n}(u, v)|
//! ```
//!
//! over the dense rational grid `G` = the table's triangle primal and dual points (`(i/N, j/N)`
//! and the centroids of the small triangles) at the table's two largest rates `N`
//! ([`triangle_sampling_rates`]: 24 and 23 for the default tables, 1,730 points a triangle),
//! evaluated from the table (a regular Loop triangle's in closed form: its patch is the quartic
//! box spline, whose table stencils are the same weights rounded to `f32`). Two
//! rates, not one: the output vertices of rate `n` (its primal *and* dual points) are all points
//! of the rate-`N` grid when `n = N`, where the deviation is zero. The parametric distance is at
//! least the distance from the sample to the output, so `e_f(n)` bounds the geometric error of
//! the uniform tessellation at those samples; it also counts tangential distortion.
//!
//! On a regular lattice whose heights are `c a^2` (`a` a lattice coordinate) the limit surface is
//! an affine map plus `c a^2` in height (Loop's box spline, the butterfly and √3 reproduce
//! quadratics up to a constant), and linear interpolation on a triangle whose corners have lattice
//! coordinates `a_1, a_2, a_3` misses by `c Var(a)`, at most `c (max - min)^2 / 4`, at the midpoint
//! of the extreme corners. The strip triangles joining the two rows' down points span `4/3n` across
//! the side (heights `2/3n` on either side), the largest of any triangle, so `e_f(n) = 4c / 9n^2`
//! for `n >= 2` when the side points `k/n` are samples (`n` divides 24 for Loop, 8 for the
//! butterfly and √3), and `e_f(1) = c / 9` (the vertex polygons, no strips). The unit tests check
//! both.
//!
//! The **tolerance rate** of triangle `f` is the smallest allowed `n` with `e_f(n) <= T`
//! ([`triangle_tolerance_rates`]: `n` among the table's rates, [`triangle_table_rates`]: 1..=24 for
//! Loop, 1..=8 for the butterfly and √3; [`triangle_tolerance_rates_among`]: any of them). As for
//! quads, `e_f` depends on `f` and `n` alone, so the rates are monotone in `T` and minimal (every
//! smaller allowed rate exceeds `T` on `G`); triangles with no allowed rate meeting `T` get the
//! largest and are listed in [`ToleranceRates::unmet`].
//!
//! # What is and is not guaranteed
//!
//! * Guaranteed on `G`: a triangle's hexagons depend on its own rate only; where its
//!   neighbours share its rate, its strips and vertex-polygon triangles are those of `L_{f,n}`
//!   too, and the output deviates from the limit by at most `T` at every sample of `G`.
//! * Not guaranteed, measured: where rates differ, the strips merge rows of different lengths
//!   and the vertex polygons join corner points at different distances from the vertex; no
//!   bound is proved for those triangles. [`measure_triangle_deviation`] measures the finished
//!   output (the Euclidean distance from limit samples to the nearest output triangle).
//! * Between samples of `G`: `e_f` is a maximum over samples, not over the continuum; the tests
//!   measure the output again on other grids.

use std::collections::{BTreeSet, HashMap};
use std::sync::OnceLock;

use rayon::prelude::*;
use table_format::{PointSet, StencilKind};

use crate::mesh::topology::NONE;
use crate::mesh::triangle_grid::TriangleGrid;
use crate::mesh::triangle_mesh::TriangleMesh;
use crate::once::TryOnce;
use crate::scheme::patch::PatchKind;
use crate::scheme::triangle::isolation::TriangleIsolation;
use crate::scheme::triangle::patch::{dual_in_patch, dual_index, primal_in_patch, primal_index};
use crate::stencil_table::StencilTable;
use crate::tessellate::kernel::{extend_weighted_sums, merge_rows, Stencils};
use crate::tessellate::loop_quartic::{polynomial_row, row_value, QuarticBasis};
use crate::tessellate::rate_memory::{by_kind, Selection, StencilBound};
use crate::tessellate::rates::{
    check_tolerance, choose_rate, sorted_candidates, FaceChoice, ToleranceRates,
};
use crate::tessellate::triangle_dual_grid::{
    is_loop_regular, zigzag_cell, TriangleStencils, MAX_TRIANGLE_RATE,
};
use crate::RuntimeError;

/// The rates a table has triangle grids for (position sections on both the primal and the dual
/// triangle grid, or, in a compact Loop table, the rates its markers list, which it expands;
/// at most [`MAX_TRIANGLE_RATE`]), ascending: the rates a tolerance may select.
pub fn triangle_table_rates(table: &StencilTable) -> Vec<u32> {
    let on = |points: PointSet| -> BTreeSet<u32> {
        table
            .index()
            .entries
            .iter()
            .filter(|e| e.key.kind == StencilKind::Position && e.key.points == points)
            .map(|e| e.key.n)
            .filter(|&n| (1..=MAX_TRIANGLE_RATE).contains(&n))
            .collect()
    };
    let stored = on(PointSet::TriangleDual)
        .intersection(&on(PointSet::TrianglePrimal))
        .copied()
        .collect::<BTreeSet<u32>>();
    stored.union(&on(PointSet::TriangleRate)).copied().collect()
}

/// The rates of the sampling grid `G` (module docs): the two largest of `rates` (one if it has
/// one), largest first.
pub fn triangle_sampling_rates(rates: &[u32]) -> Vec<u32> {
    let mut sorted = rates.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    sorted.into_iter().rev().take(2).collect()
}

/// The control points of an isolated triangle mesh (its vertices, then its phantoms), with its
/// patches and the table: what evaluates any triangle's table points.
struct Context<'a> {
    table: &'a StencilTable,
    iso: &'a TriangleIsolation,
    control: Vec<[f64; 3]>,
}

impl<'a> Context<'a> {
    fn new(table: &'a StencilTable, iso: &'a TriangleIsolation) -> Result<Self, RuntimeError> {
        if iso.patches.len() != iso.mesh.faces() {
            return Err(RuntimeError::Unsupported(format!(
                "{} patches for {} triangles",
                iso.patches.len(),
                iso.mesh.faces()
            )));
        }
        let control = iso.phantoms.extend(&iso.mesh.positions);
        if let Some(v) = iso
            .patches
            .iter()
            .flat_map(|p| &p.points)
            .find(|&&v| v as usize >= control.len())
        {
            return Err(RuntimeError::Unsupported(format!(
                "patch control point {v} is neither a vertex nor a phantom"
            )));
        }
        Ok(Context {
            table,
            iso,
            control,
        })
    }

    /// The position section of triangle `f`'s patch on `points` at rate `n`.
    fn section(&self, f: usize, points: PointSet, n: u32) -> Result<Section<'a>, RuntimeError> {
        let patch = &self.iso.patches[f];
        let key = patch.kind.section(StencilKind::Position, points, n);
        let weights = self.table.triangle_weights(&key)?;
        let k = patch.points.len();
        let count = points.count(n) as usize;
        if weights.len() != count * k {
            return Err(RuntimeError::LayoutMismatch {
                key,
                table: weights.len() / count.max(1),
                patch: k,
            });
        }
        Ok(Section {
            weights,
            k,
            corner: patch.corner,
            n,
        })
    }

    /// The control points of triangle `f`'s patch, in its layout.
    fn patch_control(&self, f: usize) -> Vec<[f64; 3]> {
        self.iso.patches[f]
            .points
            .iter()
            .map(|&v| self.control[v as usize])
            .collect()
    }

    /// Which sides of triangle `f` are on the boundary (bit `s` for side `s`).
    fn boundary_mask(&self, f: usize) -> u8 {
        let first = self.iso.mesh.face_halfedges(f).start;
        (0..3)
            .filter(|&s| self.iso.mesh.twin[first + s] == NONE)
            .fold(0, |m, s| m | 1 << s)
    }

    /// The limit samples of triangle `f` on the grid `grid`, in its order.
    fn samples(&self, f: usize, grid: &SampleGrid) -> Result<Vec<[f64; 3]>, RuntimeError> {
        let patch = &self.iso.patches[f];
        let control = self.patch_control(f);
        if let (Some(quartic), true) = (grid.quartic, is_loop_regular(patch)) {
            let polynomial = quartic.polynomial(patch.corner, &control);
            // Each line `v` of the grid once: the quartic in `u` there, then every sample on it.
            let rows: Vec<_> = grid
                .lines
                .iter()
                .map(|&v| polynomial_row(&polynomial, v))
                .collect();
            return Ok(grid
                .params
                .iter()
                .zip(&grid.line_of)
                .map(|(&[u, _], &line)| row_value(&rows[line as usize], u))
                .collect());
        }
        let mut out = Vec::with_capacity(grid.params.len());
        for &n in &grid.rates {
            for points in [PointSet::TrianglePrimal, PointSet::TriangleDual] {
                let section = self.section(f, points, n)?;
                section.extend_points(&control, points, &mut out);
            }
        }
        Ok(out)
    }

    /// The positions of the points of `L_{f,n}` ([`Ids`]).
    fn local_points(&self, f: usize, n: u32) -> Result<Vec<[f64; 3]>, RuntimeError> {
        let ids = Ids { n };
        // f's dual points, then its primal points, in the table's order: the first ids.
        let mut out = Vec::with_capacity(ids.count());
        let control = self.patch_control(f);
        for points in [PointSet::TriangleDual, PointSet::TrianglePrimal] {
            let section = self.section(f, points, n)?;
            section.extend_points(&control, points, &mut out);
        }
        out.resize(ids.count(), [0.0; 3]);
        let mesh = &self.iso.mesh;
        let first = mesh.face_halfedges(f).start;
        for s in 0..3 {
            let t = mesh.twin[first + s];
            if t == NONE {
                continue;
            }
            let t = t as usize;
            let g = mesh.face_of[t] as usize;
            let side = (t - mesh.face_halfedges(g).start) as u8;
            let theirs = self.section(g, PointSet::TriangleDual, n)?;
            // g's zigzag runs from f's corner s + 1 to corner s: reversed, it runs along f's side.
            let rows = (0..2 * n - 1).map(|k| {
                let (i, j, down) = zigzag_cell(n, side, 2 * n - 2 - k);
                theirs.weights_of(theirs.dual_row(i, j, down))
            });
            let mut row = Vec::with_capacity(2 * n as usize - 1);
            extend_weighted_sums(&self.patch_control(g), rows, &mut row);
            let first = ids.beyond(s, 0);
            out[first..first + row.len()].copy_from_slice(&row);
        }
        Ok(out)
    }
}

/// One table section of one triangle's patch, read in the triangle's own indices.
struct Section<'t> {
    weights: &'t [f32],
    k: usize,
    corner: usize,
    n: u32,
}

impl<'t> Section<'t> {
    /// The weights of table row `row`.
    fn weights_of(&self, row: usize) -> &'t [f32] {
        &self.weights[row * self.k..][..self.k]
    }

    /// The limit positions of every point of this section (on the grid `points`) of a triangle
    /// whose patch has the control points `control`, in the triangle's own indices and the
    /// table's order, appended to `out`.
    fn extend_points(&self, control: &[[f64; 3]], points: PointSet, out: &mut Vec<[f64; 3]>) {
        let n = self.n;
        let mut rows = Vec::with_capacity(points.count(n) as usize);
        if points == PointSet::TrianglePrimal {
            for j in 0..=n {
                for i in 0..=n - j {
                    rows.push(self.weights_of(self.primal_row(i, j)));
                }
            }
        } else {
            for_each_dual(n, |i, j, down| {
                rows.push(self.weights_of(self.dual_row(i, j, down)))
            });
        }
        extend_weighted_sums(control, rows.into_iter(), out);
    }

    fn primal_row(&self, i: u32, j: u32) -> usize {
        let (pi, pj) = primal_in_patch(self.corner, self.n, i, j);
        primal_index(self.n, pi, pj)
    }

    fn dual_row(&self, i: u32, j: u32, down: bool) -> usize {
        let (pi, pj) = dual_in_patch(self.corner, self.n, i, j, down);
        dual_index(self.n, pi, pj, down)
    }
}

/// Every small triangle `up(i, j)` / `down(i, j)` at rate `n`, in the table's order.
fn for_each_dual(n: u32, mut each: impl FnMut(u32, u32, bool)) {
    for j in 0..n {
        for i in 0..n - j {
            each(i, j, false);
            if i + j + 1 < n {
                each(i, j, true);
            }
        }
    }
}

/// The parameters of the centroid of `up(i, j)` / `down(i, j)` at rate `n`.
fn centroid(n: u32, i: u32, j: u32, down: bool) -> [f64; 2] {
    let shift = if down { 2.0 } else { 1.0 };
    let d = 3.0 * f64::from(n);
    [
        (3.0 * f64::from(i) + shift) / d,
        (3.0 * f64::from(j) + shift) / d,
    ]
}

/// The sampling grid `G` of every triangle: its rates and its points' parameters (per rate the
/// primal points row by row, then the dual points in the table's order).
struct SampleGrid {
    rates: Vec<u32>,
    params: Vec<[f64; 2]>,
    /// The distinct values of `v` among `params`, and per point the index of its own: a
    /// regular triangle's quartic is contracted to a quartic in `u` once per line.
    lines: Vec<f64>,
    line_of: Vec<u32>,
    /// Loop's regular patch as quartics, where the table's regular patch is the quartic box
    /// spline at every rate of the grid ([`SampleGrid::with_closed_form`]): a regular triangle's
    /// samples are then the polynomial's values.
    quartic: Option<&'static QuarticBasis>,
}

impl SampleGrid {
    fn new(rates: Vec<u32>) -> Self {
        let mut params = Vec::new();
        for &n in &rates {
            for j in 0..=n {
                for i in 0..=n - j {
                    params.push([f64::from(i) / f64::from(n), f64::from(j) / f64::from(n)]);
                }
            }
            for_each_dual(n, |i, j, down| params.push(centroid(n, i, j, down)));
        }
        let mut lines: Vec<f64> = Vec::new();
        let line_of = params
            .iter()
            .map(|&[_, v]| {
                // A dual row alternates between two lines: search from the last one made.
                let found = lines.iter().rposition(|&w| w == v);
                found.unwrap_or_else(|| {
                    lines.push(v);
                    lines.len() - 1
                }) as u32
            })
            .collect();
        SampleGrid {
            rates,
            params,
            lines,
            line_of,
            quartic: None,
        }
    }

    /// The grid, its regular triangles' samples in closed form where the table's regular patch
    /// reproduces the quartic box spline (position, d/du and d/dv of every point, to `1e-6`:
    /// [`QuarticBasis::reproduces`], the frame's own test) at every rate of the grid: the
    /// polynomial costs 15 multiply-adds a coordinate where the stencil costs 12 products and
    /// sums, and its contraction is shared by the 1,730 samples.
    fn with_closed_form(mut self, table: &dyn TriangleStencils) -> Self {
        let regular = PatchKind {
            boundary: false,
            feature: table_format::Feature::None,
            faces: 6,
            sector: 0,
        };
        let stencils = |points: PointSet, n: u32| -> Option<Stencils> {
            let [position, du, dv] = [
                StencilKind::Position,
                StencilKind::DerivativeU,
                StencilKind::DerivativeV,
            ]
            .map(|kind| {
                table
                    .triangle_weights(&regular.section(kind, points, n))
                    .ok()
            });
            Some(Stencils {
                position: position?,
                du: du?,
                dv: dv?,
            })
        };
        self.quartic = QuarticBasis::get().filter(|basis| {
            self.rates.iter().all(|&n| {
                match (
                    stencils(PointSet::TriangleDual, n),
                    stencils(PointSet::TrianglePrimal, n),
                ) {
                    (Some(dual), Some(primal)) => basis.reproduces(&dual, &primal, n),
                    _ => false,
                }
            })
        });
        self
    }
}

/// The points of `L_{f,n}`, numbered: `f`'s dual points (table order), its primal points (all
/// of them, table order), then per side `s` the neighbour's zigzag row along it, `2n - 1`
/// points from corner `s` to corner `s + 1`.
#[derive(Clone, Copy)]
struct Ids {
    n: u32,
}

impl Ids {
    fn dual(self, i: u32, j: u32, down: bool) -> usize {
        dual_index(self.n, i, j, down)
    }

    fn primal(self, i: u32, j: u32) -> usize {
        (self.n * self.n) as usize + primal_index(self.n, i, j)
    }

    fn beyond(self, side: usize, k: u32) -> usize {
        self.primal(0, self.n) + 1 + side * (2 * self.n - 1) as usize + k as usize
    }

    fn count(self) -> usize {
        self.beyond(3, 0)
    }

    /// Point `k` of `f`'s own zigzag row along side `side`.
    fn zigzag(self, side: usize, k: u32) -> usize {
        let (i, j, down) = zigzag_cell(self.n, side as u8, k);
        self.dual(i, j, down)
    }

    /// The primal point `t/n` along side `side`, from corner `side`.
    fn curve(self, side: usize, t: u32) -> usize {
        let n = self.n;
        match side {
            0 => self.primal(t, 0),
            1 => self.primal(n - t, t),
            _ => self.primal(0, n - t),
        }
    }

    /// The parameters of every point in `f`'s domain, continued across the sides.
    fn params(self) -> Vec<[f64; 2]> {
        let n = self.n;
        let mut out = vec![[0.0; 2]; self.count()];
        for_each_dual(n, |i, j, down| {
            out[self.dual(i, j, down)] = centroid(n, i, j, down)
        });
        for j in 0..=n {
            for i in 0..=n - j {
                out[self.primal(i, j)] = [f64::from(i) / f64::from(n), f64::from(j) / f64::from(n)];
            }
        }
        // The neighbour across side s is f mirrored through the side's midpoint.
        let midpoints = [[0.5, 0.0], [0.5, 0.5], [0.0, 0.5]];
        for (s, m) in midpoints.iter().enumerate() {
            for k in 0..2 * n - 1 {
                let p = out[self.zigzag(s, 2 * n - 2 - k)];
                out[self.beyond(s, k)] = [2.0 * m[0] - p[0], 2.0 * m[1] - p[1]];
            }
        }
        out
    }

    /// The triangles of `L_{f,n}` (module docs) for a triangle whose boundary sides are the bits
    /// of `boundary`, in the tessellator's own connectivity.
    fn triangles(self, boundary: u8) -> Vec<[u32; 3]> {
        let n = self.n;
        let id = |x: usize| x as u32;
        let mut out = Vec::new();
        // Hexagons around the interior primal points, as the tessellator's `connect_face`.
        for j in 1..n {
            for i in 1..n - j {
                let c = id(self.primal(i, j));
                let ring = [
                    self.dual(i, j, false),
                    self.dual(i - 1, j, true),
                    self.dual(i - 1, j, false),
                    self.dual(i - 1, j - 1, true),
                    self.dual(i, j - 1, false),
                    self.dual(i, j - 1, true),
                ];
                for r in 0..6 {
                    out.push([c, id(ring[r]), id(ring[(r + 1) % 6])]);
                }
            }
        }
        // Strips: at one rate the merge is the same whichever row is on the left (the two
        // configurations are mirror images and the merge is symmetric under the mirror).
        for s in 0..3 {
            let row = |k: u32| id(self.zigzag(s, k));
            let len = 2 * n - 1;
            if boundary & (1 << s) != 0 {
                let mut strip = vec![[0; 3]; (3 * n - 2) as usize];
                merge_rows(
                    row,
                    len,
                    |k| u64::from(k) + 1,
                    |t| id(self.curve(s, t)),
                    n + 1,
                    |t| 2 * u64::from(t),
                    &mut strip,
                );
                out.extend(strip);
            } else {
                let mut strip = vec![[0; 3]; (2 * len - 2) as usize];
                merge_rows(
                    row,
                    len,
                    |k| u64::from(k) + 1,
                    |k| id(self.beyond(s, k)),
                    len,
                    |k| u64::from(k) + 1,
                    &mut strip,
                );
                out.extend(strip);
            }
        }
        // Vertex polygons: the limit point with f's corner point and the neighbour's across
        // each interior side through the corner.
        for k in 0..3 {
            let v = id(self.curve(k, 0));
            let before = (k + 2) % 3;
            if boundary & (1 << k) == 0 {
                out.push([v, id(self.zigzag(k, 0)), id(self.beyond(k, 0))]);
            }
            if boundary & (1 << before) == 0 {
                let last = 2 * n - 2;
                out.push([
                    v,
                    id(self.beyond(before, last)),
                    id(self.zigzag(before, last)),
                ]);
            }
        }
        out
    }
}

/// Where every sample of `G` lies in `L_{f,n}`: the triangle's three points ([`Ids`]) and the
/// sample's barycentric weights in it, in `f`'s parameters.
struct Template {
    triangles: Vec<[u32; 3]>,
    weights: Vec<[f64; 3]>,
}

/// The barycentric weights of `p` in the triangle `a, b, c` of the plane (`None` if it has no
/// area).
fn barycentric(p: [f64; 2], [a, b, c]: [[f64; 2]; 3]) -> Option<[f64; 3]> {
    let det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if det.abs() < 1e-14 {
        return None;
    }
    let wb = ((p[0] - a[0]) * (c[1] - a[1]) - (p[1] - a[1]) * (c[0] - a[0])) / det;
    let wc = ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / det;
    Some([1.0 - wb - wc, wb, wc])
}

impl Template {
    /// Locate every sample of `grid` among the triangles of `L_{f,n}` (boundary sides
    /// `boundary`), with a uniform grid of `3n x 3n` cells over `f`'s parameter square.
    fn new(n: u32, boundary: u8, grid: &SampleGrid) -> Result<Self, RuntimeError> {
        let ids = Ids { n };
        let params = ids.params();
        let triangles = ids.triangles(boundary);
        let cells = 3 * n as usize;
        let cell = |x: f64| ((x * cells as f64).floor().max(0.0) as usize).min(cells - 1);
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
        for (k, t) in triangles.iter().enumerate() {
            let corners = t.map(|i| params[i as usize]);
            if barycentric(corners[0], corners).is_none() {
                continue; // no area in the parameters: covers no sample
            }
            let low = |c: usize| corners.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min);
            let high = |c: usize| {
                corners
                    .iter()
                    .map(|p| p[c])
                    .fold(f64::NEG_INFINITY, f64::max)
            };
            if high(0) < 0.0 || high(1) < 0.0 || low(0) > 1.0 || low(1) > 1.0 {
                continue;
            }
            for y in cell(low(1))..=cell(high(1)) {
                for x in cell(low(0))..=cell(high(0)) {
                    buckets[y * cells + x].push(k as u32);
                }
            }
        }
        let mut out = Template {
            triangles: Vec::with_capacity(grid.params.len()),
            weights: Vec::with_capacity(grid.params.len()),
        };
        for &p in &grid.params {
            let best = buckets[cell(p[1]) * cells + cell(p[0])]
                .iter()
                .filter_map(|&k| {
                    let t = triangles[k as usize];
                    barycentric(p, t.map(|i| params[i as usize])).map(|w| (t, w))
                })
                .max_by(|a, b| {
                    let least = |w: &[f64; 3]| w[0].min(w[1]).min(w[2]);
                    least(&a.1).total_cmp(&least(&b.1))
                });
            match best {
                Some((t, w)) if w.iter().all(|&x| x >= -1e-9) => {
                    out.triangles.push(t);
                    out.weights.push(w);
                }
                _ => {
                    return Err(RuntimeError::Unsupported(format!(
                        "no triangle of the rate-{n} tessellation covers ({}, {})",
                        p[0], p[1]
                    )))
                }
            }
        }
        Ok(out)
    }

    /// `e_f(n)`: the largest distance from a sample to `L_{f,n}` at the same parameters.
    fn deviation(&self, points: &[[f64; 3]], samples: &[[f64; 3]]) -> f64 {
        self.deviation_up_to(points, samples, f64::INFINITY)
    }

    /// `e_f(n)`, or, as soon as one sample deviates by more than `stop`, that sample's
    /// deviation (a lower bound, enough to reject the rate; as the quad selection does).
    fn deviation_up_to(&self, points: &[[f64; 3]], samples: &[[f64; 3]], stop: f64) -> f64 {
        // The largest square, rooted once: the root is monotone, so that is the largest root.
        let mut worst_squared = 0.0f64;
        for ((t, w), s) in self.triangles.iter().zip(&self.weights).zip(samples) {
            let corners = t.map(|k| points[k as usize]);
            let mut d = 0.0;
            for c in 0..3 {
                let l: f64 = (0..3).map(|k| w[k] * corners[k][c]).sum();
                d += (s[c] - l) * (s[c] - l);
            }
            if d > worst_squared {
                worst_squared = d;
                if worst_squared.sqrt() > stop {
                    break;
                }
            }
        }
        worst_squared.sqrt()
    }
}

/// The sampling grid `G` of `table` (module docs).
fn sample_grid(table: &StencilTable) -> Result<SampleGrid, RuntimeError> {
    let rates = triangle_sampling_rates(&triangle_table_rates(table));
    if rates.is_empty() {
        return Err(RuntimeError::Unsupported(
            "the stencil table has no triangle grids to measure a tolerance on".to_owned(),
        ));
    }
    Ok(SampleGrid::new(rates).with_closed_form(table))
}

/// `e_f(n)` of triangle `face` of an isolated triangle mesh (module docs): the deviation, over
/// the sampling grid `G`, of the limit surface from the tessellation of the triangle's
/// neighbourhood with every triangle at rate `n`.
pub fn triangle_face_deviation(
    table: &StencilTable,
    iso: &TriangleIsolation,
    face: usize,
    n: u32,
) -> Result<f64, RuntimeError> {
    let ctx = Context::new(table, iso)?;
    if face >= iso.patches.len() {
        return Err(RuntimeError::InvalidParameter {
            name: "face".to_owned(),
            reason: format!("{face} (the mesh has {} triangles)", iso.patches.len()),
        });
    }
    if !(1..=MAX_TRIANGLE_RATE).contains(&n) {
        return Err(RuntimeError::InvalidParameter {
            name: "rate".to_owned(),
            reason: format!("{n} (rates run from 1 to {MAX_TRIANGLE_RATE})"),
        });
    }
    let grid = sample_grid(table)?;
    let template = Template::new(n, ctx.boundary_mask(face), &grid)?;
    Ok(template.deviation(&ctx.local_points(face, n)?, &ctx.samples(face, &grid)?))
}

/// Per triangle the smallest rate `n` of the table ([`triangle_table_rates`]) with
/// `e_f(n) <= tolerance` (module docs): [`triangle_tolerance_rates_among`] with every rate of
/// the table.
pub fn triangle_tolerance_rates(
    table: &StencilTable,
    iso: &TriangleIsolation,
    tolerance: f64,
) -> Result<ToleranceRates, RuntimeError> {
    triangle_tolerance_rates_among(table, iso, tolerance, &triangle_table_rates(table))
}

/// Per triangle the smallest rate `n` of `candidates` with `e_f(n) <= tolerance` (module docs),
/// or the largest candidate (and the triangle listed in [`ToleranceRates::unmet`]) when none
/// meets it. `tolerance` is in the mesh's units; `candidates` must be non-empty, each one of the
/// table's rates.
///
/// Cost: per triangle its samples of `G` once, then for each candidate tried the `3n^2/2 + 8n`
/// table points of `L_{f,n}` and one interpolation per sample (where each sample lies is found
/// once per rate and boundary pattern, for every triangle); triangles run in parallel.
pub fn triangle_tolerance_rates_among(
    table: &StencilTable,
    iso: &TriangleIsolation,
    tolerance: f64,
    candidates: &[u32],
) -> Result<ToleranceRates, RuntimeError> {
    let selection = TriangleSelection::new(table, iso, tolerance, candidates)?;
    let faces: Vec<usize> = (0..iso.patches.len()).collect();
    Ok(ToleranceRates::from_choices(
        &selection.choose(&faces, None)?,
    ))
}

/// The selection of [`triangle_tolerance_rates_among`] at the isolated mesh's current
/// positions, face by face: what a full selection and [`super::rate_memory::RateMemory`]
/// share.
pub(crate) struct TriangleSelection<'a> {
    ctx: Context<'a>,
    tolerance: f64,
    candidates: Vec<u32>,
    sampling: Sampling<'a>,
}

/// What a triangle selection measures with, from the table and the mesh's topology alone: the
/// sampling grid `G`, and per candidate rate and boundary pattern where the samples lie in
/// `L_{f,n}`. A surface keeps one across frames ([`TriangleSelection::sharing`]): made anew,
/// it was a fifth of a bent frame's selection on the hand.
pub(crate) struct TriangleSampling {
    grid: SampleGrid,
    templates: OnceLock<HashMap<(u32, u8), Template>>,
}

impl TriangleSampling {
    /// `table`'s sampling grid; the templates are made when a selection first samples a face.
    pub(crate) fn new(table: &StencilTable) -> Result<Self, RuntimeError> {
        Ok(TriangleSampling {
            grid: sample_grid(table)?,
            templates: OnceLock::new(),
        })
    }
}

impl std::fmt::Debug for TriangleSampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TriangleSampling")
            .field("rates", &self.grid.rates)
            .field("samples", &self.grid.params.len())
            .field("templates", &self.templates.get().map(HashMap::len))
            .finish()
    }
}

/// A selection's [`TriangleSampling`]: its own, or one a surface keeps.
enum Sampling<'a> {
    Own(TriangleSampling),
    Shared(&'a TriangleSampling),
}

impl Sampling<'_> {
    fn get(&self) -> &TriangleSampling {
        match self {
            Sampling::Own(sampling) => sampling,
            Sampling::Shared(sampling) => sampling,
        }
    }
}

impl<'a> TriangleSelection<'a> {
    /// `iso`'s selection for `tolerance` among `candidates` (rates of the table).
    pub(crate) fn new(
        table: &'a StencilTable,
        iso: &'a TriangleIsolation,
        tolerance: f64,
        candidates: &[u32],
    ) -> Result<Self, RuntimeError> {
        let sampling = Sampling::Own(TriangleSampling::new(table)?);
        Self::with_sampling(table, iso, tolerance, candidates, sampling)
    }

    /// [`TriangleSelection::new`] measuring with `sampling`, made for `table` and kept with
    /// `iso` (its templates are those of the first selection's candidates and `iso`'s boundary
    /// patterns: every later selection must ask for the same).
    pub(crate) fn sharing(
        table: &'a StencilTable,
        iso: &'a TriangleIsolation,
        tolerance: f64,
        candidates: &[u32],
        sampling: &'a TriangleSampling,
    ) -> Result<Self, RuntimeError> {
        Self::with_sampling(
            table,
            iso,
            tolerance,
            candidates,
            Sampling::Shared(sampling),
        )
    }

    fn with_sampling(
        table: &'a StencilTable,
        iso: &'a TriangleIsolation,
        tolerance: f64,
        candidates: &[u32],
        sampling: Sampling<'a>,
    ) -> Result<Self, RuntimeError> {
        let ctx = Context::new(table, iso)?;
        check_tolerance(tolerance)?;
        let candidates = sorted_candidates(candidates, &triangle_table_rates(table))?;
        Ok(TriangleSelection {
            ctx,
            tolerance,
            candidates,
            sampling,
        })
    }

    /// Per candidate rate and boundary pattern, where the samples lie in `L_{f,n}`: made the
    /// first time a face is sampled (a frame that keeps every rate samples none).
    fn templates(&self) -> Result<&HashMap<(u32, u8), Template>, RuntimeError> {
        let sampling = self.sampling.get();
        sampling.templates.get_or_try(|| {
            let masks: BTreeSet<u8> = (0..self.faces())
                .map(|f| self.ctx.boundary_mask(f))
                .collect();
            let keys: Vec<(u32, u8)> = self
                .candidates
                .iter()
                .flat_map(|&n| masks.iter().map(move |&m| (n, m)))
                .collect();
            keys.par_iter()
                .map(|&(n, m)| Ok(((n, m), Template::new(n, m, &sampling.grid)?)))
                .collect::<Result<_, RuntimeError>>()
        })
    }

    /// The bounds of a patch kind's position stencils: its samples', and per candidate rate
    /// (at its index in the candidates) its dual and primal grids'.
    fn kind_bounds(&self, kind: &PatchKind) -> (StencilBound, Vec<[StencilBound; 2]>) {
        let table = self.ctx.table;
        let section = |points: PointSet, n: u32| {
            let key = kind.section(StencilKind::Position, points, n);
            table
                .triangle_weights(&key)
                .map_or(StencilBound::NONE, |w| {
                    StencilBound::of_weights(w, points.count(n) as usize)
                })
        };
        let samples = self
            .sampling
            .get()
            .grid
            .rates
            .iter()
            .flat_map(|&n| [PointSet::TrianglePrimal, PointSet::TriangleDual].map(|p| (p, n)))
            .map(|(p, n)| section(p, n))
            .fold(StencilBound::ZERO, StencilBound::max);
        let rates = self
            .candidates
            .iter()
            .map(|&n| {
                [
                    section(PointSet::TriangleDual, n),
                    section(PointSet::TrianglePrimal, n),
                ]
            })
            .collect();
        (samples, rates)
    }
}

impl Selection for TriangleSelection<'_> {
    fn tolerance(&self) -> f64 {
        self.tolerance
    }

    fn candidates(&self) -> &[u32] {
        &self.candidates
    }

    fn control(&self) -> &[[f64; 3]] {
        &self.ctx.control
    }

    fn faces(&self) -> usize {
        self.ctx.iso.patches.len()
    }

    fn corners(&self, f: usize) -> &[u32] {
        self.ctx.iso.mesh.face(f)
    }

    fn hole(&self, _: usize) -> bool {
        false
    }

    /// The triangle selection records no refutations ([`FaceChoice::refutations`]), so it is
    /// never asked.
    fn sample_deviations(&self, checks: &[(usize, u32, usize)]) -> Result<Vec<f64>, RuntimeError> {
        Err(RuntimeError::Unsupported(format!(
            "internal: {} samples looked at again, but the triangle selection records no refutations",
            checks.len()
        )))
    }

    fn choose(
        &self,
        faces: &[usize],
        _previous: Option<&[FaceChoice]>,
    ) -> Result<Vec<FaceChoice>, RuntimeError> {
        if faces.is_empty() {
            return Ok(Vec::new());
        }
        let (ctx, grid, templates) = (&self.ctx, &self.sampling.get().grid, self.templates()?);
        // Only the largest rate's deviation is reported when no rate meets the tolerance.
        let largest = self.candidates.last().copied().unwrap_or(0);
        faces
            .par_iter()
            .map(|&f| {
                choose_rate(
                    f,
                    self.tolerance,
                    &self.candidates,
                    |f| Ok((ctx.boundary_mask(f), ctx.samples(f, grid)?)),
                    |f, (mask, samples), n| {
                        let template = templates.get(&(n, *mask)).ok_or_else(|| {
                            RuntimeError::Unsupported(format!("no sample template at rate {n}"))
                        })?;
                        let stop = if n == largest {
                            f64::INFINITY
                        } else {
                            self.tolerance
                        };
                        Ok(template.deviation_up_to(&ctx.local_points(f, n)?, samples, stop))
                    },
                )
                .map(|(choice, _)| choice)
            })
            .collect()
    }

    /// A triangle's samples read its patch's points; `L_{f,n}` its own dual and primal points
    /// and the neighbours' rows across its sides, their patches' points.
    fn neighbourhoods(&self) -> Result<Vec<(Vec<u32>, Vec<StencilBound>)>, RuntimeError> {
        let (patches, mesh) = (&self.ctx.iso.patches, &self.ctx.iso.mesh);
        let kind_bounds = by_kind(patches.iter().map(|p| p.kind), |k| self.kind_bounds(k));
        let bounds_of = |g: usize| kind_bounds.get(&patches[g].kind);
        let top = self.candidates.last().copied().unwrap_or(0) as usize;
        Ok((0..patches.len())
            .into_par_iter()
            .map(|f| {
                let first = mesh.face_halfedges(f).start;
                let across: Vec<usize> = (0..3)
                    .filter_map(|s| {
                        let t = mesh.twin[first + s];
                        (t != NONE).then(|| mesh.face_of[t as usize] as usize)
                    })
                    .collect();
                let mut points: Vec<u32> = std::iter::once(f)
                    .chain(across.iter().copied())
                    .flat_map(|g| patches[g].points.iter().copied())
                    .collect();
                points.sort_unstable();
                points.dedup();
                let mut bounds = vec![StencilBound::NONE; top + 1];
                if let Some((samples, own)) = bounds_of(f) {
                    let mut local = StencilBound::ZERO;
                    for (k, &n) in self.candidates.iter().enumerate() {
                        local = local.max(own[k][0]).max(own[k][1]);
                        for &g in &across {
                            local =
                                local.max(bounds_of(g).map_or(StencilBound::NONE, |b| b.1[k][0]));
                        }
                        bounds[n as usize] = samples.plus(local);
                    }
                }
                (points, bounds)
            })
            .collect())
    }
}

/// The measured deviation of a finished triangle tessellation: the largest Euclidean distance
/// from the limit surface, sampled at the table's triangle primal and dual points at rate
/// `grid` of every triangle of the isolated mesh (`(grid+1)(grid+2)/2 + grid^2` a triangle), to
/// the nearest triangle of `tessellation` (the one-sided Hausdorff distance from the surface to
/// the mesh, at those samples). As [`crate::tessellate::rates::measure_deviation`]: independent of how the
/// rates were chosen, the whole output included.
pub fn measure_triangle_deviation(
    table: &StencilTable,
    iso: &TriangleIsolation,
    tessellation: &TriangleMesh,
    grid: u32,
) -> Result<f64, RuntimeError> {
    let ctx = Context::new(table, iso)?;
    if tessellation.triangles.is_empty() {
        return Err(RuntimeError::InvalidParameter {
            name: "tessellation".to_owned(),
            reason: "it has no triangles".to_owned(),
        });
    }
    let cells = TriangleGrid::from_mesh(tessellation);
    // The table's stencils at every sample (no closed form): a measurement apart from the
    // selection.
    let samples = SampleGrid::new(vec![grid]);
    let per_face = (0..iso.patches.len())
        .into_par_iter()
        .map(|f| -> Result<f64, RuntimeError> {
            Ok(ctx
                .samples(f, &samples)?
                .iter()
                .map(|&p| cells.nearest_distance(p))
                .fold(0.0, f64::max))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_face.into_iter().fold(0.0, f64::max))
}

/// The limit positions of triangle `face` of an isolated triangle mesh at the table's triangle
/// grid `points` ([`PointSet::TrianglePrimal`] or [`PointSet::TriangleDual`]) at rate `n`, in the
/// triangle's own parameters and the table's order.
pub fn triangle_table_positions(
    table: &StencilTable,
    iso: &TriangleIsolation,
    face: usize,
    points: PointSet,
    n: u32,
) -> Result<Vec<[f64; 3]>, RuntimeError> {
    let ctx = Context::new(table, iso)?;
    if face >= iso.patches.len() || !points.is_triangle() {
        return Err(RuntimeError::InvalidParameter {
            name: "face or grid".to_owned(),
            reason: format!("face {face} on {points:?} (triangle grids of the mesh's triangles)"),
        });
    }
    let section = ctx.section(face, points, n)?;
    let mut out = Vec::with_capacity(points.count(n) as usize);
    section.extend_points(&ctx.patch_control(face), points, &mut out);
    Ok(out)
}

#[cfg(test)]
// Tests that read an embedded table are compiled with its scheme's feature only; with a subset
// of the tables their helpers go unused.
#[cfg_attr(
    not(all(
        feature = "catmull-clark",
        feature = "loop",
        feature = "butterfly",
        feature = "sqrt3"
    )),
    allow(unused)
)]
mod tests {
    use std::collections::HashSet;

    use super::*;
    use crate::mesh::test_meshes::{lattice_torus, octahedron};
    use crate::mesh::topology::Mesh;
    use crate::scheme::loop_scheme::isolate::isolate_loop;
    use crate::scheme::region_isolate::isolate_regions;
    use crate::scheme::triangle::region_patch::RegionScheme;
    use crate::tessellate::triangle_dual_grid::tessellate_triangles;

    const SIDE: i64 = 16;

    /// The lattice torus with heights `c x^2`, `x = a - 8` (tilted out of the coordinate planes):
    /// away from the seams (`a, b` in `4..=10`) every patch and every neighbour's patch reads
    /// the quadratic lattice.
    fn quadratic_torus(c: f64) -> Mesh {
        lattice_torus(SIDE, |a, b| {
            let (x, y) = ((a - 8) as f64 + 0.5 * (b - 8) as f64, 0.75 * (b - 8) as f64);
            let z = c * ((a - 8) as f64).powi(2);
            [x, 0.6 * y + 0.8 * z, -0.8 * y + 0.6 * z]
        })
    }

    /// Triangles `2 (a + m b)` (up) and `+ 1` (down) of the cells away from the seams.
    fn inner_faces() -> Vec<usize> {
        let mut out = Vec::new();
        for b in 4..=10 {
            for a in 4..=10 {
                let f = 2 * (a + SIDE * b) as usize;
                out.extend([f, f + 1]);
            }
        }
        out
    }

    /// `e_f(n) = 4c / 9n^2` (`n >= 2`, the side points `k/n` samples) and `c / 9` at `n = 1`
    /// (module docs: the variance of the lattice coordinate over the widest triangle).
    fn check_closed_form(table: &StencilTable, iso: &TriangleIsolation, c: f64, rates: &[u32]) {
        assert_eq!(iso.steps, 0, "a regular torus is isolated");
        for &n in rates {
            let expected = if n == 1 {
                c / 9.0
            } else {
                4.0 * c / (9.0 * f64::from(n * n))
            };
            for f in inner_faces() {
                let e = triangle_face_deviation(table, iso, f, n).expect("deviation");
                // f32 weights on coordinates of size 10: a few 1e-6 at most.
                assert!(
                    (e - expected).abs() <= 1e-5,
                    "face {f} n = {n}: {e} vs {expected}"
                );
            }
        }
    }

    /// On a bumpy regular torus, the samples of every triangle in closed form (the quartic box
    /// spline, [`SampleGrid::with_closed_form`]) are the table's stencils applied to the same
    /// control points, to the table's `f32` rounding; a butterfly table's regular patch is not a
    /// quartic, and its samples stay the table's.
    #[test]
    #[cfg(all(feature = "loop", feature = "butterfly"))]
    fn regular_loop_samples_in_closed_form_are_the_tables() {
        let mesh = lattice_torus(SIDE, |a, b| {
            let (s, t) = (
                std::f64::consts::TAU * a as f64 / SIDE as f64,
                std::f64::consts::TAU * b as f64 / SIDE as f64,
            );
            let r = 3.0 + (t + 0.3 * s.sin()).cos();
            [r * s.cos(), r * s.sin(), t.sin()]
        });
        let table = StencilTable::default_loop().expect("table");
        let iso = isolate_loop(&mesh).expect("isolates");
        let grid = sample_grid(&table).expect("grid");
        assert!(
            grid.quartic.is_some(),
            "Loop's regular patch is the quartic"
        );
        let stencils = SampleGrid::new(grid.rates.clone());
        let ctx = Context::new(&table, &iso).expect("context");
        for f in 0..iso.patches.len() {
            assert!(is_loop_regular(&iso.patches[f]));
            let closed = ctx.samples(f, &grid).expect("samples");
            let table_sums = ctx.samples(f, &stencils).expect("samples");
            assert_eq!(closed.len(), 1730);
            assert_eq!(table_sums.len(), closed.len());
            for (a, b) in closed.iter().zip(&table_sums) {
                let d: f64 = (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt();
                assert!(d < 4e-6, "face {f}: {a:?} != {b:?}");
            }
        }
        let butterfly = StencilTable::default_butterfly().expect("table");
        assert!(sample_grid(&butterfly).expect("grid").quartic.is_none());
    }

    #[test]
    #[cfg(feature = "loop")]
    fn loop_deviation_has_the_closed_form_on_a_quadratic_lattice() {
        let c = 0.25;
        let table = StencilTable::default_loop().expect("table");
        let iso = isolate_loop(&quadratic_torus(c)).expect("isolates");
        check_closed_form(&table, &iso, c, &[1, 2, 3, 4, 6, 8, 12, 24]);
    }

    #[test]
    #[cfg(feature = "butterfly")]
    fn butterfly_deviation_has_the_closed_form_on_a_quadratic_lattice() {
        let c = 0.25;
        let table = StencilTable::default_butterfly().expect("table");
        let iso = isolate_regions(&quadratic_torus(c), RegionScheme::Butterfly).expect("isolates");
        check_closed_form(&table, &iso, c, &[1, 2, 4, 8]);
    }

    #[test]
    #[cfg(feature = "sqrt3")]
    fn sqrt3_deviation_has_the_closed_form_on_a_quadratic_lattice() {
        let c = 0.25;
        let table = StencilTable::default_sqrt3().expect("table");
        let iso = isolate_regions(&quadratic_torus(c), RegionScheme::Sqrt3).expect("isolates");
        check_closed_form(&table, &iso, c, &[1, 2, 4, 8]);
    }

    /// With rates among the divisors of 24 every `e_f(n)` is the closed form, so `T` just above
    /// `4c / 9m^2` selects exactly `m` (every smaller divisor exceeds it), except `m = 2`, where
    /// rate 1 already meets it (`c / 9 < 1.01 c / 9`).
    #[test]
    #[cfg(feature = "loop")]
    fn tolerance_rates_are_minimal_on_the_closed_form() {
        let c = 0.25;
        let table = StencilTable::default_loop().expect("table");
        let iso = isolate_loop(&quadratic_torus(c)).expect("isolates");
        let divisors = [1, 2, 3, 4, 6, 8, 12, 24];
        for m in [2u32, 3, 4, 6, 8, 12, 24] {
            let t = 1.01 * 4.0 * c / (9.0 * f64::from(m * m));
            let chosen = triangle_tolerance_rates_among(&table, &iso, t, &divisors).expect("rates");
            let expected = if m == 2 { 1 } else { m };
            for f in inner_faces() {
                assert_eq!(chosen.rates[f], expected, "face {f} T = {t}");
            }
        }
    }

    /// A flat lattice: the limit surface is affine on the inner triangles, which rate 1 meets
    /// for any tolerance.
    #[test]
    #[cfg(feature = "loop")]
    fn a_flat_region_gets_rate_one() {
        let table = StencilTable::default_loop().expect("table");
        let iso = isolate_loop(&quadratic_torus(0.0)).expect("isolates");
        for t in [1e-2, 1e-4, 1e-6] {
            let chosen = triangle_tolerance_rates(&table, &iso, t).expect("rates");
            for f in inner_faces() {
                assert_eq!(chosen.rates[f], 1, "face {f} T = {t}");
            }
        }
    }

    #[test]
    #[cfg(all(
        feature = "catmull-clark",
        feature = "loop",
        feature = "butterfly",
        feature = "sqrt3"
    ))]
    fn tables_say_which_rates_they_have() {
        let loop_table = StencilTable::default_loop().expect("table");
        assert_eq!(
            triangle_table_rates(&loop_table),
            (1..=24).collect::<Vec<_>>()
        );
        // The compact region tables list their rates by markers, as the Loop table does.
        for region in [
            StencilTable::default_butterfly().expect("table"),
            StencilTable::default_sqrt3().expect("table"),
        ] {
            assert_eq!(triangle_table_rates(&region), (1..=24).collect::<Vec<_>>());
        }
        let quads = StencilTable::default_catmull_clark().expect("table");
        assert!(triangle_table_rates(&quads).is_empty());
        assert_eq!(triangle_sampling_rates(&[1, 2, 3, 24, 23]), vec![24, 23]);
        // 325 + 576 primal and dual points at 24, 300 + 529 at 23.
        assert_eq!(SampleGrid::new(vec![24, 23]).params.len(), 1730);
        assert_eq!(SampleGrid::new(vec![8, 7]).params.len(), 194);
    }

    /// A lattice of `cells x cells` parallelograms with a boundary, two triangles each.
    fn open_lattice(cells: i64) -> Mesh {
        let side = cells + 1;
        let positions = (0..side * side)
            .map(|k| {
                let (a, b) = ((k % side) as f64, (k / side) as f64);
                [a + 0.5 * b, 0.8 * b, 0.1 * (a * a - b * b)]
            })
            .collect();
        let mut faces = Vec::new();
        for b in 0..cells {
            for a in 0..cells {
                let v = a + side * b;
                faces.push(vec![v, v + 1, v + side]);
                faces.push(vec![v + 1, v + side + 1, v + side]);
            }
        }
        Mesh::new(positions, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("valid")
    }

    /// The index of the output vertex at `p` (they are all distinct).
    fn vertex_at(out: &TriangleMesh, p: [f64; 3]) -> u32 {
        let (best, distance) = out
            .positions
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let d = (0..3)
                    .map(|c| (p[c] - f64::from(q[c])).powi(2))
                    .sum::<f64>();
                (i, d.sqrt())
            })
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        assert!(distance < 1e-5, "no output vertex at {p:?} ({distance})");
        best as u32
    }

    /// `L_{f,n}` over all triangles is the tessellator's uniform output, triangle for triangle:
    /// the templates follow the tessellator's connectivity (closed, extraordinary, boundary).
    #[test]
    #[cfg(feature = "loop")]
    fn local_tessellations_are_the_tessellators_triangles() {
        let table = StencilTable::default_loop().expect("table");
        for (name, mesh) in [("octahedron", octahedron()), ("open", open_lattice(3))] {
            let iso = isolate_loop(&mesh).expect("isolates");
            let ctx = Context::new(&table, &iso).expect("context");
            for n in [1u32, 2, 3, 5] {
                let rates = vec![n; iso.patches.len()];
                let (out, _) =
                    tessellate_triangles(&table, &iso.mesh, &iso.patches, &rates).expect("out");
                let sorted = |mut t: [u32; 3]| {
                    t.sort_unstable();
                    t
                };
                let expected: HashSet<[u32; 3]> =
                    out.triangles.iter().map(|&t| sorted(t)).collect();
                let mut seen = HashSet::new();
                for f in 0..iso.patches.len() {
                    let points = ctx.local_points(f, n).expect("points");
                    let ids = Ids { n };
                    for t in ids.triangles(ctx.boundary_mask(f)) {
                        let v = sorted(t.map(|i| vertex_at(&out, points[i as usize])));
                        assert!(expected.contains(&v), "{name} n = {n} face {f}: {t:?}");
                        seen.insert(v);
                    }
                }
                assert_eq!(
                    seen, expected,
                    "{name} n = {n}: every output triangle covers a face"
                );
            }
        }
    }
}
