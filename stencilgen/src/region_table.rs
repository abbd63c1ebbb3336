//! Region tables (`docs/table-format.md`, triangle point sets): the table builder the butterfly
//! and √3 share ([`crate::butterfly_table`], [`crate::sqrt3_table`]).
//!
//! Every region `r` of an interior vertex of valence `K` and rate `n` becomes six sections,
//! keyed `faces = K`, `sector = r`: positions, d/du and d/dv on the triangle primal grid
//! `(i/n, j/n)`, `i + j <= n`, and on the `n^2` centroids of its small triangles
//! ([`triangle_dual_points`]), in the region's frame and over its layout. Valence 6 is the
//! regular patch; only its region 0 is stored. The regular basis is solved once per rate on the
//! grid `1/3n` (primal points are `3i/3n`, centroids `(3i+1)/3n`) and shared by every valence.

use rayon::prelude::*;
use table_format::{
    encode, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::regular_patch::StencilKind;
use crate::triangle_patch::triangle_grid_points;
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::triangle_table::triangle_dual_points;
use crate::StencilError;

/// What to put in a region table.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionTableSpec {
    /// Interior valences (6 is the regular patch).
    pub valences: Vec<u32>,
    /// Grid rates.
    pub rates: Vec<u32>,
    /// Stored precision.
    pub precision: Precision,
}

/// The regions of one valence, evaluated in f64 with a regular basis of type `Basis`.
pub trait RegionStencilSet: Sync {
    /// The regular basis on one grid.
    type Basis: Sync + Send;
    /// The valence `K`.
    fn valence(&self) -> u32;
    /// The number of regions.
    fn region_count(&self) -> usize;
    /// Region `r`'s layout size.
    fn width(&self, r: usize) -> Result<usize, StencilError>;
    /// The `kind` stencil of region `r` at `point / basis rate`.
    fn stencil(
        &self,
        r: usize,
        basis: &Self::Basis,
        point: (i64, i64),
        kind: StencilKind,
    ) -> Result<Vec<f64>, StencilError>;
}

/// The three kinds, as the solver and the table name them.
pub const KINDS: [(StencilKind, TableKind); 3] = [
    (StencilKind::Position, TableKind::Position),
    (StencilKind::DerivativeU, TableKind::DerivativeU),
    (StencilKind::DerivativeV, TableKind::DerivativeV),
];

/// One table section: key, width, point-major weights.
type Section = (SectionKey, u32, Vec<f64>);

/// The primal points of rate `n` on the grid `1/3n`.
pub fn primal_points(n: u32) -> Vec<(i64, i64)> {
    triangle_grid_points(n)
        .into_iter()
        .map(|(i, j)| (3 * i, 3 * j))
        .collect()
}

/// The six sections of region `r` at rate `n` (`basis` on `1/3n`).
fn region_sections<R: RegionStencilSet>(
    regions: &R,
    r: usize,
    basis: &R::Basis,
    n: u32,
) -> Result<Vec<Section>, StencilError> {
    let width = regions.width(r)?;
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
                feature: table_format::Feature::None,
                faces: regions.valence(),
                sector: r as u32,
                n,
            };
            out.push((key, width as u32, weights));
        }
    }
    Ok(out)
}

/// Generate and encode the region table of `spec` for scheme `id`: `basis(d)` solves the
/// regular basis (all three kinds) on the grid `1/d`, `regions(K)` builds valence `K`'s regions.
pub fn build_region_table<R: RegionStencilSet + Send>(
    id: SchemeId,
    spec: &RegionTableSpec,
    basis: impl Fn(u32) -> Result<R::Basis, StencilError> + Sync,
    regions: impl Fn(u32) -> Result<R, StencilError> + Sync,
) -> Result<Vec<u8>, StencilError> {
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
    // The regular basis on 1/3n, the costliest part, once per rate for every valence.
    let bases = spec
        .rates
        .par_iter()
        .map(|&n| basis(3 * n))
        .collect::<Result<Vec<_>, _>>()?;
    let valences = spec
        .valences
        .par_iter()
        .map(|&k| regions(k))
        .collect::<Result<Vec<_>, _>>()?;
    let jobs: Vec<(usize, usize, usize)> = valences
        .iter()
        .enumerate()
        .flat_map(|(v, set)| {
            let count = if set.valence() == 6 {
                1
            } else {
                set.region_count()
            };
            (0..count).map(move |r| (v, r))
        })
        .flat_map(|(v, r)| (0..bases.len()).map(move |b| (v, r, b)))
        .collect();
    let sections = jobs
        .into_par_iter()
        .map(|(v, r, b)| region_sections(&valences[v], r, &bases[b], spec.rates[b]))
        .collect::<Result<Vec<_>, _>>()?;
    let meta = TableMeta {
        scheme: id,
        precision: spec.precision,
        corners: false,
    };
    let sections: Vec<Section> = sections.into_iter().flatten().collect();
    Ok(encode(meta, &sections)?)
}
