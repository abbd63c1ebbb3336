//! Stencils next to an extraordinary vertex by plain substitution, at any rational `(u, v)`.
//!
//! Unrolling the relations of [`crate::patch_stencils`]: double `x` until it leaves
//! `[0,1/2]^2` (`k` times), find the regular sub-patch `b` it is in and its local parameter
//! `t = 2x - origin_b`, and
//!
//! ```text
//! phi(x) = psi(t) R_b A^k,      d/du phi(x) = 2^(k+1) (d/du psi)(t) R_b A^k
//! ```
//!
//! with `psi` the regular basis at `t`, evaluated on the grid of `t`'s denominator. This is the
//! independent check of the grid solve (it never forms the system), and the way to evaluate at
//! rationals that are not table points.

use std::collections::HashMap;

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Zero};
use schemes::{CurveScheme, QuadScheme};

use crate::ev_tangents::ev_tangents;
use crate::exact_solve::limit_mask;
use crate::extraordinary_patch::{LocalMatrices, Neighbourhood, SUB_PATCH_ORIGINS};
use crate::patch_stencils::regular_curve;
use crate::regular_patch::{RegularBasis, StencilKind};
use crate::{Scalar, StencilError};

/// Evaluates EV-patch stencils by substitution; caches the regular basis per denominator.
#[derive(Debug)]
pub struct Substitution<S> {
    scheme: QuadScheme,
    curve: CurveScheme,
    /// The local subdivision matrices.
    pub matrices: LocalMatrices,
    bases: HashMap<u32, RegularBasis<S>>,
}

impl<S: Scalar> Substitution<S> {
    /// Prepare for `scheme` around `neighbourhood`, patch `sector`.
    pub fn new(
        scheme: &QuadScheme,
        neighbourhood: Neighbourhood,
        sector: u32,
    ) -> Result<Self, StencilError> {
        Ok(Substitution {
            scheme: scheme.clone(),
            curve: regular_curve(scheme)?,
            matrices: LocalMatrices::new(scheme, neighbourhood, sector)?,
            bases: HashMap::new(),
        })
    }

    /// The `K` weights of `kind` at `(u, v)` in `[0,1]^2`.
    pub fn stencil(
        &mut self,
        u: &BigRational,
        v: &BigRational,
        kind: StencilKind,
    ) -> Result<Vec<S>, StencilError> {
        let (zero, one) = (BigRational::zero(), BigRational::one());
        if *u < zero || *u > one || *v < zero || *v > one {
            return Err(StencilError::OutOfDomain {
                what: format!("(u, v) = ({u}, {v}) is outside the patch [0,1]^2"),
            });
        }
        if u.is_zero() && v.is_zero() {
            return self.at_vertex(kind);
        }
        let half = BigRational::new(BigInt::from(1), BigInt::from(2));
        let two = BigRational::from_integer(BigInt::from(2));
        let (mut x, mut y, mut k) = (u.clone(), v.clone(), 0u32);
        while x <= half && y <= half {
            x *= &two;
            y *= &two;
            k += 1;
        }
        let index = match (x > half, y > half) {
            (true, false) => 0,
            (true, true) => 1,
            _ => 2,
        };
        let (a0, b0) = SUB_PATCH_ORIGINS[index];
        let tu = &x * &two - BigRational::from_integer(BigInt::from(a0));
        let tv = &y * &two - BigRational::from_integer(BigInt::from(b0));
        let d = tu.denom().lcm(tv.denom());
        let n = u32::try_from(&d).map_err(|_| StencilError::OutOfDomain {
            what: format!("the denominator of ({u}, {v}) is too large"),
        })?;
        let to_i64 = |t: &BigRational| {
            i64::try_from(&(t * BigRational::from_integer(d.clone())).to_integer()).unwrap_or(0)
        };
        let (tu, tv) = (to_i64(&tu), to_i64(&tv));
        if !self.bases.contains_key(&n) {
            let basis = RegularBasis::new(&self.curve, n)?;
            self.bases.insert(n, basis);
        }
        let psi = self.bases[&n].evaluate(tu, tv, kind);
        let factor = S::from_rational(&BigRational::from_integer(BigInt::from(
            kind.doubling_factor(),
        )));
        let size = self.matrices.size();
        let r = &self.matrices.sub_patches[index];
        let mut row: Vec<S> = (0..size)
            .map(|j| {
                psi.iter().zip(r).fold(S::zero(), |acc, (p, rr)| {
                    acc + p.clone() * S::from_rational(&rr[j])
                })
            })
            .map(|w| w * factor.clone())
            .collect();
        for _ in 0..k {
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

    /// The stencil at the EV: the limit mask (exact), or the eigenvector tangent masks (f64).
    fn at_vertex(&self, kind: StencilKind) -> Result<Vec<S>, StencilError> {
        if kind == StencilKind::Position {
            // phi(0) = phi(0) A, sum phi(0) = 1.
            let mask = limit_mask(&self.matrices.a).map_err(|e| StencilError::Inconsistent {
                scheme: self.scheme.name.to_owned(),
                n: 1,
                detail: format!("limit mask at {}: {e:?}", self.matrices.describe()),
            })?;
            return Ok(mask.iter().map(S::from_rational).collect());
        }
        let tangents = ev_tangents(&self.matrices)?;
        let mask = if kind == StencilKind::DerivativeU {
            tangents.du
        } else {
            tangents.dv
        };
        mask.into_iter()
            .map(|w| S::from_f64(w))
            .collect::<Option<Vec<S>>>()
            .ok_or_else(|| StencilError::Irrational {
                what: format!(
                    "the tangent mask at the vertex ({})",
                    self.matrices.describe()
                ),
            })
    }
}
