//! Positions and first derivatives of the modified butterfly on every region of an interior
//! extraordinary vertex ([`schemes::butterfly_regions`]) at any rational point: Schaefer–Warren
//! eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the corner, and
//! section 4's derivative normalization for the regular basis.
//!
//! **Non-corner region** `r` (triangle `c0, c1, c2`, tile level `L`), at barycentric
//! `x = (u, v)`: the chart point `c = c0 + u (c1 - c0) + v (c2 - c0)`, `y = 2^L c` (level-`L`
//! coordinates), `T` the first tile holding `y`, and
//!
//! ```text
//!   phi(x)      = sum_j psi(y - j) R[j]
//!   d/du phi(x) = 2^L sum_j (D_{c1-c0} psi)(y - j) R[j],   D_w psi = w_1 psi_1 + w_2 psi_2
//!   d/dv phi(x) = 2^L sum_j (D_{c2-c0} psi)(y - j) R[j]
//! ```
//!
//! over the tile's control points `j` (`R[j]` their level-0 rows), `psi_1, psi_2` the regular
//! basis's derivatives along the skew axes ([`regular_basis_kind`]).
//!
//! **Corner region** (region 0, the EV patch): while `u + v <= 1/2`, `phi(x) = phi(2x) A` and
//! `phi'(x) = 2 phi'(2x) A`; in the outer half the tile formula above with `c0 = (0,0)`,
//! axes `(1,0), (0,1)`, `L = 3`. At `x = 0` itself:
//!
//! * the position is the left fixed vector of `A` summing to 1 (the scheme interpolates:
//!   `V`'s unit row; solved, not assumed);
//! * the derivatives come from the spectral projector `P` of `A` for the eigenvalue `1/2`:
//!   `phi(t w) = phi(0) + (t/s) phi(s w) P + o(t)` for `t = 2^-k s`, so along dyadic `t` the
//!   one-sided derivative in direction `w` is `(phi(w) - phi(0)) P`, and with `w = E_0`,
//!   `E_1` (where `phi` is a unit row: the scheme interpolates) `d/du phi(0) = (e_E0 - e_V) P`,
//!   `d/dv phi(0) = (e_E1 - e_V) P`. This needs `1/2` to be the subdominant eigenvalue,
//!   semisimple of multiplicity 2, every other eigenvalue but the simple `1` of modulus below
//!   `1/2` (true for `K = 3..=8`, checked by the tests; `lambda_1 = 1/2` by the construction
//!   of the `s_j`). `P` is computed from the right eigenvectors `r_1, r_2` of `1/2`: `t = e P`
//!   is the unique `t` with `t A = t/2` and `t r_k = e r_k`. Exact for `K = 3, 4, 6`, f64
//!   otherwise. The map `w -> D_w phi(0)` is not linear in general (the characteristic map
//!   `x -> phi(x) P` is homogeneous under doubling, not linear), so the table stores these two
//!   one-sided directional derivatives; they span the tangent plane.
//!
//! The partition of unity holds for every row (positions sum to 1, derivatives to 0).

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::butterfly_regions::{ButterflyRegion, ButterflyRegions};
use schemes::triangle_local::TrianglePoint;
use schemes::TriangleScheme;

use crate::butterfly_patch::regular_basis_kind;
use crate::exact_solve::{limit_mask, solve_dense};
use crate::regular_patch::StencilKind;
use crate::triangle_system::{TriangleStencils, MAX_BASIS_RATE};
use crate::{Scalar, StencilError};

/// The regular basis `psi` and (optionally) its skew-axis derivatives on one grid `1/n`.
#[derive(Clone, Debug)]
pub struct ButterflyBasis<S> {
    /// The grid rate.
    pub n: u32,
    /// `psi`, `psi_1`, `psi_2` ([`StencilKind`] order); `None` where not solved.
    pub kinds: [Option<TriangleStencils<S>>; 3],
}

fn kind_index(kind: StencilKind) -> usize {
    match kind {
        StencilKind::Position => 0,
        StencilKind::DerivativeU => 1,
        StencilKind::DerivativeV => 2,
    }
}

