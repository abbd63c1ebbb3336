//! Stencils of the Loop patch next to a *boundary* vertex (Schaefer–Warren sections 5.2–5.3 on
//! the triangular lattice of section 5.1, with Loop's boundary rules of Hoppe et al. 1994): by
//! substitution at any rational `(u, v)`, the limit-position mask at the vertex, and the
//! tangent masks there.
//!
//! The data are [`TriangleLocalMatrices::boundary`]: the patch of sector `s` next to a boundary
//! vertex `V` with `k` triangles, its layout `V, E_0..E_k` and the outer points of sector `s`
//! that lie inside the mesh, the local subdivision matrix `A` and the three regular
//! sub-triangles, whose points outside the mesh are phantoms. With `phi(x)` the row of the
//! `K` basis functions at `x = (u, v)` (`u, v >= 0`, `u + v <= 1`, `V` at `(0,0)`, `E_s` at
//! `(1,0)`, `E_{s+1}` at `(0,1)`), one subdivision step leaves the surface unchanged, so
//!
//! * `phi(x) = phi(2x) A` while `u + v <= 1/2`;
//! * otherwise `y = 2x` lies in a regular sub-triangle `b` and
//!   `phi(x) = sum_j psi(y - j) R_b[j]` (the quartic box spline `psi` of
//!   [`crate::loop_basis`] over the sub-triangle's twelve level-1 points `j`);
//! * at `x = 0`: `phi(0) = phi(0) A`, `sum phi(0) = 1` (the limit-position mask).
//!
//! A derivative picks up a factor 2 per halving (section 4). These are the relations of the
//! interior patch, so the same code serves both: [`crate::triangle_patch::TriangleSubstitution::boundary`]
//! unrolls them at any rational point (exactly or in f64), `patch_stencils_at` solves them on a
//! grid, and `TriangleSubstitution::limit_mask` is the left fixed vector of `A`. This module
//! adds what is particular to the boundary: [`loop_boundary_tangents`], the tangent masks at
//! `V` from the eigen-structure of the 1-ring block of `A` (f64).
//!
//! **The 1-ring block.** `V, E_0, ..., E_k` is invariant under subdivision. Its boundary rows
//! (`V' = 1/8 E_0 + 3/4 V + 1/8 E_k`, `E_0' = (V + E_0)/2`, `E_k' = (V + E_k)/2`) read only
//! boundary points, so the block is lower block-triangular: its spectrum is the cubic B-spline
//! curve's `{1, 1/2, 1/4}` together with that of the interior rows `E_1..E_{k-1}`
//! (`E_i' = 3/8 V + 3/8 E_i + 1/8 E_{i-1} + 1/8 E_{i+1}`), whose `(k-1) x (k-1)` block
//! `tridiag(1/8, 3/8, 1/8)` has the eigenvalues `mu_j = 3/8 + cos(j pi / k) / 4`,
//! `j = 1..k-1`. The boundary curve's tangent `E_k - E_0` is a left eigenvector for `1/2`;
//! the *cross-boundary* mode is the one of `mu_1 = 3/8 + cos(pi/k)/4` (for `k = 1`, which
//! has no interior neighbour, the curve's second difference `E_0 - 2V + E_1`, eigenvalue
//! `1/4`). So `mu_1 < 1/2` for `k <= 2`, `= 1/2` at the regular `k = 3`, `> 1/2` for
//! `k >= 4`, and `mu_2 = 3/8 + cos(2 pi/k)/4` reaches `1/2` at `k = 6` (a Jordan block with
//! the boundary tangent: the normals still converge to the plane of `E_k - E_0` and the
//! `mu_1` mode, but only like `1/j` after `j` halvings) and exceeds it for `k >= 7`: there the
//! two largest subdominant modes are both cross modes, whose plane does not contain the
//! boundary curve's tangent, and the surface has no tangent plane at `V` (measured in
//! `docs/algorithms/triangle-schemes.md`).

use nalgebra::DMatrix;
use schemes::tangent_frame::frame_masks;
use schemes::triangle_local::{TriangleLocalMatrices, TriangleNeighbourhood};

use crate::ev_tangents::left_null_space;
use crate::scalar::rational_to_f64;
use crate::StencilError;

