//! B-splines from their classical definitions, in exact rational arithmetic.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};

/// `p/q` as a rational.
pub fn q(p: i64, q: i64) -> BigRational {
    BigRational::new(BigInt::from(p), BigInt::from(q))
}

fn binomial(n: u32, k: u32) -> BigInt {
    (0..k).fold(BigInt::one(), |acc, i| {
        acc * BigInt::from(n - i) / BigInt::from(i + 1)
    })
}

fn factorial(n: u32) -> BigInt {
    (1..=n).fold(BigInt::one(), |acc, i| acc * BigInt::from(i))
}

/// The uniform B-spline of degree `d` with knots `0, 1, ..., d + 1`, by the truncated-power
/// formula `B_d(x) = 1/d! sum_{j=0}^{d+1} (-1)^j C(d+1, j) (x - j)_+^d` (de Boor, A Practical
/// Guide to Splines, ch. IX).
///
/// At the knots, `(x - j)_+^0` is taken as 1/2, which makes degree 0 the average of its
/// one-sided limits; for `d >= 1` the spline is continuous there and the choice is irrelevant.
pub fn uniform_bspline(d: u32, x: &BigRational) -> BigRational {
    let mut sum = BigRational::zero();
    for j in 0..=d + 1 {
        let t = x - BigRational::from_integer(BigInt::from(j));
        let power = if t.is_negative() {
            BigRational::zero()
        } else if d == 0 {
            if t.is_zero() {
                q(1, 2)
            } else {
                BigRational::one()
            }
        } else {
            num_traits::pow(t, d as usize)
        };
        let c = BigRational::from_integer(binomial(d + 1, j));
        if j % 2 == 0 {
            sum += c * power;
        } else {
            sum -= c * power;
        }
    }
    sum / BigRational::from_integer(factorial(d))
}

/// Derivative of [`uniform_bspline`]: `B_d'(x) = B_{d-1}(x) - B_{d-1}(x - 1)`.
pub fn uniform_bspline_derivative(d: u32, x: &BigRational) -> BigRational {
    uniform_bspline(d - 1, x) - uniform_bspline(d - 1, &(x - BigRational::one()))
}

/// The B-spline `N_{j,d}` on the knot sequence `knot(i)`, by the Cox–de Boor recurrence with
/// right-continuous degree-0 pieces (half-open spans `[t_i, t_{i+1})`).
pub fn cox_de_boor(
    knot: &dyn Fn(i64) -> BigRational,
    j: i64,
    d: u32,
    t: &BigRational,
) -> BigRational {
    if d == 0 {
        return if knot(j) <= *t && *t < knot(j + 1) {
            BigRational::one()
        } else {
            BigRational::zero()
        };
    }
    let d_i = i64::from(d);
    let mut value = BigRational::zero();
    let span = knot(j + d_i) - knot(j);
    if !span.is_zero() {
        value += (t - knot(j)) / span * cox_de_boor(knot, j, d - 1, t);
    }
    let span = knot(j + d_i + 1) - knot(j + 1);
    if !span.is_zero() {
        value += (knot(j + d_i + 1) - t) / span * cox_de_boor(knot, j + 1, d - 1, t);
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_at_known_points() {
        // Cubic: 1/6, 2/3, 1/6 at the interior knots; quadratic: 1/2, 1/2.
        assert_eq!(uniform_bspline(3, &q(1, 1)), q(1, 6));
        assert_eq!(uniform_bspline(3, &q(2, 1)), q(2, 3));
        assert_eq!(uniform_bspline(2, &q(1, 1)), q(1, 2));
        assert_eq!(uniform_bspline(2, &q(3, 2)), q(3, 4));
        assert_eq!(uniform_bspline_derivative(3, &q(1, 1)), q(1, 2));
    }

    #[test]
    fn cox_de_boor_matches_the_closed_form_on_uniform_knots() {
        let knot = |i: i64| BigRational::from_integer(BigInt::from(i));
        for k in 0..=40 {
            let t = q(k, 10);
            assert_eq!(cox_de_boor(&knot, 0, 3, &t), uniform_bspline(3, &t));
        }
    }
}
