//! Grid stencils from a compact Loop table: the scaling relation of the Loop patch (Schaefer–
//! Warren sections 5.2–5.3 on the triangular lattice; `stencilgen::triangle_patch`) solved by
//! substitution when a plan first asks for a grid.
//!
//! Let `phi(x)` be the row of the `K` basis functions of a patch's control points at
//! `x = (u, v)`, `u, v >= 0`, `u + v <= 1` (the vertex at `x = 0`), `A` its local subdivision
//! matrix and `R_b` the matrices of its three regular sub-triangles (12 level-1 lattice points
//! `j` each, [`sub_triangle_points`]). One subdivision step does not change the surface, so
//!
//! * `phi(x) = f phi(2x) A` when `2x` is in the patch again (`u + v <= 1/2`, `x != 0`);
//! * otherwise `y = 2x` lies in the sub-triangle `b` (next to `E_0` when `y_1 >= 1`, next to
//!   `E_1` when `y_2 >= 1`, else the middle one) and `phi(x) = f sum_j psi(y - j) R_b[j]`,
//!   `psi` Loop's regular basis, the quartic box spline (for derivatives its derivative);
//! * `phi(0)` is the limit-position mask, and the tangents at `0` are the tangent masks;
//!
//! with `f = 1` for positions and `f = 2` for derivatives (each step doubles them). `x -> 2x`
//! strictly increases `u + v`, so taking the points of a lattice `1/d` by decreasing `u + v`
//! every point is a sub-triangle point or the image of one already done. The primal grid of
//! rate `n` is on `d = n`; its dual points, the centroids `((3i+1)/3n, (3j+1)/3n)` and
//! `((3i+2)/3n, (3j+2)/3n)`, are on `d = 3n` and double to points of that lattice that are not
//! primal, so each grid is expanded on its own lattice.
//!
//! `psi` is a polynomial of degree 4 on each lattice triangle, so its values at the points
//! `k/4` determine it: on the triangle holding `y` with barycentric coordinates `l`,
//! `psi(y) = sum_{i+j+k=4} psi(p_ijk) l_i(l_1) l_j(l_2) l_k(l_3)`, `l_i(t) = prod_{m<i}
//! (4t - m)/(m + 1)` (the Lagrange basis of the degree-4 principal lattice; the derivative
//! pieces are cubics, interpolated the same way). The table stores what substitution cannot
//! produce: the lattice values of `psi` per kind, the covered rates, and per patch `A`, the
//! `R_b` and the three vertex masks, in f64. The arithmetic below is `stencilgen`'s
//! (`LoopRegularBasis::at::<f64>`, the grid system's substitution), operation for operation,
//! so the grids come out as the grid layout's f64 solves do and are rounded once to f32; they
//! agree with a grid table to 1 ulp of f32 (`runtime/tests/integration/compact_tables.rs`).

use std::sync::OnceLock;

use schemes::triangle_local::{sub_triangle_points, SUB_TRIANGLES};
use table_format::{PointSet, SchemeId, SectionKey, StencilKind, TableIndex};

use super::{check_patch_pieces, compact_pieces, GridSlots, Grids, PatchId, MAX_COMPACT_RATE};
use crate::once::TryOnce;
use crate::RuntimeError;

/// The denominator of the lattice the basis is stored on: the pieces' degree.
const LATTICE: i64 = 4;

/// Level-1 lattice points a sub-triangle's matrix has rows for.
const SUB_POINTS: usize = 12;

/// The three kinds, in the order of their slots.
const KINDS: [StencilKind; 3] = [
    StencilKind::Position,
    StencilKind::DerivativeU,
    StencilKind::DerivativeV,
];

/// What a compact Loop table's grids are expanded from, and the grids once a plan asked for
/// them.
#[derive(Debug)]
pub(super) struct TriangleExpansion {
    /// The rates the table lists; patches with all five pieces.
    slots: GridSlots,
    /// The level-1 points of each sub-triangle, in the order of its matrix's rows.
    points: [Vec<(i64, i64)>; 3],
    /// The basis at the twelve sub-triangle points of every outer lattice point
    /// ([`Pieces::basis_at_points`]), which no patch changes: `((rate * 2 + dual) * 3 + kind)`.
    basis: Vec<OnceLock<Vec<f64>>>,
}

