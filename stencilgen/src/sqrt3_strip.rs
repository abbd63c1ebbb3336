//! The √3 surface beside a straight boundary (Kobbelt's boundary rules), evaluated exactly at
//! the points `k/d` of the half-plane by the scaling relation: the strip patches of
//! docs/algorithms/sqrt3.md ("The plan for boundary patches").
//!
//! In half-plane skew coordinates (`schemes::sqrt3_boundary`, the boundary the line
//! `x_2 = 0`), a level-`N` triangle in row 4 or higher (`N`-level coordinates `y_2 >= 4`) is
//! regular: `T + int S`, `S = H/2` the support of the regular basis `psi` (reaching two and a
//! half rows down), misses the points within two thirds of a level unit of the boundary, the
//! only ones whose rules differ from the interior's. So for `x_2 > 0`, with `N` the smallest
//! level at which `y = 3^N x` has `y_2 >= 4`,
//!
//! ```text
//!   phi(x) = sum_j psi(y - j) R_N[j],     d phi / d x_i = 3^N sum_j psi_i(y - j) R_N[j]
//! ```
//!
//! over the level-`N` lattice points `j` (Schaefer–Warren eq. (2); `R_N[j]` the level-0 row of
//! point `j` after `N` ternary steps of the true rules, [`BoundaryRows`]; `psi_i` the skew-axis
//! derivatives of `psi`). `y` has denominator `d`, so `psi` is needed on the grid `1/d` only.
//! On the line itself the surface is the uniform cubic B-spline of the boundary points (the
//! boundary rules are its ternary refinement), and so is its derivative along the line. The
//! derivative across the line has no finite value there in general: at the midpoint of a
//! boundary edge the local matrix has a cross mode of `0.3722 > 1/3`, so `d phi/d x_2` grows like
//! `x_2^-0.10` towards the line (docs/algorithms/sqrt3.md); the tangent plane there is a
//! direction, a tangent mask, which this module does not compute yet.

use std::collections::BTreeMap;

use schemes::sqrt3_boundary::{BoundaryFan, BoundaryRows};
use schemes::TriangleScheme;

use crate::cone_regions::RegionBasis;
use crate::regular_patch::StencilKind;
use crate::triangle_system::MAX_BASIS_RATE;
use crate::StencilError;

/// A stencil over level-0 half-plane points `(a, b)`, `b >= 0`.
pub type StripStencil = BTreeMap<(i64, i64), f64>;

/// The lowest row of a level-`N` triangle that is certified regular (module docs).
pub const REGULAR_ROW: i64 = 4;

/// Evaluates the surface beside a straight boundary at the points `k/d` (module docs).
#[derive(Clone, Debug)]
pub struct StripEvaluator {
    d: u32,
    basis: RegionBasis<f64>,
    fan: BoundaryFan,
    rows: BoundaryRows,
}

/// The uniform cubic B-spline's four basis functions at `u` in `[0, 1]` (for the points
/// `p_{-1}, p_0, p_1, p_2`), or their derivatives.
fn cubic_b_spline(u: f64, derivative: bool) -> [f64; 4] {
    let v = 1.0 - u;
    if derivative {
        [
            -v * v / 2.0,
            (3.0 * u * u - 4.0 * u) / 2.0,
            (-3.0 * u * u + 2.0 * u + 1.0) / 2.0,
            u * u / 2.0,
        ]
    } else {
        [
            v * v * v / 6.0,
            (3.0 * u * u * u - 6.0 * u * u + 4.0) / 6.0,
            (-3.0 * u * u * u + 3.0 * u * u + 3.0 * u + 1.0) / 6.0,
            u * u * u / 6.0,
        ]
    }
}

