//! Box splines on the three-direction mesh, from their definition, in exact rational arithmetic.
//!
//! Directions `xi_1 = (1, 0)`, `xi_2 = (0, 1)`, `xi_3 = (1, -1)` in the skew lattice
//! coordinates of `schemes::triangle` (the mesh's three edge directions). `M_c` is the box spline
//! with direction `xi_j` repeated `c_j` times (de Boor, Höllig, Riemenschneider, *Box Splines*,
//! 1993, ch. I):
//!
//! * with two distinct directions `xi_a^p xi_b^q` it is a tensor product in the coordinates
//!   of that basis: `M(alpha xi_a + beta xi_b) = B_p(alpha) B_q(beta) / |det(xi_a, xi_b)|` with
//!   the cardinal B-splines `B_p` of order `p` on `[0, p]` (all three determinants are ±1);
//! * with three, by the recurrence (ibid. (I.31)): for any `t` with `sum t_xi xi = x`,
//!   `(#Xi - 2) M_Xi(x) = sum_xi t_xi M_{Xi\xi}(x) + (1 - t_xi) M_{Xi\xi}(x - xi)`.
//!
//! Lower-order pieces are discontinuous (order 1 in one direction); every value is taken as
//! the limit from the direction [`PERTURBATION`], which is parallel to no mesh line. At a point
//! `x + eps PERTURBATION` (small `eps > 0`) every piece is locally polynomial and the
//! recurrence holds there, so its limit holds for these one-sided values; the quartic box
//! spline `M_{222}` is C^2, so its one-sided value is its value.
//!
//! Nothing here subdivides: Loop's regular basis function is `M_{222}(x + (2, 0))`, the box
//! spline centred on its support (the shift is half the sum of the six directions).

use num_rational::BigRational;
use num_traits::{One, Signed, Zero};

use crate::bspline::uniform_bspline;

/// The directions `xi_1, xi_2, xi_3`.
pub const DIRECTIONS: [(i64, i64); 3] = [(1, 0), (0, 1), (1, -1)];

/// The direction every value is a one-sided limit from (its coordinates in each basis of two
/// directions are nonzero: `(1, 3)`, `(4, -3)` and `(4, 1)`).
pub const PERTURBATION: (i64, i64) = (1, 3);

/// A point in rational skew coordinates.
pub type Point = (BigRational, BigRational);

fn int(v: i64) -> BigRational {
    BigRational::from_integer(v.into())
}

/// Coordinates of `(x, y)` in the basis `(a, b)` (unimodular): `x = alpha a + beta b`.
fn coordinates(
    a: (i64, i64),
    b: (i64, i64),
    x: &BigRational,
    y: &BigRational,
) -> (BigRational, BigRational) {
    let det = a.0 * b.1 - a.1 * b.0;
    let alpha = (x * int(b.1) - y * int(b.0)) / int(det);
    let beta = (y * int(a.0) - x * int(a.1)) / int(det);
    (alpha, beta)
}

/// The cardinal B-spline of order `p` (degree `p - 1`) on `[0, p]` at `t`, one-sided from the
/// side `direction` points to where it is discontinuous (order 1 only).
fn cardinal(p: u32, t: &BigRational, direction: &BigRational) -> BigRational {
    if p >= 2 {
        return uniform_bspline(p - 1, t);
    }
    let inside = if t.is_zero() {
        direction.is_positive()
    } else if t == &BigRational::one() {
        direction.is_negative()
    } else {
        t.is_positive() && t < &BigRational::one()
    };
    if inside {
        BigRational::one()
    } else {
        BigRational::zero()
    }
}

/// `M_c(x)`: the box spline with direction `DIRECTIONS[j]` repeated `c[j]` times (at least two
/// distinct directions), as the limit from [`PERTURBATION`].
pub fn box_spline(c: [u32; 3], x: &Point) -> BigRational {
    let distinct: Vec<usize> = (0..3).filter(|&j| c[j] > 0).collect();
    match distinct.as_slice() {
        [a, b] => {
            let (da, db) = (DIRECTIONS[*a], DIRECTIONS[*b]);
            let (alpha, beta) = coordinates(da, db, &x.0, &x.1);
            let (pa, pb) = coordinates(da, db, &int(PERTURBATION.0), &int(PERTURBATION.1));
            // |det| = 1 for every pair of the three directions.
            cardinal(c[*a], &alpha, &pa) * cardinal(c[*b], &beta, &pb)
        }
        [_, _, _] => {
            // t: x_1 on one copy of xi_1, x_2 on one copy of xi_2, 0 elsewhere.
            let t = [x.0.clone(), x.1.clone(), BigRational::zero()];
            let total: u32 = c.iter().sum();
            let mut sum = BigRational::zero();
            for j in 0..3 {
                let mut rest = c;
                rest[j] -= 1;
                let shifted = (&x.0 - int(DIRECTIONS[j].0), &x.1 - int(DIRECTIONS[j].1));
                sum += &t[j] * box_spline(rest, x)
                    + (int(i64::from(c[j])) - &t[j]) * box_spline(rest, &shifted);
            }
            sum / int(i64::from(total) - 2)
        }
        _ => BigRational::zero(),
    }
}

/// Loop's regular basis function: the quartic box spline `M_{222}` centred at the origin,
/// `phi(x) = M_{222}(x + (2, 0))`; supported on the hexagon of radius 2 (the 2-ring).
pub fn loop_basis(x: &Point) -> BigRational {
    box_spline([2, 2, 2], &(&x.0 + int(2), x.1.clone()))
}
