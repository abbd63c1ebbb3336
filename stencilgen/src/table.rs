//! Stencil sets as versioned binary tables (`docs/table-format.md`).
//!
//! Two layouts ([`QuadLayout`]):
//!
//! * **Compact** (the default): the pieces of the scaling relation from which every grid
//!   stencil follows by substitution (`crate::patch_stencils`' module docs): per rate, the
//!   regular curve basis at `t/n` (solved from the curve's own scaling relation); per patch,
//!   its local subdivision matrix `A`, its three sub-patch matrices `R_b` and its stencils at
//!   the vertex itself (the limit-position mask, solved as the one fixed point of the patch's
//!   system, and the tangent masks of [`ev_tangents`]). In f64. The runtime expands the grids
//!   when it plans (`subtess::stencil_table`); they equal the grids of the other layout to
//!   1 ulp of f32 (`runtime/tests/integration/compact_tables.rs`).
//! * **Grids**: each patch stencil grid as two sections, its primal and its dual points, of
//!   `K` weights per point, solved on the grid (the whole system of `crate::patch_stencils`).
//!
//! The default table (what `subtess` embeds) is Catmull–Clark, interior valences 3..=8, darts of
//! valences 3..=8 (every sector) and boundary vertices with 1..=6 faces ("edge only"),
//! n = 1..=24, compact, from the f64 path
//! (which agrees with exact arithmetic within 1e-12); `--exact` solves in exact rationals
//! instead.

use num_rational::BigRational;
use schemes::QuadScheme;
use table_format::{
    encode, Feature, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::ev_tangents::ev_tangents;
use crate::extraordinary_patch::{LocalMatrices, Neighbourhood};
use crate::patch_stencils::{patch_stencils_with, quad_scheme, regular_curve, PatchStencils};
use crate::regular_patch::{RegularBasis, StencilKind};
use crate::stencil_set::{stencil_set_with_progress, StencilSetSpec};
use crate::{Scalar, StencilError};

/// What to put in a table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableSpec {
    /// The scheme.
    pub scheme: QuadScheme,
    /// Patches and rates.
    pub set: StencilSetSpec,
    /// Stored precision ([`QuadLayout::Compact`] stores f64 only).
    pub precision: Precision,
    /// Generate from exact rationals (slower) instead of the f64 path.
    pub exact: bool,
    /// What the sections hold.
    pub layout: QuadLayout,
}

/// What a quad scheme's table stores (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuadLayout {
    /// The scaling relation's pieces; the reader expands the grids.
    Compact,
    /// Every grid point's stencil.
    Grids,
}

impl TableSpec {
    /// The default table `subtess` embeds.
    pub fn default_catmull_clark() -> Result<Self, StencilError> {
        let scheme = quad_scheme("catmull-clark")?;
        Ok(TableSpec {
            scheme,
            set: StencilSetSpec::default_catmull_clark(),
            precision: Precision::F64,
            exact: false,
            layout: QuadLayout::Compact,
        })
    }
}

impl TableSpec {
    /// The pinned-corner companion of the default table: only the one-face boundary vertex in
    /// "edge and corner" mode (OpenSubdiv's `interpolateboundary 1`), every default rate. Every
    /// other patch is the same in both modes, so the runtime lays this small table over the
    /// default one for meshes that pin their corners.
    pub fn default_corners() -> Result<Self, StencilError> {
        let mut spec = TableSpec::default_catmull_clark()?;
        spec.set.valences = Vec::new();
        spec.set.darts = Vec::new();
        spec.set.boundary_faces = vec![1];
        spec.set.boundary_mode = schemes::BoundaryMode::EdgeAndCorner;
        Ok(spec)
    }
}

