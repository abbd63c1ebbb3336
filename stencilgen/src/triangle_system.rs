//! The uniform scaling-relation system on the triangular lattice (Schaefer–Warren section 5.1):
//! the regular basis function of Loop, the butterfly and √3 on the grid `(1/n) Z^2`.
//!
//! Coordinates are the skew lattice coordinates of `schemes::triangle` (the face
//! `(0,0), (1,0), (0,1)` is parameterized barycentrically by `(i/n, j/n)`, `i + j <= n`). A mask
//! `s_i` with dilation `d` gives `phi(x) = f sum_i s_i phi(d x - i)` (eq. (3); `f = 1`, or `d`
//! for a first derivative). The support of `phi` is the fixed set of `S = (S + H)/d`, `H` the
//! convex hull of the mask's indices: `S = H / (d - 1)`. The unknowns are `phi(k/n)` at the grid
//! points strictly inside `S` (a continuous `phi` vanishes on its boundary), so the
//! polygonal support is used exactly, not a bounding box: a box would add unknowns outside `S`
//! whose homogeneous relations close on themselves. Classes are the residue pairs
//! `(k_1 mod n, k_2 mod n)`, mapped to `(d k_1 mod n, d k_2 mod n)`; normalization per class as
//! in [`crate::bivariate_system`] (eq. (4), and section 4's tangent normalization in two
//! variables). √3 is solved as its two-step ternary form (`d = 3`), aligned with the original
//! lattice as section 5.1 suggests; the parameter of a control point is its lattice position.

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::One;
use schemes::LatticeMask;

use crate::regular_patch::StencilKind;
use crate::scaling_system::{add_to_row, NormalizationRow, Relation, ScalingSystem, SparseRow};
use crate::solve::{solve_system, Solution};
use crate::{Scalar, StencilError};

/// Largest grid rate accepted (the f64 path solves each orbit densely; the orbit of residue
/// `(0,0)` at `n = 2^k` holds every class).
pub const MAX_TRIANGLE_RATE: u32 = 24;

/// Values of a triangle scheme's regular basis function (or a derivative) on `(1/n) Z^2`.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleStencils<S> {
    /// The mask's name.
    pub scheme: String,
    /// Grid rate.
    pub n: u32,
    /// What was solved for.
    pub kind: StencilKind,
    /// The mask's dilation `d`.
    pub dilation: u32,
    /// The convex hull `H` of the mask's indices, counter-clockwise; the support is `H/(d-1)`.
    pub hull: Vec<(i64, i64)>,
    /// Numerator box `([lo_1, hi_1], [lo_2, hi_2])` holding the support: points `k/n`.
    pub bbox: ((i64, i64), (i64, i64)),
    /// Values at `k/n` over the box, row-major with `k_2` outer (zero outside the support).
    pub values: Vec<S>,
    /// Largest residual over the system.
    pub residual: f64,
}

impl<S: Scalar> TriangleStencils<S> {
    /// The value at `(k_1/n, k_2/n)` (zero outside the support).
    pub fn at(&self, k1: i64, k2: i64) -> S {
        let ((l1, h1), (l2, h2)) = self.bbox;
        if k1 < l1 || k1 > h1 || k2 < l2 || k2 > h2 {
            return S::zero();
        }
        self.values[((k2 - l2) * (h1 - l1 + 1) + (k1 - l1)) as usize].clone()
    }

    /// The grid numerators `k` with `k/n` in the closed support, `k_2` outer.
    pub fn points(&self) -> Vec<(i64, i64)> {
        let ((l1, h1), (l2, h2)) = self.bbox;
        (l2..=h2)
            .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
            .filter(|&k| in_support(&self.hull, self.dilation, self.n, k, false))
            .collect()
    }

