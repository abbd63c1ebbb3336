//! Regular input faces evaluated whole, from the input points.
//!
//! Isolation refines the whole mesh (`scheme::catmull_clark::isolate`), so a regular input quad
//! far from any irregularity becomes `4^s` isolated faces after `s` steps, each a bicubic
//! B-spline patch whose control points the refinement map makes every frame. They are pieces of
//! one patch: the input face's own, over its 16 input points (the B-spline's subdivision is its
//! knot insertion), and the dual points of its pieces at rate `n` are the dual points of the
//! input face at rate `N = 2^s n`: `(a + (2i + 1) / 2n) / 2^s = (2(a n + i) + 1) / 2N` along
//! each side, the piece in cell `a` (Schaefer and Warren's scaling relation, on the regular
//! patch). So such a face is evaluated as one tensor product at rate `N` from its input points,
//! its points written into its pieces' blocks, and the refinement map keeps only the rows the
//! other faces read.
//!
//! Why: the map cost the quad-dominant sword (`../shared/models/odedstein`, 348 of its 22,465
//! faces triangles) an eighth of its frame, and a tensor product contracts its columns once per
//! group of four where `4^s` pieces contracted theirs once each: at rate 4 the sword's frame
//! went from 41.6 to 37.6 ms on one thread (docs/benchmarks.md).
//!
//! Each piece's points stay in its own order: piece `k` is turned by a quarter `turns` times
//! from the input face's axes ([`Placement`]). Every group of four columns of the input face
//! is contracted once and its rows made two at a time (a row and its mirror, as
//! [`super::rows_by_pairs`] does); then each run of four rows goes to its piece, as rows under
//! no turn or half a turn (reversed), as the piece's columns under a quarter (four rows
//! transposed), so that every store takes four consecutive points. The points are staged in a
//! worker's buffer in the output's order and copied out whole: written straight to their
//! pieces, a block at a time out of order, the frame took 38.8 ms (35 staged, 41 face by
//! face). Only rate 4 takes this path ([`WHOLE_RATE`]).

use std::ops::Range;

use wide::f32x4;

use super::{contract_columns, even_odd, pair_points, DualGrid, FaceEval, SeparableBasis};
use crate::scheme::catmull_clark::adaptive::bspline;
use crate::scheme::catmull_clark::isolate::{Placement, MAX_STEPS};
use crate::scheme::stencil::Stencil;
use crate::tessellate::kernel::{relative, total_bytes, vec_bytes};
use crate::tessellate::lane_stencils::{store_points, store_points_reversed, LANES};
use crate::RuntimeError;

/// Cells per side of an input face, at most ([`MAX_STEPS`] steps).
const MAX_CELLS: usize = 1 << MAX_STEPS;

/// Rows of an input face evaluated whole, at most (a rate of 64 along its side).
const MAX_ROWS: usize = 64;

/// The rate of the isolated faces evaluated whole. The code takes any multiple of four (a
/// group of four columns then lies in one piece); at rate 8 the sword's frame measured slower
/// than face by face (125 against 113 ms, the face's staged points, 24 KiB, no longer in the
/// first-level cache beside the rows), so only rate 4 takes this path (docs/benchmarks.md).
const WHOLE_RATE: u32 = 4;

/// A worker's buffers for [`InputPatches::evaluate_unit`]: the rows of one group of columns of
/// an input face between their sums and their stores, and the face's points staged in the
/// output's order.
pub(super) struct Scratch {
    rows: Vec<Points>,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
}

/// Four points' positions and unit normals, a coordinate per vector.
pub(super) type Points = ([f32x4; 3], [f32x4; 3]);

/// One input face evaluated whole: its isolated faces `faces` (contiguous, one block of `n^2`
/// points each, in face order), where they lie, its 16 input points and its rate.
#[derive(Clone, Debug)]
struct InputPatch {
    faces: Range<u32>,
    /// `pieces[a][b]`: the face in cell `(a, b)` ([`Placement`]), as its index from
    /// `faces.start`, and its quarter turns.
    pieces: [[(u8, u8); MAX_CELLS]; MAX_CELLS],
    /// `net[a][b]` at `(a - 1, b - 1)` of the input face's grid, as indices into the frame's
    /// control points (the input points follow the map's rows).
    net: [[u32; 4]; 4],
    /// The rate of its isolated faces.
    n: u32,
    /// Its basis at rate `2^steps n` (`InputPatches::bases`).
    basis: u32,
}

/// What a frame evaluates as one piece of work: a face, or an input face's faces together.
#[derive(Clone, Copy, Debug)]
enum Unit {
    Face(u32),
    Patch(u32),
}

