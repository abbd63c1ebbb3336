//! The regular patch: tensor products of a curve scheme's basis on the grid `(1/n) Z`.
//!
//! In a regular region a tensor-product quad scheme's basis function of control point
//! `(p, q)` is `phi(u - p) phi(v - q)` (Schaefer–Warren section 5.3: tangent masks are the
//! curve limit mask tensored with the curve derivative mask). On the cell `[0,1]^2` the
//! 16 control points `p, q in -1..=2` matter for a curve basis supported on `[-2, 2]`.

use schemes::CurveScheme;

use crate::{curve_stencils, BasisFunction, Scalar, StencilError};

/// What a stencil evaluates: the position or one of the two first derivatives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StencilKind {
    /// The limit position.
    Position,
    /// The derivative along `u`.
    DerivativeU,
    /// The derivative along `v`.
    DerivativeV,
}

impl StencilKind {
    /// All three, in table order.
    pub const ALL: [StencilKind; 3] = [
        StencilKind::Position,
        StencilKind::DerivativeU,
        StencilKind::DerivativeV,
    ];

    /// The factor the scaling relation picks up per halving: 1 for positions, 2 for derivatives.
    pub fn doubling_factor(self) -> i64 {
        match self {
            StencilKind::Position => 1,
            _ => 2,
        }
    }
}

/// The curve basis and its derivative at one grid rate, for tensor-product evaluation.
#[derive(Clone, Debug)]
pub struct RegularBasis<S> {
    /// The grid rate.
    pub n: u32,
    values: BasisFunction<S>,
    derivatives: BasisFunction<S>,
}

/// Control-point offsets of one cell, per axis.
pub const CELL_OFFSETS: [i64; 4] = [-1, 0, 1, 2];

impl<S: Scalar> RegularBasis<S> {
    /// Solve the curve scheme at rate `n` (values and derivatives).
    pub fn new(curve: &CurveScheme, n: u32) -> Result<Self, StencilError> {
        let values = curve_stencils::<S>(curve, n, false)?.functions.remove(0);
        let derivatives = curve_stencils::<S>(curve, n, true)?.functions.remove(0);
        if values.support != (-2, 2) {
            return Err(StencilError::UnsupportedScheme {
                scheme: curve.name.clone(),
                reason: format!(
                    "regular patches need a curve basis on [-2, 2], this one has {:?}",
                    values.support
                ),
            });
        }
        Ok(RegularBasis {
            n,
            values,
            derivatives,
        })
    }

    /// The weights `phi(t/n - p)` (or `phi'`) of the four control points `p` in
    /// [`CELL_OFFSETS`] of one axis at `t/n`.
    pub fn axis_weights(&self, t: i64, derivative: bool) -> [S; 4] {
        let n = i64::from(self.n);
        let f = if derivative {
            &self.derivatives
        } else {
            &self.values
        };
        CELL_OFFSETS.map(|p| f.at(t - p * n))
    }

    /// The 16 tensor-product weights at `t = (tu/n, tv/n)` in `[0,1]^2`, control points
    /// `(p, q)` in [`CELL_OFFSETS`] order with `q` outer.
    pub fn evaluate(&self, tu: i64, tv: i64, kind: StencilKind) -> Vec<S> {
        let wu = self.axis_weights(tu, kind == StencilKind::DerivativeU);
        let wv = self.axis_weights(tv, kind == StencilKind::DerivativeV);
        wv.iter()
            .flat_map(|b| wu.iter().map(move |a| a.clone() * b.clone()))
            .collect()
    }
}
