//! Stencil sets as versioned binary tables (`docs/table-format.md`).
//!
//! Each patch stencil grid becomes two sections, its primal and its dual points, of `K`
//! weights per point. The default table (what `subtess` embeds) is Catmull–Clark, interior
//! valences 3..=8 and boundary vertices with 1..=6 faces ("edge only"), n = 1..=24, positions
//! and both derivatives, in f32, from the f64 path (which agrees with exact arithmetic within
//! 1e-12, far below f32 resolution); `--exact` generates from exact rationals instead.

use num_rational::BigRational;
use schemes::QuadScheme;
use table_format::{
    encode, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::ev_tangents::ev_tangents;
use crate::extraordinary_patch::LocalMatrices;
use crate::patch_stencils::{quad_scheme, PatchStencils};
use crate::regular_patch::StencilKind;
use crate::stencil_set::{stencil_set_with_progress, StencilSetSpec};
use crate::{Scalar, StencilError};

/// What to put in a table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableSpec {
    /// The scheme.
    pub scheme: QuadScheme,
    /// Patches and rates.
    pub set: StencilSetSpec,
    /// Stored precision.
    pub precision: Precision,
    /// Generate from exact rationals (slower) instead of the f64 path.
    pub exact: bool,
}

impl TableSpec {
    /// The default table `subtess` embeds.
    pub fn default_catmull_clark() -> Result<Self, StencilError> {
        let scheme = quad_scheme("catmull-clark")?;
        Ok(TableSpec {
            scheme,
            set: StencilSetSpec::default_catmull_clark(),
            precision: Precision::F32,
            exact: false,
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
    let sections = if spec.exact {
        sections::<BigRational>(spec, progress)?
    } else {
        sections::<f64>(spec, progress)?
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
                faces: grid.neighbourhood.faces,
                sector: grid.sector,
                n: grid.n,
            };
            out.push((key, width as u32, rows[range].concat()));
        }
    }
    Ok(out)
}
