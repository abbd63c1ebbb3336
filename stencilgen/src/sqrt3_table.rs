//! √3 stencil tables (`docs/table-format.md`, "Compact region tables" and the triangle point
//! sets; scheme id 5).
//!
//! The default layout is compact, as the butterfly's ([`crate::region_table`]). In the grid
//! layout (`--grids`) every region `r` of an interior vertex of valence `K` ([`schemes::sqrt3_regions`]: the nine
//! triangles of a sector whose surface the vertex shapes) and rate `n` becomes six sections, keyed
//! `faces = K`, `sector = r`: positions, d/du and d/dv on the triangle primal grid `(i/n, j/n)`,
//! `i + j <= n`, and on the `n^2` centroids of its small triangles
//! ([`crate::triangle_table::triangle_dual_points`]), in the region's frame and over its layout —
//! the butterfly table's shape ([`crate::butterfly_table`]). Valence 6 is the regular patch; only
//! its region 0 is stored. At `V` itself (region 0's primal `(0, 0)`) the derivative sections hold
//! the tangent masks of [`crate::sqrt3_regions`]' convention (Loop's: the subdominant left
//! eigenvectors normalized on the reference net), not derivatives, which do not exist there for `K
//! != 6`.
//!
//! The weights are [`Sqrt3RegionStencils`]': the regular basis `psi` and its derivatives solved
//! once per rate on the grid `1/3n` (primal points are `3i/3n`, centroids `(3i+1)/3n`;
//! [`crate::sqrt3_patch::sqrt3_regular_basis_kind`]: exactly and rounded, which at these rates, all
//! multiples of 3, beats the f64 solve), the regions' matrices in f64 (`alpha_K` is irrational at
//! `K = 5, 7, 8`), so f64 throughout; a test compares a small table with the exact path. `tables/`
//! embeds [`default_sqrt3_table`] (compact, n = 1..=24); `stencilgen tables --schemes sqrt3`
//! writes any range (time and size in docs/table-format.md).
//!
//! The sections are built by the builder both region schemes share, [`crate::region_table`].

use schemes::TriangleScheme;
use table_format::{Precision, SchemeId};

use crate::region_table::{
    build_compact_region_table, build_region_table, RegionLayout, RegionTableSpec, KINDS,
};
use crate::sqrt3_regions::{Sqrt3Basis, Sqrt3RegionStencils};
use crate::triangle_patch::triangle_scheme;
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::StencilError;

/// What to put in a √3 table.
pub type Sqrt3TableSpec = RegionTableSpec;

impl RegionTableSpec {
    /// The table `subtess` embeds (`tables::default_sqrt3`): valences 3..=8, n = 1..=24,
    /// compact, f64 (the butterfly's embedded shape; 2.6 MiB).
    pub fn default_sqrt3() -> Self {
        RegionTableSpec {
            valences: (3..=8).collect(),
            rates: (1..=MAX_TRIANGLE_RATE).collect(),
            precision: Precision::F64,
            layout: RegionLayout::Compact,
        }
    }
}

/// The √3 table `subtess` embeds ([`RegionTableSpec::default_sqrt3`]), encoded (deterministic:
/// the same bytes on every run).
pub fn default_sqrt3_table() -> Result<Vec<u8>, StencilError> {
    build_sqrt3_table(&RegionTableSpec::default_sqrt3())
}

/// Generate and encode the √3 table of `spec`.
pub fn build_sqrt3_table(spec: &Sqrt3TableSpec) -> Result<Vec<u8>, StencilError> {
    let scheme: TriangleScheme = triangle_scheme("sqrt3")?;
    if spec.layout == RegionLayout::Compact {
        return build_compact_region_table(SchemeId::Sqrt3, spec, &scheme.regular_mask(), |k| {
            Ok(Sqrt3RegionStencils::<f64>::new(&scheme, k)?.compact_pieces())
        });
    }
    let kinds = KINDS.map(|(k, _)| k);
    build_region_table(
        SchemeId::Sqrt3,
        spec,
        |d| Sqrt3Basis::<f64>::new(&scheme, d, &kinds),
        |k| Sqrt3RegionStencils::<f64>::new(&scheme, k),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region_table::primal_points;
    use crate::triangle_table::triangle_dual_points;
    use num_rational::BigRational;
    use table_format::{AlignedBytes, Table};
    use table_format::{PointSet, SectionKey};

    /// A small f64 table holds, section by section, the exact path's weights (valences 3, 4
    /// and 6, where √3 is rational) within 1e-12, at the documented points; valence 6 holds
    /// region 0 only.
    #[test]
    fn a_small_table_holds_the_exact_stencils() {
        let spec = Sqrt3TableSpec {
            valences: vec![3, 4, 6],
            rates: vec![1, 2],
            precision: Precision::F64,
            layout: RegionLayout::Grids,
        };
        let bytes = AlignedBytes::from_slice(&build_sqrt3_table(&spec).expect("builds"));
        let table = Table::parse(bytes.as_bytes()).expect("parses");
        assert_eq!(table.meta.scheme, SchemeId::Sqrt3);
        let scheme = triangle_scheme("sqrt3").expect("catalogued");
        let mut checked = 0;
        for k in [3u32, 4, 6] {
            let exact = Sqrt3RegionStencils::<BigRational>::new(&scheme, k).expect("exact");
            for n in [1u32, 2] {
                let basis =
                    Sqrt3Basis::<BigRational>::new(&scheme, 3 * n, &KINDS.map(|(kind, _)| kind))
                        .expect("exact basis");
                for r in 0..exact.regions.regions.len() {
                    for (kind, table_kind) in KINDS {
                        for (set, points) in [
                            (PointSet::TrianglePrimal, primal_points(n)),
                            (PointSet::TriangleDual, triangle_dual_points(n)),
                        ] {
                            let key = SectionKey {
                                kind: table_kind,
                                points: set,
                                boundary: false,
                                feature: table_format::Feature::None,
                                faces: k,
                                sector: r as u32,
                                n,
                            };
                            let Ok(stored) = table.weights_f64(&key) else {
                                assert!(k == 6 && r > 0, "{key} missing");
                                continue;
                            };
                            assert!(k != 6 || r == 0, "{key} stored at the regular valence");
                            let width = exact.region(r).expect("region").size();
                            assert_eq!(stored.len(), points.len() * width, "{key}");
                            for (p, row) in points.iter().zip(stored.chunks(width)) {
                                let want = exact.stencil(r, &basis, *p, kind).expect("stencil");
                                for (a, b) in row.iter().zip(&want) {
                                    let b: f64 = crate::Scalar::to_f64(b);
                                    assert!((a - b).abs() < 1e-12, "{key} at {p:?}: {a} vs {b}");
                                    checked += 1;
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
    }
}
