//! √3 stencil tables (`docs/table-format.md`, triangle point sets; scheme id 5).
//!
//! Every region `r` of an interior vertex of valence `K` ([`schemes::sqrt3_regions`]: the nine
//! triangles of a sector whose surface the vertex shapes) and rate `n` becomes six sections,
//! keyed `faces = K`, `sector = r`: positions, d/du and d/dv on the triangle primal grid
//! `(i/n, j/n)`, `i + j <= n`, and on the `n^2` centroids of its small triangles
//! ([`triangle_dual_points`]), in the region's frame and over its layout — the butterfly
//! table's shape ([`crate::butterfly_table`]). Valence 6 is the regular patch; only its region 0
//! is stored. At `V` itself (region 0's primal `(0, 0)`) the derivative sections hold the
//! tangent masks of [`crate::sqrt3_regions`]' convention (Loop's: the subdominant left
//! eigenvectors normalized on the reference net), not derivatives, which do not exist there
//! for `K != 6`.
//!
//! The weights are [`Sqrt3RegionStencils`]': the regular basis `psi` and its derivatives
//! solved once per rate on the grid `1/3n` (primal points are `3i/3n`, centroids
//! `(3i+1)/3n`; [`crate::sqrt3_patch::sqrt3_regular_basis_kind`]: exactly and rounded, which
//! at these rates, all multiples of 3, beats the f64 solve), the regions' matrices in f64
//! (`alpha_K` is irrational at `K = 5, 7, 8`), so f64 throughout; a test compares a small
//! table with the exact path. Not embedded in `tables/`: written by
//! `stencilgen tables --schemes sqrt3` (time and size in docs/table-format.md).

use rayon::prelude::*;
use schemes::TriangleScheme;
use table_format::{
    encode, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::regular_patch::StencilKind;
use crate::sqrt3_regions::{Sqrt3Basis, Sqrt3RegionStencils};
use crate::triangle_patch::{triangle_grid_points, triangle_scheme};
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::triangle_table::triangle_dual_points;
use crate::StencilError;

/// What to put in a √3 table.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3TableSpec {
    /// Interior valences (6 is the regular patch).
    pub valences: Vec<u32>,
    /// Grid rates.
    pub rates: Vec<u32>,
    /// Stored precision.
    pub precision: Precision,
}

impl Sqrt3TableSpec {
    /// The table `stencilgen tables --schemes sqrt3` writes by default: valences 3..=8,
    /// n = 1..=8, f32 (the butterfly's embedded shape).
    pub fn default_sqrt3() -> Self {
        Sqrt3TableSpec {
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

/// The primal points of rate `n` on the grid `1/3n`.
fn primal_points(n: u32) -> Vec<(i64, i64)> {
    triangle_grid_points(n)
        .into_iter()
        .map(|(i, j)| (3 * i, 3 * j))
        .collect()
}

/// The six sections of region `r` at rate `basis.n / 3`.
fn region_sections(
    regions: &Sqrt3RegionStencils<f64>,
    r: usize,
    basis: &Sqrt3Basis<f64>,
) -> Result<Vec<Section>, StencilError> {
    let n = basis.n / 3;
    let width = regions.region(r)?.size();
    let primal = primal_points(n);
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

/// Generate and encode the √3 table of `spec`.
pub fn build_sqrt3_table(spec: &Sqrt3TableSpec) -> Result<Vec<u8>, StencilError> {
    let scheme: TriangleScheme = triangle_scheme("sqrt3")?;
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
    // psi and its derivatives on 1/3n: the costliest part, once per rate for every valence.
    let bases = spec
        .rates
        .par_iter()
        .map(|&n| Sqrt3Basis::<f64>::new(&scheme, 3 * n, &kinds))
        .collect::<Result<Vec<_>, _>>()?;
    let valences = spec
        .valences
        .par_iter()
        .map(|&k| Sqrt3RegionStencils::<f64>::new(&scheme, k))
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
        scheme: SchemeId::Sqrt3,
        precision: spec.precision,
        corners: false,
    };
    let sections: Vec<Section> = sections.into_iter().flatten().collect();
    Ok(encode(meta, &sections)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;
    use table_format::{AlignedBytes, Table};

    /// A small f64 table holds, section by section, the exact path's weights (valences 3, 4
    /// and 6, where √3 is rational) within 1e-12, at the documented points; valence 6 holds
    /// region 0 only.
    #[test]
    fn a_small_table_holds_the_exact_stencils() {
        let spec = Sqrt3TableSpec {
            valences: vec![3, 4, 6],
            rates: vec![1, 2],
            precision: Precision::F64,
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