impl<S: Scalar> ButterflyBasis<S> {
    /// Solve `kinds` of the butterfly's regular basis on the rate-`n` grid (exactly, then
    /// rounded: [`regular_basis_kind`]).
    pub fn new(
        scheme: &TriangleScheme,
        n: u32,
        kinds: &[StencilKind],
    ) -> Result<Self, StencilError> {
        let mut out = ButterflyBasis {
            n,
            kinds: [None, None, None],
        };
        for &k in kinds {
            out.kinds[kind_index(k)] = Some(regular_basis_kind::<S>(scheme, n, k)?);
        }
        Ok(out)
    }

    fn get(&self, kind: StencilKind) -> Result<&TriangleStencils<S>, StencilError> {
        self.kinds[kind_index(kind)]
            .as_ref()
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!("the regular basis at rate {} lacks {kind:?}", self.n),
            })
    }
}

/// Every region of one valence, its matrices in the field `S`, ready to evaluate.
#[derive(Clone, Debug)]
pub struct ButterflyRegionStencils<S> {
    /// The regions ([`schemes::butterfly_regions`]).
    pub regions: ButterflyRegions,
    /// The corner's `A` in `S`.
    a: Vec<Vec<S>>,
    /// Per region, its tile rows in `S`.
    rows: Vec<Vec<Vec<S>>>,
    /// The limit-position mask at `V` (corner layout).
    pub limit: Vec<S>,
    /// `d/du phi(0)`, `d/dv phi(0)` of the corner (module docs).
    pub vertex_tangents: [Vec<S>; 2],
}

/// An entry in `S`: the exact rational when there is one, else the f64.
fn entry<S: Scalar>(
    exact: Option<&BigRational>,
    value: f64,
    what: &str,
) -> Result<S, StencilError> {
    match exact {
        Some(r) => Ok(S::from_rational(r)),
        None => S::from_f64(value).ok_or_else(|| StencilError::Irrational {
            what: what.to_owned(),
        }),
    }
}

fn matrix<S: Scalar>(
    exact: Option<&Vec<Vec<BigRational>>>,
    values: &[Vec<f64>],
    what: &str,
) -> Result<Vec<Vec<S>>, StencilError> {
    values
        .iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(|(j, &x)| entry(exact.map(|e| &e[i][j]), x, what))
                .collect()
        })
        .collect()
}

