//! Positions and first derivatives of the modified butterfly on every region of an interior
//! extraordinary vertex ([`schemes::butterfly_regions`]) at any rational point: Schaefer–Warren
//! eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the corner, and
//! section 4's derivative normalization for the regular basis. The evaluation is
//! [`crate::cone_regions`]'s, shared with √3 (dilation 2 here); this module holds what is the
//! butterfly's own, the masks at the vertex ([`butterfly_vertex_masks`]).
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

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::cone_local::ConeLocalMatrices;
use schemes::triangle_local::TrianglePoint;

use crate::cone_patch::limit_mask_f64;
pub use crate::cone_regions::{
    ConeRegionStencils, ConeRegionSubstitution, RegionBasis, VertexMasks,
};
use crate::exact_solve::{limit_mask, solve_dense};
use crate::{Scalar, StencilError};

/// The butterfly's regular basis `psi` and (optionally) its skew-axis derivatives on one grid
/// `1/n` ([`RegionBasis`]).
pub type ButterflyBasis<S> = RegionBasis<S>;

/// Every butterfly region of one valence, ready to evaluate ([`ConeRegionStencils`]).
pub type ButterflyRegionStencils<S> = ConeRegionStencils<S>;

/// Evaluates every butterfly region at any rational point ([`ConeRegionSubstitution`]).
pub type ButterflyRegionSubstitution<S> = ConeRegionSubstitution<S>;

/// The butterfly's masks at `V` (module docs): the limit mask, solved (it is `V`'s unit row,
/// the scheme interpolating), and the one-sided derivatives `(e_E0 - e_V) P`,
/// `(e_E1 - e_V) P` with `P` the spectral projector of `A` for `lambda = 1/2`; exact where `A`
/// is rational, f64 by SVDs otherwise.
pub(crate) fn butterfly_vertex_masks<S: Scalar>(
    m: &ConeLocalMatrices,
    failure: &dyn Fn(String) -> StencilError,
    what: &str,
) -> Result<VertexMasks<S>, StencilError> {
    let valence = m.valence;
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
    let (limit, tangents) = match &m.a_exact {
        Some(a) => {
            let limit = limit_mask(a).map_err(|e| failure(format!("limit mask: {e:?}")))?;
            let t = vertex_tangents_exact(a, [(i0, iv), (i1, iv)]).map_err(failure)?;
            (
                limit.iter().map(S::from_rational).collect(),
                t.map(|row| row.iter().map(S::from_rational).collect()),
            )
        }
        None => {
            let limit = limit_mask_f64(&m.a).map_err(failure)?;
            let t = vertex_tangents_f64(&m.a, [(i0, iv), (i1, iv)]).map_err(failure)?;
            let conv = |v: Vec<f64>| -> Result<Vec<S>, StencilError> {
                v.into_iter()
                    .map(|x| {
                        S::from_f64(x).ok_or_else(|| StencilError::Irrational {
                            what: what.to_owned(),
                        })
                    })
                    .collect()
            };
            let [du, dv] = t;
            (conv(limit)?, [conv(du)?, conv(dv)?])
        }
    };
    Ok(VertexMasks {
        limit,
        lambda: 0.5,
        tangents,
    })
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

/// `(e_a - e_b) P` in f64 (as [`vertex_tangents_exact`]), by SVDs.
fn vertex_tangents_f64(
    a: &[Vec<f64>],
    pairs: [(usize, usize); 2],
) -> Result<[Vec<f64>; 2], String> {
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
    Ok([solve(pairs[0])?, solve(pairs[1])?])
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::TriangleScheme;

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
