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
}
