//! Butterfly stencil tables (`docs/table-format.md`, triangle point sets).
//!
//! Every region `r` of an interior vertex of valence `K` ([`schemes::butterfly_regions`]: the
//! nine triangles of a sector whose surface the vertex shapes) and rate `n` becomes six
//! sections, keyed `faces = K`, `sector = r`: positions, d/du and d/dv on the triangle primal
//! grid `(i/n, j/n)`, `i + j <= n`, and on the `n^2` centroids of its small triangles
//! ([`triangle_dual_points`]), in the region's frame and over its layout. Valence 6 is the
//! regular patch; only its region 0 is stored (every region of a regular vertex is the same
//! regular patch, and the runtime reads region 0 around a triangle's corner 0).
//!
//! The weights are [`ButterflyRegionStencils`]': the regular basis `psi` solved exactly on the
//! grid `1/3n` (primal points are `3i/3n`, centroids `(3i+1)/3n`) and rounded to f64, the
//! region's matrices in f64 (the butterfly's extraordinary weights are irrational at
//! `K = 5, 7, 8`), so f64 throughout; the tests compare with the exact path where it exists.

use rayon::prelude::*;
use schemes::TriangleScheme;
use table_format::{
    encode, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::butterfly_regions::{ButterflyBasis, ButterflyRegionStencils};
use crate::regular_patch::StencilKind;
use crate::triangle_patch::{triangle_grid_points, triangle_scheme};
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::triangle_table::triangle_dual_points;
use crate::StencilError;

/// What to put in a butterfly table.
#[derive(Clone, Debug, PartialEq)]
pub struct ButterflyTableSpec {
    /// Interior valences (6 is the regular patch).
    pub valences: Vec<u32>,
    /// Grid rates.
    pub rates: Vec<u32>,
    /// Stored precision.
    pub precision: Precision,
}

impl ButterflyTableSpec {
    /// The butterfly table `subtess` embeds: valences 3..=8, n = 1..=8, f32 (5.3 MiB; the
    /// rates up to 24 make a 109.2 MiB table, written by `stencilgen tables` in about 14 CPU
    /// minutes).
    pub fn default_butterfly() -> Self {
        ButterflyTableSpec {
            valences: (3..=8).collect(),
            rates: (1..=8).collect(),
            precision: Precision::F32,
        }
    }
}

const KINDS: [(StencilKind, TableKind); 3] = [
    (StencilKind::Position, TableKind::Position),
    (StencilKind::DerivativeU, TableKind::DerivativeU),
    (StencilKind::DerivativeV, TableKind::DerivativeV),
];

/// One table section: key, width, point-major weights.
type Section = (SectionKey, u32, Vec<f64>);

/// The six sections of region `r` at rate `basis.n / 3`.
fn region_sections(
    regions: &ButterflyRegionStencils<f64>,
    r: usize,
    basis: &ButterflyBasis<f64>,
) -> Result<Vec<Section>, StencilError> {
    let n = basis.n / 3;
    let width = regions.region(r)?.size();
    let primal: Vec<(i64, i64)> = triangle_grid_points(n)
        .into_iter()
        .map(|(i, j)| (3 * i, 3 * j))
        .collect();
    let dual = triangle_dual_points(n);
    let mut out = Vec::with_capacity(6);
    for (kind, table_kind) in KINDS {
        for (points, set) in [
            (&primal, PointSet::TrianglePrimal),
            (&dual, PointSet::TriangleDual),
        ] {
            let mut weights = Vec::with_capacity(points.len() * width);
            for &p in points {
                weights.extend(regions.stencil(r, basis, p, kind)?);
            }
            let key = SectionKey {
                kind: table_kind,
                points: set,
                boundary: false,
                faces: regions.regions.valence,
                sector: r as u32,
                n,
            };
            out.push((key, width as u32, weights));
        }
    }
    Ok(out)
}

/// Generate and encode the butterfly table of `spec`.
pub fn build_butterfly_table(spec: &ButterflyTableSpec) -> Result<Vec<u8>, StencilError> {
    let scheme: TriangleScheme = triangle_scheme("butterfly")?;
    if let Some(&n) = spec
        .rates
        .iter()
        .find(|&&n| n == 0 || n > MAX_TRIANGLE_RATE)
    {
        return Err(StencilError::RateOutOfRange {
            n,
            max: MAX_TRIANGLE_RATE,
        });
    }
    let kinds = KINDS.map(|(k, _)| k);
    // The regular basis on 1/3n, the costliest part (an exact solve per rate and kind).
    let bases = spec
        .rates
        .par_iter()
        .map(|&n| ButterflyBasis::<f64>::new(&scheme, 3 * n, &kinds))
        .collect::<Result<Vec<_>, _>>()?;
    let valences = spec
        .valences
        .par_iter()
        .map(|&k| ButterflyRegionStencils::<f64>::new(&scheme, k))
        .collect::<Result<Vec<_>, _>>()?;
    let jobs: Vec<(usize, usize, usize)> = valences
        .iter()
        .enumerate()
        .flat_map(|(v, regions)| {
            let count = if regions.regions.valence == 6 {
                1
            } else {
                regions.regions.regions.len()
            };
            (0..count).map(move |r| (v, r))
        })
        .flat_map(|(v, r)| (0..bases.len()).map(move |b| (v, r, b)))
        .collect();
    let sections = jobs
        .into_par_iter()
        .map(|(v, r, b)| region_sections(&valences[v], r, &bases[b]))
        .collect::<Result<Vec<_>, _>>()?;
    let meta = TableMeta {
        scheme: SchemeId::Butterfly,
        precision: spec.precision,
        corners: false,
    };
    let sections: Vec<Section> = sections.into_iter().flatten().collect();
    Ok(encode(meta, &sections)?)
}

/// The butterfly table `subtess` embeds ([`ButterflyTableSpec::default_butterfly`]), encoded
/// (deterministic: the same bytes on every run).
pub fn default_butterfly_table() -> Result<Vec<u8>, StencilError> {
    build_butterfly_table(&ButterflyTableSpec::default_butterfly())
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;
    use table_format::{AlignedBytes, Table};

    /// A small f64 table holds, section by section, the exact path's weights (valences 3 and
    /// 4, where the butterfly is rational) within 1e-12, at the documented points.
    #[test]
    fn a_small_table_holds_the_exact_stencils() {
        let spec = ButterflyTableSpec {
            valences: vec![3, 4],
            rates: vec![1, 2],
            precision: Precision::F64,
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
                            (
                                PointSet::TrianglePrimal,
                                triangle_grid_points(n)
                                    .into_iter()
                                    .map(|(i, j)| (3 * i, 3 * j))
                                    .collect::<Vec<_>>(),
                            ),
                            (PointSet::TriangleDual, triangle_dual_points(n)),
                        ] {
                            let key = SectionKey {
                                kind: table_kind,
                                points: set,
                                boundary: false,
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
