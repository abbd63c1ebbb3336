//! Table faces at rates 16, 24, 32, ... through one subdivision step: three regular sub-patches
//! as tensor products, the quarter at the vertex from the table at half the rate.
//!
//! A compact table stores, per patch, its local subdivision matrix `A` and its three regular
//! sub-patch matrices `R_b` (docs/table-format.md, "Compact quad tables"), with which the
//! patch's basis `phi` satisfies (Schaefer–Warren section 5.2, the scaling relation;
//! `stencil_table::quad_expansion` derives the table's grids from the same two identities):
//!
//! ```text
//! phi(x) = phi(2x) A             for x in [0, 1/2]^2 (the quarter at the vertex),
//! phi(x) = psi(2x - o_b) R_b     for x in sub-patch b (o_0 = (1,0), o_1 = (1,1), o_2 = (0,1)),
//! ```
//!
//! `psi` the regular bicubic B-spline. At a rate `n = 2m` the dual point
//! `((2i+1)/2n, (2j+1)/2n)` doubles to `((2i+1)/2m, (2j+1)/2m)`: the dual point `(i, j)` of rate
//! `m` in the quarter at the vertex, `(i - m, j)`, `(i - m, j - m)` or `(i, j - m)` of rate `m`
//! in sub-patch 0, 1 or 2. So the face's `n^2` points are the patch's own dual grid at rate `m`
//! over the level-1 points `A P` and three regular dual grids at rate `m` over the nets `R_b P`.
//! Each step doubles a derivative, which a unit normal does not see.
//!
//! Why: a table face sums `K = 2N + 8` control points for each of its points (`9 K`
//! multiply-adds a point: position, `d/du`, `d/dv`); three quarters of them through the
//! tensor product cost the level-1 points once (a few terms each: `R_b` and `A` are the
//! subdivision rules, sparse) and then the regular face's separable sums.

use table_format::{PointSet, StencilKind};
use wide::f32x4;

use crate::scheme::patch::{dual_index_in_patch, PatchKind};
use crate::stencil_table::StencilTable;
use crate::tessellate::kernel::{total_bytes, vec_bytes, MAX_PATCH};
use crate::RuntimeError;

/// Whether a face at rate `n` is split: a multiple of 8 from 16 on, so that the quarter's and
/// the sub-patches' rows (`n / 2` points) are whole groups of four (`lane_stencils::LANES`).
///
/// Why not 8: the triangulated Spot's frame at rate 8 took 3% longer split (its rate-4
/// tensor products and the level-1 points cost what the table's sums at rate 8 do); at 16,
/// 12% less (docs/benchmarks.md).
pub(crate) fn splits(n: u32) -> bool {
    n >= 16 && n % 8 == 0
}

/// Level-1 points a plan may need: the `K` of `A` and the `48` of the nets, before the
/// repeated ones are merged.
pub(crate) const MAX_LEVEL_ONE: usize = MAX_PATCH + 48;

/// One patch kind's split at one rate and face corner, in the face's own parameters.
#[derive(Clone, Debug)]
pub(crate) struct SubPatchPlan {
    /// Half the face's rate: the rate of the quarter and of the sub-patches.
    pub(crate) m: usize,
    /// The distinct level-1 points, each a sparse row over the patch's `K` control points:
    /// row `r`'s terms are `terms[ends[r - 1]..ends[r]]`, (control point, weight in every
    /// lane).
    ends: Vec<u32>,
    terms: Vec<(u8, f32x4)>,
    /// The level-1 layout (`A`'s rows) as level-1 points: the quarter's control points.
    pub(crate) quarter: Vec<u8>,
    /// Where the quarter's points start in the face's grid (its rows are `n` apart).
    pub(crate) quarter_at: usize,
    /// The three sub-patches in the face's parameters: the 4 x 4 net (`net[a][b]`, `a` along the
    /// face's `u`) as level-1 points, and where its `m x m` points start in the face's grid.
    pub(crate) nets: [([[u8; 4]; 4], usize); 3],
}