impl TriangleExpansion {
    /// The expansion of a validated triangle-scheme table, `None` if it holds no
    /// scaling-relation pieces. Pieces in a table of another triangle scheme, in f32, a patch
    /// piece without the others it needs or of another width, a basis that is not a centred
    /// square window on the lattice `1/4`, a missing basis kind, a rate marker outside
    /// `1..=`[`MAX_COMPACT_RATE`], a patch of no control points: each an error naming
    /// the piece.
    pub(super) fn new(index: &TableIndex) -> Result<Option<Self>, RuntimeError> {
        let Some(pieces) = compact_pieces(index)? else {
            return Ok(None);
        };
        let incomplete = |what: String| RuntimeError::InvalidParameter {
            name: "table".to_owned(),
            reason: format!(
                "{what}: a compact Loop table needs every piece of the scaling relation; \
                 regenerate it with `stencilgen tables --schemes loop`"
            ),
        };
        if index.meta.scheme != SchemeId::Loop {
            return Err(incomplete(format!(
                "a {} table stores {}, but only Loop tables are compact",
                index.meta.scheme.name(),
                pieces[0]
            )));
        }
        let patchless = |key: &SectionKey| !key.boundary && key.faces == 0 && key.sector == 0;
        let mut rates = Vec::new();
        let mut patches = Vec::new();
        for key in pieces {
            let width = index.entry(key)?.width;
            match key.points {
                PointSet::LoopBasis => {
                    // A centred square window: (2h + 1)^2 values (the format checked the rows).
                    if key.n != LATTICE as u32 || !patchless(key) || width % 2 == 0 {
                        return Err(incomplete(format!(
                            "{key} is not a table-wide window of odd width on the lattice 1/4"
                        )));
                    }
                }
                PointSet::TriangleRate => {
                    if key.kind != StencilKind::Position
                        || !patchless(key)
                        || !(1..=MAX_COMPACT_RATE).contains(&key.n)
                    {
                        return Err(incomplete(format!(
                            "{key} is not a position rate marker in \
                             1..={MAX_COMPACT_RATE} without a patch"
                        )));
                    }
                    rates.push(key.n);
                }
                PointSet::Subdivision | PointSet::SubTriangles | PointSet::VertexMask => {
                    let a = SectionKey {
                        kind: StencilKind::Position,
                        points: PointSet::Subdivision,
                        ..*key
                    };
                    if key.n != 0 || width == 0 {
                        return Err(incomplete(format!(
                            "{key} is not a patch piece (n = 0, at least one control point)"
                        )));
                    }
                    if key.points != PointSet::Subdivision {
                        // Checked from A's side below; a piece without A would be unused.
                        if index.entry(&a).is_err() {
                            return Err(incomplete(format!("{key} has no {a}")));
                        }
                        continue;
                    }
                    if key.kind != StencilKind::Position {
                        return Err(incomplete(format!("{key} is not of kind position")));
                    }
                    check_patch_pieces(index, key, width, PointSet::SubTriangles, incomplete)?;
                    patches.push((PatchId::of(key), width));
                }
                // The format admits no other non-grid point set in a triangle table.
                _ => return Err(incomplete(format!("{key} does not belong to a Loop table"))),
            }
        }
        for kind in KINDS {
            let key = basis_key(kind);
            if index.entry(&key).is_err() {
                return Err(incomplete(format!("the table has no {key}")));
            }
        }
        if rates.is_empty() {
            return Err(incomplete("the table lists no rate".to_owned()));
        }
        Ok(Some(TriangleExpansion {
            points: SUB_TRIANGLES.map(sub_triangle_points),
            basis: (0..rates.len() * 2 * KINDS.len())
                .map(|_| OnceLock::new())
                .collect(),
            slots: GridSlots::new(rates, patches),
        }))
    }

