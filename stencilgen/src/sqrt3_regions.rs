//! Positions and first derivatives of √3 (two steps as one ternary step) on every region of an
//! interior extraordinary vertex ([`schemes::sqrt3_regions`]) at any rational point:
//! Schaefer–Warren eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the
//! corner, section 4's derivative normalization for the regular basis, and Loop's tangent
//! convention at the vertex itself.
//!
//! **Non-corner region** `r` (triangle `c0, c1, c2`, ternary tile level `L`), at barycentric
//! `x = (u, v)`: the chart point `c = c0 + u (c1 - c0) + v (c2 - c0)`, `y = 3^L c` (level-`L`
//! coordinates), `T` the first tile holding `y`, and
//!
//! ```text
//!   phi(x)      = sum_j psi(y - j) R[j]
//!   d/du phi(x) = 3^L sum_j (D_{c1-c0} psi)(y - j) R[j],   D_w psi = w_1 psi_1 + w_2 psi_2
//!   d/dv phi(x) = 3^L sum_j (D_{c2-c0} psi)(y - j) R[j]
//! ```
//!
//! over the tile's control points `j` (`R[j]` their level-0 rows), `psi_1, psi_2` the regular
//! basis's derivatives along the skew axes ([`sqrt3_regular_basis_kind`]).
//!
//! **Corner region** (region 0, the EV patch of [`crate::sqrt3_patch`]): while
//! `u + v <= 1/3`, `phi(x) = phi(3x) A` and `phi'(x) = 3 phi'(3x) A`; in the outer part the tile
//! formula with `c0 = (0,0)`, axes `(1,0), (0,1)`, `L = 2`.
//!
//! **At `x = 0`** the position is the limit mask (`phi(0) = phi(0) A`, `sum = 1`). The
//! derivative does not exist in the patch's parameters unless `K = 6`: the subdominant
//! eigenvalue of the two-step `A` is `lambda = (2 + 2 cos(2π/K))/9` (Kobbelt 2000; `1/9, 2/9,
//! 0.2946, 1/3, 0.3606, 0.3794` for `K = 3..=8`), not `1/3`, so `phi'(3^-k x) = 3^k phi'(x) A^k`
//! grows or shrinks like `(3 lambda)^-k`. The repo's convention for Loop's vertex
//! ([`crate::triangle_patch::loop_ev_tangents`]) is used instead: the left eigenvectors of the
//! 1-ring block of `A` (`V, E_0..E_{K-1}`; the ring reads only the ring) for `lambda` span the
//! tangent masks, normalized on the reference net `V = 0`, `E_i = (cos 2πi/K, sin 2πi/K)` so
//! that the `u` mask maps it to `E_0` and the `v` mask to `E_1`. They give the tangent plane
//! (the limit surface's normal is their cross product), and at `K = 6`, where the net is the
//! lattice, they are the true derivatives (psi's skew-axis derivatives gathered: tested).
//! Mapping the net to `E_0`, `E_1` is the same as mapping its `E_0, E_1` skew coordinates
//! `(sin((1-i)θ), sin(iθ))/sin θ` to `(1,0)`, `(0,1)` (a linear map of the plane applied to
//! net and targets alike); for `K = 3, 4, 6` those are integers and `lambda` is rational, so
//! the exact path computes the masks exactly that way (f64 and exact agree: tested).
//!
//! The partition of unity holds for every row (positions sum to 1, derivatives to 0).
//!
//! The evaluation is [`crate::cone_regions`]'s, shared with the butterfly (dilation 3 here);
//! this module holds what is √3's own, the masks at the vertex ([`sqrt3_vertex_masks`]).

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use schemes::cone_local::ConeLocalMatrices;

use crate::butterfly_regions::null_space;
use crate::cone_patch::limit_mask_f64;
pub use crate::cone_regions::{
    ConeRegionStencils, ConeRegionSubstitution, RegionBasis, VertexMasks,
};
use crate::exact_solve::limit_mask;
use crate::triangle_patch::ring_tangents;
use crate::{Scalar, StencilError};

/// √3's regular basis `psi` and (optionally) its skew-axis derivatives on one grid `1/n`
/// ([`RegionBasis`]).
pub type Sqrt3Basis<S> = RegionBasis<S>;

/// Every √3 region of one valence, ready to evaluate ([`ConeRegionStencils`]).
pub type Sqrt3RegionStencils<S> = ConeRegionStencils<S>;

/// Evaluates every √3 region at any rational point ([`ConeRegionSubstitution`]).
pub type Sqrt3RegionSubstitution<S> = ConeRegionSubstitution<S>;

/// √3's masks at `V` (module docs): the limit mask and Loop's tangent convention over the
/// 1-ring block of `A`, whose subdominant eigenvalue `lambda = (2 + 2 cos(2π/K))/9` is
/// returned too; exact where `A` is rational, f64 otherwise. The masks are zero beyond the
/// 1-ring.
pub(crate) fn sqrt3_vertex_masks<S: Scalar>(
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

/// Loop's vertex tangent convention (module docs) exactly, over the 1-ring of the rational
/// `A` (`K = 3, 4, 6`): `lambda = (2 + 2 cos(2π/K))/9` (Kobbelt's double-step eigenvalue; a
/// two-dimensional left eigenspace is required, not assumed), the reference net in `E_0, E_1`
/// skew coordinates (integers there), targets `(1, 0)` and `(0, 1)`.
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

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::TriangleScheme;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
    }

    #[test]
    fn exact_refuses_irrational_valences() {
        assert!(Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), 5).is_err());
        assert!(Sqrt3RegionStencils::<f64>::new(&sqrt3(), 5).is_ok());
    }

    #[test]
    fn vertex_tangents_exact_equal_f64_and_sum_to_zero() {
        // The exact normalization (skew net) and Loop's (cos/sin net) are the same convention.
        for k in [3u32, 4, 6] {
            let e = Sqrt3RegionStencils::<BigRational>::new(&sqrt3(), k).expect("exact");
            let f = Sqrt3RegionStencils::<f64>::new(&sqrt3(), k).expect("f64");
            for (te, tf) in e.vertex_tangents.iter().zip(&f.vertex_tangents) {
                assert!(te.iter().sum::<BigRational>().is_zero(), "K = {k}");
                for (a, b) in te.iter().zip(tf) {
                    assert!((crate::Scalar::to_f64(a) - b).abs() < 1e-12, "K = {k}");
                }
            }
        }
    }
}
