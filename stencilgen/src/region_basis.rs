//! The regular basis of the butterfly and of √3 on the grids a compact region table stores it
//! on, by the cascade iteration of its refinement equation, and its canonical values (the ones
//! the table stores, [`schemes::lattice_symmetry`]).
//!
//! `psi` satisfies `psi(x) = sum_i s_i psi(λ x - i)` (the regular mask `s`, dilation `λ`: 2
//! for the butterfly, 3 for two √3 steps), `psi_1 = d psi / d x_1` the same relation times `λ`.
//! On the grid `(1/d) Z^2` the points `x = k/d` strictly inside the support map to points of
//! the same grid (`λ k - i d`), so the values there are a fixed point of the linear map
//! `T v (k) = f sum_i s_i v(λ k - i d)` (`f = 1` or `λ`), normalized per residue class
//! `r = k mod d` at `y = r/d` by
//!
//! ```text
//!   sum_j psi(y - j) = 1,        sum_j (j - y) psi(y - j) = 0              (positions)
//!   sum_j psi_1(y - j) = 0,      sum_j (j_1 - y_1) psi_1(y - j) = 1,
//!                                sum_j (j_2 - y_2) psi_1(y - j) = 0        (d/dx_1)
//! ```
//!
//! (Schaefer–Warren eq. (4) and section 4; both schemes reproduce linear functions, so the
//! positions' moments vanish). Those linear forms are left eigenvectors of `T` (the mask's sum
//! rules: the form of class `r` applied to `T v` is the form of class `λ r` applied to `v`,
//! times `1, λ^-1, λ^-1` for positions and `λ, 1, 1` for `psi_1`), so on the affine set where
//! they hold `T` is a contraction by the next eigenvalue (`λ^-2` times `f`, or the scheme's
//! smoothness limit): iterating `v <- P(T v)`, `P` the orthogonal projection of each class onto
//! its normalization, converges to the basis from any start, and does not amplify rounding the
//! way substitution along the orbits does (the projection removes, every step, the components
//! `T` would grow). This is the scaling relation solved by iteration rather than by
//! factoring each orbit: the orbits of the butterfly's odd grids are cycles of length up to 22
//! (the order of 2 mod 69) over 27 values a class, which the SVD of
//! [`crate::float_solve`] takes minutes over, and the exact path longer (`1/72`: 23.7 minutes
//! for the table's rates); the iteration costs about 100 passes over the grid.
//!
//! The iteration stops [`SETTLE_PASSES`] passes after one changes no value by more than
//! [`SETTLED`] of the largest value; the result agrees with the orbit solves (exact, or SVD
//! in f64) to about 1e-15 (tested at every rate the old path solves in seconds). It is
//! deterministic: the same bytes on every run.

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};
use schemes::lattice_symmetry::{
    in_open_support, quarter_points, rotate_back, support_box, to_quarter, to_wedge, wedge_points,
};
use schemes::LatticeMask;

use crate::regular_patch::StencilKind;
use crate::triangle_system::TriangleStencils;
use crate::StencilError;

/// Passes after the changes fell below the stopping threshold (each divides the error by the
/// contraction factor again).
pub const SETTLE_PASSES: usize = 8;

/// The stopping threshold: a pass changes no value by more than this times the largest.
/// Rounding alone moves values by up to about `12 eps` a pass (measured at the butterfly's
/// `psi_1`), so the iteration never gets quieter than that; the contraction (at least halving
/// the error every pass) has reached the rounding level well before.
pub const SETTLED: f64 = 64.0 * f64::EPSILON;

/// Passes at most: the slowest contraction measured (√3's and the butterfly's `psi_1`) needs
/// fewer than 150.
pub const MAX_PASSES: usize = 2000;

/// The canonical values of a regular basis on one grid `1/d`: what a compact region table
/// stores per rate.
#[derive(Clone, Debug, PartialEq)]
pub struct CanonicalBasis {
    /// The grid denominator.
    pub d: u32,
    /// `psi` at [`wedge_points`], in their order.
    pub psi: Vec<f64>,
    /// `psi_1` at [`quarter_points`], in their order.
    pub psi_1: Vec<f64>,
}

/// A grid point's numerators `k` (the point `k/d`) and the basis's value there.
pub type GridValue = ((i64, i64), f64);

/// One value's relation: `(index of lambda k - i d, f s_i)` pairs.
type Terms = Vec<(usize, f64)>;

