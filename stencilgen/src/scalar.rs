//! The number types the solver runs on: exact rationals and f64, behind one trait, so that
//! assembly, substitution and verification are written once.

use std::fmt::Debug;
use std::ops::{Add, Mul, Sub};

use num_rational::BigRational;
use num_traits::Zero;

// The tolerance is the f64 solver's acceptance test and the conversion the rationals', so
// both live below this module (which dispatches to the solvers); their old paths stay.
pub use crate::float_solve::FLOAT_TOLERANCE;
use crate::orbit_block::{BlockFailure, OrbitBlock};
pub use crate::rational::rational_to_f64;

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