/// `(faces, sector)` of boundary matrices, or an error saying they are not.
fn boundary_of(matrices: &TriangleLocalMatrices) -> Result<(u32, u32), StencilError> {
    match matrices.neighbourhood {
        TriangleNeighbourhood::Boundary { faces, sector } => Ok((faces, sector)),
        TriangleNeighbourhood::Interior { valence } => Err(StencilError::UnsupportedScheme {
            scheme: matrices.scheme.clone(),
            reason: format!(
                "these are the matrices of an interior vertex of valence {valence}; use triangle_patch for them"
            ),
        }),
    }
}

/// The eigen-structure at a boundary vertex and the tangent masks there (f64, `K` weights
/// each, zero beyond the 1-ring `V, E_0..E_k`).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopBoundaryTangents {
    /// The eigenvalue of the boundary curve's tangent `E_k - E_0`: 1/2.
    pub along: f64,
    /// The eigenvalue of the cross-boundary mode: `3/8 + cos(pi/k)/4` for `k >= 2`, `1/4`
    /// (the curve's second difference) for `k = 1`.
    pub across: f64,
    /// All eigenvalues of the 1-ring block (real parts), largest first.
    pub ring_eigenvalues: Vec<f64>,
    /// Tangent mask in the direction of `E_s` (the patch's `u`).
    pub du: Vec<f64>,
    /// Tangent mask in the direction of `E_{s+1}` (the patch's `v`).
    pub dv: Vec<f64>,
}

/// Real parts of the eigenvalues of `m`, largest first, by a bounded Schur iteration.
fn eigenvalues(m: &DMatrix<f64>) -> Result<Vec<f64>, String> {
    if m.nrows() == 0 {
        return Ok(Vec::new());
    }
    let schur = nalgebra::linalg::Schur::try_new(m.clone(), 1e-14, 100_000)
        .ok_or_else(|| "the eigenvalue iteration did not converge".to_owned())?;
    let mut values: Vec<f64> = schur.complex_eigenvalues().iter().map(|z| z.re).collect();
    values.sort_by(|x, y| y.total_cmp(x));
    Ok(values)
}