impl SubPatchPlan {
    /// Its vectors' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        total_bytes([
            vec_bytes(&self.ends),
            vec_bytes(&self.terms),
            vec_bytes(&self.quarter),
        ])
    }

    /// The split of a face of patch `kind` (`k` control points, the vertex at the face's corner
    /// `corner`) at rate `n`, or `None` where the table has no pieces for it (a table of grids,
    /// a one-face boundary corner, whose stencils depend on the mesh's boundary mode), `n` is
    /// a rate that does not split ([`splits`]), or `K` is beyond [`MAX_PATCH`].
    pub(crate) fn new(
        table: &StencilTable,
        kind: &PatchKind,
        k: usize,
        corner: usize,
        n: u32,
    ) -> Result<Option<Self>, RuntimeError> {
        if !splits(n) || k > MAX_PATCH || (kind.boundary && kind.faces == 1) {
            return Ok(None);
        }
        let a_key = kind.section(StencilKind::Position, PointSet::Subdivision, 0);
        let r_key = kind.section(StencilKind::Position, PointSet::SubPatches, 0);
        let index = table.index();
        if index.get(&a_key).is_none() || index.get(&r_key).is_none() {
            return Ok(None);
        }
        let a = index.weights_f64(table.bytes(), &a_key)?;
        let r = index.weights_f64(table.bytes(), &r_key)?;
        if a.len() != k * k || r.len() != 48 * k {
            return Err(RuntimeError::LayoutMismatch {
                key: a_key,
                table: a.len() / k.max(1),
                patch: k,
            });
        }
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let quarter: Vec<u8> = a
            .chunks_exact(k)
            .map(|row| intern(&mut rows, row))
            .collect();
        let (n, m) = (n as usize, n as usize / 2);
        // The face's block (its first point) holding the canonical block `(bu, bv)` (the
        // quarter at (0, 0), sub-patch 0 at (1, 0), 1 at (1, 1), 2 at (0, 1)).
        let block_at = |bu: usize, bv: usize| -> usize {
            let mut at = 0;
            for (fi, fj) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                let (pi, pj) = dual_index_in_patch(corner, fi * m, fj * m, n);
                if (pi / m, pj / m) == (bu, bv) {
                    at = fj * m * n + fi * m;
                }
            }
            at
        };
        let mut nets = [([[0u8; 4]; 4], 0); 3];
        for (b, (net, at)) in nets.iter_mut().enumerate() {
            // `R_b`'s row `4 q + p` is the net's point `(p, q)` in the patch's parameters; a
            // rotation of the parameters is the same rotation of the net's indices.
            for (i, column) in net.iter_mut().enumerate() {
                for (j, point) in column.iter_mut().enumerate() {
                    let (p, q) = dual_index_in_patch(corner, i, j, 4);
                    let row = (16 * b + 4 * q + p) * k;
                    *point = intern(&mut rows, &r[row..row + k]);
                }
            }
            let (bu, bv) = [(1, 0), (1, 1), (0, 1)][b];
            *at = block_at(bu, bv);
        }
        let mut ends = Vec::with_capacity(rows.len());
        let mut terms = Vec::new();
        for row in &rows {
            for (l, &w) in row.iter().enumerate() {
                if w != 0.0 {
                    terms.push((l as u8, f32x4::splat(w as f32)));
                }
            }
            ends.push(terms.len() as u32);
        }
        Ok(Some(SubPatchPlan {
            m,
            ends,
            terms,
            quarter,
            quarter_at: block_at(0, 0),
            nets,
        }))
    }

    /// The level-1 points from the patch's control points `local` (`[x, y, z, 0]`, relative to
    /// its origin; every row's weights sum to one, so the level-1 points are relative to the
    /// same origin), into `out` (as many as the plan has rows).
    #[inline(always)]
    pub(crate) fn level_one(&self, local: &[f32x4], out: &mut [f32x4; MAX_LEVEL_ONE]) {
        let mut start = 0;
        for (point, &end) in out.iter_mut().zip(&self.ends) {
            let mut sum = f32x4::ZERO;
            for &(l, w) in self.terms.get(start..end as usize).unwrap_or_default() {
                if let Some(&q) = local.get(usize::from(l)) {
                    sum += w * q;
                }
            }
            *point = sum;
            start = end as usize;
        }
    }
}

/// The index of `row` among `rows`, appended if new (the sub-patches' nets share rows and
/// columns, and their points near the vertex are `A`'s).
fn intern(rows: &mut Vec<Vec<f64>>, row: &[f64]) -> u8 {
    match rows.iter().position(|known| known == row) {
        Some(at) => at as u8,
        None => {
            rows.push(row.to_vec());
            (rows.len() - 1) as u8
        }
    }
}
