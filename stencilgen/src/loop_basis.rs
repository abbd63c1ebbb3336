//! Loop's regular basis function at any rational point, as exact quartic pieces.
//!
//! In regular regions Loop is the quartic box spline `psi` (section 5.1): a polynomial of
//! degree 4 on each triangle of the lattice. The grid system of [`crate::triangle_system`]
//! gives `psi` exactly at the points `k/4`; on each lattice triangle those are the 15 points
//! of the principal lattice of degree 4, which determine the quartic piece. Interpolating them
//! with the Lagrange basis of that lattice,
//!
//! ```text
//! L_ijk(l1, l2, l3) = l_i(l1) l_j(l2) l_k(l3),  l_i(t) = prod_{m < i} (4t - m) / (m + 1),
//! ```
//!
//! (`i + j + k = 4`, `(l1, l2, l3)` barycentric in the triangle) evaluates `psi` — or its
//! derivatives, cubic pieces, from the derivative grid — at any rational point without forming
//! a system for that point's denominator. This is what lets the patch stencils reach the
//! dual points `1/3n` of rates up to 24 (denominators up to 72) cheaply. The independent
//! check is `subtess_tests::box_spline` (the box spline from its definition).

use num_rational::BigRational;
use schemes::TriangleScheme;

use crate::regular_patch::StencilKind;
use crate::triangle_system::{triangle_stencils, TriangleStencils};
use crate::{Scalar, StencilError};

/// The grid the pieces are read from: degree 4 needs the points `k/4`.
const DEGREE: i64 = 4;

/// Loop's regular basis function (or one of its derivatives) at any rational point.
#[derive(Clone, Debug)]
pub struct LoopRegularBasis {
    /// Positions, or derivatives along the skew axes.
    pub kind: StencilKind,
    exact: TriangleStencils<BigRational>,
    float: TriangleStencils<f64>,
}

impl LoopRegularBasis {
    /// Solve the rate-4 grid of the scheme's regular mask (which must be polynomial of degree
    /// 4: Loop) and keep it for interpolation.
    pub fn new(scheme: &TriangleScheme, kind: StencilKind) -> Result<Self, StencilError> {
        if !scheme.polynomial {
            return Err(StencilError::UnsupportedScheme {
                scheme: scheme.name.to_owned(),
                reason: "its regular basis is not piecewise polynomial, so it has no quartic pieces to interpolate".to_owned(),
            });
        }
        let exact = triangle_stencils::<BigRational>(&scheme.regular_mask(), DEGREE as u32, kind)?;
        let float = TriangleStencils {
            scheme: exact.scheme.clone(),
            n: exact.n,
            kind,
            dilation: exact.dilation,
            hull: exact.hull.clone(),
            bbox: exact.bbox,
            values: exact.values.iter().map(Scalar::to_f64).collect(),
            residual: exact.residual,
        };
        Ok(LoopRegularBasis { kind, exact, float })
    }

    /// `psi(x / d, y / d)` in lattice (skew) coordinates, the function centred at the origin
    /// as in [`TriangleStencils::at`].
    pub fn at<S: Scalar>(&self, x: i64, y: i64, d: i64) -> S {
        let (a, b) = (x.div_euclid(d), y.div_euclid(d));
        let (s, t) = (x - a * d, y - b * d);
        // Barycentric coordinates (numerators over d) in the up triangle (a,b),(a+1,b),(a,b+1)
        // or the down triangle (a+1,b),(a,b+1),(a+1,b+1).
        let up = s + t <= d;
        let lambda = if up {
            [d - s - t, s, t]
        } else {
            [d - t, d - s, s + t - d]
        };
        // The principal-lattice point (i, j, k) / 4 of that triangle, as numerators over 4.
        let corner = |i: i64, j: i64, k: i64| {
            if up {
                (4 * a + j, 4 * b + k)
            } else {
                (4 * a + i + k, 4 * b + j + k)
            }
        };
        let ratio = |p: i64, q: i64| S::from_rational(&BigRational::new(p.into(), q.into()));
        // l_i(lambda / d) for i = 0..=4, per barycentric coordinate.
        let factors: Vec<[S; 5]> = lambda
            .iter()
            .map(|&l| {
                let mut f: [S; 5] = std::array::from_fn(|_| ratio(1, 1));
                for i in 1..=DEGREE as usize {
                    let m = i as i64 - 1;
                    f[i] = f[i - 1].clone() * ratio(DEGREE * l - m * d, d * (m + 1));
                }
                f
            })
            .collect();
        let mut sum = S::zero();
        for i in 0..=DEGREE {
            for j in 0..=DEGREE - i {
                let k = DEGREE - i - j;
                let (p, q) = corner(i, j, k);
                let value = self.value::<S>(p, q);
                if value.is_negligible() && S::EXACT {
                    continue;
                }
                sum = sum
                    + value
                        * factors[0][i as usize].clone()
                        * factors[1][j as usize].clone()
                        * factors[2][k as usize].clone();
            }
        }
        sum
    }

    /// The f64 values [`Self::at`] interpolates, `psi(k_1/4, k_2/4)`, on the square window
    /// `|k_1|, |k_2| <= h` that holds the support, `k_2` outer: `(2h + 1, values)`. What a
    /// compact Loop table stores ([`table_format::PointSet::LoopBasis`]) so that the runtime
    /// evaluates `at::<f64>` bit for bit (zero outside the window, as `at` is outside the
    /// solved box).
    pub fn lattice_window(&self) -> (u32, Vec<f64>) {
        let ((l1, h1), (l2, h2)) = self.float.bbox;
        let h = [l1, h1, l2, h2].iter().map(|v| v.abs()).max().unwrap_or(0);
        let values = (-h..=h)
            .flat_map(|k2| (-h..=h).map(move |k1| (k1, k2)))
            .map(|(k1, k2)| self.float.at(k1, k2))
            .collect();
        ((2 * h + 1) as u32, values)
    }

    fn value<S: Scalar>(&self, p: i64, q: i64) -> S {
        if S::EXACT {
            S::from_rational(&self.exact.at(p, q))
        } else {
            let v = self.float.at(p, q);
            S::from_f64(v).unwrap_or_else(|| S::from_rational(&self.exact.at(p, q)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle_patch::triangle_scheme;

    #[test]
    fn interpolation_reproduces_every_solved_grid() {
        let loop_ = triangle_scheme("loop").expect("catalogued");
        for kind in [StencilKind::Position, StencilKind::DerivativeU] {
            let basis = LoopRegularBasis::new(&loop_, kind).expect("polynomial");
            for n in [3u32, 5, 6, 7] {
                let grid = triangle_stencils::<BigRational>(&loop_.regular_mask(), n, kind)
                    .expect("solvable");
                for (x, y) in grid.points() {
                    let exact: BigRational = basis.at(x, y, i64::from(n));
                    assert_eq!(exact, grid.at(x, y), "{kind:?} at ({x}, {y})/{n}");
                    let float: f64 = basis.at(x, y, i64::from(n));
                    assert!((float - exact.to_f64()).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn non_polynomial_schemes_are_refused() {
        let butterfly = triangle_scheme("butterfly").expect("catalogued");
        assert!(LoopRegularBasis::new(&butterfly, StencilKind::Position).is_err());
    }
}