/// Tangent masks at the boundary vertex `V` from the eigen-structure of the 1-ring block of
/// `A` (`V, E_0..E_k`, invariant under subdivision; see the module docs).
///
/// The tangent plane is spanned by the boundary curve's tangent `t = E_k - E_0` (eigenvalue
/// 1/2, in closed form, checked to be an eigenvector) and the left eigenvector `c` of the
/// cross-boundary eigenvalue (`mu_1 = 3/8 + cos(pi/k)/4`, the largest of the block of the
/// interior neighbours `E_1..E_{k-1}`; `1/4` for `k = 1`), taken independent of `t` (at
/// `k = 3` both eigenvalues are 1/2). The masks are normalized on the planar reference net
/// `V = 0`, `E_i = (cos i theta, sin i theta)`, `theta = pi / max(k, 2)` (the half-disk for
/// `k >= 2`; the quarter-disk for `k = 1`, whose half-disk net would put `V, E_0, E_1` on one
/// line): the `u` mask maps the net to `E_s`'s position, the `v` mask to `E_{s+1}`'s. So
/// `du x dv` points to the same side as the patch `V, E_s, E_{s+1}`. At `k = 3` the net is
/// the lattice and the masks are the box spline's derivatives along the skew axes at `V`
/// (phantoms expanded). At `k = 6` the normals converge to this plane only like `1/j`
/// (`mu_2 = 1/2`, a Jordan block). For `k >= 7` the pair `(1/2, mu_1)` is not the subdominant
/// pair of `A` (`mu_2 > 1/2`) and the limit surface has no tangent plane at `V`: the masks are
/// still the plane of the boundary tangent and the dominant cross mode, which the surface's
/// normals do not converge to (see the module docs).
pub fn loop_boundary_tangents(
    matrices: &TriangleLocalMatrices,
) -> Result<LoopBoundaryTangents, StencilError> {
    let (faces, sector) = boundary_of(matrices)?;
    let k = faces as usize;
    let ring = k + 2;
    let failure = |what: &str| StencilError::Inconsistent {
        scheme: "tangents at a boundary vertex".to_owned(),
        n: 0,
        detail: format!("{} with {faces} triangles: {what}", matrices.scheme),
    };
    let a1 = DMatrix::from_fn(ring, ring, |i, j| rational_to_f64(&matrices.a[i][j]));
    let ring_eigenvalues = eigenvalues(&a1).map_err(|e| failure(&e))?;
    // Layout indices: V = 0, E_i = 1 + i.
    let mut t = vec![0.0; ring];
    t[1] = -1.0;
    t[1 + k] = 1.0;
    let t_a: Vec<f64> = (0..ring)
        .map(|j| (0..ring).map(|i| t[i] * a1[(i, j)]).sum())
        .collect();
    if t_a.iter().zip(&t).any(|(x, y)| (x - 0.5 * y).abs() > 1e-12) {
        return Err(failure(
            "E_k - E_0 is not a left eigenvector for 1/2 (the boundary rules changed?)",
        ));
    }
    let across = if k == 1 {
        0.25
    } else {
        let interior = a1.view((2, 2), (k - 1, k - 1)).clone_owned();
        eigenvalues(&interior)
            .map_err(|e| failure(&e))?
            .first()
            .copied()
            .ok_or_else(|| failure("no interior neighbour"))?
    };
    // The eigenvector of `across` farthest from t's direction (at k = 3 the eigenspace also
    // holds t itself).
    let t_norm2: f64 = t.iter().map(|x| x * x).sum();
    let c = left_null_space(&a1, across)
        .into_iter()
        .map(|w| {
            let along: f64 = w.iter().zip(&t).map(|(a, b)| a * b).sum::<f64>() / t_norm2;
            w.iter()
                .zip(&t)
                .map(|(a, b)| a - along * b)
                .collect::<Vec<f64>>()
        })
        .max_by(|x, y| {
            let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>();
            norm(x).total_cmp(&norm(y))
        })
        .filter(|c| c.iter().map(|a| a * a).sum::<f64>() > 1e-12)
        .ok_or_else(|| failure("no cross-boundary eigenvector"))?;
    let step = std::f64::consts::PI / k.max(2) as f64;
    let edge = |i: usize| {
        let a = step * i as f64;
        [a.cos(), a.sin()]
    };
    let net: Vec<(usize, [f64; 2])> = (0..=k).map(|i| (1 + i, edge(i))).collect();
    let s = sector as usize;
    let [du, dv] = frame_masks(
        [&t, &c],
        &net,
        [1.0, 1.0],
        [edge(s), edge(s + 1)],
        matrices.size(),
    )
    .ok_or_else(|| failure("the tangent and cross modes do not span the reference net's plane"))?;
    Ok(LoopBoundaryTangents {
        along: 0.5,
        across,
        ring_eigenvalues,
        du,
        dv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regular_patch::StencilKind;
    use crate::triangle_patch::{triangle_scheme, TriangleSubstitution};
    use num_bigint::BigInt;
    use num_rational::BigRational;

    fn q(p: i64, r: i64) -> BigRational {
        BigRational::new(p.into(), r.into())
    }

    #[test]
    fn cross_eigenvalue_is_the_tridiagonal_closed_form() {
        // tridiag(1/8, 3/8, 1/8) of size k-1 has eigenvalues 3/8 + cos(j pi/k)/4.
        let loop_ = triangle_scheme("loop").expect("catalogued");
        for k in 1..=8u32 {
            let m = TriangleLocalMatrices::boundary(&loop_, k, 0).expect("valid");
            let t = loop_boundary_tangents(&m).expect("tangents");
            let expected = if k == 1 {
                0.25
            } else {
                0.375 + 0.25 * (std::f64::consts::PI / f64::from(k)).cos()
            };
            assert!((t.across - expected).abs() < 1e-12, "k = {k}: {}", t.across);
            assert_eq!(t.ring_eigenvalues.len(), k as usize + 2);
            assert!((t.ring_eigenvalues[0] - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let loop_ = triangle_scheme("loop").expect("catalogued");
        let mut s = TriangleSubstitution::<BigRational>::boundary(&loop_, 3, 1).expect("valid");
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        let too_fine = BigRational::new(1.into(), BigInt::from(3).pow(50));
        assert!(s.stencil(&too_fine, &q(0, 1)).is_err());
        assert!(s
            .stencil_of_kind(&q(0, 1), &q(0, 1), StencilKind::DerivativeU)
            .is_err());
        assert!(TriangleSubstitution::<f64>::boundary(&loop_, 3, 3).is_err());
        let interior = TriangleLocalMatrices::new(&loop_, 5).expect("valid");
        assert!(loop_boundary_tangents(&interior).is_err());
    }
}
