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
//! A derivative picks up a factor 2 per halving (section 4). [`TriangleBoundarySubstitution`]
//! unrolls these at any rational point, exactly or in f64 (one generic implementation over
//! [`Scalar`]); the grid system of [`crate::triangle_patch`] solves the same relations on a
//! grid. [`boundary_limit_mask`] solves for the left fixed vector of `A`;
//! [`loop_boundary_tangents`] gives the tangent masks at `V` from the eigen-structure of the
//! 1-ring block of `A` (f64).
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

use std::collections::HashMap;

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::triangle_local::{TriangleLocalMatrices, TriangleNeighbourhood};
use schemes::TriangleScheme;

use crate::ev_tangents::left_null_space;
use crate::exact_solve::solve_dense;
use crate::loop_basis::LoopRegularBasis;
use crate::regular_patch::StencilKind;
use crate::scalar::rational_to_f64;
use crate::triangle_patch::sub_triangle_of;
use crate::{Scalar, StencilError};

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

/// `sum_j psi(y - j) R_b[j]` with `y = Y / d` (level-1 sector coordinates): the weights of a
/// point of a regular sub-triangle over the layout, `psi` from the exact quartic pieces of
/// [`LoopRegularBasis`] (any denominator).
fn sub_triangle_weights<S: Scalar>(
    matrices: &TriangleLocalMatrices,
    basis: &LoopRegularBasis,
    y: (i64, i64),
    d: i64,
) -> Vec<S> {
    let sub = &matrices.sub_triangles[sub_triangle_of(y, d)];
    let mut out = vec![S::zero(); matrices.size()];
    for (&(j1, j2), row) in sub.points.iter().zip(&sub.rows) {
        let psi: S = basis.at(y.0 - d * j1, y.1 - d * j2, d);
        if S::EXACT && psi.is_negligible() {
            continue;
        }
        for (o, r) in out.iter_mut().zip(row) {
            if !r.is_zero() {
                *o = o.clone() + psi.clone() * S::from_rational(r);
            }
        }
    }
    out
}

/// The limit-position mask at `V`: the left fixed vector of `A` (`phi(0) = phi(0) A`) with
/// weights summing to 1, solved exactly. For Loop's boundary rules it is the cubic B-spline
/// curve's limit `(E_0 + 4 V + E_k) / 6` (the boundary rows read only boundary points).
pub fn boundary_limit_mask(
    matrices: &TriangleLocalMatrices,
) -> Result<Vec<BigRational>, StencilError> {
    let size = matrices.size();
    let mut rows: Vec<(Vec<BigRational>, BigRational)> = (0..size)
        .map(|j| {
            let mut row: Vec<BigRational> = (0..size).map(|i| matrices.a[i][j].clone()).collect();
            row[j] -= BigRational::one();
            (row, BigRational::zero())
        })
        .collect();
    rows.push((vec![BigRational::one(); size], BigRational::one()));
    solve_dense(rows, size).map_err(|e| StencilError::Inconsistent {
        scheme: matrices.scheme.clone(),
        n: 1,
        detail: format!(
            "limit mask next to a boundary vertex ({:?}): {e:?}",
            matrices.neighbourhood
        ),
    })
}

/// Evaluates stencils of the Loop patch next to a boundary vertex by substitution at any
/// rational `(u, v)`; caches the regular basis per kind.
#[derive(Debug)]
pub struct TriangleBoundarySubstitution<S> {
    scheme: TriangleScheme,
    /// The local subdivision matrices ([`TriangleLocalMatrices::boundary`]).
    pub matrices: TriangleLocalMatrices,
    bases: HashMap<StencilKind, LoopRegularBasis>,
    field: std::marker::PhantomData<S>,
}

impl<S: Scalar> TriangleBoundarySubstitution<S> {
    /// Prepare for the patch of sector `sector` next to a boundary vertex with `faces`
    /// triangles (`faces >= 1`, `sector < faces`), Loop's boundary rules.
    pub fn new(scheme: &TriangleScheme, faces: u32, sector: u32) -> Result<Self, StencilError> {
        Ok(TriangleBoundarySubstitution {
            scheme: scheme.clone(),
            matrices: TriangleLocalMatrices::boundary(scheme, faces, sector)?,
            bases: HashMap::new(),
            field: std::marker::PhantomData,
        })
    }

    /// Switch to the patch of sector `sector` next to a boundary vertex with `faces`
    /// triangles, keeping the cached regular basis (it does not depend on the patch).
    pub fn select_patch(&mut self, faces: u32, sector: u32) -> Result<(), StencilError> {
        self.matrices = TriangleLocalMatrices::boundary(&self.scheme, faces, sector)?;
        Ok(())
    }

    /// The `K` position weights at `(u, v)`, `u, v >= 0`, `u + v <= 1`, in the layout order
    /// of [`schemes::triangle_local::triangle_boundary_layout`].
    pub fn stencil(&mut self, u: &BigRational, v: &BigRational) -> Result<Vec<S>, StencilError> {
        self.stencil_of_kind(u, v, StencilKind::Position)
    }

