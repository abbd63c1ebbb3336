//! The masks at an interior extraordinary vertex `V` itself — the corner region's `x = 0`,
//! where the scaling relation gives the position (the limit mask) but the derivatives need
//! the spectrum of `A` — for each family of [`crate::cone_regions`]: the butterfly's
//! one-sided derivatives through the spectral projector of `1/2`, √3's tangents by Loop's
//! convention over the 1-ring. The derivations are in the scheme modules' docs
//! ([`crate::butterfly_regions`], [`crate::sqrt3_regions`]).
//!
//! The masks live here, with the family dispatch ([`vertex_masks`]), rather than in those
//! modules because the shared region evaluation builds them and the scheme modules are built
//! on it: dependencies point from the scheme-specific modules to the shared ones, never back.

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use schemes::cone_local::{ConeFamily, ConeLocalMatrices};
use schemes::triangle_local::TrianglePoint;

use crate::cone_patch::limit_mask_f64;
use crate::exact_solve::{limit_mask, null_space, solve_dense};
use crate::triangle_patch::ring_tangents;
use crate::{Scalar, StencilError};

/// The masks at `V` itself (the corner region's `x = 0`), corner layout.
#[derive(Clone, Debug)]
pub struct VertexMasks<S> {
    /// The limit-position mask: the left fixed vector of `A` summing to 1.
    pub limit: Vec<S>,
    /// The subdominant eigenvalue of `A` (f64): `1/2` for the butterfly,
    /// `(2 + 2 cos(2π/K))/9` for √3.
    pub lambda: f64,
    /// The two tangent masks, for `d/du` and `d/dv` (the scheme's convention).
    pub tangents: [Vec<S>; 2],
}

/// The masks at `V` of `family`'s scheme over the corner matrices `m`, in the field `S`;
/// `failure` turns a reason into the caller's error, `what` names the matrices in an
/// [`StencilError::Irrational`].
pub(crate) fn vertex_masks<S: Scalar>(
    family: ConeFamily,
    m: &ConeLocalMatrices,
    failure: &dyn Fn(String) -> StencilError,
    what: &str,
) -> Result<VertexMasks<S>, StencilError> {
    match family {
        ConeFamily::Butterfly => butterfly_vertex_masks::<S>(m, failure, what),
        ConeFamily::Sqrt3 => sqrt3_vertex_masks::<S>(m, failure, what),
    }
}