    /// The grid stencils of `key` (a triangle primal or dual section), expanded on first use
    /// from `bytes`, the bytes `index` was parsed from. `None` if the table cannot expand it.
    pub(super) fn grid<'s>(
        &'s self,
        index: &TableIndex,
        bytes: &[u8],
        key: &SectionKey,
    ) -> Option<Result<&'s [f32], RuntimeError>> {
        let primal = match key.points {
            PointSet::TrianglePrimal => true,
            PointSet::TriangleDual => false,
            _ => return None,
        };
        let slot = self.slots.slot(key)?;
        let basis =
            |dual: usize| &self.basis[(slot.rate * 2 + dual) * KINDS.len() + key.kind as usize];
        Some(
            slot.grids
                .get_or_try(|| {
                    Pieces::read(index, bytes, key, slot.k, &self.points)?.grids(
                        key.kind,
                        key.n,
                        [basis(0), basis(1)],
                    )
                })
                .map(|grids| &*grids[usize::from(!primal)]),
        )
    }
}

/// The key of the basis section of `kind`.
fn basis_key(kind: StencilKind) -> SectionKey {
    SectionKey {
        kind,
        points: PointSet::LoopBasis,
        boundary: false,
        feature: table_format::Feature::None,
        faces: 0,
        sector: 0,
        n: LATTICE as u32,
    }
}

/// The pieces of one patch for one kind, read from the table, their lengths checked.
struct Pieces<'a> {
    k: usize,
    /// `A`, `K x K`.
    a: &'a [f64],
    /// `R_0, R_1, R_2`, `36 x K`.
    sub_triangles: &'a [f64],
    /// The stencil at the vertex for this kind.
    vertex: &'a [f64],
    /// `psi(k/4)` on the window `|k_1|, |k_2| <= h`, `k_2` outer.
    basis: &'a [f64],
    /// `h`.
    half: i64,
    /// The level-1 points of each sub-triangle.
    points: &'a [Vec<(i64, i64)>; 3],
}