    /// [`Self::stencil`] for positions or derivatives along `u` (towards `E_s`) and `v`
    /// (towards `E_{s+1}`): double `x` `j` times until `u + v > 1/2`, take the regular
    /// sub-triangle's weights at `2x`, apply `A` `j` times (times 2 per step for a
    /// derivative). Any denominator that fits 64 bits works ([`LoopRegularBasis`]). At
    /// `V` the position is [`boundary_limit_mask`] and the derivatives are
    /// [`loop_boundary_tangents`]' masks, irrational in general: f64 only.
    pub fn stencil_of_kind(
        &mut self,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let (zero, one) = (BigRational::zero(), BigRational::one());
        if *u < zero || *v < zero || u + v > one {
            return Err(StencilError::OutOfDomain {
                what: format!("(u, v) = ({u}, {v}) is outside the patch u, v >= 0, u + v <= 1"),
            });
        }
        if u.is_zero() && v.is_zero() {
            if kind == StencilKind::Position {
                return Ok(boundary_limit_mask(&self.matrices)?
                    .iter()
                    .map(S::from_rational)
                    .collect());
            }
            let t = loop_boundary_tangents(&self.matrices)?;
            let mask = if kind == StencilKind::DerivativeU {
                t.du
            } else {
                t.dv
            };
            return mask
                .into_iter()
                .map(S::from_f64)
                .collect::<Option<Vec<S>>>()
                .ok_or_else(|| StencilError::Irrational {
                    what: format!(
                        "the tangent mask at a boundary vertex ({:?})",
                        self.matrices.neighbourhood
                    ),
                });
        }
        let half = BigRational::new(BigInt::from(1), BigInt::from(2));
        let two = BigRational::from_integer(BigInt::from(2));
        let (mut x, mut y, mut steps) = (u.clone(), v.clone(), 0u32);
        while &x + &y <= half {
            x *= &two;
            y *= &two;
            steps += 1;
        }
        let (y1, y2) = (&x * &two, &y * &two);
        let d = y1.denom().lcm(y2.denom());
        let numerator = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer())
        };
        let too_big = || StencilError::OutOfDomain {
            what: format!("the denominator of ({u}, {v}) does not fit in 64 bits"),
        };
        let point = (
            numerator(&y1).map_err(|_| too_big())?,
            numerator(&y2).map_err(|_| too_big())?,
        );
        let d = i64::try_from(&d).map_err(|_| too_big())?;
        if !self.bases.contains_key(&kind) {
            let basis = LoopRegularBasis::new(&self.scheme, kind)?;
            self.bases.insert(kind, basis);
        }
        let factor = S::from_rational(&BigRational::from_integer(BigInt::from(
            kind.doubling_factor(),
        )));
        let mut row: Vec<S> = sub_triangle_weights(&self.matrices, &self.bases[&kind], point, d)
            .into_iter()
            .map(|w: S| w * factor.clone())
            .collect();
        let size = self.matrices.size();
        for _ in 0..steps {
            // phi_j(x) = f sum_i phi_i(2x) A[i][j].
            row = (0..size)
                .map(|j| {
                    row.iter()
                        .zip(&self.matrices.a)
                        .filter(|(_, a)| !a[j].is_zero())
                        .fold(S::zero(), |acc, (w, a)| {
                            acc + w.clone() * S::from_rational(&a[j])
                        })
                        * factor.clone()
                })
                .collect();
        }
        Ok(row)
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
    let image = |w: &[f64]| {
        (0..=k).fold([0.0, 0.0], |acc, i| {
            let e = edge(i);
            [acc[0] + w[1 + i] * e[0], acc[1] + w[1 + i] * e[1]]
        })
    };
    let (g0, g1) = (image(&t), image(&c));
    let det = g0[0] * g1[1] - g0[1] * g1[0];
    if det.abs() < 1e-12 {
        return Err(failure(
            "the tangent and cross modes do not span the reference net's plane",
        ));
    }
    // The mask c0 t + c1 c whose image is `target`.
    let mask = |target: [f64; 2]| -> Vec<f64> {
        let c0 = (target[0] * g1[1] - target[1] * g1[0]) / det;
        let c1 = (g0[0] * target[1] - g0[1] * target[0]) / det;
        let mut m: Vec<f64> = t.iter().zip(&c).map(|(a, b)| c0 * a + c1 * b).collect();
        m.resize(matrices.size(), 0.0);
        m
    };
    let s = sector as usize;
    Ok(LoopBoundaryTangents {
        along: 0.5,
        across,
        ring_eigenvalues,
        du: mask(edge(s)),
        dv: mask(edge(s + 1)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle_patch::triangle_scheme;

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
        let mut s = TriangleBoundarySubstitution::<BigRational>::new(&loop_, 3, 1).expect("valid");
        assert!(s.stencil(&q(2, 3), &q(2, 3)).is_err());
        assert!(s.stencil(&q(-1, 3), &q(0, 1)).is_err());
        let too_fine = BigRational::new(1.into(), BigInt::from(3).pow(50));
        assert!(s.stencil(&too_fine, &q(0, 1)).is_err());
        assert!(s
            .stencil_of_kind(&q(0, 1), &q(0, 1), StencilKind::DerivativeU)
            .is_err());
        assert!(TriangleBoundarySubstitution::<f64>::new(&loop_, 3, 3).is_err());
        let interior = TriangleLocalMatrices::new(&loop_, 5).expect("valid");
        assert!(loop_boundary_tangents(&interior).is_err());
    }
}
