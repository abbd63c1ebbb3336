//! Curve stencils: basis-function values (or derivatives) of a scheme on `(1/n) Z`.

use num_bigint::BigInt;
use num_rational::BigRational;
use schemes::CurveScheme;

use crate::curve_system::CurveSystem;
use crate::solve::{solve_system, Solution};
use crate::{Scalar, StencilError};

/// Largest grid rate accepted (the solver itself has no limit; this keeps a mistyped rate
/// from running for minutes).
pub const MAX_RATE: u32 = 1024;

/// Values of one scaling function on the grid `(1/n) Z`.
#[derive(Clone, Debug, PartialEq)]
pub struct BasisFunction<S> {
    /// Component name (`phi` for uniform schemes).
    pub name: String,
    /// Integer support hull `[lo, hi]`.
    pub support: (i64, i64),
    /// Values at `x = lo, lo + 1/n, ..., hi` (both ends included, where they are zero).
    pub values: Vec<S>,
    n: i64,
}

impl<S: Scalar> BasisFunction<S> {
    /// The value at `x = k/n` (zero outside the support).
    pub fn at(&self, k: i64) -> S {
        let first = self.support.0 * self.n;
        usize::try_from(k - first)
            .ok()
            .and_then(|i| self.values.get(i).cloned())
            .unwrap_or_else(S::zero)
    }

    /// The grid points `x = lo, lo + 1/n, ..., hi`, as exact rationals.
    pub fn grid(&self) -> Vec<BigRational> {
        let first = self.support.0 * self.n;
        (0..self.values.len() as i64)
            .map(|i| BigRational::new(BigInt::from(first + i), BigInt::from(self.n)))
            .collect()
    }
}

/// The stencils of one scheme at one grid rate.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveStencils<S> {
    /// The scheme's catalogue name.
    pub scheme: String,
    /// The grid rate.
    pub n: u32,
    /// Whether these are derivative values (tangent masks).
    pub derivative: bool,
    /// One function per component of the scheme.
    pub functions: Vec<BasisFunction<S>>,
    /// Largest absolute residual over every equation of the system (0 when exact).
    pub residual: f64,
}

impl<S: Scalar> CurveStencils<S> {
    /// The stencil (or tangent mask) of a uniform scheme at `x = numerator / n`: the nonzero
    /// weights `phi(x - k)` of the control points `k`, in increasing `k`.
    pub fn mask_at(&self, numerator: i64) -> Vec<(i64, S)> {
        let f = &self.functions[0];
        let n = i64::from(self.n);
        let (lo, hi) = f.support;
        ((numerator - hi * n).div_euclid(n)..=(numerator - lo * n).div_euclid(n))
            .map(|k| (k, f.at(numerator - k * n)))
            .filter(|(_, w)| !w.is_zero())
            .collect()
    }
}

/// Solve the scaling-relation system of `scheme` on `(1/n) Z`: basis-function values, or with
/// `derivative` the first derivatives (tangent masks, Schaefer–Warren section 4).
///
/// Exact in `BigRational`; in `f64` through an SVD least-squares solve with the residual
/// reported in [`CurveStencils::residual`].
pub fn curve_stencils<S: Scalar>(
    scheme: &CurveScheme,
    n: u32,
    derivative: bool,
) -> Result<CurveStencils<S>, StencilError> {
    if n == 0 || n > MAX_RATE {
        return Err(StencilError::RateOutOfRange { n, max: MAX_RATE });
    }
    let curve = CurveSystem::<S>::new(scheme, n, derivative)?;
    let Solution { values, residual } = solve_system::<S>(&curve.system, &scheme.name, n)?;
    let n_i = i64::from(n);
    let functions = scheme
        .components
        .iter()
        .enumerate()
        .map(|(c, component)| {
            let (lo, hi) = curve.supports[c];
            BasisFunction {
                name: component.name.clone(),
                support: (lo, hi),
                values: (lo * n_i..=hi * n_i)
                    .map(|k| {
                        curve
                            .unknown(c, k)
                            .map_or_else(S::zero, |u| values[u].clone())
                    })
                    .collect(),
                n: n_i,
            }
        })
        .collect();
    Ok(CurveStencils {
        scheme: scheme.name.clone(),
        n,
        derivative,
        functions,
        residual,
    })
}