/// The input faces a [`DualGrid`] evaluates whole ([`DualGrid::with_input_patches`]).
#[derive(Clone, Debug)]
pub(super) struct InputPatches {
    patches: Vec<InputPatch>,
    /// Cells per side of an input face (`2^steps`).
    cells: usize,
    /// The B-spline factors at the rates `2^steps n` met, with those rates.
    bases: Vec<(usize, SeparableBasis)>,
    /// The input points to the control points the other faces read: a selection of the
    /// isolation's rows, then (in the frame) the input points.
    map: Stencil<f64>,
    /// The frame's pieces of work, and where each one's points end.
    units: Vec<Unit>,
    unit_ends: Vec<usize>,
}

impl InputPatches {
    /// The map from the input points to the rows of the control points the plan reads; the
    /// input points follow them.
    pub(super) fn map(&self) -> &Stencil<f64> {
        &self.map
    }

    /// Where each piece of work's points end (the plan's `evaluate` hands them out).
    pub(super) fn unit_ends(&self) -> &[usize] {
        &self.unit_ends
    }

    /// About the heap bytes.
    pub(super) fn heap_bytes(&self) -> usize {
        total_bytes([
            vec_bytes(&self.patches),
            vec_bytes(&self.bases),
            self.map.heap_bytes(),
            vec_bytes(&self.units),
            vec_bytes(&self.unit_ends),
        ])
    }

    /// Evaluate piece of work `unit` into its points.
    pub(super) fn evaluate_unit(
        &self,
        grid: &DualGrid,
        unit: usize,
        control: &[[f64; 3]],
        (positions, normals): (&mut [[f32; 3]], &mut [[f32; 3]]),
        scratch: &mut Scratch,
    ) {
        match self.units[unit] {
            Unit::Face(f) => grid.evaluate_face(f as usize, control, positions, normals),
            Unit::Patch(k) => self.evaluate_patch(
                &self.patches[k as usize],
                control,
                positions,
                normals,
                scratch,
            ),
        }
    }

    /// A worker's buffers for [`InputPatches::evaluate_unit`] (made once per chunk of units).
    pub(super) fn scratch() -> Scratch {
        Scratch {
            rows: vec![([f32x4::ZERO; 3], [f32x4::ZERO; 3]); MAX_ROWS],
            positions: Vec::new(),
            normals: Vec::new(),
        }
    }

    /// Every point of `patch`'s faces ([`InputPatches`], module docs): every group of four
    /// columns of the input face contracted once, its rows made two at a time (a row and its
    /// mirror, [`pair_points`]), each run of four rows stored in its piece's block in the
    /// worker's buffers, which are then copied out whole.
    fn evaluate_patch(
        &self,
        patch: &InputPatch,
        control: &[[f64; 3]],
        out_positions: &mut [[f32; 3]],
        out_normals: &mut [[f32; 3]],
        scratch: &mut Scratch,
    ) {
        scratch.positions.resize(out_positions.len(), [0.0; 3]);
        scratch.normals.resize(out_normals.len(), [0.0; 3]);
        let Scratch {
            rows: buffer,
            positions,
            normals,
        } = scratch;
        let (n, cells) = (patch.n as usize, self.cells);
        let Some((_, basis)) = self.bases.get(patch.basis as usize) else {
            return;
        };
        let origin = control[patch.net[1][1] as usize];
        let g = patch
            .net
            .map(|column| column.map(|v| relative(control[v as usize], origin)));
        let origin = origin.map(|c| f32x4::splat(c as f32));
        let rows = cells * n;
        if rows > MAX_ROWS || buffer.len() < rows {
            return;
        }
        // Columns and rows walk cell by cell, four at a time.
        let mut columns = basis.x_lanes.iter().zip(&basis.dx_lanes);
        for pieces in &patch.pieces[..cells] {
            for i in (0..n).step_by(LANES) {
                let Some((x, dx)) = columns.next() else {
                    return;
                };
                let (q, dq) = contract_columns(&g, x, dx);
                let (sq, sdq) = (even_odd(&q), even_odd(&dq));
                for (row, w) in basis.y_pairs.iter().enumerate() {
                    let (p, normal) = pair_points(&sq, &sdq, w, origin);
                    buffer[row] = (p[0], normal[0]);
                    buffer[rows - 1 - row] = (p[1], normal[1]);
                }
                let mut runs = buffer[..rows].chunks_exact(LANES);
                for &(k, turns) in &pieces[..cells] {
                    let k = usize::from(k);
                    let block = k * n * n..(k + 1) * n * n;
                    for j in (0..n).step_by(LANES) {
                        let Some(Ok(run)) = runs.next().map(<&[_; LANES]>::try_from) else {
                            return;
                        };
                        let out = (&mut positions[block.clone()], &mut normals[block.clone()]);
                        store_run(run, out, n, (i, j), turns);
                    }
                }
            }
        }
        out_positions.copy_from_slice(positions);
        out_normals.copy_from_slice(normals);
    }
}

