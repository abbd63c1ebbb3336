//! Stencils of the modified butterfly's patch next to an interior extraordinary vertex
//! (Schaefer–Warren sections 5.2–5.3 on the triangular lattice of section 5.1), by the grid
//! system and by substitution.
//!
//! Let `phi(x)` be the row of the `N = 3K + 9` basis functions of the layout of
//! [`schemes::butterfly_local`] at `x = (u, v)` in the patch `u, v >= 0`, `u + v <= 1`. One step
//! of subdivision does not change the surface, so
//!
//! * `phi(x) = phi(2x) A` when `2x` is in the patch again (`u + v <= 1/2`);
//! * otherwise `y = 2^L x` (`L = 3`, level-`L` skew coordinates) lies in a regular tile `T` of
//!   the outer half, and `phi(x) = sum_j psi(y - j) R_T[j]` over the tile's control points `j`,
//!   with `psi` the butterfly's regular basis function from the uniform system of
//!   [`crate::triangle_system`] (non-polynomial: solved on the grid, not from pieces) and
//!   `R_T[j]` the level-0 weights of level-`L` point `j`;
//! * the partition of unity `sum_j phi_j(x) = 1`.
//!
//! At the grid points `(i/n, j/n)`, `i + j <= n`, this is a `ScalingSystem` whose classes are
//! the grid points (`x -> 2x` maps the grid into itself): triangular except at `x = 0`, where
//! `phi(0) = phi(0) A`, `sum phi(0) = 1` (the scheme interpolates, so the solution is `V`'s unit
//! row — the tests check it, nothing assumes it). `y = 2^L x` has denominator `n`, so `psi` is
//! needed on the rate-`n` grid only. [`ButterflySubstitution`] unrolls the same relations at any
//! rational point without forming a system (the independent cross-check).
//!
//! **Irrational weights.** For `K = 5, 7, 8` the extraordinary edge rule's weights involve
//! `cos(2π/K)`: only the f64 path serves them (the exact path returns
//! [`StencilError::Irrational`]). The f64 path's relation coefficients are the f64 entries of
//! `A`, carried into the system's rational coefficient rows exactly (every f64 is a dyadic
//! rational), so the solver sees precisely the f64 matrix.
//!
//! The grid system, the substitution and the helpers that read the matrices are
//! [`crate::cone_patch`]'s, shared with √3 (dilation 2 here, 3 there), and so is the policy for
//! solving the regular basis; this module names them for the butterfly.

use schemes::cone_local::ConeFamily;
use schemes::TriangleScheme;

pub use crate::cone_patch::{
    cone_matrices as butterfly_matrices, cone_patch_stencils as butterfly_patch_stencils,
    cone_patch_stencils_at as butterfly_patch_stencils_at,
};
use crate::cone_patch::{family_regular_basis_kind, ConePatchStencils, ConeSubstitution};
use crate::regular_patch::StencilKind;
use crate::triangle_system::TriangleStencils;
use crate::{Scalar, StencilError};

/// Position stencils at the grid points of the butterfly EV patch ([`ConePatchStencils`]).
pub type ButterflyPatchStencils<S> = ConePatchStencils<S>;

/// Butterfly EV-patch stencils by substitution at any rational `(u, v)`
/// ([`ConeSubstitution`], dilation 2: the level-`L` point is `2^L 2^k x` after the doublings).
pub type ButterflySubstitution<S> = ConeSubstitution<S>;

/// The butterfly's regular basis function on the rate-`d` grid, in the field `S`: solved
/// exactly and rounded, except at odd rates in an inexact field, where the f64 solve is the
/// fast one ([`crate::cone_patch::solves_basis_in_field`] says why).
pub fn regular_basis<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
) -> Result<TriangleStencils<S>, StencilError> {
    regular_basis_kind(scheme, d, StencilKind::Position)
}

/// [`regular_basis`] or one of its derivatives along the skew axes, on the rate-`d` grid,
/// `d <= `[`crate::triangle_system::MAX_BASIS_RATE`] (the exact path reaches the dual grid's
/// `3n`): the butterfly's case of [`family_regular_basis_kind`], which holds the normalization
/// and the policy.
pub fn regular_basis_kind<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
    kind: StencilKind,
) -> Result<TriangleStencils<S>, StencilError> {
    family_regular_basis_kind(ConeFamily::Butterfly, scheme, d, kind)
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;

    fn butterfly() -> TriangleScheme {
        TriangleScheme::by_name("butterfly").expect("catalogued")
    }

    #[test]
    fn exact_mode_refuses_irrational_valences_and_names_the_cosine() {
        for k in [5, 7, 8] {
            let e = butterfly_patch_stencils::<BigRational>(&butterfly(), k, 2)
                .expect_err("irrational");
            assert!(matches!(e, StencilError::Irrational { .. }));
            assert!(e.to_string().contains(&format!("cos(2 pi/{k})")), "{e}");
            assert!(ButterflySubstitution::<BigRational>::new(&butterfly(), k).is_err());
        }
        assert!(butterfly_patch_stencils::<f64>(&butterfly(), 5, 2).is_ok());
    }

    /// At odd rates the f64 field solves in f64 directly: the same values as the exact solve,
    /// rounded, within 1e-12.
    #[test]
    fn odd_rates_in_f64_agree_with_the_exact_basis() {
        for kind in [
            StencilKind::Position,
            StencilKind::DerivativeU,
            StencilKind::DerivativeV,
        ] {
            let float = regular_basis_kind::<f64>(&butterfly(), 9, kind).expect("f64");
            let exact = regular_basis_kind::<BigRational>(&butterfly(), 9, kind).expect("exact");
            assert_eq!(float.values.len(), exact.values.len());
            for (a, b) in float.values.iter().zip(&exact.values) {
                assert!((a - b.to_f64()).abs() < 1e-12, "{kind:?}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn points_outside_the_patch_and_bad_rates_are_errors() {
        let mut s = ButterflySubstitution::<BigRational>::new(&butterfly(), 4).expect("valid");
        let q = |p: i64, r: i64| BigRational::new(p.into(), r.into());
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        // 8 * 25/53 has denominator 53 > 24: the regular system is not solved there.
        assert!(matches!(
            s.stencil(&q(25, 53), &q(0, 1)),
            Err(StencilError::RateOutOfRange { n: 53, .. })
        ));
        assert!(butterfly_patch_stencils::<f64>(&butterfly(), 5, 0).is_err());
        assert!(butterfly_patch_stencils::<f64>(&butterfly(), 5, 25).is_err());
    }
}
