//! Uniform bivariate masks: `phi(x) = sum_{i in Z^2} s_i phi(2x - i)` (Schaefer–Warren
//! section 5.1). Quad schemes are tensor products of curve masks; triangle schemes will give
//! their masks on the lattice Z^2 in their own (skewed) coordinates.

use num_rational::Rational64;

use crate::{CurveScheme, Translates};

/// A uniform bivariate subdivision mask.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BivariateMask {
    /// Name, for messages.
    pub name: String,
    /// The nonzero mask entries `((i, j), s_ij)`.
    pub weights: Vec<((i64, i64), Rational64)>,
}

impl BivariateMask {
    /// The tensor product `s_ij = s_i s_j` of a uniform curve mask; `None` for a vector scheme.
    pub fn tensor(curve: &CurveScheme) -> Option<Self> {
        if !curve.is_uniform() || curve.components[0].translates != Translates::All {
            return None;
        }
        let terms = &curve.components[0].refinement;
        let weights = terms
            .iter()
            .flat_map(|tj| {
                terms
                    .iter()
                    .map(move |ti| ((ti.shift, tj.shift), ti.weight * tj.weight))
            })
            .collect();
        Some(BivariateMask {
            name: format!("{} x {}", curve.name, curve.name),
            weights,
        })
    }

    /// The integer box `[lo, hi]^2` holding the support: `[min i, max i]` over the mask's
    /// indices in each coordinate (the support of a uniform mask is the hull of its indices).
    pub fn support(&self) -> ((i64, i64), (i64, i64)) {
        let xs = self.weights.iter().map(|((i, _), _)| *i);
        let ys = self.weights.iter().map(|((_, j), _)| *j);
        (
            (xs.clone().min().unwrap_or(0), xs.max().unwrap_or(0)),
            (ys.clone().min().unwrap_or(0), ys.max().unwrap_or(0)),
        )
    }
}
