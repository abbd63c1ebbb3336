//! The √3 surface next to a boundary (Kobbelt's boundary rules) with the generator's own
//! regular basis: `schemes::sqrt3_boundary_surface` evaluates it by certified levels (its docs
//! have the method) from `psi` on the grid `1/d`, which this module solves
//! ([`RegionBasis`], the same solve as the interior tables'). The runtime's boundary patches
//! evaluate the same surface from the table's `psi`; this is the independent side of their
//! checks, and what `stencilgen stencil --scheme sqrt3 --boundary` prints.

use schemes::loop_regular::RegularDerivative;
use schemes::sqrt3_boundary_surface::{BoundarySurface, Refused, RegularBasis};
pub use schemes::sqrt3_boundary_surface::{FanStencil, StripStencil, REGULAR_ROW};
use schemes::TriangleScheme;

use crate::cone_regions::RegionBasis;
use crate::regular_patch::StencilKind;
use crate::triangle_system::MAX_BASIS_RATE;
use crate::StencilError;

/// The surface beside a boundary with the generator's basis on the grid `1/d`.
pub type BoundaryEvaluator = BoundarySurface<RegionBasis<f64>>;

impl RegularBasis for RegionBasis<f64> {
    fn denominator(&self) -> i64 {
        i64::from(self.n)
    }

    fn support_box(&self, what: RegularDerivative) -> ((i64, i64), (i64, i64)) {
        self.kinds[index(what)]
            .as_ref()
            .map_or(((0, -1), (0, -1)), |psi| psi.bbox)
    }

    fn value(&self, what: RegularDerivative, k: (i64, i64)) -> f64 {
        self.kinds[index(what)]
            .as_ref()
            .map_or(0.0, |psi| psi.at(k.0, k.1))
    }
}

/// Where `what` sits in [`RegionBasis::kinds`].
fn index(what: RegularDerivative) -> usize {
    match what {
        RegularDerivative::Position => 0,
        RegularDerivative::U => 1,
        RegularDerivative::V => 2,
    }
}

/// The derivative a stencil kind asks of the surface.
pub fn derivative(kind: StencilKind) -> RegularDerivative {
    match kind {
        StencilKind::Position => RegularDerivative::Position,
        StencilKind::DerivativeU => RegularDerivative::U,
        StencilKind::DerivativeV => RegularDerivative::V,
    }
}

impl From<Refused> for StencilError {
    fn from(refused: Refused) -> Self {
        StencilError::OutOfDomain { what: refused.0 }
    }
}

/// `psi` and its two skew-axis derivatives solved on the grid `1/d`
/// (`1..=`[`MAX_BASIS_RATE`]).
fn basis(d: u32) -> Result<RegionBasis<f64>, StencilError> {
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
    RegionBasis::new(&scheme, d, &kinds)
}

/// The half-plane beside a straight boundary, on the grid `1/d`.
pub fn strip(d: u32) -> Result<BoundaryEvaluator, StencilError> {
    Ok(BoundarySurface::strip(basis(d)?))
}