/// Four rows of four points each (`points[r]`: the position and the normal of the input face's
/// columns `i..i + 4` on row `j + r` of the cell) into their piece's block `out`, turned `turns`
/// quarters: rows stay rows under no turn or half a turn (reversed), and become the piece's
/// columns under a quarter, transposed, so that every store takes four consecutive points.
#[inline(always)]
fn store_run(
    points: &[Points; LANES],
    (positions, normals): (&mut [[f32; 3]], &mut [[f32; 3]]),
    n: usize,
    (i, j): (usize, usize),
    turns: u8,
) {
    let mut put = |(v, w): Points, at: usize, reversed: bool| {
        let out = at..at + LANES;
        if reversed {
            store_points_reversed(v, &mut positions[out.clone()]);
            store_points_reversed(w, &mut normals[out]);
        } else {
            store_points(v, &mut positions[out.clone()]);
            store_points(w, &mut normals[out]);
        }
    };
    match turns {
        0 => (0..LANES).for_each(|r| put(points[r], (j + r) * n + i, false)),
        2 => (0..LANES).for_each(|r| put(points[r], (n - 1 - j - r) * n + n - LANES - i, true)),
        _ => {
            let columns = transpose(points);
            for (l, column) in columns.into_iter().enumerate() {
                // Column `i + l`, rows `j..j + 4`: under one quarter turn the piece's row
                // `n - 1 - i - l` from its column `j` on, under three its row `i + l`
                // backwards from its column `n - 1 - j`.
                if turns == 1 {
                    put(column, (n - 1 - i - l) * n + j, false);
                } else {
                    put(column, (i + l) * n + n - LANES - j, true);
                }
            }
        }
    }
}

/// Four rows of four points as four columns: column `l` holds point `l` of every row, row by
/// row in the lanes (positions and normals alike).
#[inline(always)]
fn transpose(rows: &[Points; LANES]) -> [Points; LANES] {
    let p: [[f32x4; LANES]; 3] = std::array::from_fn(|c| f32x4::transpose(rows.map(|(p, _)| p[c])));
    let m: [[f32x4; LANES]; 3] = std::array::from_fn(|c| f32x4::transpose(rows.map(|(_, m)| m[c])));
    std::array::from_fn(|l| ([p[0][l], p[1][l], p[2][l]], [m[0][l], m[1][l], m[2][l]]))
}

/// The cubic B-spline's factors at the dual points of rate `n`, from its polynomials in f64
/// ([`bspline`]): the regular patch's table stencils are their products (the table's own
/// factors, [`SeparableBasis::from_stencils`], to f32 rounding), and rates `2^s n` run past the
/// table's.
fn bspline_basis(n: usize) -> SeparableBasis {
    let mut x: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; n]);
    let mut dx = x.clone();
    for i in 0..n.div_ceil(2) {
        let (w, d) = bspline((2 * i + 1) as f64 / (2 * n) as f64);
        // The B-spline is symmetric: `B_a(1 - t) = B_{3-a}(t)`, its derivative changes sign.
        // Mirrored by construction, the rows pair exactly ([`SeparableBasis::y_pairs`]).
        for a in 0..4 {
            x[a][i] = w[a] as f32;
            dx[a][i] = d[a] as f32;
            x[3 - a][n - 1 - i] = w[a] as f32;
            dx[3 - a][n - 1 - i] = -d[a] as f32;
        }
    }
    SeparableBasis::from_factors(x.clone(), dx.clone(), x, dx)
}

/// The faces `run` of one input face by cell ([`InputPatch::pieces`]), or `None` unless they
/// tile its `cells x cells` cells once each.
fn cells_of(
    run: Range<usize>,
    placement: impl Fn(usize) -> Option<Placement>,
    cells: usize,
) -> Option<[[(u8, u8); MAX_CELLS]; MAX_CELLS]> {
    let mut pieces = [[(0u8, 0u8); MAX_CELLS]; MAX_CELLS];
    let mut seen = [[false; MAX_CELLS]; MAX_CELLS];
    for (k, f) in run.enumerate() {
        let p = placement(f)?;
        let (a, b) = (p.a as usize, p.b as usize);
        if a >= cells || b >= cells || std::mem::replace(&mut seen[a][b], true) {
            return None;
        }
        pieces[a][b] = (u8::try_from(k).ok()?, p.turns);
    }
    Some(pieces)
}

