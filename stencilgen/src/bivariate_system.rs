//! The uniform bivariate scaling-relation system on `[lo, hi]^2` at spacing `1/n`
//! (Schaefer–Warren section 5.1): the general path for surface schemes whose regular basis is
//! not a tensor product (triangle schemes), checked against tensor products of curve solutions.
//!
//! Unknowns are `phi(k/n)`, `k in Z^2` strictly inside the support box. Relations
//! `phi(k/n) = f sum_i s_i phi((2k - i n)/n)` (`f = 1`, or 2 for first derivatives); classes are
//! the residue pairs `(k_1 mod n, k_2 mod n)`, mapped to their doubles. Normalization per class
//! at `x = r/n`: `sum_{i in Z^2} phi(x - i) = 1`, or for `d/dx_c`
//! `sum_i (i_c - x_c) d_c phi(x - i) = 1`, `sum_i (i_d - x_d) d_c phi(x - i) = 0` (`d != c`)
//! and `sum_i d_c phi(x - i) = 0` (Schaefer–Warren section 4, in two variables).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::One;
use schemes::BivariateMask;

use crate::regular_patch::StencilKind;
use crate::scaling_system::{add_to_row, NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::{Scalar, StencilError};

/// Values of a bivariate basis function on its support box at spacing `1/n`.
#[derive(Clone, Debug, PartialEq)]
pub struct BivariateStencils<S> {
    /// Grid rate.
    pub n: u32,
    /// What was solved for.
    pub kind: StencilKind,
    /// Support box `([lo_x, hi_x], [lo_y, hi_y])`.
    pub support: ((i64, i64), (i64, i64)),
    /// Values at `(lo_x + i/n, lo_y + j/n)`, row-major with `j` outer, ends included.
    pub values: Vec<S>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> BivariateStencils<S> {
    /// The value at `(k1/n, k2/n)` (zero outside the box).
    pub fn at(&self, k1: i64, k2: i64) -> S {
        let n = i64::from(self.n);
        let ((lx, hx), (ly, hy)) = self.support;
        if k1 < lx * n || k1 > hx * n || k2 < ly * n || k2 > hy * n {
            return S::zero();
        }
        let width = (hx - lx) * n + 1;
        self.values[((k2 - ly * n) * width + (k1 - lx * n)) as usize].clone()
    }
}

/// Solve the bivariate system of `mask` at rate `n`.
pub fn bivariate_stencils<S: Scalar>(
    mask: &BivariateMask,
    n: u32,
    kind: StencilKind,
) -> Result<BivariateStencils<S>, StencilError> {
    if n == 0 || n > 64 {
        return Err(StencilError::RateOutOfRange { n, max: 64 });
    }
    let ni = i64::from(n);
    let support = mask.support();
    let ((lx, hx), (ly, hy)) = support;
    let inner_w = (hx - lx) * ni - 1;
    let inner_h = (hy - ly) * ni - 1;
    let unknown = |k1: i64, k2: i64| -> Option<usize> {
        let (i, j) = (k1 - lx * ni - 1, k2 - ly * ni - 1);
        (i >= 0 && j >= 0 && i < inner_w && j < inner_h).then(|| (j * inner_w + i) as usize)
    };
    let class = |k1: i64, k2: i64| (k1.rem_euclid(ni) * ni + k2.rem_euclid(ni)) as u32;
    let next = (0..ni * ni)
        .map(|c| Some(class(2 * (c / ni), 2 * (c % ni))))
        .collect();
    let mut system = ScalingSystem::<S>::new(next);
    let factor = BigRational::from_integer(BigInt::from(kind.doubling_factor()));
    for k2 in ly * ni + 1..hy * ni {
        for k1 in lx * ni + 1..hx * ni {
            let mut terms: SparseRow = Vec::new();
            for ((i, j), w) in &mask.weights {
                if let Some(v) = unknown(2 * k1 - i * ni, 2 * k2 - j * ni) {
                    add_to_row(
                        &mut terms,
                        v,
                        &factor
                            * BigRational::new(BigInt::from(*w.numer()), BigInt::from(*w.denom())),
                    );
                }
            }
            system.push_unknown(
                class(k1, k2),
                Relation {
                    terms,
                    constant: S::zero(),
                },
                format!("phi({k1}/{n}, {k2}/{n})"),
            );
        }
    }
    // Normalization: the stencil reproduces 1 (positions), or maps the linear functions
    // x_1, x_2 to their derivatives (1, 0) or (0, 1) and constants to 0 (tangents; one
    // linear row alone would leave the other derivative free, since it obeys the same relation).
    let rows: Vec<(usize, i64)> = match kind {
        StencilKind::Position => vec![(2, 1)],
        StencilKind::DerivativeU => vec![(2, 0), (0, 1), (1, 0)],
        StencilKind::DerivativeV => vec![(2, 0), (0, 0), (1, 1)],
    };
    for r1 in 0..ni {
        for r2 in 0..ni {
            let x = [
                BigRational::new(r1.into(), ni.into()),
                BigRational::new(r2.into(), ni.into()),
            ];
            for &(moment, rhs) in &rows {
                let mut terms: SparseRow = Vec::new();
                for k2 in (ly * ni + 1..hy * ni).filter(|k| k.rem_euclid(ni) == r2) {
                    for k1 in (lx * ni + 1..hx * ni).filter(|k| k.rem_euclid(ni) == r1) {
                        let Some(u) = unknown(k1, k2) else { continue };
                        // x - i = k/n  =>  i = (r - k)/n.
                        let i = [(r1 - k1) / ni, (r2 - k2) / ni];
                        let coef = match moment {
                            2 => BigRational::one(),
                            c => BigRational::from_integer(i[c].into()) - &x[c],
                        };
                        add_to_row(&mut terms, u, coef);
                    }
                }
                system.normalization.push(NormalizationRow {
                    class: class(r1, r2),
                    terms,
                    rhs: BigRational::from_integer(rhs.into()),
                    label: format!("x = ({r1}/{n}, {r2}/{n})"),
                });
            }
        }
    }
    let Solution { values, residual } = solve_system::<S>(&system, &mask.name, n)?;
    let values = (ly * ni..=hy * ni)
        .flat_map(|k2| (lx * ni..=hx * ni).map(move |k1| (k1, k2)))
        .map(|(k1, k2)| unknown(k1, k2).map_or_else(S::zero, |u| values[u].clone()))
        .collect();
    Ok(BivariateStencils {
        n,
        kind,
        support,
        values,
        residual,
    })
}