/// Generate and encode the table of `spec`, reporting `progress(done, total)` grids.
pub fn build_table(
    spec: &TableSpec,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<u8>, StencilError> {
    let scheme_id =
        SchemeId::from_name(spec.scheme.name).ok_or_else(|| StencilError::UnsupportedScheme {
            scheme: spec.scheme.name.to_owned(),
            reason: "the table format has no id for it".to_owned(),
        })?;
    if spec.layout == QuadLayout::Compact && spec.precision != Precision::F64 {
        return Err(StencilError::UnsupportedScheme {
            scheme: spec.scheme.name.to_owned(),
            reason: "compact tables store f64 (their pieces expand to the f32 grids within 1 ulp \
                     only from f64); write f32 grids with the grid layout"
                .to_owned(),
        });
    }
    let sections = match (spec.layout, spec.exact) {
        (QuadLayout::Compact, true) => compact_sections::<BigRational>(spec, progress)?,
        (QuadLayout::Compact, false) => compact_sections::<f64>(spec, progress)?,
        (QuadLayout::Grids, true) => sections::<BigRational>(spec, progress)?,
        (QuadLayout::Grids, false) => sections::<f64>(spec, progress)?,
    };
    let meta = TableMeta {
        scheme: scheme_id,
        precision: spec.precision,
        corners: spec.set.boundary_mode == schemes::BoundaryMode::EdgeAndCorner,
    };
    Ok(encode(meta, &sections)?)
}

/// The default table's bytes (deterministic: the same bytes on every run).
pub fn default_table() -> Result<Vec<u8>, StencilError> {
    build_table(&TableSpec::default_catmull_clark()?, &|_, _| {})
}

/// The embedded pinned-corner companion table ([`TableSpec::default_corners`]), encoded.
pub fn default_corner_table() -> Result<Vec<u8>, StencilError> {
    build_table(&TableSpec::default_corners()?, &|_, _| {})
}

type Section = (SectionKey, u32, Vec<f64>);

/// The section key's sharp feature of a neighbourhood.
fn feature(nb: Neighbourhood) -> Feature {
    if nb.dart {
        Feature::Dart
    } else {
        Feature::None
    }
}

/// The compact layout's sections (module docs), reporting `progress(done, total)` over rates
/// and patches.
fn compact_sections<S: Scalar + Send + Sync>(
    spec: &TableSpec,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<Section>, StencilError> {
    let curve = regular_curve(&spec.scheme)?;
    let patches = spec.set.patches();
    let total = spec.set.rates.len() + patches.len();
    let mut out = Vec::new();
    let key = |kind, points, nb: Option<Neighbourhood>, sector, n| SectionKey {
        kind,
        points,
        boundary: nb.is_some_and(|nb| nb.boundary.is_some()),
        feature: nb.map_or(Feature::None, feature),
        faces: nb.map_or(0, |nb| nb.faces),
        sector,
        n,
    };
    for (done, &n) in spec.set.rates.iter().enumerate() {
        let basis = RegularBasis::<S>::new(&curve, n)?;
        for (kind, derivative) in [(TableKind::Position, false), (TableKind::DerivativeU, true)] {
            let rows: Vec<f64> = (0..=i64::from(n))
                .flat_map(|t| basis.axis_weights(t, derivative))
                .map(|w| w.to_f64())
                .collect();
            out.push((key(kind, PointSet::CurveBasis, None, 0, n), 4, rows));
        }
        progress(done + 1, total);
    }
    // The vertex's limit-position mask is the fixed point of any rate's system; rate 1's is
    // the smallest.
    let basis = RegularBasis::<S>::new(&curve, 1)?;
    let to_f64 = |rows: &[Vec<BigRational>]| -> Vec<f64> {
        rows.iter()
            .flatten()
            .map(<f64 as Scalar>::from_rational)
            .collect()
    };
    for (done, &(nb, sector)) in patches.iter().enumerate() {
        let matrices = LocalMatrices::new(&spec.scheme, nb, sector)?;
        let width = matrices.size() as u32;
        let at = |kind, points| key(kind, points, Some(nb), sector, 0);
        let position = patch_stencils_with(&spec.scheme, &matrices, &basis, StencilKind::Position)?;
        let limit = position
            .stencils
            .first()
            .cloned()
            .flatten()
            .ok_or_else(|| StencilError::UnsupportedScheme {
                scheme: spec.scheme.name.to_owned(),
                reason: format!("no limit position at the vertex of {}", matrices.describe()),
            })?;
        let tangents = ev_tangents(&matrices)?;
        out.push((
            at(TableKind::Position, PointSet::VertexMask),
            width,
            limit.iter().map(Scalar::to_f64).collect(),
        ));
        out.push((
            at(TableKind::DerivativeU, PointSet::VertexMask),
            width,
            tangents.du,
        ));
        out.push((
            at(TableKind::DerivativeV, PointSet::VertexMask),
            width,
            tangents.dv,
        ));
        out.push((
            at(TableKind::Position, PointSet::Subdivision),
            width,
            to_f64(&matrices.a),
        ));
        out.push((
            at(TableKind::Position, PointSet::SubPatches),
            width,
            to_f64(&matrices.sub_patches.concat()),
        ));
        progress(spec.set.rates.len() + done + 1, total);
    }
    Ok(out)
}

fn sections<S: Scalar + Send + Sync>(
    spec: &TableSpec,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<Section>, StencilError> {
    let grids: Vec<PatchStencils<S>> =
        stencil_set_with_progress(&spec.scheme, &spec.set, progress)?;
    let mut out = Vec::with_capacity(2 * grids.len());
    for grid in grids {
        let kind = match grid.kind {
            StencilKind::Position => TableKind::Position,
            StencilKind::DerivativeU => TableKind::DerivativeU,
            StencilKind::DerivativeV => TableKind::DerivativeV,
        };
        // Tangents at the vertex itself are irrational: exact grids leave them out, f64 fills them.
        let vertex_tangent = match (grid.kind, grid.stencils.first()) {
            (StencilKind::Position, _) | (_, Some(Some(_))) => None,
            _ => {
                let t = ev_tangents(&LocalMatrices::new(
                    &spec.scheme,
                    grid.neighbourhood,
                    grid.sector,
                )?)?;
                Some(if grid.kind == StencilKind::DerivativeU {
                    t.du
                } else {
                    t.dv
                })
            }
        };
        let width = grid
            .stencils
            .iter()
            .flatten()
            .map(Vec::len)
            .next()
            .unwrap_or(0);
        let rows: Vec<Vec<f64>> = grid
            .stencils
            .iter()
            .map(|s| match s {
                Some(w) => w.iter().map(Scalar::to_f64).collect(),
                None => vertex_tangent
                    .clone()
                    .unwrap_or_else(|| vec![f64::NAN; width]),
            })
            .collect();
        let primal = ((grid.n + 1) * (grid.n + 1)) as usize;
        for (points, range) in [
            (PointSet::Primal, 0..primal),
            (PointSet::Dual, primal..rows.len()),
        ] {
            let key = SectionKey {
                kind,
                points,
                boundary: grid.neighbourhood.boundary.is_some(),
                feature: feature(grid.neighbourhood),
                faces: grid.neighbourhood.faces,
                sector: grid.sector,
                n: grid.n,
            };
            out.push((key, width as u32, rows[range].concat()));
        }
    }
    Ok(out)
}
