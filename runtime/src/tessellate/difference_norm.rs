//! The norm of the stencils of a table face's deviations: what lets a face around an
//! extraordinary vertex keep its tolerance rate while its neighbourhood bends a little
//! ([`super::rate_memory`]).
//!
//! At a sample `s` outside the corner squares of corners without a regular chart, the selection
//! measures `|S_f(s) - x_s|`, `x_s` the point of `L_{f,n}` at the sample's own parameters
//! ([`super::rates::ChartBound`]). Both ends are affine combinations of the isolated control
//! points, so the difference is one stencil `c_s` over them: the sample's table stencil less the
//! weighted stencils of the three dual points (or boundary-curve points) that `x_s` combines.
//! If every control point lies within `delta` of its image under an affine map (a rigid one, or
//! [`super::rate_memory`]'s fit), the difference moves by at most `|c_s|_1 delta` from the map's
//! image of it.
//!
//! `c_s` annihilates every control net whose limit surface is affine in the face's parameters
//! over the part of `L_{f,n}` that `x_s` reads, so `|c_s|_1` is second order in `1/n` as for a
//! regular grid ([`super::rates::chart_norm`]), where the table's stencils are smooth
//! functions of the parameters: everywhere but at an extraordinary vertex, whose corner square
//! the bound leaves to the two-ended norm `C_f`. On the isolated Spot the faces around its
//! extraordinary vertices come out as the regular grid's: 0.18 at rate 2, 0.081-0.087 at 3,
//! 0.047-0.052 at 4 (docs/benchmarks.md), where `C_f` is about 2.1.

use std::collections::HashMap;
use std::sync::Mutex;

use table_format::PointSet;

use crate::mesh::topology::Mesh;
use crate::scheme::patch::{FacePatch, PatchKind};
use crate::stencil_table::StencilTable;
use crate::tessellate::rates::{
    across, beyond_index, chart_corner, chart_corner_terms, corner_square, curve_index, grid_row,
    grid_side, linear_terms, placed_axes, position_weights, ChartCorner, Vertex, SELECTION_GRID,
};
use crate::RuntimeError;

/// The largest `|c_s|_1` over face `f`'s samples at rate `n` outside the corner squares of
/// corners without a chart ([`chart_corner`]), plus `2^-20` for the `f32` rounding of the
/// stencils (a regular patch's samples are the bicubic B-spline in closed form, whose table
/// stencils are rounded to within `2^-24` of weights of norm one). `None` where a point `x_s`
/// reads is not a table face's (faces sampled adaptively, listed ascending in `adaptive`, and
/// holes).
///
/// A face whose neighbourhood has the shape of one measured before ([`Norms`]) takes that
/// norm.
pub(crate) fn difference_norm(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    adaptive: &[usize],
    f: usize,
    n: u32,
    norms: &Norms,
) -> Result<Option<f64>, RuntimeError> {
    let m = n as usize;
    let charts: [Option<ChartCorner>; 4] =
        std::array::from_fn(|corner| chart_corner(mesh, f, corner, m));
    let sides: [Option<(usize, usize)>; 4] = std::array::from_fn(|side| across(mesh, f, side));
    // Every face whose dual points `x_s` reads, each once, in the order of their roles: the
    // face, those across its sides, the charts' faces; all from the table.
    let mut read: Vec<usize> = vec![f];
    let roles = sides.iter().flatten().map(|&(g, _)| g).chain(
        charts
            .iter()
            .flatten()
            .flat_map(|c| c.points.map(|(g, _)| g)),
    );
    for g in roles {
        if !read.contains(&g) {
            read.push(g);
        }
    }
    let table_face = |g: usize| {
        g < patches.len()
            && !mesh.holes.get(g).copied().unwrap_or(true)
            && adaptive.binary_search(&g).is_err()
    };
    if !read.iter().all(|&g| table_face(g)) {
        return Ok(None);
    }
    let mut stencil = Stencil::default();
    let samples = [
        stencil.section(table, &patches[f], PointSet::Primal, SELECTION_GRID)?,
        stencil.section(table, &patches[f], PointSet::Dual, SELECTION_GRID)?,
    ];
    let duals = read
        .iter()
        .map(|&g| Ok((g, stencil.section(table, &patches[g], PointSet::Dual, n)?)))
        .collect::<Result<Vec<_>, RuntimeError>>()?;
    let curves = match sides.iter().any(Option::is_none) {
        true => Some(stencil.section(table, &patches[f], PointSet::Primal, n)?),
        false => None,
    };
    // What the sums below read, faces by their roles: all their value depends on.
    let role = |g: usize| read.iter().position(|&e| e == g);
    let shape = Shape {
        n,
        faces: duals
            .iter()
            .map(|(g, rows)| (patches[*g].kind, rows.corner, rows.slots.clone()))
            .collect(),
        sides: sides.map(|side| side.map(|(g, other)| (role(g), other))),
        charts: charts
            .map(|chart| chart.map(|c| (c.through_face, c.points.map(|(g, ij)| (role(g), ij))))),
    };
    if let Some(&norm) = norms.lock().get(&shape) {
        return Ok(Some(norm));
    }
    let h = 0.5 / m as f64;
    let mut largest = 0.0f64;
    for (sample_rows, axis) in samples.iter().zip(placed_axes(m)?) {
        for (j, v) in axis.places.iter().enumerate() {
            for (i, u) in axis.places.iter().enumerate() {
                let terms: [(f64, Source); 3] = match u.corner_with(v) {
                    Some(corner) => {
                        let (Some(chart), Some((_, a, b))) =
                            (charts[corner], corner_square(u.t, v.t, m))
                        else {
                            continue;
                        };
                        chart_corner_terms(a, b, h, chart.through_face)
                            .map(|(w, k)| (w, Source::Dual(chart.points[usize::from(k)])))
                    }
                    None => linear_terms(u, v, m, |side| Ok(sides[side].is_none()))?.map(
                        |(w, vertex)| {
                            let source = match vertex {
                                Vertex::Dual(i, j) => Source::Dual((f, (i, j))),
                                Vertex::Beyond(side, t) => match sides[side] {
                                    Some((g, other)) => {
                                        Source::Dual((g, beyond_index(other, t, m)))
                                    }
                                    None => Source::Curve(curve_index(side, t, m)),
                                },
                            };
                            (w, source)
                        },
                    ),
                };
                stencil.add(1.0, sample_rows, (i, j));
                for (w, source) in terms {
                    let (rows, ij) = match source {
                        Source::Dual((g, ij)) => (duals.iter().find(|(e, _)| *e == g), ij),
                        Source::Curve(ij) => (None, ij),
                    };
                    match (source, rows, &curves) {
                        (Source::Dual(_), Some((_, rows)), _) => stencil.add(-w, rows, ij),
                        (Source::Curve(_), _, Some(rows)) => stencil.add(-w, rows, ij),
                        // Read above: every source has its rows.
                        _ => return Ok(None),
                    }
                }
                largest = largest.max(stencil.take_norm());
            }
        }
    }
    let norm = largest + 2f64.powi(-20);
    norms.lock().insert(shape, norm);
    Ok(Some(norm))
}