/// The values of `psi` (`kind` position) or `psi_1` (`DerivativeU`) of `mask` at the grid
/// points of `1/d` strictly inside the support, by the cascade iteration (module docs); the
/// points in the order of [`support_box`] (`k_2` outer) with their values.
pub fn cascade(
    mask: &LatticeMask,
    d: u32,
    kind: StencilKind,
) -> Result<Vec<GridValue>, StencilError> {
    let unsupported = |reason: String| StencilError::UnsupportedScheme {
        scheme: mask.name.clone(),
        reason,
    };
    if d == 0 || d > crate::triangle_system::MAX_BASIS_RATE {
        return Err(StencilError::RateOutOfRange {
            n: d,
            max: crate::triangle_system::MAX_BASIS_RATE,
        });
    }
    let hull = mask.hull();
    if hull.len() < 3 || mask.dilation < 2 {
        return Err(unsupported(
            "the mask's support is not two-dimensional, or its dilation is below 2".to_owned(),
        ));
    }
    let ((l1, h1), (l2, h2)) = support_box(&hull, mask.dilation, d);
    let points: Vec<(i64, i64)> = (l2..=h2)
        .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
        .filter(|&k| in_open_support(&hull, mask.dilation, d, k))
        .collect();
    let index: HashMap<(i64, i64), usize> =
        points.iter().enumerate().map(|(u, &k)| (k, u)).collect();
    let (n, lambda) = (i64::from(d), i64::from(mask.dilation));
    let factor = match kind {
        StencilKind::Position => 1,
        StencilKind::DerivativeU => lambda,
        StencilKind::DerivativeV => {
            return Err(unsupported(
                "the cascade solves psi and psi_1; psi_2 is psi_1 rotated".to_owned(),
            ))
        }
    };
    // f s_i, correctly rounded (the quotient of two integers that f64 holds exactly).
    let terms: Vec<Terms> = points
        .iter()
        .map(|k| {
            mask.weights
                .iter()
                .filter_map(|((i1, i2), w)| {
                    let at = (lambda * k.0 - i1 * n, lambda * k.1 - i2 * n);
                    index
                        .get(&at)
                        .map(|&v| (v, (factor * w.numer()) as f64 / *w.denom() as f64))
                })
                .collect()
        })
        .collect();
    // The normalization of each class: three forms, their Gram matrix inverted once.
    let targets = match kind {
        StencilKind::Position => Vector3::new(1.0, 0.0, 0.0),
        _ => Vector3::new(0.0, 1.0, 0.0),
    };
    let mut by_class: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (u, k) in points.iter().enumerate() {
        by_class
            .entry((k.0.rem_euclid(n), k.1.rem_euclid(n)))
            .or_default()
            .push(u);
    }
    let mut classes: Vec<((i64, i64), Vec<usize>)> = by_class.into_iter().collect();
    // A fixed order: the passes' arithmetic does not depend on the hash map's.
    classes.sort_unstable();
    let mut projections = Vec::with_capacity(classes.len());
    for (r, members) in &classes {
        // Rows: 1, j_1 - y_1, j_2 - y_2 at y = r/d for the point k = d (y - j): j - y = -k/d.
        let forms: Vec<[f64; 3]> = members
            .iter()
            .map(|&u| {
                let k = points[u];
                [1.0, -k.0 as f64 / n as f64, -k.1 as f64 / n as f64]
            })
            .collect();
        let mut gram = Matrix3::<f64>::zeros();
        for f in &forms {
            for a in 0..3 {
                for b in 0..3 {
                    gram[(a, b)] += f[a] * f[b];
                }
            }
        }
        let inverse = gram.try_inverse().ok_or_else(|| {
            unsupported(format!(
                "the normalization of class {r:?} on the grid 1/{d} is degenerate"
            ))
        })?;
        projections.push((members.clone(), forms, inverse));
    }
    let mut v = vec![0.0f64; points.len()];
    let project = |v: &mut [f64]| {
        for (members, forms, inverse) in &projections {
            let mut residual = -targets;
            for (&u, f) in members.iter().zip(forms) {
                for a in 0..3 {
                    residual[a] += f[a] * v[u];
                }
            }
            let c = inverse * residual;
            for (&u, f) in members.iter().zip(forms) {
                v[u] -= f[0] * c[0] + f[1] * c[1] + f[2] * c[2];
            }
        }
    };
    project(&mut v);
    let mut next = vec![0.0f64; points.len()];
    let mut settled = None;
    for pass in 0..MAX_PASSES {
        for (o, t) in next.iter_mut().zip(&terms) {
            *o = t.iter().fold(0.0, |acc, &(u, w)| acc + w * v[u]);
        }
        project(&mut next);
        let scale = next.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let change = next
            .iter()
            .zip(&v)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        std::mem::swap(&mut v, &mut next);
        match settled {
            None if change <= SETTLED * scale => settled = Some(pass),
            Some(at) if pass >= at + SETTLE_PASSES => {
                return Ok(points.into_iter().zip(v).collect());
            }
            _ => {}
        }
    }
    Err(StencilError::Inconsistent {
        scheme: mask.name.clone(),
        n: d,
        detail: format!("the cascade iteration did not settle in {MAX_PASSES} passes"),
    })
}