    /// The stencil at the point `x = k/n`: `(j, phi(x - j))` for every lattice point `j` with a
    /// nonzero weight (Schaefer–Warren eq. (2): the limit at `x` is `sum_j p_j phi(x - j)`).
    pub fn stencil_at(&self, k: (i64, i64)) -> Vec<((i64, i64), S)> {
        let n = i64::from(self.n);
        let ((l1, h1), (l2, h2)) = self.bbox;
        let mut out = Vec::new();
        for j2 in (k.1 - h2).div_euclid(n) - 1..=(k.1 - l2).div_euclid(n) + 1 {
            for j1 in (k.0 - h1).div_euclid(n) - 1..=(k.0 - l1).div_euclid(n) + 1 {
                let v = self.at(k.0 - j1 * n, k.1 - j2 * n);
                if !v.is_zero() {
                    out.push(((j1, j2), v));
                }
            }
        }
        out
    }
}

/// Whether `k/n` lies in the support `H/(d - 1)`: strictly inside, or in the closed polygon.
fn in_support(hull: &[(i64, i64)], d: u32, n: u32, k: (i64, i64), strict: bool) -> bool {
    let (n, s) = (i64::from(n), i64::from(d) - 1);
    let q = (s * k.0, s * k.1);
    (0..hull.len()).all(|e| {
        let (a, b) = (hull[e], hull[(e + 1) % hull.len()]);
        let cross = (n * (b.0 - a.0)) * (q.1 - n * a.1) - (n * (b.1 - a.1)) * (q.0 - n * a.0);
        if strict {
            cross > 0
        } else {
            cross >= 0
        }
    })
}

/// Largest rate [`triangle_stencils_up_to`] is used at: the centroids of the rate-24 grid
/// live on `1/72`, where the butterfly table needs its regular basis (exact path only; the f64
/// path's dense orbit factorizations are out of reach there, docs/algorithms/butterfly.md).
pub const MAX_BASIS_RATE: u32 = 3 * MAX_TRIANGLE_RATE;

/// Solve the triangular-lattice system of `mask` at rate `n` (`1..=`[`MAX_TRIANGLE_RATE`]).
pub fn triangle_stencils<S: Scalar>(
    mask: &LatticeMask,
    n: u32,
    kind: StencilKind,
) -> Result<TriangleStencils<S>, StencilError> {
    triangle_stencils_up_to(mask, n, kind, MAX_TRIANGLE_RATE)
}

