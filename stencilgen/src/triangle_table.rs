//! Loop stencil tables (`docs/table-format.md`, triangle point sets and "Compact Loop tables").
//!
//! Two layouts ([`TriangleLayout`]):
//!
//! * **Compact** (the default): the pieces of the scaling relation from which every grid
//!   stencil follows by substitution ([`crate::triangle_patch`]' module docs): per kind, Loop's
//!   regular basis `psi` (the quartic box spline, or its derivative) on the lattice `k/4`, the
//!   interpolation data of its quartic pieces ([`LoopRegularBasis::lattice_window`]); a marker
//!   per rate; per patch, its local subdivision matrix `A`, its three sub-triangle matrices `R_b`
//!   (12 level-1 points each) and its stencils at the vertex itself (the limit-position mask,
//!   solved as the fixed point of the patch's system, and the tangent masks of
//!   [`loop_ev_tangents`] or [`loop_boundary_tangents`]). In f64. The runtime expands the grids
//!   when a plan asks (`subtess::stencil_table`): `phi(x) = f phi(2x) A` while `u + v <= 1/2`,
//!   else `f sum_j psi(2x - j) R_b[j]`, `f = 1` for positions and 2 for derivatives, with the
//!   same operations in the same order as the grid system below, so the two layouts' grids
//!   are equal (measured: bit for bit; `runtime/tests/integration/compact_tables.rs`).
//! * **Grids**: each Loop patch (interior vertex of valence `v`, `v = 6` being the regular
//!   patch; each sector of a boundary vertex with `k` triangles, `k = 3` being the regular
//!   boundary) and rate `n` becomes six sections: positions, d/du and d/dv on the triangle
//!   primal grid `(i/n, j/n)`, `i + j <= n`, and on the `n^2` centroids of the grid's small
//!   triangles (the dual points of section 5.5), in the order [`triangle_dual_points`] gives.
//!   Every point's weights come from the scaling-relation grid system of
//!   [`crate::triangle_patch`] (the centroids live on the grid `1/3n`); the tangent rows at the
//!   vertex itself are [`loop_ev_tangents`]' or [`loop_boundary_tangents`]' masks.
//!
//! The default table is compact and generated from the f64 path, which agrees with exact
//! arithmetic within 1e-12 (checked by the tests against the exact path).

use num_rational::BigRational;
use rayon::prelude::*;
use schemes::triangle_local::TriangleLocalMatrices;
use schemes::TriangleScheme;
use table_format::{
    encode, PointSet, Precision, SchemeId, SectionKey, StencilKind as TableKind, TableMeta,
};

use crate::loop_basis::LoopRegularBasis;
use crate::regular_patch::StencilKind;
use crate::triangle_boundary::loop_boundary_tangents;
use crate::triangle_patch::{
    loop_ev_tangents, patch_stencils_at, triangle_grid_points, triangle_scheme,
};
use crate::triangle_system::MAX_TRIANGLE_RATE;
use crate::{Scalar, StencilError};

/// What to put in a triangle-scheme table.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleTableSpec {
    /// The scheme (Loop: the only one with exact local matrices).
    pub scheme: TriangleScheme,
    /// Interior valences (6 is the regular patch).
    pub valences: Vec<u32>,
    /// Triangle counts of the boundary vertices (3 is the regular boundary; every sector).
    pub boundary_faces: Vec<u32>,
    /// Grid rates.
    pub rates: Vec<u32>,
    /// Stored precision ([`TriangleLayout::Compact`] stores f64 only).
    pub precision: Precision,
    /// What the sections hold.
    pub layout: TriangleLayout,
}

/// What a Loop table stores (module docs). Butterfly and √3 tables choose between the same two
/// with [`crate::region_table::RegionLayout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleLayout {
    /// The scaling relation's pieces; the reader expands the grids.
    Compact,
    /// Every grid point's stencil.
    Grids,
}

impl TriangleTableSpec {
    /// The Loop table `subtess` embeds: interior valences 3..=12, boundary vertices with
    /// 1..=6 triangles, n = 1..=24, compact (f64).
    pub fn default_loop() -> Result<Self, StencilError> {
        Ok(TriangleTableSpec {
            scheme: triangle_scheme("loop")?,
            valences: (3..=12).collect(),
            boundary_faces: (1..=6).collect(),
            rates: (1..=MAX_TRIANGLE_RATE).collect(),
            precision: Precision::F64,
            layout: TriangleLayout::Compact,
        })
    }
}

/// The centroids of the `n^2` small triangles of the rate-`n` grid, as numerators over `3n`,
/// in table order: row `j` outer, each row `up(0,j), down(0,j), up(1,j), .., up(n-1-j, j)`
/// (`up(i,j) = (i,j),(i+1,j),(i,j+1)`, `down(i,j) = (i+1,j),(i,j+1),(i+1,j+1)`).
pub fn triangle_dual_points(n: u32) -> Vec<(i64, i64)> {
    let n = i64::from(n);
    let mut out = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n - j {
            out.push((3 * i + 1, 3 * j + 1));
            if i + j + 2 <= n {
                out.push((3 * i + 2, 3 * j + 2));
            }
        }
    }
    out
}

