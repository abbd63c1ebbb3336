//! The grids of √3's boundary patches ([`crate::scheme::sqrt3::boundary_patch`]), made when a
//! plan is built from the table's regular basis `psi` on the grid `1/3n` and Kobbelt's rules
//! (`schemes::sqrt3_boundary_surface`: by certified levels, the B-spline on the boundary). No
//! table bytes: the rules' rows are the subdivision matrix, and `psi` is the interior's.
//!
//! A patch's triangle is `c_0, c_1, c_2` in its sector's chart; its point `(u, v)` is the chart
//! point `x = c_0 + u (c_1 - c_0) + v (c_2 - c_0)`, with the grids' numerators over `d = 3n`
//! (primal points `(3i, 3j)`, centroids `(3i+1, 3j+1)` and `(3i+2, 3j+2)`), and
//! `d/du = D_{c_1 - c_0}`, `d/dv = D_{c_2 - c_0}` from the chart axes' derivatives. Off the
//! boundary these are the surface's derivatives. **On the boundary** (a primal point on a
//! boundary side, or the boundary vertex `V`) the derivative across does not exist in general,
//! so the rows there are tangent masks: `du` the derivative along the boundary (towards
//! `E_0`), `dv` the cross mask ([`BoundarySurface::cross_mask`]), a pair with the chart's
//! orientation, so `du x dv` is the normal.

use std::collections::HashMap;

use rayon::prelude::*;
use schemes::loop_regular::RegularDerivative;
use schemes::sqrt3_boundary::FanPoint;
use schemes::sqrt3_boundary_surface::{BoundarySurface, FanStencil};
use table_format::{PointSet, SectionKey, StencilKind};

use crate::scheme::sqrt3::boundary_patch::BoundaryPatch;
use crate::scheme::triangle::patch::TrianglePatch;
use crate::stencil_table::{RateBasis, StencilTable, TriangleStencils};
use crate::RuntimeError;

/// A √3 table with the grids of the boundary patches a plan reads: every `(patch, rate)` met,
/// made together (in parallel) when built; every other section is the table's.
#[derive(Debug)]
pub struct Sqrt3BoundaryStencils<'t> {
    table: &'t StencilTable,
    grids: HashMap<SectionKey, Box<[f32]>>,
}

impl<'t> Sqrt3BoundaryStencils<'t> {
    /// The grids of every boundary patch among `patches` at its rate in `rates`.
    pub fn new(
        table: &'t StencilTable,
        patches: &[TrianglePatch],
        rates: &[u32],
    ) -> Result<Self, RuntimeError> {
        // By fan and rate: one surface each, whose memo of the rules' rows its kinds share.
        let mut wanted: Vec<(u32, u32, BoundaryPatch)> = patches
            .iter()
            .zip(rates)
            .filter(|(p, _)| p.kind.boundary)
            .map(|(p, &n)| {
                let patch = BoundaryPatch::unpacked(p.kind.faces, p.kind.sector);
                (patch.faces, n, patch)
            })
            .collect();
        wanted.sort_unstable();
        wanted.dedup();
        let groups: Vec<&[(u32, u32, BoundaryPatch)]> =
            wanted.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)).collect();
        let made: Vec<Vec<Grid>> = groups
            .par_iter()
            .map(|group| fan_grids(table, group))
            .collect::<Result<_, _>>()?;
        Ok(Sqrt3BoundaryStencils {
            table,
            grids: made.into_iter().flatten().collect(),
        })
    }
}

impl TriangleStencils for Sqrt3BoundaryStencils<'_> {
    fn triangle_weights(&self, key: &SectionKey) -> Result<&[f32], RuntimeError> {
        if !key.boundary {
            return self.table.triangle_weights(key);
        }
        self.grids.get(key).map(|g| &**g).ok_or_else(|| {
            RuntimeError::Unsupported(format!(
                "{key}: a √3 boundary patch's grid that the plan did not make"
            ))
        })
    }
}

/// One made grid and its key.
type Grid = (SectionKey, Box<[f32]>);

/// The six grids (primal and dual, three kinds) of every patch of `group` (one fan, one rate).
fn fan_grids(
    table: &StencilTable,
    group: &[(u32, u32, BoundaryPatch)],
) -> Result<Vec<Grid>, RuntimeError> {
    let Some(&(faces, n, _)) = group.first() else {
        return Ok(Vec::new());
    };
    let basis: &RateBasis = table.regular_basis(n)?;
    let mut surface = if faces == 3 {
        BoundarySurface::strip(basis)
    } else {
        BoundarySurface::fan(faces, basis).map_err(|e| {
            RuntimeError::Unsupported(format!("√3 boundary patches of {faces} triangles: {e}"))
        })?
    };
    let mut out = Vec::with_capacity(6 * group.len());
    for &(_, _, patch) in group {
        out.extend(patch_grids(&mut surface, patch, n)?);
    }
    Ok(out)
}