/// The butterfly's masks at `V` ([`crate::butterfly_regions`] module docs): the limit mask,
/// solved (it is `V`'s unit row, the scheme interpolating), and the one-sided derivatives
/// `(e_E0 - e_V) P`, `(e_E1 - e_V) P` with `P` the spectral projector of `A` for
/// `lambda = 1/2`; exact where `A` is rational, f64 by SVDs otherwise.
fn butterfly_vertex_masks<S: Scalar>(
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

/// √3's masks at `V` ([`crate::sqrt3_regions`] module docs): the limit mask and Loop's
/// tangent convention over the 1-ring block of `A`, whose subdominant eigenvalue
/// `lambda = (2 + 2 cos(2π/K))/9` is returned too; exact where `A` is rational, f64 otherwise.
/// The masks are zero beyond the 1-ring.
fn sqrt3_vertex_masks<S: Scalar>(
    m: &ConeLocalMatrices,
    failure: &dyn Fn(String) -> StencilError,
    what: &str,
) -> Result<VertexMasks<S>, StencilError> {
    let valence = m.valence;
    let size = m.size();
    let ring = 1 + valence as usize;
    // The layout starts V, E_0..E_{K-1} (sqrt3_layout): the ring block is A's corner.
    let a1 = DMatrix::from_fn(ring, ring, |i, j| m.a[i][j]);
    let (lambda, [du, dv]) = ring_tangents(&a1, valence as usize).map_err(failure)?;
    let (limit, tangents) = match &m.a_exact {
        Some(ax) => {
            let limit = limit_mask(ax).map_err(|e| failure(format!("limit mask: {e:?}")))?;
            let t = ring_tangents_exact(ax, valence).map_err(failure)?;
            let widen = |v: Vec<BigRational>| -> Vec<S> {
                let mut out: Vec<S> = v.iter().map(S::from_rational).collect();
                out.resize(size, S::zero());
                out
            };
            let [tu, tv] = t;
            (
                limit.iter().map(S::from_rational).collect(),
                [widen(tu), widen(tv)],
            )
        }
        None => {
            let limit = limit_mask_f64(&m.a).map_err(failure)?;
            let conv = |v: Vec<f64>| -> Result<Vec<S>, StencilError> {
                let mut out = v
                    .into_iter()
                    .map(|x| {
                        S::from_f64(x).ok_or_else(|| StencilError::Irrational {
                            what: what.to_owned(),
                        })
                    })
                    .collect::<Result<Vec<S>, _>>()?;
                out.resize(size, S::zero());
                Ok(out)
            };
            (conv(limit)?, [conv(du)?, conv(dv)?])
        }
    };
    Ok(VertexMasks {
        limit,
        lambda,
        tangents,
    })
}

/// Loop's vertex tangent convention ([`crate::sqrt3_regions`] module docs) exactly, over the
/// 1-ring of the rational `A` (`K = 3, 4, 6`): `lambda = (2 + 2 cos(2π/K))/9` (Kobbelt's
/// double-step eigenvalue; a two-dimensional left eigenspace is required, not assumed), the
/// reference net in `E_0, E_1` skew coordinates (integers there), targets `(1, 0)` and
/// `(0, 1)`.
fn ring_tangents_exact(
    a: &[Vec<BigRational>],
    valence: u32,
) -> Result<[Vec<BigRational>; 2], String> {
    let k = valence as usize;
    let ring = 1 + k;
    let q = |p: i64, r: i64| BigRational::new(BigInt::from(p), BigInt::from(r));
    let cos = match valence {
        3 => q(-1, 2),
        4 => q(0, 1),
        6 => q(1, 2),
        _ => return Err(format!("cos(2 pi/{valence}) is irrational")),
    };
    let lambda = (q(2, 1) + q(2, 1) * cos) / q(9, 1);
    // Left eigenvectors: the right null space of B^T - lambda I.
    let shifted: Vec<Vec<BigRational>> = (0..ring)
        .map(|i| {
            (0..ring)
                .map(|j| {
                    let x = a[j][i].clone();
                    if i == j {
                        x - &lambda
                    } else {
                        x
                    }
                })
                .collect()
        })
        .collect();
    let basis = null_space(shifted, ring);
    if basis.len() != 2 {
        return Err(format!(
            "lambda = {lambda} has {} left eigenvectors on the 1-ring, not 2",
            basis.len()
        ));
    }
    let theta = 2.0 * std::f64::consts::PI / f64::from(valence);
    let net: Vec<(i64, i64)> = (0..k)
        .map(|i| {
            let t = i as f64 * theta;
            let x = (theta - t).sin() / theta.sin();
            let y = t.sin() / theta.sin();
            (x.round() as i64, y.round() as i64)
        })
        .collect();
    let image = |w: &[BigRational]| {
        net.iter()
            .enumerate()
            .fold((q(0, 1), q(0, 1)), |(x, y), (i, &(n1, n2))| {
                (x + &w[1 + i] * q(n1, 1), y + &w[1 + i] * q(n2, 1))
            })
    };
    let (g0, g1) = (image(&basis[0]), image(&basis[1]));
    let det = &g0.0 * &g1.1 - &g0.1 * &g1.0;
    if det.is_zero() {
        return Err("the eigenvectors do not span the reference net's plane".to_owned());
    }
    let mask = |t: (BigRational, BigRational)| -> Vec<BigRational> {
        let c0 = (&t.0 * &g1.1 - &t.1 * &g1.0) / &det;
        let c1 = (&g0.0 * &t.1 - &g0.1 * &t.0) / &det;
        basis[0]
            .iter()
            .zip(&basis[1])
            .map(|(a, b)| &c0 * a + &c1 * b)
            .collect()
    };
    Ok([mask((q(1, 1), q(0, 1))), mask((q(0, 1), q(1, 1)))])
}
