//! Curve subdivision schemes: uniform masks and stationary vector (matrix-mask) schemes.
//!
//! Every scheme is written in one form, the *vector scheme* of Schaefer–Warren section 3
//! (after Micchelli and Sauer): a finite list of [`Component`]s, each a scaling function
//! `phi_c` with a refinement relation
//!
//! ```text
//! phi_c(x) = sum_t  w_t * phi_{c_t}(2x - i_t)          (Schaefer–Warren eq. (3))
//! ```
//!
//! and the set of integer translates `k` at which `phi_c(x - k)` is the basis function of a
//! control point of the curve. A uniform scheme with mask `s_i` is one component whose terms
//! are `(s_i, c = 0, i)` and whose translates are all of Z. The non-uniform cubic B-spline of
//! section 2 is five components: the uniform B-spline serving every point left of the origin,
//! the three special points -1, 0, 1, and the uniform B-spline serving every point right of it.
//!
//! Each component is written in its own shifted coordinate (the paper's choice in section 2):
//! `phi_c` is centred on the control point it belongs to, so the basis function of control
//! point `k` of component `c` is `phi_c(x - k)`, and the curve is
//! `p(x) = sum_c sum_{k in T_c} p_k phi_c(x - k)` (Schaefer–Warren eq. (2)).

use num_rational::Rational64;
use num_traits::Zero;

/// One term `weight * phi_component(2x - shift)` of a refinement relation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Term {
    /// The subdivision-matrix entry: how much the coarse point contributes to the fine point.
    pub weight: Rational64,
    /// Index (into [`CurveScheme::components`]) of the fine point's scaling function.
    pub component: usize,
    /// Integer shift `i` of the fine point relative to twice the coarse point's index.
    pub shift: i64,
}

/// The integer translates `k` for which `phi_c(x - k)` is a basis function of the curve.
///
/// Only the partition of unity (Schaefer–Warren eq. (4)) needs this: the refinement relation
/// of a component does not depend on which translates of it are present.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Translates {
    /// Every integer (a uniform scheme).
    All,
    /// Every integer `k <= bound`.
    AtMost(i64),
    /// Every integer `k >= bound`.
    AtLeast(i64),
    /// Exactly one control point, at `k`.
    Only(i64),
}

impl Translates {
    /// Whether `k` is one of the translates.
    pub fn contains(self, k: i64) -> bool {
        match self {
            Translates::All => true,
            Translates::AtMost(b) => k <= b,
            Translates::AtLeast(b) => k >= b,
            Translates::Only(b) => k == b,
        }
    }
}

/// One scaling function of a (vector) curve scheme with its refinement relation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Component {
    /// A short name used in output (`"phi"` for uniform schemes).
    pub name: String,
    /// Which translates of this function are control-point basis functions.
    pub translates: Translates,
    /// The refinement relation `phi(x) = sum w phi_c(2x - i)`: column of S, Schaefer–Warren
    /// eq. (3) (section 3's matrix mask, one row of it, for vector schemes).
    pub refinement: Vec<Term>,
}

/// A stationary curve subdivision scheme, as data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CurveScheme {
    /// The catalogue name (`four-point`, `cubic-bspline`, ...).
    pub name: String,
    /// One line saying what the scheme is and where it comes from.
    pub description: String,
    /// The scaling functions; a uniform scheme has exactly one.
    pub components: Vec<Component>,
}

/// Names of the schemes [`CurveScheme::by_name`] knows, in catalogue order.
pub const CURVE_SCHEME_NAMES: [&str; 6] = [
    "cubic-bspline",
    "quadratic-bspline",
    "four-point",
    "sw-nonpoly",
    "six-point",
    "nonuniform-cubic-bspline",
];

impl CurveScheme {
    /// A uniform scheme from its mask `s_i = numerators[j] / denominator`, `i = first_index + j`.
    pub fn uniform(
        name: &str,
        description: &str,
        numerators: &[i64],
        denominator: i64,
        first_index: i64,
    ) -> Self {
        let refinement = mask_terms(numerators, denominator, first_index, 0);
        CurveScheme {
            name: name.to_owned(),
            description: description.to_owned(),
            components: vec![Component {
                name: "phi".to_owned(),
                translates: Translates::All,
                refinement,
            }],
        }
    }