/// [`triangle_stencils`] with the rate bounded by `max_rate` instead (at most
/// [`MAX_BASIS_RATE`]): for the exact path at the dual grid's rates.
pub fn triangle_stencils_up_to<S: Scalar>(
    mask: &LatticeMask,
    n: u32,
    kind: StencilKind,
    max_rate: u32,
) -> Result<TriangleStencils<S>, StencilError> {
    let max = max_rate.min(MAX_BASIS_RATE);
    if n == 0 || n > max {
        return Err(StencilError::RateOutOfRange { n, max });
    }
    let hull = mask.hull();
    if hull.len() < 3 || mask.dilation < 2 {
        return Err(StencilError::UnsupportedScheme {
            scheme: mask.name.clone(),
            reason: "the mask's support is not two-dimensional, or its dilation is below 2"
                .to_owned(),
        });
    }
    let (ni, d) = (i64::from(n), i64::from(mask.dilation));
    let lo = |c: fn(&(i64, i64)) -> i64| {
        hull.iter()
            .map(c)
            .min()
            .map_or(0, |m| (m * ni).div_euclid(d - 1))
    };
    let hi = |c: fn(&(i64, i64)) -> i64| {
        hull.iter()
            .map(c)
            .max()
            .map_or(0, |m| -(-m * ni).div_euclid(d - 1))
    };
    let bbox = ((lo(|p| p.0), hi(|p| p.0)), (lo(|p| p.1), hi(|p| p.1)));
    let ((l1, h1), (l2, h2)) = bbox;
    let inner: Vec<(i64, i64)> = (l2..=h2)
        .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
        .filter(|&k| in_support(&hull, mask.dilation, n, k, true))
        .collect();
    let index: HashMap<(i64, i64), usize> =
        inner.iter().enumerate().map(|(u, &k)| (k, u)).collect();
    let class = |k: (i64, i64)| (k.0.rem_euclid(ni) * ni + k.1.rem_euclid(ni)) as u32;
    let next = (0..ni * ni)
        .map(|c| Some(class((d * (c / ni), d * (c % ni)))))
        .collect();
    let mut system = ScalingSystem::<S>::new(next);
    let factor = BigRational::from_integer(BigInt::from(match kind {
        StencilKind::Position => 1,
        _ => d,
    }));
    for &k in &inner {
        let mut terms: SparseRow = Vec::new();
        for ((i1, i2), w) in &mask.weights {
            if let Some(&v) = index.get(&(d * k.0 - i1 * ni, d * k.1 - i2 * ni)) {
                add_to_row(
                    &mut terms,
                    v,
                    &factor * BigRational::new(BigInt::from(*w.numer()), BigInt::from(*w.denom())),
                );
            }
        }
        system.push_unknown(
            class(k),
            Relation {
                terms,
                constant: S::zero(),
            },
            format!("phi({}/{n}, {}/{n})", k.0, k.1),
        );
    }
    let rows: Vec<(usize, i64)> = match kind {
        StencilKind::Position => vec![(2, 1)],
        StencilKind::DerivativeU => vec![(2, 0), (0, 1), (1, 0)],
        StencilKind::DerivativeV => vec![(2, 0), (0, 0), (1, 1)],
    };
    let mut by_class: Vec<Vec<(i64, i64)>> = vec![Vec::new(); (ni * ni) as usize];
    for &k in &inner {
        by_class[class(k) as usize].push(k);
    }
    for r1 in 0..ni {
        for r2 in 0..ni {
            let x = [
                BigRational::new(r1.into(), ni.into()),
                BigRational::new(r2.into(), ni.into()),
            ];
            for &(moment, rhs) in &rows {
                let mut terms: SparseRow = Vec::new();
                for &k in &by_class[class((r1, r2)) as usize] {
                    // x - i = k/n  =>  i = (r - k)/n.
                    let i = [(r1 - k.0) / ni, (r2 - k.1) / ni];
                    let coef = match moment {
                        2 => BigRational::one(),
                        c => BigRational::from_integer(i[c].into()) - &x[c],
                    };
                    add_to_row(&mut terms, index[&k], coef);
                }
                system.normalization.push(NormalizationRow {
                    class: class((r1, r2)),
                    terms,
                    rhs: BigRational::from_integer(rhs.into()),
                    label: format!("x = ({r1}/{n}, {r2}/{n})"),
                });
            }
        }
    }
    let Solution { values, residual } = solve_system::<S>(&system, &mask.name, n)?;
    let values = (l2..=h2)
        .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
        .map(|k| index.get(&k).map_or_else(S::zero, |&u| values[u].clone()))
        .collect();
    Ok(TriangleStencils {
        scheme: mask.name.clone(),
        n,
        kind,
        dilation: mask.dilation,
        hull,
        bbox,
        values,
        residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemes::TriangleScheme;

    #[test]
    fn loop_support_is_the_two_ring_hexagon() {
        let mask = TriangleScheme::by_name("loop")
            .expect("catalogued")
            .regular_mask();
        let s = triangle_stencils::<f64>(&mask, 1, StencilKind::Position).expect("solvable");
        assert_eq!(s.bbox, ((-2, 2), (-2, 2)));
        // 19 lattice points in the closed hexagon of radius 2; 7 strictly inside.
        assert_eq!(s.points().len(), 19);
        assert_eq!(
            s.points()
                .iter()
                .filter(|&&k| in_support(&s.hull, 2, 1, k, true))
                .count(),
            7
        );
    }

    #[test]
    fn rates_out_of_range_are_errors() {
        let mask = TriangleScheme::by_name("sqrt3")
            .expect("catalogued")
            .regular_mask();
        for n in [0, MAX_TRIANGLE_RATE + 1] {
            assert!(matches!(
                triangle_stencils::<f64>(&mask, n, StencilKind::Position),
                Err(StencilError::RateOutOfRange { .. })
            ));
        }
    }
}
