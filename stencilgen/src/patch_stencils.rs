//! Stencils of the patch next to an extraordinary vertex, from the scaling relation on a grid
//! (Schaefer–Warren section 5.2, in the matrix form of `shared/notes/extraordinary-stencils.md`).
//!
//! Let `phi(x)` be the row vector of the `K` basis functions of the patch's control points
//! ([`crate::extraordinary_patch`]) at `x` in `[0,1]^2`. Refining once does not change the
//! surface, so
//!
//! * `phi(x) = phi(2x) A` for `x` in `[0,1/2]^2`;
//! * `phi(x) = psi(t) R_b` for `x` in regular sub-patch `b`, `t = 2x - origin_b`, where `psi`
//!   is the regular tensor-product basis ([`crate::regular_patch`]);
//! * for derivatives each step picks up a factor 2 (`d/du phi(x) = 2 (d/du phi)(2x) A`);
//! * the partition of unity `sum_j phi_j(x) = 1` (tangents: `sum_j = 0`).
//!
//! Written at every primal point `(i/n, j/n)` and dual point `((2i+1)/2n, (2j+1)/2n)` — whose
//! doubles lie on the `1/n` grid — this is a [`ScalingSystem`] whose classes are the grid
//! points: `x` is written through `2x`, a point of a regular sub-patch through known values
//! only. The system is triangular except at `x = 0`, which maps to itself: there
//! `phi(0) = phi(0) A` with `sum phi(0) = 1`, the limit-position mask (left eigenvector of `A`
//! for eigenvalue 1). The orbit solver handles all of it, exactly or in f64. The tangents at
//! `x = 0` itself are not parametric derivatives (for `v != 4` the characteristic map scales by
//! the subdominant eigenvalue, not 1/2): they come from [`crate::ev_tangents`].

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::{CurveScheme, QuadScheme};

