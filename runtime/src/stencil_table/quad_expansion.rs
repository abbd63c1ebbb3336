//! Grid stencils from a compact quad table: the scaling relation of Schaefer–Warren (section
//! 5.2, in the matrix form of `shared/notes/extraordinary-stencils.md`) solved by substitution
//! when a plan first asks for a grid.
//!
//! Let `phi(x)` be the row of the `K` basis functions of a patch's control points at `x` in
//! `[0,1]^2` (the vertex at `x = 0`), `A` its local subdivision matrix and `R_b` the matrices of
//! its three regular sub-patches. One subdivision step does not change the surface, so
//!
//! * `phi(x) = phi(2x) A` for `x` in `[0,1/2]^2`, `x != 0`;
//! * `phi(x) = psi(2x - o_b) R_b` for `x` in sub-patch `b` with origin `o_b`, `psi` the
//!   regular tensor-product basis, `psi_(p,q)(t) = w_p(t_u) w_q(t_v)`;
//! * `phi(0)` is the limit-position mask, and the tangents at `0` are the tangent masks (not
//!   parametric derivatives: the characteristic map scales by the subdominant eigenvalue);
//! * each step multiplies a derivative by 2.
//!
//! On the rate-`n` grids the doubled point of a grid point is a primal grid point again (a dual
//! point `((2i+1)/2n, (2j+1)/2n)` doubles to the primal `((2i+1)/n, (2j+1)/n)`), so the relation
//! is triangular once the points are taken by decreasing `max(u, v)`: every grid point is a
//! sub-patch point (known from the curve basis `w`) or the image of a point already done. The
//! table stores exactly what substitution cannot produce: `w` per rate (solved from the curve's
//! own scaling relation), and per patch `A`, the `R_b` and the three vertex masks. The grids come
//! out in f64 and are rounded once to f32, as the grid layout's solves are; they agree with a
//! grid table to 1 ulp of f32 (`runtime/tests/integration/compact_tables.rs`).
//!
//! The choice at `max(u, v) = 1/2` follows the grid layout's system (`x` is written through
//! `2x`, not through the sub-patch), so that the two layouts round the same sums.

use table_format::{PointSet, SectionKey, StencilKind, TableIndex};

use super::{check_patch_pieces, compact_pieces, GridSlots, Grids, PatchId, MAX_COMPACT_RATE};
use crate::once::TryOnce;
use crate::RuntimeError;

/// What a compact table's grids are expanded from, and the grids once a plan asked for them.
#[derive(Debug)]
pub(super) struct QuadExpansion {
    /// Rates with both curve-basis sections; patches with all five pieces.
    slots: GridSlots,
}

impl QuadExpansion {
    /// The expansion of a validated table, `None` if it holds no scaling-relation pieces. A
    /// piece without the others it needs (a patch's `A` without its sub-patch matrices or vertex
    /// masks, a curve basis without its derivative) or in f32 is an error naming it.
    pub(super) fn new(index: &TableIndex) -> Result<Option<Self>, RuntimeError> {
        let Some(pieces) = compact_pieces(index)? else {
            return Ok(None);
        };
        let incomplete = |what: String| RuntimeError::InvalidParameter {
            name: "table".to_owned(),
            reason: format!(
                "{what}: a compact table needs every piece of the scaling relation; regenerate \
                 it with `stencilgen tables`"
            ),
        };
        let mut rates = Vec::new();
        let mut patches = Vec::new();
        for key in pieces {
            match key.points {
                PointSet::CurveBasis => {
                    // Four control points an axis: the sub-patch matrices' 4 x 4 nets.
                    if index.entry(key)?.width != 4 {
                        return Err(incomplete(format!("{key} is not 4 weights a row")));
                    }
                    if !(1..=MAX_COMPACT_RATE).contains(&key.n) {
                        return Err(incomplete(format!(
                            "{key} is not at a rate in 1..={MAX_COMPACT_RATE}"
                        )));
                    }
                    let derivative = SectionKey {
                        kind: StencilKind::DerivativeU,
                        ..*key
                    };
                    match (key.kind, index.get(&derivative)) {
                        (StencilKind::Position, None) => {
                            return Err(incomplete(format!("{key} has no derivative section")))
                        }
                        (StencilKind::Position, Some(_)) => rates.push(key.n),
                        _ => {}
                    }
                }
                PointSet::Subdivision => {
                    let width = index.entry(key)?.width;
                    check_patch_pieces(index, key, width, PointSet::SubPatches, incomplete)?;
                    patches.push((PatchId::of(key), width));
                }
                _ => {}
            }
        }
        Ok(Some(QuadExpansion {
            slots: GridSlots::new(rates, patches),
        }))
    }