/// The norms made so far, by the shape of what they read ([`Shape`]): the faces around
/// extraordinary vertices of one valence are mostly alike, so a mesh has far fewer shapes
/// than faces.
#[derive(Debug, Default)]
pub(crate) struct Norms(Mutex<HashMap<Shape, f64>>);

impl Norms {
    /// How many shapes were measured.
    #[cfg(all(test, feature = "catmull-clark"))]
    pub(crate) fn shapes(&self) -> usize {
        self.lock().len()
    }

    /// The map, whether or not another thread panicked holding it (a norm is inserted whole).
    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<Shape, f64>> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// Everything a face's norm depends on at rate `n`, its faces numbered by role (the face, then
/// those across its sides, then its charts' faces, each once): per face its patch kind, the
/// corner its patch starts at and where its points lie among all those read (the points the
/// faces share); per side the face across and its side there, or a boundary curve; per corner
/// its chart.
#[derive(Debug, PartialEq, Eq, Hash)]
pub(crate) struct Shape {
    n: u32,
    faces: Vec<(PatchKind, usize, Vec<usize>)>,
    sides: [Option<(Option<usize>, usize)>; 4],
    #[allow(clippy::type_complexity)]
    charts: [Option<(bool, [(Option<usize>, (usize, usize)); 4])>; 4],
}

/// A vertex of `L_{f,n}` that `x_s` reads: dual point `(i, j)` of a face (its own indices), or
/// primal point `(i, j)` of the face itself (a boundary curve's).
#[derive(Clone, Copy)]
enum Source {
    Dual((usize, (usize, usize))),
    Curve((usize, usize)),
}

/// A table section of one face's position stencils, and where each of its patch's points
/// lies in a [`Stencil`].
struct Rows<'t> {
    weights: &'t [f32],
    side: usize,
    corner: usize,
    slots: Vec<usize>,
}

/// A stencil over the control points that the faces read, summed from table rows.
#[derive(Default)]
struct Stencil {
    /// The control points seen, and the stencil's weight on each.
    points: Vec<u32>,
    weights: Vec<f64>,
}

impl Stencil {
    /// `patch`'s grid `set` at rate `n`, its points given their slots here.
    fn section<'t>(
        &mut self,
        table: &'t StencilTable,
        patch: &FacePatch,
        set: PointSet,
        n: u32,
    ) -> Result<Rows<'t>, RuntimeError> {
        let side = grid_side(set == PointSet::Primal, n) as usize;
        let weights = position_weights(table, patch, set, n, side)?;
        let slots = patch
            .points
            .iter()
            .map(|&p| {
                self.points.iter().position(|&q| q == p).unwrap_or_else(|| {
                    self.points.push(p);
                    self.weights.push(0.0);
                    self.points.len() - 1
                })
            })
            .collect();
        Ok(Rows {
            weights,
            side,
            corner: patch.corner,
            slots,
        })
    }

    /// Add `w` times the stencil of point `ij` (the face's own indices) of `rows`.
    fn add(&mut self, w: f64, rows: &Rows, ij: (usize, usize)) {
        let row = grid_row(rows.weights, rows.side, rows.corner, rows.slots.len(), ij);
        for (&x, &slot) in row.iter().zip(&rows.slots) {
            if let Some(c) = self.weights.get_mut(slot) {
                *c += w * f64::from(x);
            }
        }
    }

    /// `|c|_1` of the stencil summed so far, which starts again from zero.
    fn take_norm(&mut self) -> f64 {
        self.weights
            .iter_mut()
            .map(|w| std::mem::take(w).abs())
            .sum()
    }
}