use crate::ev_tangents::ev_tangents;
use crate::extraordinary_patch::{LocalMatrices, Neighbourhood, SUB_PATCH_ORIGINS};
use crate::regular_patch::{RegularBasis, StencilKind};
use crate::scaling_system::{NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::{Scalar, StencilError};

/// Stencils of one kind at every primal and dual grid point of an EV patch.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchStencils<S> {
    /// The scheme's name.
    pub scheme: String,
    /// The vertex's neighbourhood.
    pub neighbourhood: Neighbourhood,
    /// The sector whose patch this is.
    pub sector: u32,
    /// Grid rate.
    pub n: u32,
    /// Positions or derivatives.
    pub kind: StencilKind,
    /// Grid points as numerators over `2n`: primal `(2i, 2j)`, `0 <= i, j <= n`, row by row,
    /// then dual `(2i+1, 2j+1)`, `0 <= i, j < n`.
    pub points: Vec<(i64, i64)>,
    /// `K` weights per point in the layout order. Tangents at the EV itself come from
    /// [`ev_tangents`] and are `None` in exact arithmetic (they are irrational).
    pub stencils: Vec<Option<Vec<S>>>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> PatchStencils<S> {
    /// The stencil at `(a/2n, b/2n)`, if that is a grid point with a stencil.
    pub fn at(&self, a: i64, b: i64) -> Option<&[S]> {
        let i = self.points.iter().position(|&p| p == (a, b))?;
        self.stencils[i].as_deref()
    }
}

/// The primal then dual grid points of rate `n`, as numerators over `2n`.
pub fn grid_points(n: u32) -> Vec<(i64, i64)> {
    let n = i64::from(n);
    let primal = (0..=n).flat_map(|j| (0..=n).map(move |i| (2 * i, 2 * j)));
    let dual = (0..n).flat_map(|j| (0..n).map(move |i| (2 * i + 1, 2 * j + 1)));
    primal.chain(dual).collect()
}

/// Which regular sub-patch holds `(a/2n, b/2n)` (`max(a, b) > n`), and the local parameter
/// `t = 2x - origin` as numerators over `n`.
pub fn sub_patch_of(a: i64, b: i64, n: i64) -> (usize, (i64, i64)) {
    let index = match (a > n, b > n) {
        (true, false) => 0,
        (true, true) => 1,
        _ => 2,
    };
    let (a0, b0) = SUB_PATCH_ORIGINS[index];
    (index, (a - a0 * n, b - b0 * n))
}

/// Solve the patch system of `scheme` around `neighbourhood`, patch `sector`, at rate `n`, for
/// one `kind`.
pub fn patch_stencils<S: Scalar>(
    scheme: &QuadScheme,
    neighbourhood: Neighbourhood,
    sector: u32,
    n: u32,
    kind: StencilKind,
) -> Result<PatchStencils<S>, StencilError> {
    let matrices = LocalMatrices::new(scheme, neighbourhood, sector)?;
    let curve = regular_curve(scheme)?;
    let basis = RegularBasis::<S>::new(&curve, n)?;
    patch_stencils_with(scheme, &matrices, &basis, kind)
}

/// The curve scheme whose tensor product is `scheme`'s regular case.
pub fn regular_curve(scheme: &QuadScheme) -> Result<CurveScheme, StencilError> {
    curve_scheme(scheme.regular_curve)
}

/// A curve scheme from the catalogue, or an error listing the catalogue.
pub fn curve_scheme(name: &str) -> Result<CurveScheme, StencilError> {
    CurveScheme::by_name(name).ok_or_else(|| StencilError::UnknownScheme {
        name: name.to_owned(),
        known: schemes::curve::CURVE_SCHEME_NAMES.join(", "),
    })
}

/// A quad scheme from the catalogue, or an error listing the catalogue.
pub fn quad_scheme(name: &str) -> Result<QuadScheme, StencilError> {
    QuadScheme::by_name(name).ok_or_else(|| StencilError::UnknownScheme {
        name: name.to_owned(),
        known: schemes::quad::QUAD_SCHEME_NAMES.join(", "),
    })
}

/// [`patch_stencils`] with the local matrices and the regular basis already built.
pub fn patch_stencils_with<S: Scalar>(
    scheme: &QuadScheme,
    matrices: &LocalMatrices,
    basis: &RegularBasis<S>,
    kind: StencilKind,
) -> Result<PatchStencils<S>, StencilError> {
    let n = i64::from(basis.n);
    let k = matrices.size();
    let factor = BigRational::from_integer(BigInt::from(kind.doubling_factor()));
    // Columns of A, scaled: phi_j(x) = sum_i factor A[i][j] phi_i(2x).
    let columns: Vec<Vec<(usize, BigRational)>> = (0..k)
        .map(|j| {
            (0..k)
                .filter(|&i| !matrices.a[i][j].is_zero())
                .map(|i| (i, &factor * &matrices.a[i][j]))
                .collect()
        })
        .collect();
    // psi(t) R_b = sum_q w_v(t_v, q) [sum_p w_u(t_u, p) R_b[(p, q)]]: the bracket depends on
    // t_u only, so it is computed once per column of the grid (`separable[b][t_u][q]`), which
    // cuts the exact arithmetic for the known values about fourfold.
    let separable: Vec<Vec<Vec<Vec<S>>>> = matrices
        .sub_patches
        .iter()
        .map(|r| {
            (0..=n)
                .map(|tu| {
                    let wu = basis.axis_weights(tu, kind == StencilKind::DerivativeU);
                    (0..4)
                        .map(|q| {
                            (0..k)
                                .map(|j| {
                                    wu.iter().enumerate().fold(S::zero(), |acc, (p, w)| {
                                        let entry = &r[4 * q + p][j];
                                        if entry.is_zero() {
                                            acc
                                        } else {
                                            acc + w.clone() * S::from_rational(&(&factor * entry))
                                        }
                                    })
                                })
                                .collect()
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let points = grid_points(basis.n);
    let class_of: HashMap<(i64, i64), u32> = points
        .iter()
        .enumerate()
        .map(|(c, &p)| (p, c as u32))
        .collect();
    let next: Vec<Option<u32>> = points
        .iter()
        .map(|&(a, b)| {
            let is_origin_tangent = (a, b) == (0, 0) && kind != StencilKind::Position;
            (a.max(b) <= n && !is_origin_tangent).then(|| class_of[&(2 * a, 2 * b)])
        })
        .collect();
    // Tangents at the EV itself are not unknowns of this system (see the module docs).
    let has_unknowns = |&(a, b): &(i64, i64)| (a, b) != (0, 0) || kind == StencilKind::Position;
    let mut first = Vec::with_capacity(points.len());
    let mut count = 0;
    for p in &points {
        first.push(count);
        count += if has_unknowns(p) { k } else { 0 };
    }
    let mut system = ScalingSystem::<S>::new(next.clone());
    for (c, &(a, b)) in points.iter().enumerate() {
        if !has_unknowns(&(a, b)) {
            continue;
        }
        let constants: Vec<S> = if a.max(b) <= n {
            vec![S::zero(); k]
        } else {
            let (index, (tu, tv)) = sub_patch_of(a, b, n);
            let wv = basis.axis_weights(tv, kind == StencilKind::DerivativeV);
            let columns = &separable[index][tu as usize];
            (0..k)
                .map(|j| {
                    wv.iter().zip(columns).fold(S::zero(), |acc, (w, column)| {
                        acc + w.clone() * column[j].clone()
                    })
                })
                .collect()
        };
        for (j, constant) in constants.into_iter().enumerate() {
            let terms: SparseRow = match next[c] {
                Some(target) => {
                    let base = first[target as usize];
                    columns[j]
                        .iter()
                        .map(|(i, w)| (base + i, w.clone()))
                        .collect()
                }
                None => Vec::new(),
            };
            system.push_unknown(
                c as u32,
                Relation { terms, constant },
                format!("phi_{j}({a}/{}, {b}/{})", 2 * n, 2 * n),
            );
        }
        let rhs = if kind == StencilKind::Position {
            BigRational::one()
        } else {
            BigRational::zero()
        };
        let start = first[c];
        system.normalization.push(NormalizationRow {
            class: c as u32,
            terms: (start..start + k)
                .map(|u| (u, BigRational::one()))
                .collect(),
            rhs,
            label: format!("x = ({a}/{}, {b}/{})", 2 * n, 2 * n),
        });
    }
    let Solution { values, residual } = solve_system::<S>(&system, scheme.name, basis.n)?;
    let mut stencils: Vec<Option<Vec<S>>> = points
        .iter()
        .enumerate()
        .map(|(c, p)| has_unknowns(p).then(|| values[first[c]..first[c] + k].to_vec()))
        .collect();
    if kind != StencilKind::Position {
        // The EV tangent masks are irrational in general: filled in where S takes f64 values.
        let tangents = ev_tangents(matrices)?;
        let mask = if kind == StencilKind::DerivativeU {
            tangents.du
        } else {
            tangents.dv
        };
        stencils[0] = mask.into_iter().map(S::from_f64).collect();
    }
    Ok(PatchStencils {
        scheme: scheme.name.to_owned(),
        neighbourhood: matrices.neighbourhood,
        sector: matrices.sector,
        n: basis.n,
        kind,
        points,
        stencils,
        residual,
    })
}