    /// A scheme from the catalogue ([`CURVE_SCHEME_NAMES`]); `quadratic-bspline` is also
    /// known as `chaikin`.
    pub fn by_name(name: &str) -> Option<Self> {
        let scheme = match name {
            "cubic-bspline" => Self::uniform(
                "cubic-bspline",
                "uniform cubic B-spline (Lane-Riesenfeld), mask (1,4,6,4,1)/8",
                &[1, 4, 6, 4, 1],
                8,
                -2,
            ),
            "quadratic-bspline" | "chaikin" => Self::uniform(
                "quadratic-bspline",
                "uniform quadratic B-spline (Chaikin corner cutting), mask (1,3,3,1)/4 on i = -1..2",
                &[1, 3, 3, 1],
                4,
                -1,
            ),
            "four-point" => Self::uniform(
                "four-point",
                "Dyn-Levin-Gregory four-point interpolatory scheme, mask (-1,0,9,16,9,0,-1)/16",
                &[-1, 0, 9, 16, 9, 0, -1],
                16,
                -3,
            ),
            "sw-nonpoly" => Self::uniform(
                "sw-nonpoly",
                "Schaefer-Warren section 5.4 C1 non-polynomial scheme, mask (1,3,4,3,1)/6",
                &[1, 3, 4, 3, 1],
                6,
                -2,
            ),
            "six-point" => Self::uniform(
                "six-point",
                "six-point interpolatory scheme, mask (3,0,-25,0,150,256,150,0,-25,0,3)/256",
                &[3, 0, -25, 0, 150, 256, 150, 0, -25, 0, 3],
                256,
                -5,
            ),
            "nonuniform-cubic-bspline" => nonuniform_cubic_bspline(),
            _ => return None,
        };
        Some(scheme)
    }

    /// Whether this is a uniform scheme: one component, translates all of Z.
    pub fn is_uniform(&self) -> bool {
        self.components.len() == 1 && self.components[0].translates == Translates::All
    }

    /// The largest `|shift|` in any refinement term: every support lies in
    /// `[min shift, max shift]`.
    pub fn shift_range(&self) -> (i64, i64) {
        let shifts = self
            .components
            .iter()
            .flat_map(|c| c.refinement.iter().map(|t| t.shift));
        let lo = shifts.clone().min().unwrap_or(0);
        let hi = shifts.max().unwrap_or(0);
        (lo, hi)
    }

    /// The integer hull `[lo_c, hi_c]` of each component's support.
    ///
    /// The support of `phi_c` is the smallest family of intervals with
    /// `supp phi_c = hull_t (supp phi_{c_t} + i_t) / 2` (from eq. (3)); `[min i, max i]` is
    /// invariant under that map, so iterating it from there (rounding outwards to integers)
    /// decreases monotonically and stops at an integer hull of the true supports. For a
    /// uniform mask on `i = p..=q` this is exactly `[p, q]`.
    pub fn supports(&self) -> Vec<(i64, i64)> {
        let (lo, hi) = self.shift_range();
        let mut supports = vec![(lo, hi); self.components.len()];
        loop {
            let next: Vec<(i64, i64)> = self
                .components
                .iter()
                .map(|c| {
                    let lo = c
                        .refinement
                        .iter()
                        .map(|t| (supports[t.component].0 + t.shift).div_euclid(2))
                        .min()
                        .unwrap_or(0);
                    let hi = c
                        .refinement
                        .iter()
                        .map(|t| -((-(supports[t.component].1 + t.shift)).div_euclid(2)))
                        .max()
                        .unwrap_or(0);
                    (lo, hi)
                })
                .collect();
            if next == supports {
                return supports;
            }
            supports = next;
        }
    }

    /// Whether subdivision maps linear data to linear data: with `p_k = k` at every control
    /// point, every fine point gets `k'/2 + c` for one constant `c`.
    ///
    /// This is what the tangent normalization `sum_k (k - x) phi'(x - k) = 1` (Schaefer–Warren
    /// section 4) needs: the limit of `p_k = k` is then `x + 2c`, whose derivative is 1.
    pub fn reproduces_linear(&self) -> bool {
        let (lo, hi) = self.shift_range();
        let window = 4 * (hi - lo + 1) + 8;
        let mut offset: Option<Rational64> = None;
        for (c_fine, component) in self.components.iter().enumerate() {
            for k_fine in -window..=window {
                if !component.translates.contains(k_fine) {
                    continue;
                }
                let mut value = Rational64::zero();
                for coarse in &self.components {
                    for term in coarse.refinement.iter().filter(|t| t.component == c_fine) {
                        let twice_k = k_fine - term.shift;
                        if twice_k.rem_euclid(2) == 0 && coarse.translates.contains(twice_k / 2) {
                            value += term.weight * Rational64::from_integer(twice_k / 2);
                        }
                    }
                }
                let c = value - Rational64::new(k_fine, 2);
                match offset {
                    None => offset = Some(c),
                    Some(o) if o != c => return false,
                    Some(_) => {}
                }
            }
        }
        true
    }

    /// The sum of the weights of each component's refinement relation. For a convergent
    /// uniform scheme it is 2 (the even and the odd fine points are each an affine
    /// combination); special columns of a non-uniform scheme need not sum to 2.
    pub fn column_sums(&self) -> Vec<Rational64> {
        self.components
            .iter()
            .map(|c| c.refinement.iter().map(|t| t.weight).sum())
            .collect()
    }
}

fn mask_terms(
    numerators: &[i64],
    denominator: i64,
    first_index: i64,
    component: usize,
) -> Vec<Term> {
    numerators
        .iter()
        .zip(first_index..)
        .filter(|(&num, _)| num != 0)
        .map(|(&num, shift)| Term {
            weight: Rational64::new(num, denominator),
            component,
            shift,
        })
        .collect()
}

/// The five components of the section-2 example, in catalogue order.
const LEFT: usize = 0;
const RIGHT: usize = 4;

