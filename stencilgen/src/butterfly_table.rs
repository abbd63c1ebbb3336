//! Butterfly stencil tables (`docs/table-format.md`, "Compact region tables" and the triangle
//! point sets).
//!
//! The default layout is compact ([`crate::region_table`]: per rate the regular basis by its
//! canonical values, per valence `A`, the masks at `V` and each region's tile rows; the runtime
//! expands the grids). In the grid layout (`--grids`, the reference the compact one is tested
//! against) every region `r` of an interior vertex of valence `K` ([`schemes::butterfly_regions`]: the nine
//! triangles of a sector whose surface the vertex shapes) and rate `n` becomes six sections, keyed
//! `faces = K`, `sector = r`: positions, d/du and d/dv on the triangle primal grid `(i/n, j/n)`,
//! `i + j <= n`, and on the `n^2` centroids of its small triangles
//! ([`crate::triangle_table::triangle_dual_points`]), in the region's frame and over its layout.
//! Valence 6 is the regular patch; only its region 0 is stored (every region of a regular vertex is
//! the same regular patch, and the runtime reads region 0 around a triangle's corner 0).
//!
//! The weights are [`ButterflyRegionStencils`]': the regular basis `psi` solved on the grid `1/3n`
//! (primal points are `3i/3n`, centroids `(3i+1)/3n`; exactly and rounded, or in f64 at odd
//! rates: [`crate::butterfly_patch::regular_basis_kind`]), the region's
//! matrices in f64 (the butterfly's extraordinary weights are irrational at `K = 5, 7, 8`), so f64
//! throughout; the tests compare with the exact path where it exists.
//!
//! The sections are built by the builder both region schemes share, [`crate::region_table`].

use schemes::TriangleScheme;
use table_format::{Precision, SchemeId};

use crate::butterfly_regions::{ButterflyBasis, ButterflyRegionStencils};
use crate::region_table::{
    build_compact_region_table, build_region_table, RegionLayout, RegionTableSpec, KINDS,
};
use crate::triangle_patch::triangle_scheme;
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::StencilError;

/// What to put in a butterfly table.
pub type ButterflyTableSpec = RegionTableSpec;

impl RegionTableSpec {
    /// The butterfly table `subtess` embeds: valences 3..=8, n = 1..=24, compact, f64
    /// (3.2 MiB; the grid layout of the same rates is 109.2 MiB, and its orbit solves take
    /// about 14 CPU minutes).
    pub fn default_butterfly() -> Self {
        RegionTableSpec {
            valences: (3..=8).collect(),
            rates: (1..=MAX_TRIANGLE_RATE).collect(),
            precision: Precision::F64,
            layout: RegionLayout::Compact,
        }
    }
}

/// The butterfly table `subtess` embeds ([`RegionTableSpec::default_butterfly`]), encoded
/// (deterministic: the same bytes on every run).
pub fn default_butterfly_table() -> Result<Vec<u8>, StencilError> {
    build_butterfly_table(&RegionTableSpec::default_butterfly())
}

/// Generate and encode the butterfly table of `spec`.
pub fn build_butterfly_table(spec: &ButterflyTableSpec) -> Result<Vec<u8>, StencilError> {
    let scheme: TriangleScheme = triangle_scheme("butterfly")?;
    if spec.layout == RegionLayout::Compact {
        return build_compact_region_table(
            SchemeId::Butterfly,
            spec,
            &scheme.regular_mask(),
            |k| Ok(ButterflyRegionStencils::<f64>::new(&scheme, k)?.compact_pieces()),
        );
    }
    let kinds = KINDS.map(|(k, _)| k);
    build_region_table(
        SchemeId::Butterfly,
        spec,
        |d| ButterflyBasis::<f64>::new(&scheme, d, &kinds),
        |k| ButterflyRegionStencils::<f64>::new(&scheme, k),
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

    /// A small f64 table holds, section by section, the exact path's weights (valences 3 and
    /// 4, where the butterfly is rational) within 1e-12, at the documented points.
    #[test]
    fn a_small_table_holds_the_exact_stencils() {
        let spec = ButterflyTableSpec {
            valences: vec![3, 4],
            rates: vec![1, 2],
            precision: Precision::F64,
            layout: RegionLayout::Grids,
        };
        let bytes = AlignedBytes::from_slice(&build_butterfly_table(&spec).expect("builds"));
        let table = Table::parse(bytes.as_bytes()).expect("parses");
        let scheme = triangle_scheme("butterfly").expect("catalogued");
        let mut checked = 0;
        for k in [3u32, 4] {
            let exact = ButterflyRegionStencils::<BigRational>::new(&scheme, k).expect("exact");
            for n in [1u32, 2] {
                let basis = ButterflyBasis::<BigRational>::new(
                    &scheme,
                    3 * n,
                    &KINDS.map(|(kind, _)| kind),
                )
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
                            let stored = table.weights_f64(&key).expect("section");
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