/// The six grids (primal and dual, three kinds) of one boundary patch at rate `n`, on its fan's
/// `surface`.
fn patch_grids(
    surface: &mut BoundarySurface<&RateBasis>,
    patch: BoundaryPatch,
    n: u32,
) -> Result<Vec<Grid>, RuntimeError> {
    let refused = |e: schemes::sqrt3_boundary_surface::Refused| {
        RuntimeError::Unsupported(format!("√3 boundary patch {patch:?} at rate {n}: {e}"))
    };
    let layout = patch.layout();
    let column = |p: &FanPoint| layout.binary_search(p).ok();
    let k = layout.len();
    let d = 3 * i64::from(n);
    let sector = i64::from(patch.sector);
    let [c0, c1, c2] = patch.corners();
    let (e1, e2) = ((c1.0 - c0.0, c1.1 - c0.1), (c2.0 - c0.0, c2.1 - c0.1));
    let last = i64::from(patch.faces) - 1;
    // The boundary parameter of a chart point on the boundary (numerator over d), if it is.
    let on_boundary = |x: (i64, i64)| -> Option<i64> {
        if patch.is_strip() {
            (x.1 == 0).then_some(x.0)
        } else if x == (0, 0) {
            Some(0)
        } else if sector == 0 && x.1 == 0 {
            Some(x.0)
        } else if sector == last && x.0 == 0 {
            Some(-x.1)
        } else {
            None
        }
    };
    let key = patch.kind().ok_or_else(|| {
        RuntimeError::Unsupported(format!("√3 boundary patch {patch:?} has no table key"))
    })?;
    let mut out = Vec::with_capacity(6);
    for points in [PointSet::TrianglePrimal, PointSet::TriangleDual] {
        let params = grid_params(points, n);
        let mut rows = [
            vec![0.0f32; params.len() * k],
            vec![0.0f32; params.len() * k],
            vec![0.0f32; params.len() * k],
        ];
        for (i, &(p1, p2)) in params.iter().enumerate() {
            let x = (
                d * c0.0 + p1 * e1.0 + p2 * e2.0,
                d * c0.1 + p1 * e1.1 + p2 * e2.1,
            );
            let position = surface
                .stencil(sector, x, RegularDerivative::Position)
                .map_err(refused)?;
            let (du, dv) = match on_boundary(x) {
                Some(tau) => (
                    surface.boundary_tangent(tau),
                    surface.cross_mask(tau).map_err(refused)?,
                ),
                None => {
                    let u = surface
                        .stencil(sector, x, RegularDerivative::U)
                        .map_err(refused)?;
                    let v = surface
                        .stencil(sector, x, RegularDerivative::V)
                        .map_err(refused)?;
                    (along(&u, &v, e1), along(&u, &v, e2))
                }
            };
            for (grid, stencil) in rows.iter_mut().zip([&position, &du, &dv]) {
                for (p, &w) in stencil {
                    let c = column(p).ok_or_else(|| {
                        RuntimeError::Unsupported(format!(
                            "√3 boundary patch {patch:?} at rate {n} reads {p:?} beyond its layout"
                        ))
                    })?;
                    grid[i * k + c] = w as f32;
                }
            }
        }
        for (grid, kind) in rows.into_iter().zip([
            StencilKind::Position,
            StencilKind::DerivativeU,
            StencilKind::DerivativeV,
        ]) {
            out.push((key.section(kind, points, n), grid.into_boxed_slice()));
        }
    }
    Ok(out)
}

/// The derivative along the chart vector `e`: `e_1 d/dx_1 + e_2 d/dx_2`.
fn along(u: &FanStencil, v: &FanStencil, e: (i64, i64)) -> FanStencil {
    let mut out = FanStencil::new();
    for (stencil, f) in [(u, e.0), (v, e.1)] {
        if f != 0 {
            for (&p, &w) in stencil {
                *out.entry(p).or_insert(0.0) += f as f64 * w;
            }
        }
    }
    out
}

/// The numerators over `3n` of a triangle grid's points in its order
/// ([`crate::scheme::triangle::patch`]): primal `(i/n, j/n)` row by row; dual, row `j`
/// holding `up(0,j), down(0,j), .., up(n-1-j, j)`.
fn grid_params(points: PointSet, n: u32) -> Vec<(i64, i64)> {
    let n = i64::from(n);
    let mut out = Vec::new();
    for j in 0..=n {
        for i in 0..=n - j {
            match points {
                PointSet::TrianglePrimal => out.push((3 * i, 3 * j)),
                _ => {
                    if i + j < n {
                        out.push((3 * i + 1, 3 * j + 1));
                        if i + j + 1 < n {
                            out.push((3 * i + 2, 3 * j + 2));
                        }
                    }
                }
            }
        }
    }
    out
}