/// `(fine point k, numerator, denominator)`: one entry of a subdivision-matrix column.
type MatrixEntry = (i64, i64, i64);

/// Component serving the fine control point `k` of the non-uniform example.
fn nonuniform_component_of(k: i64) -> usize {
    match k {
        k if k <= -2 => LEFT,
        k if k >= 2 => RIGHT,
        k => (k + 2) as usize,
    }
}

/// Schaefer–Warren section 2: the non-uniform cubic B-spline whose knot spacing doubles on one
/// side of the origin, as a vector scheme of five components (section 3).
///
/// The special columns are the ones the paper prints (its 5x5 matrix, extended by the uniform
/// entries 1/8 and 1/2 that column -1 and column 1 have outside the 2-ring). They are the
/// knot-insertion matrix of the knots `t_i = i` for `i < 0` and `t_i = 2i` for `i > 0`
/// (the text states the mirror image; `subtess-tests` checks the printed matrix against
/// Cox–de Boor), so control point `k` sits at `x = k` and the B-spline parameter is
/// `t = x` for `x <= 0` and `t = 2x` for `x >= 0`.
fn nonuniform_cubic_bspline() -> CurveScheme {
    let cubic = [1, 4, 6, 4, 1];
    // Column h of S: (fine point k, numerator, denominator).
    let special_columns: [(i64, [MatrixEntry; 5]); 3] = [
        (
            -1,
            [(-4, 1, 8), (-3, 1, 2), (-2, 25, 32), (-1, 5, 8), (0, 5, 24)],
        ),
        (
            0,
            [(-2, 3, 32), (-1, 3, 8), (0, 29, 40), (1, 3, 5), (2, 3, 20)],
        ),
        (
            1,
            [(0, 1, 15), (1, 2, 5), (2, 29, 40), (3, 1, 2), (4, 1, 8)],
        ),
    ];
    let mut components = vec![Component {
        name: "left".to_owned(),
        translates: Translates::AtMost(-2),
        refinement: mask_terms(&cubic, 8, -2, LEFT),
    }];
    for (h, column) in special_columns {
        components.push(Component {
            name: format!("point{h}"),
            translates: Translates::Only(h),
            // phi_h(y) = Phi_h(y + h) = sum_k S[k][h] Phi_k(2y + 2h) and Phi_k(x) = phi_c(k)(x - k).
            refinement: column
                .iter()
                .map(|&(k, num, den)| Term {
                    weight: Rational64::new(num, den),
                    component: nonuniform_component_of(k),
                    shift: k - 2 * h,
                })
                .collect(),
        });
    }
    components.push(Component {
        name: "right".to_owned(),
        translates: Translates::AtLeast(2),
        refinement: mask_terms(&cubic, 8, -2, RIGHT),
    });
    CurveScheme {
        name: "nonuniform-cubic-bspline".to_owned(),
        description: "Schaefer-Warren section 2: cubic B-spline with knot spacing 1 left of the origin and 2 right of it, as a 5-component vector scheme".to_owned(),
        components,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_is_complete_and_uniform_masks_sum_to_two() {
        for name in CURVE_SCHEME_NAMES {
            let scheme = CurveScheme::by_name(name).expect("catalogued");
            assert_eq!(scheme.name, name);
            for sum in scheme
                .column_sums()
                .into_iter()
                .take(usize::from(scheme.is_uniform()))
            {
                assert_eq!(sum, Rational64::from_integer(2), "{name}");
            }
        }
        assert!(CurveScheme::by_name("no-such-scheme").is_none());
    }

    #[test]
    fn supports_of_uniform_masks_are_their_index_ranges() {
        let expect = [
            ("cubic-bspline", (-2, 2)),
            ("quadratic-bspline", (-1, 2)),
            ("four-point", (-3, 3)),
            ("sw-nonpoly", (-2, 2)),
            ("six-point", (-5, 5)),
        ];
        for (name, support) in expect {
            let scheme = CurveScheme::by_name(name).expect("catalogued");
            assert_eq!(scheme.supports(), vec![support], "{name}");
        }
    }

    #[test]
    fn nonuniform_example_supports_are_the_bspline_knot_spans() {
        // Control points -1, 0, 1 are the B-splines on knots (-3,-2,-1,0,2), (-2,-1,0,2,4),
        // (-1,0,2,4,6) in t, i.e. x in [-3,1], [-2,2], [-1,3]: [-2,2] in each local coordinate.
        let scheme = CurveScheme::by_name("nonuniform-cubic-bspline").expect("catalogued");
        assert_eq!(scheme.supports(), vec![(-2, 2); 5]);
    }

    #[test]
    fn linear_precision() {
        for name in [
            "cubic-bspline",
            "quadratic-bspline",
            "four-point",
            "sw-nonpoly",
            "six-point",
        ] {
            assert!(
                CurveScheme::by_name(name)
                    .expect("catalogued")
                    .reproduces_linear(),
                "{name}"
            );
        }
        // In the uniform parameter x the section-2 example is not linear in x (t = 2x on one side).
        let nonuniform = CurveScheme::by_name("nonuniform-cubic-bspline").expect("catalogued");
        assert!(!nonuniform.reproduces_linear());
    }
}
