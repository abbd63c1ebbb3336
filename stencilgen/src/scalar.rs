//! The number types the solver runs on: exact rationals and f64, behind one trait, so that
//! assembly, substitution and verification are written once.

use std::fmt::Debug;
use std::ops::{Add, Mul, Sub};

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{ToPrimitive, Zero};

use crate::orbit_block::{BlockFailure, OrbitBlock};

/// A field the scaling-relation system can be solved in.
pub trait Scalar:
    Clone + Debug + PartialEq + Zero + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
    /// Whether values are exact (residuals must be exactly zero).
    const EXACT: bool;

    /// The (exact) rational `r` in this field.
    fn from_rational(r: &BigRational) -> Self;

    /// The nearest f64.
    fn to_f64(&self) -> f64;

    /// An f64 as a value of this field, where the field takes approximate values (`None` for
    /// exact arithmetic: an f64 there would pass for exact).
    fn from_f64(x: f64) -> Option<Self>;

    /// Whether an equation's residual counts as satisfied: exactly zero for exact
    /// arithmetic, within [`FLOAT_TOLERANCE`] for f64.
    fn is_negligible(&self) -> bool;

    /// Solve the closed system of one residue cycle (see [`OrbitBlock`]): the values of the
    /// block's unknowns, step by step.
    fn solve_orbit(block: &OrbitBlock<Self>) -> Result<Vec<Vec<Self>>, BlockFailure>;
}

/// Largest residual an f64 solution may leave in any equation and still count as a solution.
pub const FLOAT_TOLERANCE: f64 = 1e-9;

impl Scalar for BigRational {
    const EXACT: bool = true;

    fn from_rational(r: &BigRational) -> Self {
        r.clone()
    }

    fn to_f64(&self) -> f64 {
        rational_to_f64(self)
    }

    fn from_f64(_: f64) -> Option<Self> {
        None
    }

    fn is_negligible(&self) -> bool {
        Zero::is_zero(self)
    }

    fn solve_orbit(block: &OrbitBlock<Self>) -> Result<Vec<Vec<Self>>, BlockFailure> {
        crate::exact_solve::solve_orbit(block)
    }
}

impl Scalar for f64 {
    const EXACT: bool = false;

    fn from_rational(r: &BigRational) -> Self {
        rational_to_f64(r)
    }

    fn to_f64(&self) -> f64 {
        *self
    }

    fn from_f64(x: f64) -> Option<Self> {
        Some(x)
    }

    fn is_negligible(&self) -> bool {
        self.abs() <= FLOAT_TOLERANCE
    }

    fn solve_orbit(block: &OrbitBlock<Self>) -> Result<Vec<Vec<Self>>, BlockFailure> {
        crate::float_solve::solve_orbit(block)
    }
}

/// The f64 nearest to a rational whose numerator and denominator may both overflow f64:
/// both are shifted down to 64 significant bits first, so the quotient keeps full precision.
pub fn rational_to_f64(r: &BigRational) -> f64 {
    let (num, den) = (r.numer(), r.denom());
    let shift = |x: &BigInt| x.bits().saturating_sub(64);
    let (sn, sd) = (shift(num), shift(den));
    let n = (num >> sn).to_f64().unwrap_or(f64::NAN);
    let d = (den >> sd).to_f64().unwrap_or(f64::NAN);
    (n / d) * (sn as f64 - sd as f64).exp2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_rationals_convert_without_overflow() {
        let big = BigInt::from(3u8).pow(1000);
        let r = BigRational::new(big.clone() * 2, big * 3);
        assert!((rational_to_f64(&r) - 2.0 / 3.0).abs() < 1e-15);
        let small = BigRational::new(BigInt::from(-1), BigInt::from(5589));
        assert_eq!(rational_to_f64(&small), -1.0 / 5589.0);
    }
}
