//! Assembly of the scaling-relation system of a curve scheme on the grid `(1/n) Z`.
//!
//! Unknowns are `phi_c(k/n)` for every component `c` and every `k/n` strictly inside the
//! component's support `[lo_c, hi_c]` (values at and beyond the ends are zero: the basis
//! functions are continuous and compactly supported). The equations are
//!
//! * the scaling relation at every unknown (Schaefer–Warren eq. (3), or its derivative,
//!   section 4, which doubles every weight):
//!   `phi_c(k/n) - f sum_t w_t phi_{c_t}((2k - i_t n)/n) = 0`, `f = 1` or `2`;
//! * the normalization at points `x = X/n`: the partition of unity (eq. (4))
//!   `sum_c sum_{k in T_c} phi_c(x - k) = 1`, or for tangents
//!   `sum_c sum_{k in T_c} (k - x) phi_c'(x - k) = 1` (section 4).
//!
//! For a uniform scheme the normalization points are `X = 0..n` (one per residue). For a
//! scheme with special components they cover every point where a special basis function or
//! the end of a one-sided family of translates is nonzero.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::One;
use schemes::{CurveScheme, Translates};

use crate::orbits::doubling;
use crate::scaling_system::{add_to_row, NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::{Scalar, StencilError};

/// The scaling-relation system of one scheme at one grid rate.
#[derive(Clone, Debug)]
pub struct CurveSystem<S> {
    /// Grid rate: the grid is `(1/n) Z`.
    pub n: u32,
    /// Whether the unknowns are derivatives `phi'` (tangent masks) instead of values.
    pub derivative: bool,
    /// Integer support hull `[lo_c, hi_c]` of every component.
    pub supports: Vec<(i64, i64)>,
    /// First unknown of every component; component `c` owns `offsets[c]..offsets[c + 1]`.
    pub offsets: Vec<usize>,
    /// The equations; unknown `u` stands for `phi_c(k/n)` with `(c, k) = point_of(u)`, its
    /// class is the residue `k mod n`.
    pub system: ScalingSystem<S>,
}

impl<S: Scalar> CurveSystem<S> {
    /// Build the system of `scheme` on `(1/n) Z`.
    pub fn new(scheme: &CurveScheme, n: u32, derivative: bool) -> Result<Self, StencilError> {
        if derivative && !scheme.reproduces_linear() {
            return Err(StencilError::NoLinearPrecision {
                scheme: scheme.name.clone(),
            });
        }
        let n_i = i64::from(n);
        let supports = scheme.supports();
        let mut offsets = vec![0usize];
        for &(lo, hi) in &supports {
            let count = usize::try_from((hi - lo) * n_i - 1).unwrap_or(0);
            offsets.push(offsets[offsets.len() - 1] + count);
        }
        let mut system = CurveSystem {
            n,
            derivative,
            supports,
            offsets,
            system: ScalingSystem::new(doubling(n)),
        };
        let factor = BigRational::from_integer(BigInt::from(if derivative { 2 } else { 1 }));
        for (c, component) in scheme.components.iter().enumerate() {
            let (lo, hi) = system.supports[c];
            for k in lo * n_i + 1..hi * n_i {
                let mut row: SparseRow = Vec::new();
                for term in &component.refinement {
                    if let Some(v) = system.unknown(term.component, 2 * k - term.shift * n_i) {
                        add_to_row(&mut row, v, &factor * ratio(term.weight));
                    }
                }
                let relation = Relation {
                    terms: row,
                    constant: S::zero(),
                };
                let label = format!("{}({k}/{n})", component.name);
                system
                    .system
                    .push_unknown(k.rem_euclid(n_i) as u32, relation, label);
            }
        }
        for numerator in normalization_points(scheme, &system.supports, n_i) {
            let x = BigRational::new(BigInt::from(numerator), BigInt::from(n_i));
            let mut terms: SparseRow = Vec::new();
            for (c, component) in scheme.components.iter().enumerate() {
                let (lo, hi) = system.supports[c];
                // x - k inside (lo, hi)  <=>  numerator - k n in (lo n, hi n).
                let k_min = (numerator - hi * n_i).div_euclid(n_i);
                let k_max = (numerator - lo * n_i).div_euclid(n_i) + 1;
                for k in k_min..=k_max {
                    if !component.translates.contains(k) {
                        continue;
                    }
                    if let Some(u) = system.unknown(c, numerator - k * n_i) {
                        let coef = if derivative {
                            BigRational::from_integer(BigInt::from(k)) - &x
                        } else {
                            BigRational::one()
                        };
                        add_to_row(&mut terms, u, coef);
                    }
                }
            }
            system.system.normalization.push(NormalizationRow {
                class: numerator.rem_euclid(n_i) as u32,
                terms,
                rhs: BigRational::one(),
                label: format!("x = {x}"),
            });
        }
        Ok(system)
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.offsets[self.offsets.len() - 1]
    }

    /// The unknown `phi_c(k/n)`, or `None` where `k/n` is outside the open support.
    pub fn unknown(&self, c: usize, k: i64) -> Option<usize> {
        let (lo, hi) = self.supports[c];
        let n = i64::from(self.n);
        if k <= lo * n || k >= hi * n {
            return None;
        }
        Some(self.offsets[c] + usize::try_from(k - lo * n - 1).ok()?)
    }

    /// `(component, numerator k)` of unknown `u`: it stands for `phi_c(k/n)`.
    pub fn point_of(&self, u: usize) -> (usize, i64) {
        let c = self.offsets.partition_point(|&o| o <= u) - 1;
        let (lo, _) = self.supports[c];
        (c, lo * i64::from(self.n) + 1 + (u - self.offsets[c]) as i64)
    }
}

fn ratio(r: num_rational::Rational64) -> BigRational {
    BigRational::new(BigInt::from(*r.numer()), BigInt::from(*r.denom()))
}

/// Numerators `X` of the points `x = X/n` where the normalization is imposed.
///
/// Uniform components repeat with period 1, so `X = 0..n` covers them. A one-sided or single
/// family of translates makes the sum change near its end; every point where such a family
/// meets the others is covered (with one support width of margin on its open side).
fn normalization_points(scheme: &CurveScheme, supports: &[(i64, i64)], n: i64) -> Vec<i64> {
    let mut lo_x = 0i64;
    let mut hi_x = 1i64;
    for (component, &(lo, hi)) in scheme.components.iter().zip(supports) {
        let width = hi - lo;
        let span = match component.translates {
            Translates::All => None,
            Translates::AtMost(b) => Some((b + lo - width, b + hi)),
            Translates::AtLeast(b) => Some((b + lo, b + hi + width)),
            Translates::Only(b) => Some((b + lo, b + hi)),
        };
        if let Some((a, b)) = span {
            lo_x = lo_x.min(a);
            hi_x = hi_x.max(b);
        }
    }
    (lo_x * n..hi_x * n).collect()
}