    /// The grid stencils of `key` (a primal or dual section), expanded on first use from
    /// `bytes`, the bytes `index` was parsed from. `None` if the table cannot expand it.
    pub(super) fn grid<'s>(
        &'s self,
        index: &TableIndex,
        bytes: &[u8],
        key: &SectionKey,
    ) -> Option<Result<&'s [f32], RuntimeError>> {
        let primal = match key.points {
            PointSet::Primal => true,
            PointSet::Dual => false,
            _ => return None,
        };
        let slot = self.slots.slot(key)?;
        Some(
            slot.grids
                .get_or_try(|| expand(index, bytes, key, slot.k))
                .map(|grids| &*grids[usize::from(!primal)]),
        )
    }
}

/// The pieces of one patch at one rate, read from the table.
struct Pieces<'a> {
    k: usize,
    n: usize,
    /// `A`, `K x K`.
    a: &'a [f64],
    /// `R_0, R_1, R_2`, `48 x K`.
    sub_patches: &'a [f64],
    /// The stencil at the vertex for this kind.
    vertex: &'a [f64],
    /// `w_p(t/n)`, `t = 0..=n`, 4 a row.
    values: &'a [f64],
    /// `w_p'(t/n)`.
    derivatives: &'a [f64],
}

fn expand(
    index: &TableIndex,
    bytes: &[u8],
    key: &SectionKey,
    k: usize,
) -> Result<Grids, RuntimeError> {
    let piece = |kind, points, n| -> Result<&[f64], RuntimeError> {
        let at = SectionKey {
            kind,
            points,
            n,
            ..*key
        };
        Ok(index.weights_f64(bytes, &at)?)
    };
    let basis = |kind| -> Result<&[f64], RuntimeError> {
        let at = SectionKey {
            kind,
            points: PointSet::CurveBasis,
            boundary: false,
            feature: table_format::Feature::None,
            faces: 0,
            sector: 0,
            n: key.n,
        };
        Ok(index.weights_f64(bytes, &at)?)
    };
    let pieces = Pieces {
        k,
        n: key.n as usize,
        a: piece(StencilKind::Position, PointSet::Subdivision, 0)?,
        sub_patches: piece(StencilKind::Position, PointSet::SubPatches, 0)?,
        vertex: piece(key.kind, PointSet::VertexMask, 0)?,
        values: basis(StencilKind::Position)?,
        derivatives: basis(StencilKind::DerivativeU)?,
    };
    Ok(pieces.grids(key.kind))
}

