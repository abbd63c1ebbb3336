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
//! basis's derivatives along the skew axes ([`crate::sqrt3_patch::sqrt3_regular_basis_kind`]).
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
//! The evaluation is [`crate::cone_regions`]'s, shared with the butterfly (dilation 3 here),
//! and so is the code of the masks at the vertex derived above (written next to the
//! butterfly's, since the shared evaluation builds them); this module names the types for √3
//! and holds the derivation.

pub use crate::cone_regions::{
    ConeRegionStencils, ConeRegionSubstitution, RegionBasis, VertexMasks,
};

/// √3's regular basis `psi` and (optionally) its skew-axis derivatives on one grid `1/n`
/// ([`RegionBasis`]).
pub type Sqrt3Basis<S> = RegionBasis<S>;

/// Every √3 region of one valence, ready to evaluate ([`ConeRegionStencils`]).
pub type Sqrt3RegionStencils<S> = ConeRegionStencils<S>;

/// Evaluates every √3 region at any rational point ([`ConeRegionSubstitution`]).
pub type Sqrt3RegionSubstitution<S> = ConeRegionSubstitution<S>;

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;
    use num_traits::Zero;
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