/// One table section: key, width, point-major weights.
type Section = (SectionKey, u32, Vec<f64>);

/// The sections of one patch at one rate and kind: the primal grid and the dual points.
fn patch_sections(
    matrices: &TriangleLocalMatrices,
    basis: &LoopRegularBasis,
    key: SectionKey,
    vertex_tangent: Option<&[f64]>,
) -> Result<[Section; 2], StencilError> {
    let n = key.n;
    let width = matrices.size();
    let grid = |points: &[(i64, i64)], d: u32| -> Result<Vec<f64>, StencilError> {
        let solved = patch_stencils_at::<f64>(matrices, basis, points, d)?;
        let mut rows = solved.stencils.iter();
        let mut out = Vec::with_capacity(points.len() * width);
        for &p in points {
            if p == (0, 0) && basis.kind != StencilKind::Position {
                let t = vertex_tangent.ok_or_else(|| StencilError::Inconsistent {
                    scheme: matrices.scheme.clone(),
                    n,
                    detail: "a derivative section without the vertex's tangent mask".to_owned(),
                })?;
                out.extend_from_slice(t);
            } else if let Some(row) = rows.next() {
                out.extend(row.iter().map(Scalar::to_f64));
            }
        }
        Ok(out)
    };
    let primal = grid(&triangle_grid_points(n), n)?;
    let dual = grid(&triangle_dual_points(n), 3 * n)?;
    Ok([
        (
            SectionKey {
                points: PointSet::TrianglePrimal,
                ..key
            },
            width as u32,
            primal,
        ),
        (
            SectionKey {
                points: PointSet::TriangleDual,
                ..key
            },
            width as u32,
            dual,
        ),
    ])
}

/// A section of one patch's pieces (`n = 0`): `rows x width` weights.
fn piece(
    kind: TableKind,
    points: PointSet,
    (boundary, faces, sector): (bool, u32, u32),
    width: usize,
    weights: Vec<f64>,
) -> Section {
    let key = SectionKey {
        kind,
        points,
        boundary,
        feature: table_format::Feature::None,
        faces,
        sector,
        n: 0,
    };
    (key, width as u32, weights)
}

/// The compact layout's sections (module docs): per kind the Loop basis's rate-4 lattice
/// values, per rate a marker, per patch `A`, the sub-triangle matrices and the three vertex
/// masks.
fn compact_sections(
    bases: &[LoopRegularBasis],
    kinds: &[(StencilKind, TableKind)],
    patches: &[Patch],
    rates: &[u32],
) -> Result<Vec<Section>, StencilError> {
    let mut out = Vec::new();
    for (basis, &(_, kind)) in bases.iter().zip(kinds) {
        let (width, values) = basis.lattice_window();
        let key = SectionKey {
            kind,
            points: PointSet::LoopBasis,
            boundary: false,
            feature: table_format::Feature::None,
            faces: 0,
            sector: 0,
            n: LOOP_BASIS_LATTICE,
        };
        out.push((key, width, values));
    }
    for &n in rates {
        let key = SectionKey {
            kind: TableKind::Position,
            points: PointSet::TriangleRate,
            boundary: false,
            feature: table_format::Feature::None,
            faces: 0,
            sector: 0,
            n,
        };
        out.push((key, 0, Vec::new()));
    }
    let to_f64 = |rows: &[Vec<BigRational>]| -> Vec<f64> {
        rows.iter().flatten().map(Scalar::to_f64).collect()
    };
    for (id, matrices, (du, dv)) in patches {
        let k = matrices.size();
        // The limit-position mask: the fixed point phi(0) = phi(0) A of the patch's system,
        // solved as the grid layout solves it (the same block at every rate).
        let vertex = patch_stencils_at::<f64>(matrices, &bases[0], &[(0, 0)], 1)?;
        let position =
            vertex
                .stencils
                .into_iter()
                .next()
                .ok_or_else(|| StencilError::Inconsistent {
                    scheme: matrices.scheme.clone(),
                    n: 1,
                    detail: "the patch system has no stencil at the vertex".to_owned(),
                })?;
        let sub_triangles: Vec<Vec<BigRational>> = matrices
            .sub_triangles
            .iter()
            .flat_map(|sub| sub.rows.iter().cloned())
            .collect();
        out.push(piece(
            TableKind::Position,
            PointSet::Subdivision,
            *id,
            k,
            to_f64(&matrices.a),
        ));
        out.push(piece(
            TableKind::Position,
            PointSet::SubTriangles,
            *id,
            k,
            to_f64(&sub_triangles),
        ));
        for (kind, mask) in [
            (TableKind::Position, position),
            (TableKind::DerivativeU, du.clone()),
            (TableKind::DerivativeV, dv.clone()),
        ] {
            out.push(piece(kind, PointSet::VertexMask, *id, k, mask));
        }
    }
    Ok(out)
}