impl<'a> Pieces<'a> {
    /// The pieces of `key`'s patch and kind, with every length the expansion indexes by
    /// checked here (a table that passed load validation has them; this keeps every index in
    /// bounds whatever the bytes).
    fn read(
        index: &TableIndex,
        bytes: &'a [u8],
        key: &SectionKey,
        k: usize,
        points: &'a [Vec<(i64, i64)>; 3],
    ) -> Result<Self, RuntimeError> {
        let piece = |kind, points, rows: usize| -> Result<&'a [f64], RuntimeError> {
            let at = SectionKey {
                kind,
                points,
                n: 0,
                ..*key
            };
            let weights = index.weights_f64(bytes, &at)?;
            if k == 0 || weights.len() != rows * k {
                return Err(RuntimeError::InvalidParameter {
                    name: "table".to_owned(),
                    reason: format!("{at} has {} weights, not {rows} x {k}", weights.len()),
                });
            }
            Ok(weights)
        };
        let basis = index.weights_f64(bytes, &basis_key(key.kind))?;
        let width = index.entry(&basis_key(key.kind))?.width as usize;
        if width % 2 == 0 || basis.len() != width * width {
            return Err(RuntimeError::InvalidParameter {
                name: "table".to_owned(),
                reason: format!(
                    "{} is not a square window of odd width",
                    basis_key(key.kind)
                ),
            });
        }
        if points.iter().any(|p| p.len() != SUB_POINTS) {
            return Err(RuntimeError::InvalidParameter {
                name: "table".to_owned(),
                reason: "a sub-triangle without twelve level-1 points".to_owned(),
            });
        }
        Ok(Pieces {
            k,
            a: piece(StencilKind::Position, PointSet::Subdivision, k)?,
            sub_triangles: piece(
                StencilKind::Position,
                PointSet::SubTriangles,
                3 * SUB_POINTS,
            )?,
            vertex: piece(key.kind, PointSet::VertexMask, 1)?,
            basis,
            half: (width / 2) as i64,
            points,
        })
    }

    /// Both grids of `kind` at rate `n` (module docs), rounded to f32. `basis` caches
    /// [`Self::basis_at_points`] on the primal lattice `1/n` and the dual one `1/3n`.
    fn grids(
        &self,
        kind: StencilKind,
        n: u32,
        basis: [&OnceLock<Vec<f64>>; 2],
    ) -> Result<Grids, RuntimeError> {
        if !(1..=MAX_COMPACT_RATE).contains(&n) {
            return Err(RuntimeError::InvalidParameter {
                name: "table".to_owned(),
                reason: format!("rate {n} is outside 1..={MAX_COMPACT_RATE}"),
            });
        }
        let factor = if kind == StencilKind::Position {
            1.0
        } else {
            2.0
        };
        let n = i64::from(n);
        // The primal grid (i/n, j/n), i + j <= n, j outer.
        let primal: Vec<(i64, i64)> = (0..=n)
            .flat_map(|j| (0..=n - j).map(move |i| (i, j)))
            .collect();
        // The centroids over 3n in table order: row j, up(0, j), down(0, j), up(1, j), ...
        let mut dual = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n - j {
                dual.push((3 * i + 1, 3 * j + 1));
                if i + j + 2 <= n {
                    dual.push((3 * i + 2, 3 * j + 2));
                }
            }
        }
        let round = |v: Vec<f64>| -> Box<[f32]> { v.into_iter().map(|w| w as f32).collect() };
        Ok([
            round(self.lattice(&primal, n, factor, basis[0])),
            round(self.lattice(&dual, 3 * n, factor, basis[1])),
        ])
    }

    /// The stencils at the points `(i/d, j/d)` of `wanted` (`i, j >= 0`, `i + j <= d`), in
    /// order, `K` each: every point of the lattice they double to is computed once, by
    /// decreasing `i + j`, so that `phi(2x)` is known when `phi(x)` needs it.
    fn lattice(
        &self,
        wanted: &[(i64, i64)],
        d: i64,
        factor: f64,
        basis: &OnceLock<Vec<f64>>,
    ) -> Vec<f64> {
        let k = self.k;
        let side = (d + 1) as usize;
        let at = |(i, j): (i64, i64)| j as usize * side + i as usize;
        // The wanted points and the points they double to inside the patch.
        let mut seen = vec![false; side * side];
        let mut needed = Vec::new();
        for &p in wanted {
            let mut p = p;
            while !seen[at(p)] {
                seen[at(p)] = true;
                needed.push(p);
                if p == (0, 0) || 2 * (p.0 + p.1) > d {
                    break;
                }
                p = (2 * p.0, 2 * p.1);
            }
        }
        needed.sort_by_key(|&(i, j)| std::cmp::Reverse(i + j));
        // `needed` depends on the lattice only, so whichever patch fills the cache fills it
        // for all.
        let basis = basis.get_or_init(|| self.basis_at_points(&needed, d));
        // Where each computed point's row is in `values`.
        let mut row_of = vec![0usize; side * side];
        let mut values = vec![0.0f64; needed.len() * k];
        for (r, &p) in needed.iter().enumerate() {
            let (done, rest) = values.split_at_mut(r * k);
            let row = &mut rest[..k];
            if p == (0, 0) {
                row.copy_from_slice(self.vertex);
            } else if 2 * (p.0 + p.1) <= d {
                // phi(x) = f phi(2x) A: row i of A scaled by the doubled point's weight i,
                // summed over i ascending as the grid system's substitution sums. The doubled
                // point has the larger i + j, so it is done.
                let from = row_of[at((2 * p.0, 2 * p.1))];
                let doubled = &done[from * k..(from + 1) * k];
                for (&w, a) in doubled.iter().zip(self.a.chunks_exact(k)) {
                    for (o, &e) in row.iter_mut().zip(a) {
                        if e != 0.0 {
                            *o += (factor * e) * w;
                        }
                    }
                }
            } else {
                let psi = &basis[at(p) * SUB_POINTS..(at(p) + 1) * SUB_POINTS];
                self.regular((2 * p.0, 2 * p.1), d, psi, row);
                for o in row.iter_mut() {
                    *o *= factor;
                }
            }
            row_of[at(p)] = r;
        }
        let mut out = Vec::with_capacity(wanted.len() * k);
        for &p in wanted {
            let r = row_of[at(p)];
            out.extend_from_slice(&values[r * k..(r + 1) * k]);
        }
        out
    }

    /// The sub-triangle `b` holding `y = Y / d` (level-1 coordinates, `Y_1 + Y_2 > d`).
    fn sub_triangle(y: (i64, i64), d: i64) -> usize {
        if y.0 >= d {
            0
        } else if y.1 >= d {
            2
        } else {
            1
        }
    }

    /// `psi(y - j)` for the twelve level-1 points `j` of the sub-triangle holding `y = 2x`, at
    /// every lattice point `x = (i/d, j/d)` of `needed` with `2x` outside the patch
    /// (`2(i + j) > d`), twelve values a point at `12 (j (d + 1) + i)`. It depends on the
    /// lattice and the kind only, not on the patch: computed once per table and shared by every
    /// patch's expansion, where evaluating the basis for each patch was most of a Loop
    /// expansion's time.
    fn basis_at_points(&self, needed: &[(i64, i64)], d: i64) -> Vec<f64> {
        let side = (d + 1) as usize;
        let mut out = vec![0.0; side * side * SUB_POINTS];
        for &(i, j) in needed.iter().filter(|&&(i, j)| 2 * (i + j) > d) {
            let y = (2 * i, 2 * j);
            let at = (j as usize * side + i as usize) * SUB_POINTS;
            let points = &self.points[Self::sub_triangle(y, d)];
            for (o, &(j1, j2)) in out[at..at + SUB_POINTS].iter_mut().zip(points) {
                *o = self.psi(y.0 - d * j1, y.1 - d * j2, d);
            }
        }
        out
    }

    /// `sum_j psi(y - j) R_b[j]` at `y = Y / d` (level-1 coordinates) in its sub-triangle `b`,
    /// given the twelve `psi(y - j)` ([`Self::basis_at_points`]).
    fn regular(&self, y: (i64, i64), d: i64, psis: &[f64], out: &mut [f64]) {
        let b = Self::sub_triangle(y, d);
        let k = self.k;
        let rows = &self.sub_triangles[b * SUB_POINTS * k..(b + 1) * SUB_POINTS * k];
        for (&psi, r) in psis.iter().zip(rows.chunks_exact(k)) {
            for (o, &e) in out.iter_mut().zip(r) {
                if e != 0.0 {
                    *o += psi * e;
                }
            }
        }
    }

    /// `psi(x/d, y/d)` from the lattice values (module docs): the Lagrange basis of the
    /// degree-4 principal lattice of the lattice triangle holding the point.
    fn psi(&self, x: i64, y: i64, d: i64) -> f64 {
        let (a, b) = (x.div_euclid(d), y.div_euclid(d));
        let (s, t) = (x - a * d, y - b * d);
        // Barycentric coordinates (numerators over d) in the up triangle (a,b),(a+1,b),(a,b+1)
        // or the down triangle (a+1,b),(a,b+1),(a+1,b+1).
        let up = s + t <= d;
        let lambda = if up {
            [d - s - t, s, t]
        } else {
            [d - t, d - s, s + t - d]
        };
        // l_i(lambda / d), i = 0..=4: the products in stencilgen's order, each factor the
        // correctly rounded quotient of two small integers.
        let factors = lambda.map(|l| {
            let mut f = [1.0f64; 5];
            for i in 1..=LATTICE as usize {
                let m = i as i64 - 1;
                f[i] = f[i - 1] * ((LATTICE * l - m * d) as f64 / (d * (m + 1)) as f64);
            }
            f
        });
        let mut sum = 0.0;
        for i in 0..=LATTICE {
            for j in 0..=LATTICE - i {
                let k = LATTICE - i - j;
                // The principal-lattice point (i, j, k)/4 of the triangle, over 4.
                let (p, q) = if up {
                    (LATTICE * a + j, LATTICE * b + k)
                } else {
                    (LATTICE * a + i + k, LATTICE * b + j + k)
                };
                sum += self.value(p, q)
                    * factors[0][i as usize]
                    * factors[1][j as usize]
                    * factors[2][k as usize];
            }
        }
        sum
    }

    /// `psi(p/4, q/4)`: zero outside the stored window.
    fn value(&self, p: i64, q: i64) -> f64 {
        let h = self.half;
        if p.abs() > h || q.abs() > h {
            return 0.0;
        }
        self.basis[((q + h) * (2 * h + 1) + (p + h)) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rate cap is both tessellators' largest rate.
    #[test]
    fn the_rate_cap_is_the_tessellators() {
        assert_eq!(
            MAX_COMPACT_RATE,
            crate::tessellate::triangle_dual_grid::MAX_TRIANGLE_RATE
        );
        assert_eq!(MAX_COMPACT_RATE, crate::tessellate::dual_grid::MAX_RATE);
    }
}