impl<S: Scalar> ButterflyRegionStencils<S> {
    /// Build the regions of the modified butterfly at valence `valence` (an exact field only
    /// where the weights are rational, `K = 3, 4, 6`).
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        let regions = ButterflyRegions::new(scheme, valence)?;
        if S::EXACT && !regions.is_rational() {
            return Err(StencilError::Irrational {
                what: format!(
                    "the modified butterfly at valence {valence} (its extraordinary edge \
                     weights involve cos(2 pi/{valence}))"
                ),
            });
        }
        let m = &regions.corner;
        let what = format!("the butterfly at valence {valence}");
        let a = matrix::<S>(m.a_exact.as_ref(), &m.a, &what)?;
        let rows = regions
            .regions
            .iter()
            .map(|r| matrix::<S>(r.regular_rows_exact.as_ref(), &r.regular_rows, &what))
            .collect::<Result<Vec<_>, _>>()?;
        let failure = |detail: String| StencilError::Inconsistent {
            scheme: scheme.name.to_owned(),
            n: 1,
            detail: format!("valence {valence}: {detail}"),
        };
        let layout = &m.layout;
        let index = |p: TrianglePoint| {
            layout
                .iter()
                .position(|&q| q == p)
                .ok_or_else(|| failure(format!("{p:?} is not in the corner layout")))
        };
        let (iv, i0, i1) = (
            index(TrianglePoint::Centre)?,
            index(TrianglePoint::Sector { s: 0, a: 1, b: 0 })?,
            index(TrianglePoint::Sector {
                s: 1 % valence,
                a: 1,
                b: 0,
            })?,
        );
        let (limit, vertex_tangents) = match &m.a_exact {
            Some(a) => {
                let limit = limit_mask(a).map_err(|e| failure(format!("limit mask: {e:?}")))?;
                let t = vertex_tangents_exact(a, [(i0, iv), (i1, iv)]).map_err(failure)?;
                (
                    limit.iter().map(S::from_rational).collect(),
                    t.map(|row| row.iter().map(S::from_rational).collect()),
                )
            }
            None => {
                let (limit, t) =
                    limit_and_tangents_f64(&m.a, [(i0, iv), (i1, iv)]).map_err(failure)?;
                let conv = |v: Vec<f64>| -> Result<Vec<S>, StencilError> {
                    v.into_iter()
                        .map(|x| {
                            S::from_f64(x)
                                .ok_or_else(|| StencilError::Irrational { what: what.clone() })
                        })
                        .collect()
                };
                let [du, dv] = t;
                (conv(limit)?, [conv(du)?, conv(dv)?])
            }
        };
        Ok(ButterflyRegionStencils {
            regions,
            a,
            rows,
            limit,
            vertex_tangents,
        })
    }

    /// The region `r`.
    pub fn region(&self, r: usize) -> Result<&ButterflyRegion, StencilError> {
        self.regions
            .regions
            .get(r)
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!(
                    "region {r} of {} at valence {}",
                    self.regions.regions.len(),
                    self.regions.valence
                ),
            })
    }

    /// The `kind` stencil of region `r` at `(u, v) = (i/n, j/n)`, `n = basis.n`, `i, j >= 0`,
    /// `i + j <= n`, over the region's layout (module docs). `basis` must hold `kind`.
    pub fn stencil(
        &self,
        r: usize,
        basis: &ButterflyBasis<S>,
        point: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let region = self.region(r)?;
        let d = i64::from(basis.n);
        let (i, j) = point;
        if i < 0 || j < 0 || i + j > d {
            return Err(StencilError::OutOfDomain {
                what: format!("({i}/{d}, {j}/{d}) is outside the region u, v >= 0, u + v <= 1"),
            });
        }
        if !region.is_corner() {
            let y = region.triangle.chart_point(i, j, d);
            return self.tile(r, basis, y, kind);
        }
        if (i, j) == (0, 0) {
            return Ok(match kind {
                StencilKind::Position => self.limit.clone(),
                StencilKind::DerivativeU => self.vertex_tangents[0].clone(),
                StencilKind::DerivativeV => self.vertex_tangents[1].clone(),
            });
        }
        let (mut x, mut k) = ((i, j), 0u32);
        while 2 * (x.0 + x.1) <= d {
            x = (2 * x.0, 2 * x.1);
            k += 1;
        }
        let mut row = self.tile(r, basis, x, kind)?;
        let two = S::from_rational(&BigRational::from_integer(BigInt::from(2)));
        for _ in 0..k {
            row = (0..row.len())
                .map(|c| {
                    let sum = row
                        .iter()
                        .zip(&self.a)
                        .filter(|(w, ai)| !w.is_zero() && !ai[c].is_zero())
                        .fold(S::zero(), |acc, (w, ai)| acc + w.clone() * ai[c].clone());
                    if kind == StencilKind::Position {
                        sum
                    } else {
                        sum * two.clone()
                    }
                })
                .collect();
        }
        Ok(row)
    }

    /// The tile formula at the chart point `c / n` of region `r` (module docs).
    fn tile(
        &self,
        r: usize,
        basis: &ButterflyBasis<S>,
        c: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let region = self.region(r)?;
        let d = i64::from(basis.n);
        let scale = 1i64 << region.tile_level;
        let y = (scale * c.0, scale * c.1);
        let tile = region
            .tile_containing(y, d)
            .ok_or_else(|| StencilError::OutOfDomain {
                what: format!(
                    "({}/{d}, {}/{d}) (level {}) is in no regular tile of region {r}",
                    y.0, y.1, region.tile_level
                ),
            })?;
        let [e1, e2] = region.triangle.axes();
        let axis = match kind {
            StencilKind::Position => None,
            StencilKind::DerivativeU => Some(e1),
            StencilKind::DerivativeV => Some(e2),
        };
        let int = |x: i64| S::from_rational(&BigRational::from_integer(BigInt::from(x)));
        let mut out = vec![S::zero(); region.size()];
        for &u in &region.tiles[tile].points {
            let (j1, j2) = region.regular_points[u];
            let at = (y.0 - d * j1, y.1 - d * j2);
            let w = match axis {
                None => basis.get(StencilKind::Position)?.at(at.0, at.1),
                // D_w psi = w_1 psi_1 + w_2 psi_2, times 2^L for the level-L coordinates.
                Some((w1, w2)) => {
                    let mut w = S::zero();
                    if w1 != 0 {
                        w = w + int(w1 * scale)
                            * basis.get(StencilKind::DerivativeU)?.at(at.0, at.1);
                    }
                    if w2 != 0 {
                        w = w + int(w2 * scale)
                            * basis.get(StencilKind::DerivativeV)?.at(at.0, at.1);
                    }
                    w
                }
            };
            if w.is_zero() {
                continue;
            }
            for (o, rw) in out.iter_mut().zip(&self.rows[r][u]) {
                if !rw.is_zero() {
                    *o = o.clone() + w.clone() * rw.clone();
                }
            }
        }
        Ok(out)
    }
}