impl StripEvaluator {
    /// An evaluator on the grid `1/d` (`1..=`[`MAX_BASIS_RATE`]): solves `psi` and its two
    /// skew-axis derivatives there.
    pub fn new(d: u32) -> Result<Self, StencilError> {
        if d == 0 || d > MAX_BASIS_RATE {
            return Err(StencilError::RateOutOfRange {
                n: d,
                max: MAX_BASIS_RATE,
            });
        }
        let scheme = TriangleScheme::by_name("sqrt3").ok_or_else(|| StencilError::OutOfDomain {
            what: "the sqrt3 scheme".to_owned(),
        })?;
        let kinds = [
            StencilKind::Position,
            StencilKind::DerivativeU,
            StencilKind::DerivativeV,
        ];
        let fan = BoundaryFan::new(3);
        Ok(StripEvaluator {
            d,
            basis: RegionBasis::new(&scheme, d, &kinds)?,
            fan,
            rows: BoundaryRows::new(fan),
        })
    }

    /// The stencil of `kind` (position, `d/dx_1`, `d/dx_2`) at `x = k/d` over the level-0
    /// half-plane points. Refuses `k_2 < 0`, and the derivative across the line at `k_2 = 0`
    /// (unbounded there in general, module docs).
    pub fn stencil(
        &mut self,
        k: (i64, i64),
        kind: StencilKind,
    ) -> Result<StripStencil, StencilError> {
        let d = i64::from(self.d);
        if k.1 < 0 || (k.1 == 0 && kind == StencilKind::DerivativeV) {
            return Err(StencilError::OutOfDomain {
                what: format!(
                    "{kind:?} at ({}/{d}, {}/{d}): below the boundary, or across it on it \
                     (unbounded there in general)",
                    k.0, k.1
                ),
            });
        }
        if k.1 == 0 {
            let base = k.0.div_euclid(d);
            let u = k.0.rem_euclid(d) as f64 / d as f64;
            let weights = cubic_b_spline(u, kind == StencilKind::DerivativeU);
            return Ok((-1..=2)
                .zip(weights)
                .map(|(m, w)| ((base + m, 0), w))
                .filter(|&(_, w)| w != 0.0)
                .collect());
        }
        // The smallest level at which x lies in row REGULAR_ROW or above.
        let (mut level, mut y, mut factor) = (0u32, k, 1.0);
        while y.1 < REGULAR_ROW * d {
            level += 1;
            y = (3 * y.0, 3 * y.1);
            factor *= 3.0;
        }
        let psi = self.basis.get(kind)?;
        let ((l1, h1), (l2, h2)) = psi.bbox;
        let scale = if kind == StencilKind::Position {
            1.0
        } else {
            factor
        };
        let mut out = StripStencil::new();
        // j with y - d j in the support's box: d j_i in [y_i - h_i, y_i - l_i].
        for j2 in (y.1 - h2).div_euclid(d)..=(y.1 - l2).div_euclid(d) + 1 {
            for j1 in (y.0 - h1).div_euclid(d)..=(y.0 - l1).div_euclid(d) + 1 {
                let w = psi.at(y.0 - d * j1, y.1 - d * j2);
                if w == 0.0 {
                    continue;
                }
                let name =
                    self.fan
                        .canonical(0, (j1, j2))
                        .ok_or_else(|| StencilError::OutOfDomain {
                            what: format!("level-{level} point ({j1}, {j2}) below the boundary"),
                        })?;
                for (p, r) in self.rows.row(level, name) {
                    *out.entry(BoundaryFan::in_sector_zero(p)).or_insert(0.0) += scale * w * r;
                }
            }
        }
        out.retain(|_, w| *w != 0.0);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Positions sum to 1 and derivatives to 0 (partition of unity), off the line and on it.
    #[test]
    fn stencils_are_affine() {
        let mut e = StripEvaluator::new(6).expect("psi on 1/6");
        for k in [(0, 0), (3, 0), (1, 1), (2, 3), (5, 1), (0, 6), (4, 2)] {
            for kind in [
                StencilKind::Position,
                StencilKind::DerivativeU,
                StencilKind::DerivativeV,
            ] {
                if k.1 == 0 && kind == StencilKind::DerivativeV {
                    assert!(e.stencil(k, kind).is_err());
                    continue;
                }
                let s = e.stencil(k, kind).expect("evaluates");
                let sum: f64 = s.values().sum();
                let want = if kind == StencilKind::Position {
                    1.0
                } else {
                    0.0
                };
                assert!((sum - want).abs() < 1e-12, "{k:?} {kind:?}: {sum}");
            }
        }
    }
}
