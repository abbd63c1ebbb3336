//! Stencils of √3's patch next to an interior extraordinary vertex, two √3 steps at a time
//! (Schaefer–Warren sections 5.1–5.3: the two-step ternary form aligned with the original
//! lattice), by the grid system and by substitution.
//!
//! Let `phi(x)` be the row of the `N = 3K + 9` basis functions of the layout of
//! [`schemes::sqrt3_local`] at `x = (u, v)` in the patch `u, v >= 0`, `u + v <= 1`. Two √3
//! steps do not change the surface, so
//!
//! * `phi(x) = phi(3x) A` when `3x` is in the patch again (`u + v <= 1/3`);
//! * otherwise `y = 3^L x` (`L = 2`, level-`L` skew coordinates) lies in a regular tile `T` of
//!   the outer part, and `phi(x) = sum_j psi(y - j) R_T[j]` over the tile's control points `j`,
//!   with `psi` the regular two-step basis function from the uniform system of
//!   [`crate::triangle_system`] (non-polynomial: solved on the grid) and `R_T[j]` the level-0
//!   weights of level-`L` point `j`;
//! * the partition of unity `sum_j phi_j(x) = 1`.
//!
//! At the grid points `(i/n, j/n)`, `i + j <= n`, this is a `ScalingSystem` whose classes are
//! the grid points (`x -> 3x` maps the grid into itself inside `u + v <= 1/3`): triangular
//! except at `x = 0`, where `phi(0) = phi(0) A`, `sum phi(0) = 1` gives the limit mask at `V`
//! (√3 approximates, so it is not a unit row). `y = 9x` has denominator `n`, so `psi` is
//! needed on the rate-`n` grid only. [`Sqrt3Substitution`] unrolls the same relations at any
//! rational point without forming a system (the independent cross-check).
//!
//! **Irrational weights.** For `K = 5, 7, 8` the vertex weight `alpha_K = (4 - 2 cos(2π/K))/9`
//! is irrational: only the f64 path serves them (the exact path returns
//! [`StencilError::Irrational`]). The f64 path's relation coefficients are the f64 entries of
//! `A`, carried into the system's rational coefficient rows exactly (every f64 is a dyadic
//! rational), so the solver sees precisely the f64 matrix.
//!
//! The grid system, the substitution and the helpers that read the matrices are
//! [`crate::cone_patch`]'s, shared with the butterfly (dilation 3 here, 2 there), and so is the
//! policy for solving the regular basis; this module names them for √3.

use schemes::cone_local::ConeFamily;
use schemes::TriangleScheme;

pub use crate::cone_patch::{
    cone_matrices as sqrt3_matrices, cone_patch_stencils as sqrt3_patch_stencils,
    cone_patch_stencils_at as sqrt3_patch_stencils_at,
};
use crate::cone_patch::{family_regular_basis_kind, ConePatchStencils, ConeSubstitution};
use crate::regular_patch::StencilKind;
use crate::triangle_system::TriangleStencils;
use crate::{Scalar, StencilError};

/// Position stencils at the grid points of the √3 EV patch ([`ConePatchStencils`]).
pub type Sqrt3PatchStencils<S> = ConePatchStencils<S>;

/// √3 EV-patch stencils by substitution at any rational `(u, v)` ([`ConeSubstitution`],
/// dilation 3: the level-`L` point is `9 * 3^k x` after the triplings).
pub type Sqrt3Substitution<S> = ConeSubstitution<S>;

/// √3's regular (two-step, ternary) basis function on the rate-`d` grid, in the field `S`:
/// always solved exactly and rounded ([`crate::cone_patch::solves_basis_in_field`] says why).
pub fn sqrt3_regular_basis<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
) -> Result<TriangleStencils<S>, StencilError> {
    sqrt3_regular_basis_kind(scheme, d, StencilKind::Position)
}

/// [`sqrt3_regular_basis`] or one of its derivatives along the skew axes, on the rate-`d`
/// grid, `d <= `[`crate::triangle_system::MAX_BASIS_RATE`] (the tables' dual points need
/// `3n`): √3's case of [`family_regular_basis_kind`], which holds the normalization and the
/// policy.
pub fn sqrt3_regular_basis_kind<S: Scalar>(
    scheme: &TriangleScheme,
    d: u32,
    kind: StencilKind,
) -> Result<TriangleStencils<S>, StencilError> {
    family_regular_basis_kind(ConeFamily::Sqrt3, scheme, d, kind)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle_system::triangle_stencils;
    use crate::triangle_system::{triangle_stencils_up_to, MAX_BASIS_RATE};
    use num_rational::BigRational;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
    }

    #[test]
    fn exact_mode_refuses_irrational_valences_and_names_the_cosine() {
        for k in [5, 7, 8] {
            let e = sqrt3_patch_stencils::<BigRational>(&sqrt3(), k, 2).expect_err("irrational");
            assert!(matches!(e, StencilError::Irrational { .. }));
            assert!(e.to_string().contains(&format!("cos(2 pi/{k})")), "{e}");
            assert!(Sqrt3Substitution::<BigRational>::new(&sqrt3(), k).is_err());
        }
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 2).is_ok());
    }

    #[test]
    fn points_outside_the_patch_and_bad_rates_are_errors() {
        let mut s = Sqrt3Substitution::<BigRational>::new(&sqrt3(), 4).expect("valid");
        let q = |p: i64, r: i64| BigRational::new(p.into(), r.into());
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        // 9 * 20/53 has denominator 53 > 24: the regular system is not solved there.
        assert!(matches!(
            s.stencil(&q(20, 53), &q(0, 1)),
            Err(StencilError::RateOutOfRange { n: 53, .. })
        ));
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 0).is_err());
        assert!(sqrt3_patch_stencils::<f64>(&sqrt3(), 5, 25).is_err());
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        let loop_basis =
            triangle_stencils::<BigRational>(&loop_.regular_mask(), 2, StencilKind::Position)
                .expect("solvable");
        assert!(s.share_basis(loop_basis).is_err());
        assert!(matches!(
            sqrt3_patch_stencils::<f64>(&loop_, 5, 2),
            Err(StencilError::UnsupportedScheme { .. })
        ));
    }

    #[test]
    #[ignore = "timing sweep (a few minutes): exact against f64 solves of psi and its derivatives at rates 3..=15"]
    fn f64_and_exact_regular_bases_agree_at_the_table_rates() {
        let scheme = sqrt3();
        let mask = scheme.regular_mask();
        for d in (3..=15).step_by(3) {
            for kind in StencilKind::ALL {
                let t0 = std::time::Instant::now();
                let e = triangle_stencils_up_to::<BigRational>(&mask, d, kind, MAX_BASIS_RATE)
                    .expect("exact");
                let te = t0.elapsed().as_secs_f64();
                let t1 = std::time::Instant::now();
                let f =
                    triangle_stencils_up_to::<f64>(&mask, d, kind, MAX_BASIS_RATE).expect("f64");
                let tf = t1.elapsed().as_secs_f64();
                let worst = e
                    .values
                    .iter()
                    .zip(&f.values)
                    .map(|(a, b)| (crate::Scalar::to_f64(a) - b).abs())
                    .fold(0.0, f64::max);
                eprintln!("rate {d} {kind:?}: exact {te:.2} s, f64 {tf:.2} s, |diff| {worst:e}");
                assert!(worst < 1e-12, "rate {d} {kind:?}: {worst}");
            }
        }
    }
}