/// Evaluates every region at any rational point, caching the regular basis per rate and kind.
#[derive(Debug)]
pub struct ButterflyRegionSubstitution<S> {
    scheme: TriangleScheme,
    /// The regions and their matrices.
    pub stencils: ButterflyRegionStencils<S>,
    bases: HashMap<u32, ButterflyBasis<S>>,
}

impl<S: Scalar> ButterflyRegionSubstitution<S> {
    /// Prepare for valence `valence`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, StencilError> {
        Ok(ButterflyRegionSubstitution {
            scheme: scheme.clone(),
            stencils: ButterflyRegionStencils::new(scheme, valence)?,
            bases: HashMap::new(),
        })
    }

    /// The `kind` stencil of region `r` at `(u, v)`, `u, v >= 0`, `u + v <= 1`; the common
    /// denominator of `u` and `v` must be at most [`MAX_BASIS_RATE`] (the regular basis is
    /// solved on that grid: rates with large odd parts take minutes).
    pub fn stencil(
        &mut self,
        r: usize,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let d = u.denom().lcm(v.denom());
        let rate = u32::try_from(&d)
            .ok()
            .filter(|&x| x <= MAX_BASIS_RATE)
            .ok_or_else(|| StencilError::RateOutOfRange {
                n: u32::try_from(&d).unwrap_or(u32::MAX),
                max: MAX_BASIS_RATE,
            })?;
        let num = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer()).map_err(|_| {
                StencilError::OutOfDomain {
                    what: format!("{t} does not fit the grid"),
                }
            })
        };
        let point = (num(u)?, num(v)?);
        let needs_basis = point != (0, 0) || !self.stencils.region(r)?.is_corner();
        if needs_basis {
            let entry = self.bases.entry(rate).or_insert(ButterflyBasis {
                n: rate,
                kinds: [None, None, None],
            });
            let slot = &mut entry.kinds[kind_index(kind)];
            if slot.is_none() {
                *slot = Some(regular_basis_kind::<S>(&self.scheme, rate, kind)?);
            }
        }
        let empty = ButterflyBasis {
            n: rate,
            kinds: [None, None, None],
        };
        let basis = self.bases.get(&rate).unwrap_or(&empty);
        self.stencils.stencil(r, basis, point, kind)
    }
}

/// A basis of the right null space of the dense rational matrix `m` (`rows x width`).
pub(crate) fn null_space(mut m: Vec<Vec<BigRational>>, width: usize) -> Vec<Vec<BigRational>> {
    let mut pivots = Vec::new();
    let mut rank = 0;
    for col in 0..width {
        let Some(p) = (rank..m.len()).find(|&i| !m[i][col].is_zero()) else {
            continue;
        };
        m.swap(rank, p);
        let inv = m[rank][col].recip();
        for x in m[rank].iter_mut() {
            *x *= &inv;
        }
        let pivot = m[rank].clone();
        for (i, row) in m.iter_mut().enumerate() {
            if i == rank || row[col].is_zero() {
                continue;
            }
            let f = row[col].clone();
            for (x, y) in row.iter_mut().zip(&pivot) {
                if !y.is_zero() {
                    *x -= &f * y;
                }
            }
        }
        pivots.push(col);
        rank += 1;
    }
    (0..width)
        .filter(|c| !pivots.contains(c))
        .map(|free| {
            let mut v = vec![BigRational::zero(); width];
            v[free] = BigRational::one();
            for (i, &p) in pivots.iter().enumerate() {
                v[p] = -m[i][free].clone();
            }
            v
        })
        .collect()
}

