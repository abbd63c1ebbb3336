//! Positions and first derivatives of the modified butterfly on every region of an interior
//! extraordinary vertex ([`schemes::butterfly_regions`]) at any rational point: Schaefer–Warren
//! eq. (2) on the regular tiles, the scaling relation (eq. (3)) inside the corner, and
//! section 4's derivative normalization for the regular basis. The evaluation is
//! [`crate::cone_regions`]'s, shared with √3 (dilation 2 here), and so is the code of the
//! masks at the vertex derived below (written next to √3's, since the shared evaluation builds
//! them); this module names the types for the butterfly and holds the derivation.
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
//! basis's derivatives along the skew axes ([`crate::butterfly_patch::regular_basis_kind`]).
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

pub use crate::cone_regions::{
    ConeRegionStencils, ConeRegionSubstitution, RegionBasis, VertexMasks,
};

/// The butterfly's regular basis `psi` and (optionally) its skew-axis derivatives on one grid
/// `1/n` ([`RegionBasis`]).
pub type ButterflyBasis<S> = RegionBasis<S>;

/// Every butterfly region of one valence, ready to evaluate ([`ConeRegionStencils`]).
pub type ButterflyRegionStencils<S> = ConeRegionStencils<S>;

/// Evaluates every butterfly region at any rational point ([`ConeRegionSubstitution`]).
pub type ButterflyRegionSubstitution<S> = ConeRegionSubstitution<S>;

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;
    use schemes::TriangleScheme;

    fn butterfly() -> TriangleScheme {
        TriangleScheme::by_name("butterfly").expect("catalogued")
    }

    #[test]
    fn exact_refuses_irrational_valences() {
        assert!(ButterflyRegionStencils::<BigRational>::new(&butterfly(), 5).is_err());
        assert!(ButterflyRegionStencils::<f64>::new(&butterfly(), 5).is_ok());
    }
}