impl CanonicalBasis {
    /// Solve `mask`'s basis on `1/d` ([`cascade`]) and keep its canonical values.
    pub fn new(mask: &LatticeMask, d: u32) -> Result<Self, StencilError> {
        let hull = mask.hull();
        let pick = |kind, at: Vec<(i64, i64)>| -> Result<Vec<f64>, StencilError> {
            let values: HashMap<(i64, i64), f64> = cascade(mask, d, kind)?.into_iter().collect();
            Ok(at
                .iter()
                .map(|k| values.get(k).copied().unwrap_or(0.0))
                .collect())
        };
        Ok(CanonicalBasis {
            d,
            psi: pick(StencilKind::Position, wedge_points(&hull, mask.dilation, d))?,
            psi_1: pick(
                StencilKind::DerivativeU,
                quarter_points(&hull, mask.dilation, d),
            )?,
        })
    }

    /// The basis everywhere on the grid, from the canonical values by the lattice's symmetries
    /// (`psi(x) = psi(w(x))`, `psi_1(x) = ±psi_1(q(x))`, `psi_2(y) = psi_1(rho^-1 y)`): what a
    /// reader of the table evaluates; `psi`, `psi_1`, `psi_2` in [`StencilKind`] order, the
    /// kinds of a `crate::cone_regions::RegionBasis`.
    pub fn spread(&self, mask: &LatticeMask) -> [TriangleStencils<f64>; 3] {
        let hull = mask.hull();
        let wedge: HashMap<(i64, i64), f64> = wedge_points(&hull, mask.dilation, self.d)
            .into_iter()
            .zip(self.psi.iter().copied())
            .collect();
        let quarter: HashMap<(i64, i64), f64> = quarter_points(&hull, mask.dilation, self.d)
            .into_iter()
            .zip(self.psi_1.iter().copied())
            .collect();
        let psi = |k: (i64, i64)| wedge.get(&to_wedge(k)).copied().unwrap_or(0.0);
        let psi_1 = |k: (i64, i64)| {
            let (q, sign) = to_quarter(k);
            quarter.get(&q).map_or(0.0, |v| sign * v)
        };
        let bbox = support_box(&hull, mask.dilation, self.d);
        let ((l1, h1), (l2, h2)) = bbox;
        let grid = |kind, f: &dyn Fn((i64, i64)) -> f64| TriangleStencils {
            scheme: mask.name.clone(),
            n: self.d,
            kind,
            dilation: mask.dilation,
            hull: hull.clone(),
            bbox,
            values: (l2..=h2)
                .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
                .map(|k| {
                    if in_open_support(&hull, mask.dilation, self.d, k) {
                        f(k)
                    } else {
                        0.0
                    }
                })
                .collect(),
            residual: 0.0,
        };
        [
            grid(StencilKind::Position, &psi),
            grid(StencilKind::DerivativeU, &psi_1),
            grid(StencilKind::DerivativeV, &|k| psi_1(rotate_back(k))),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cone_patch::family_regular_basis_kind;
    use schemes::cone_local::ConeFamily;
    use schemes::TriangleScheme;

    /// The canonical values, spread by the symmetries, are the orbit solves' basis (exact and
    /// rounded, or the SVD's in f64 at the butterfly's odd rates) within 2e-14, every kind,
    /// at rates the old path solves in seconds.
    #[test]
    fn the_cascade_is_the_orbit_solve() {
        for (name, family, rates) in [
            ("butterfly", ConeFamily::Butterfly, vec![3, 6, 9, 12, 15]),
            ("sqrt3", ConeFamily::Sqrt3, vec![3, 6, 9, 12]),
        ] {
            let scheme = TriangleScheme::by_name(name).expect("catalogued");
            let mask = scheme.regular_mask();
            for d in rates {
                let basis = CanonicalBasis::new(&mask, d)
                    .expect("settles")
                    .spread(&mask);
                for (slot, kind) in [
                    StencilKind::Position,
                    StencilKind::DerivativeU,
                    StencilKind::DerivativeV,
                ]
                .into_iter()
                .enumerate()
                {
                    let want =
                        family_regular_basis_kind::<f64>(family, &scheme, d, kind).expect("solves");
                    let got = &basis[slot];
                    assert_eq!(got.bbox, want.bbox);
                    let worst = got
                        .values
                        .iter()
                        .zip(&want.values)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(worst < 2e-14, "{name} 1/{d} {kind:?}: {worst:e}");
                }
            }
        }
    }
}