impl DualGrid {
    /// Evaluate the regular input faces whole from the input points ([`InputPatches`]), where
    /// isolation took `steps` steps: `nets[F]` is input face `F`'s 16 input points when it is a
    /// B-spline patch of plain points (no hole, no sharp feature, no reflected point),
    /// `origin[f]` and `placement(f)` say where isolated face `f` lies, `map` makes the isolated
    /// points from the input points. An input face whose isolated faces all take the
    /// separable path at rate [`WHOLE_RATE`] is evaluated whole; the map keeps the rows the
    /// other faces read. Nothing changes where no face qualifies. The plan's `evaluate` then
    /// reads the map's rows followed by the input points (`GridPlan::control_map`), not the
    /// isolated mesh's points.
    pub(crate) fn with_input_patches(
        mut self,
        steps: usize,
        nets: &[Option<[[u32; 4]; 4]>],
        origin: &[u32],
        placement: impl Fn(usize) -> Option<Placement>,
        map: &Stencil<f64>,
    ) -> Result<Self, RuntimeError> {
        if steps == 0 || steps > MAX_STEPS || nets.iter().all(Option::is_none) {
            return Ok(self);
        }
        let cells = 1usize << steps;
        let pieces = cells * cells;
        let faces = self.faces.len();
        let mut patches = Vec::new();
        let mut bases: Vec<(usize, SeparableBasis)> = Vec::new();
        let mut f = 0;
        while f < faces {
            let run = f..(f + pieces).min(faces);
            let input = origin[f] as usize;
            let n = self.rates[f];
            let whole = run.len() == pieces
                && n == WHOLE_RATE
                && cells * n as usize <= MAX_ROWS
                && run.clone().all(|g| {
                    origin[g] as usize == input
                        && self.rates[g] == n
                        && matches!(self.faces[g], FaceEval::Separable { .. })
                });
            let found = nets.get(input).copied().flatten().filter(|_| whole);
            let Some((net, pieces)) =
                found.and_then(|net| Some((net, cells_of(run.clone(), &placement, cells)?)))
            else {
                f += 1;
                continue;
            };
            let rate = cells * n as usize;
            let basis = match bases.iter().position(|(m, _)| *m == rate) {
                Some(k) => k,
                None => {
                    bases.push((rate, bspline_basis(rate)));
                    bases.len() - 1
                }
            };
            for g in run.clone() {
                self.faces[g] = FaceEval::Input;
            }
            patches.push(InputPatch {
                faces: run.start as u32..run.end as u32,
                pieces,
                net,
                n,
                basis: basis as u32,
            });
            f = run.end;
        }
        if patches.is_empty() {
            return Ok(self);
        }
        // The rows the other faces read, renumbered in order; the input points after them.
        let mut read = vec![false; map.rows()];
        let mut mark = |v: u32| {
            if let Some(r) = read.get_mut(v as usize) {
                *r = true;
            }
        };
        for face in &self.faces {
            if let FaceEval::Separable { grid } | FaceEval::Phantom { grid, .. } = face {
                grid.iter().flatten().for_each(|&v| mark(v));
            }
        }
        self.control.iter().for_each(|&v| mark(v));
        let rows: Vec<u32> = (0..map.rows() as u32)
            .filter(|&v| read[v as usize])
            .collect();
        let mut renumber = vec![u32::MAX; map.rows()];
        for (new, &old) in rows.iter().enumerate() {
            renumber[old as usize] = new as u32;
        }
        let moved = |v: u32| renumber[v as usize];
        for face in &mut self.faces {
            if let FaceEval::Separable { grid } | FaceEval::Phantom { grid, .. } = face {
                *grid = grid.map(|column| column.map(moved));
            }
        }
        for v in &mut self.control {
            *v = moved(*v);
        }
        // The input points follow the rows: every index must fit in u32.
        let too_many =
            || RuntimeError::Unsupported("more control points than u32 indices".to_owned());
        let base = u32::try_from(rows.len()).map_err(|_| too_many())?;
        let last = patches
            .iter()
            .flat_map(|patch| patch.net.iter().flatten())
            .max()
            .copied()
            .unwrap_or(0);
        base.checked_add(last).ok_or_else(too_many)?;
        for patch in &mut patches {
            patch.net = patch.net.map(|column| column.map(|v| base + v));
        }
        // The units: the faces in order, a patch's faces as one.
        let mut units = Vec::with_capacity(faces);
        let mut unit_ends = Vec::with_capacity(faces);
        let mut next = patches.iter().enumerate().peekable();
        let mut f = 0;
        while f < faces {
            match next.peek() {
                Some((k, patch)) if patch.faces.start as usize == f => {
                    units.push(Unit::Patch(*k as u32));
                    f = patch.faces.end as usize;
                    next.next();
                }
                _ => {
                    units.push(Unit::Face(f as u32));
                    f += 1;
                }
            }
            unit_ends.push(self.face_ends[f - 1]);
        }
        self.input = Some(InputPatches {
            patches,
            cells,
            bases,
            map: map.select(&rows),
            units,
            unit_ends,
        });
        Ok(self)
    }
}