/// The denominator of the lattice the Loop basis's pieces are stored on (its degree).
const LOOP_BASIS_LATTICE: u32 = 4;

/// One patch: `(boundary, faces, sector)`, the local matrices, the tangent masks at the vertex.
type Patch = (
    (bool, u32, u32),
    TriangleLocalMatrices,
    (Vec<f64>, Vec<f64>),
);

/// Generate and encode the table of `spec`.
pub fn build_triangle_table(spec: &TriangleTableSpec) -> Result<Vec<u8>, StencilError> {
    let scheme_id = SchemeId::from_name(spec.scheme.name)
        .filter(|id| id.is_triangle())
        .ok_or_else(|| StencilError::UnsupportedScheme {
            scheme: spec.scheme.name.to_owned(),
            reason: "the table format has no triangle-scheme id for it (only loop has exact local matrices)".to_owned(),
        })?;
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
    if spec.layout == TriangleLayout::Compact && spec.precision != Precision::F64 {
        return Err(StencilError::UnsupportedScheme {
            scheme: spec.scheme.name.to_owned(),
            reason: "compact tables store f64 (their pieces expand to the f32 grids within 1 ulp \
                     only from f64); write f32 grids with the grid layout"
                .to_owned(),
        });
    }
    let kinds = [
        (StencilKind::Position, TableKind::Position),
        (StencilKind::DerivativeU, TableKind::DerivativeU),
        (StencilKind::DerivativeV, TableKind::DerivativeV),
    ];
    let bases = kinds
        .iter()
        .map(|&(kind, _)| LoopRegularBasis::new(&spec.scheme, kind))
        .collect::<Result<Vec<_>, _>>()?;
    let mut patches: Vec<Patch> = Vec::new();
    for &v in &spec.valences {
        let m = TriangleLocalMatrices::new(&spec.scheme, v)?;
        let t = loop_ev_tangents(&m)?;
        patches.push(((false, v, 0), m, (t.du, t.dv)));
    }
    for &faces in &spec.boundary_faces {
        for sector in 0..faces {
            let m = TriangleLocalMatrices::boundary(&spec.scheme, faces, sector)?;
            let t = loop_boundary_tangents(&m)?;
            patches.push(((true, faces, sector), m, (t.du, t.dv)));
        }
    }
    let meta = TableMeta {
        scheme: scheme_id,
        precision: spec.precision,
        corners: false,
    };
    if spec.layout == TriangleLayout::Compact {
        return Ok(encode(
            meta,
            &compact_sections(&bases, &kinds, &patches, &spec.rates)?,
        )?);
    }
    let jobs: Vec<(usize, usize, u32)> = (0..patches.len())
        .flat_map(|p| (0..kinds.len()).map(move |k| (p, k)))
        .flat_map(|(p, k)| spec.rates.iter().map(move |&n| (p, k, n)))
        .collect();
    let sections = jobs
        .into_par_iter()
        .map(|(p, k, n)| {
            let ((boundary, faces, sector), matrices, (du, dv)) = &patches[p];
            let tangent = match kinds[k].0 {
                StencilKind::Position => None,
                StencilKind::DerivativeU => Some(du.as_slice()),
                StencilKind::DerivativeV => Some(dv.as_slice()),
            };
            let key = SectionKey {
                kind: kinds[k].1,
                points: PointSet::TrianglePrimal,
                boundary: *boundary,
                feature: table_format::Feature::None,
                faces: *faces,
                sector: *sector,
                n,
            };
            patch_sections(matrices, &bases[k], key, tangent)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let sections: Vec<Section> = sections.into_iter().flatten().collect();
    Ok(encode(meta, &sections)?)
}

/// The Loop table `subtess` embeds ([`TriangleTableSpec::default_loop`]), encoded
/// (deterministic: the same bytes on every run).
pub fn default_loop_table() -> Result<Vec<u8>, StencilError> {
    build_triangle_table(&TriangleTableSpec::default_loop()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_points_are_the_centroids_in_zigzag_rows() {
        for n in 1..=9u32 {
            let points = triangle_dual_points(n);
            assert_eq!(points.len() as u32, n * n);
            let ni = i64::from(n);
            // The first 2n - 1 are the zigzag along v = 0, alternating up and down.
            for (t, &(x, y)) in points[..(2 * n - 1) as usize].iter().enumerate() {
                let t = t as i64;
                let expected = if t % 2 == 0 {
                    (3 * (t / 2) + 1, 1)
                } else {
                    (3 * (t / 2) + 2, 2)
                };
                assert_eq!((x, y), expected, "n = {n}");
            }
            // All distinct, strictly inside the patch.
            let mut sorted = points.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), points.len());
            assert!(points
                .iter()
                .all(|&(x, y)| x > 0 && y > 0 && x + y < 3 * ni));
        }
    }
}