/// `(e_a - e_b) P` for the two pairs `(a, b)`, `P` the spectral projector of `A` for `1/2`,
/// exactly: `t` solves `t (A - I/2) = 0`, `t r_k = e r_k` over the right eigenvectors `r_k`.
fn vertex_tangents_exact(
    a: &[Vec<BigRational>],
    pairs: [(usize, usize); 2],
) -> Result<[Vec<BigRational>; 2], String> {
    let n = a.len();
    let half = BigRational::new(BigInt::from(1), BigInt::from(2));
    let shifted: Vec<Vec<BigRational>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    if i == j {
                        &a[i][j] - &half
                    } else {
                        a[i][j].clone()
                    }
                })
                .collect()
        })
        .collect();
    let right = null_space(shifted.clone(), n);
    if right.len() != 2 {
        return Err(format!(
            "the eigenvalue 1/2 of A has {} independent right eigenvectors, not 2",
            right.len()
        ));
    }
    let solve = |(p, q): (usize, usize)| -> Result<Vec<BigRational>, String> {
        let mut rows: Vec<(Vec<BigRational>, BigRational)> = (0..n)
            .map(|j| {
                (
                    (0..n).map(|i| shifted[i][j].clone()).collect(),
                    BigRational::zero(),
                )
            })
            .collect();
        for r in &right {
            rows.push((r.clone(), &r[p] - &r[q]));
        }
        solve_dense(rows, n).map_err(|e| format!("tangent at the vertex: {e:?}"))
    };
    Ok([solve(pairs[0])?, solve(pairs[1])?])
}

/// The f64 limit mask and `(e_a - e_b) P` (as [`vertex_tangents_exact`]), by SVDs.
fn limit_and_tangents_f64(
    a: &[Vec<f64>],
    pairs: [(usize, usize); 2],
) -> Result<(Vec<f64>, [Vec<f64>; 2]), String> {
    let n = a.len();
    let am = DMatrix::from_fn(n, n, |i, j| a[i][j]);
    let lstsq = |lhs: DMatrix<f64>, rhs: nalgebra::DVector<f64>| -> Result<Vec<f64>, String> {
        Ok(lhs
            .svd(true, true)
            .solve(&rhs, 1e-12)
            .map_err(|e| e.to_owned())?
            .iter()
            .copied()
            .collect())
    };
    // limit: (A^T - I) l = 0, 1^T l = 1.
    let mut lhs = DMatrix::<f64>::zeros(n + 1, n);
    let mut rhs = nalgebra::DVector::<f64>::zeros(n + 1);
    for j in 0..n {
        for i in 0..n {
            lhs[(j, i)] = am[(i, j)] - if i == j { 1.0 } else { 0.0 };
        }
        lhs[(n, j)] = 1.0;
    }
    rhs[n] = 1.0;
    let limit = lstsq(lhs, rhs)?;
    let shifted = &am - DMatrix::identity(n, n) * 0.5;
    let svd = shifted.clone().svd(false, true);
    let v_t = svd.v_t.ok_or("no SVD")?;
    let right: Vec<Vec<f64>> = (0..n)
        .filter(|&i| svd.singular_values[i] < 1e-8)
        .map(|i| v_t.row(i).iter().copied().collect())
        .collect();
    if right.len() != 2 {
        return Err(format!(
            "the eigenvalue 1/2 of A has {} independent right eigenvectors, not 2",
            right.len()
        ));
    }
    let solve = |(p, q): (usize, usize)| -> Result<Vec<f64>, String> {
        let mut lhs = DMatrix::<f64>::zeros(n + 2, n);
        let mut rhs = nalgebra::DVector::<f64>::zeros(n + 2);
        for j in 0..n {
            for i in 0..n {
                lhs[(j, i)] = shifted[(i, j)];
            }
        }
        for (k, r) in right.iter().enumerate() {
            for i in 0..n {
                lhs[(n + k, i)] = r[i];
            }
            rhs[n + k] = r[p] - r[q];
        }
        lstsq(lhs, rhs)
    };
    Ok((limit, [solve(pairs[0])?, solve(pairs[1])?]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn butterfly() -> TriangleScheme {
        TriangleScheme::by_name("butterfly").expect("catalogued")
    }

    #[test]
    fn null_space_of_a_rank_one_matrix() {
        let q = |x: i64| BigRational::from_integer(BigInt::from(x));
        // [1 2 3] has the null space spanned by (-2, 1, 0), (-3, 0, 1).
        let ns = null_space(vec![vec![q(1), q(2), q(3)]], 3);
        assert_eq!(ns, vec![vec![q(-2), q(1), q(0)], vec![q(-3), q(0), q(1)]]);
    }

    #[test]
    fn exact_refuses_irrational_valences() {
        assert!(ButterflyRegionStencils::<BigRational>::new(&butterfly(), 5).is_err());
        assert!(ButterflyRegionStencils::<f64>::new(&butterfly(), 5).is_ok());
    }
}