/// The fan of `faces` triangles around a boundary vertex, on the grid `1/d`.
pub fn fan(faces: u32, d: u32) -> Result<BoundaryEvaluator, StencilError> {
    Ok(BoundarySurface::fan(faces, basis(d)?)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Positions sum to 1 and derivatives to 0 (partition of unity), off the line and on it.
    /// The cross masks on the line sum to 0 (a direction, no constant part), map the flat
    /// lattice to `(0, 1)`, and settle at a vertex (`t = 0`), at the edge's midpoint (`1/2`,
    /// where the derivative itself grows without bound) and at a point with a longer cycle
    /// (`1/4 -> 3/4 -> 1/4`).
    #[test]
    fn cross_masks_on_the_line() {
        let mut e = strip(4).expect("psi on 1/4");
        for k in [0, 1, 2, 4, 6] {
            let m = e.cross_mask_on_line(k).expect("settles");
            let sum: f64 = m.values().sum();
            assert!(sum.abs() < 1e-10, "{k}: {sum}");
            let image = m.iter().fold([0.0, 0.0], |acc, (&(a, b), &w)| {
                [acc[0] + w * a as f64, acc[1] + w * b as f64]
            });
            assert!(
                image[0].abs() < 1e-9 && (image[1] - 1.0).abs() < 1e-9,
                "{k}: {image:?}"
            );
        }
    }

    #[test]
    fn stencils_are_affine() {
        let mut e = strip(6).expect("psi on 1/6");
        for k in [(0, 0), (3, 0), (1, 1), (2, 3), (5, 1), (0, 6), (4, 2)] {
            for kind in [
                RegularDerivative::Position,
                RegularDerivative::U,
                RegularDerivative::V,
            ] {
                if k.1 == 0 && kind == RegularDerivative::V {
                    assert!(e.half_plane_stencil(k, kind).is_err());
                    continue;
                }
                let s = e.half_plane_stencil(k, kind).expect("evaluates");
                let sum: f64 = s.values().sum();
                let want = if kind == RegularDerivative::Position {
                    1.0
                } else {
                    0.0
                };
                assert!((sum - want).abs() < 1e-12, "{k:?} {kind:?}: {sum}");
            }
        }
    }

    /// A generic embedding of fan points (fixed pseudo-random coordinates).
    fn embed(p: &schemes::sqrt3_boundary::FanPoint) -> [f64; 3] {
        let (s, a, b) = *p;
        let h = |i: i64| ((i as f64 * 12.9898).sin() * 43_758.545).rem_euclid(1.0);
        let key = i64::from(s) * 97 + a * 13 + b * 5;
        [h(3 * key), h(3 * key + 1), h(3 * key + 2)]
    }

    fn apply(m: &FanStencil) -> [f64; 3] {
        m.iter().fold([0.0; 3], |acc, (p, &w)| {
            let x = embed(p);
            [acc[0] + w * x[0], acc[1] + w * x[1], acc[2] + w * x[2]]
        })
    }

    fn unit_cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
        let c = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        [c[0] / n, c[1] / n, c[2] / n]
    }

    fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let sin = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        sin.atan2(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
    }

    /// The power-iterated mask at a fan's vertex spans, with the boundary tangent, the plane of
    /// the eigen-solved masks (`crate::sqrt3_fan_tangents`, nalgebra's Schur form): on a generic
    /// embedding the two normals agree (sector 0's `du x dv` against `t x c`) to 1e-8 rad,
    /// orientation included, at K = 1, 2, 4, 5, 6, 7.
    #[test]
    fn vertex_masks_are_the_eigen_solved_ones() {
        let psi = basis(3).expect("psi on 1/3");
        for k in [1u32, 2, 4, 5, 6, 7] {
            let mut surface = BoundarySurface::fan(k, psi.clone()).expect("a fan");
            let c = surface.cross_mask_at_vertex().expect("settles");
            let t: FanStencil = [((0, 1, 0), 0.5), ((k, 1, 0), -0.5)].into();
            let solved = crate::sqrt3_fan_tangents::sqrt3_fan_tangents(k, 0).expect("solves");
            let stencil = |w: &[f64]| -> FanStencil {
                solved
                    .layout
                    .iter()
                    .copied()
                    .zip(w.iter().copied())
                    .collect()
            };
            let want = unit_cross(apply(&stencil(&solved.du)), apply(&stencil(&solved.dv)));
            let got = unit_cross(apply(&t), apply(&c));
            assert!(angle(want, got) < 1e-8, "K = {k}: {}", angle(want, got));
        }
    }

    /// On a fan's rays the walked masks are the limits of the exact normals above the ray: at
    /// `tau = 1/3, -2/3, 1, 3, 9, 10` (rays of `E_0` and `E_K`) of fans of 1, 2, 4 and 5
    /// triangles, the normal of (the boundary's tangent, the exact cross derivative at distance
    /// `e = 1/18, 1/54` from the ray) turns towards (tangent, mask) by a factor below 0.6 and
    /// ends within 0.11 rad (measured: 0.004 to 0.10, about a third per step in `e`, as on the
    /// half-plane's line; from `tau = 3` on every fan gives the half-plane's numbers).
    #[test]
    fn ray_masks_are_the_limits_of_exact_normals() {
        let d = 54;
        let psi = basis(d as u32).expect("psi on 1/54");
        for k in [1u32, 2, 4, 5] {
            let mut surface = BoundarySurface::fan(k, psi.clone()).expect("a fan");
            let last = i64::from(k) - 1;
            for tau in [18i64, -36, 54, 162, 486, 540] {
                let mask = surface.cross_mask(tau).expect("walks");
                // Along the boundary towards E_0, and the chart point at distance e across it.
                type Across = fn(i64, i64) -> (i64, i64);
                let (sector, along, across): (i64, RegularDerivative, Across) = if tau > 0 {
                    (0, RegularDerivative::U, |t, e| (t, e))
                } else {
                    (last, RegularDerivative::V, |t, e| (e, -t - e))
                };
                let on = if tau > 0 { (tau, 0) } else { (0, -tau) };
                let mut du = surface.stencil(sector, on, along).expect("along");
                if tau < 0 {
                    du.values_mut().for_each(|w| *w = -*w);
                }
                let du = apply(&du);
                let want = unit_cross(du, apply(&mask));
                let mut angles = Vec::new();
                for e in [9, 3, 1] {
                    let x = across(tau, e);
                    let (u, v) = (
                        apply(&surface.stencil(sector, x, RegularDerivative::U).expect("u")),
                        apply(&surface.stencil(sector, x, RegularDerivative::V).expect("v")),
                    );
                    // The derivative across: sector 0's v, sector K-1's u.
                    let cross = if tau > 0 { v } else { u };
                    angles.push(angle(want, unit_cross(du, cross)));
                }
                assert!(
                    angles[2] < 0.6 * angles[1] && angles[2] < 0.11,
                    "K = {k}, tau = {tau}/{d}: {angles:?}"
                );
            }
        }
    }
}