impl Pieces<'_> {
    /// Both grids of `kind` (module docs), rounded to f32.
    fn grids(&self, kind: StencilKind) -> Grids {
        let (k, n) = (self.k, self.n);
        let factor = if kind == StencilKind::Position {
            1.0
        } else {
            2.0
        };
        let (u_derivative, v_derivative) = match kind {
            StencilKind::Position => (false, false),
            StencilKind::DerivativeU => (true, false),
            StencilKind::DerivativeV => (false, true),
        };
        let axis = |t: usize, derivative: bool| -> &[f64] {
            let rows = if derivative {
                self.derivatives
            } else {
                self.values
            };
            &rows[4 * t..4 * t + 4]
        };
        // columns[b][t_u][q] = sum_p w_p(t_u) factor R_b[(p, q)]: the sub-patch stencil at
        // (t_u, t_v) is then sum_q w_q(t_v) columns[b][t_u][q], four rows instead of sixteen.
        let columns: Vec<Vec<f64>> = (0..3)
            .map(|b| {
                let r = &self.sub_patches[16 * k * b..16 * k * (b + 1)];
                let mut out = vec![0.0; (n + 1) * 4 * k];
                for tu in 0..=n {
                    let wu = axis(tu, u_derivative);
                    for q in 0..4 {
                        let column = &mut out[(tu * 4 + q) * k..(tu * 4 + q + 1) * k];
                        for (p, &w) in wu.iter().enumerate() {
                            let row = &r[(4 * q + p) * k..(4 * q + p + 1) * k];
                            for (c, &e) in column.iter_mut().zip(row) {
                                *c += w * (factor * e);
                            }
                        }
                    }
                }
                out
            })
            .collect();
        // Points in units of 1/2n: primal (2i, 2j), dual (2i+1, 2j+1).
        let sub_patch = |a: usize, b: usize, out: &mut [f64]| {
            let (index, (a0, b0)) = match (a > n, b > n) {
                (true, false) => (0, (1, 0)),
                (true, true) => (1, (1, 1)),
                _ => (2, (0, 1)),
            };
            let (tu, tv) = (a - a0 * n, b - b0 * n);
            let wv = axis(tv, v_derivative);
            let column = &columns[index][tu * 4 * k..(tu + 1) * 4 * k];
            for (q, &w) in wv.iter().enumerate() {
                for (o, &c) in out.iter_mut().zip(&column[q * k..(q + 1) * k]) {
                    *o += w * c;
                }
            }
        };
        // phi(x) = factor phi(2x) A: row i of A scaled by the doubled point's weight i.
        let through_a = |doubled: &[f64], out: &mut [f64]| {
            for (i, &d) in doubled.iter().enumerate() {
                let row = &self.a[i * k..(i + 1) * k];
                for (o, &e) in out.iter_mut().zip(row) {
                    *o += (factor * e) * d;
                }
            }
        };
        let side = n + 1;
        let mut primal = vec![0.0f64; side * side * k];
        for m in (0..=n).rev() {
            // The points with max(i, j) = m, whose doubles (max 2m) are done.
            let ring = (0..=m).map(|i| (i, m)).chain((0..m).map(|j| (m, j)));
            for (i, j) in ring {
                let at = (j * side + i) * k;
                if (i, j) == (0, 0) {
                    primal[..k].copy_from_slice(self.vertex);
                } else if 2 * m <= n {
                    // The doubled point (2i, 2j) comes later in memory (row j' = 2j >= j,
                    // and i' = 2i > i where the rows are equal).
                    let from = (2 * j * side + 2 * i) * k;
                    let (point, after) = primal[at..].split_at_mut(k);
                    through_a(&after[from - at - k..from - at], point);
                } else {
                    sub_patch(2 * i, 2 * j, &mut primal[at..at + k]);
                }
            }
        }
        let mut dual = vec![0.0f64; n * n * k];
        for j in 0..n {
            for i in 0..n {
                let out = &mut dual[(j * n + i) * k..(j * n + i + 1) * k];
                let (a, b) = (2 * i + 1, 2 * j + 1);
                if a.max(b) <= n {
                    let from = (b * side + a) * k;
                    through_a(&primal[from..from + k], out);
                } else {
                    sub_patch(a, b, out);
                }
            }
        }
        let round = |v: Vec<f64>| -> Box<[f32]> { v.into_iter().map(|w| w as f32).collect() };
        [round(primal), round(dual)]
    }
}
