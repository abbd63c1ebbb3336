//! Tolerance rates kept from frame to frame for a mesh that moves: a face whose neighbourhood
//! moved almost rigidly since its rate was chosen keeps that rate without being sampled again,
//! when a bound proves that the full selection ([`super::rates`]) would choose it again.
//!
//! # The bound
//!
//! Every quantity the selection compares with the tolerance `T` is a distance between two
//! affine combinations of the isolated control points: a sample `S_f(s) = sum_i w_i P_i` (table
//! stencils, or the B-spline in closed form) and a point of the face-local tessellation
//! `L_{f,n}`, a convex combination of dual and limit points (stencils again); in a corner
//! square, the distance from `S_f(s)` to the nearest of a set of such triangles. An affine map
//! `x -> A x + t` of the control points maps every such point by the same map (the weights sum
//! to one), so a difference `d` becomes `A d`, of length between `(1 - s) |d|` and
//! `(1 + s) |d|` for `s = |A - R|_F` and any rotation `R` (Weyl; the nearest triangle's
//! distance too, through the image of the nearest point one way and its preimage the other),
//! exactly `|d|` for a rigid map (`s = 0`). If every control point of the face's neighbourhood
//! lies within `delta` of where the map carries its place then, a sample moves by at most
//! `|w|_1 delta` more and a point of `L_{f,n}` by at most the largest `|w|_1` of the points it
//! combines, so each distance changes by at most `C_f delta` beyond the map's scaling, with
//!
//! ```text
//! C_f = max |w|_1 over the face's sample stencils + max |w|_1 over the stencils of L_{f,m}, m <= n_f
//! ```
//!
//! (`2` where all are B-spline weights, which are non-negative; the table's extraordinary
//! stencils have negative weights and norms a little above one). The rate `n_f` chosen when the
//! face was last sampled, with its deviation `e_f(n_f) <= T` and every smaller candidate refuted
//! by a sample deviating by `d_m > T`, is the full selection's choice now if
//!
//! ```text
//! (1 + s) e_f(n_f) + C_f delta + margin <= T   and   (1 - s) min_m d_m - C_f delta - margin > T
//! ```
//!
//! (the first keeps `n_f` within `T` at every sample; the second keeps a sample beyond `T` at
//! every smaller rate, which refutes it whatever the other samples give). `margin` covers
//! rounding: the table's `f32` weights sum to one only to a few units in their last place, so
//! the computed deviations follow the map only up to the largest `|sum w - 1|` of the
//! stencils (both ends of a distance, measured per patch kind) times the length of the map's
//! translation; plus, for `f64`'s own rounding, `1e-12 C_f` times the neighbourhood's
//! largest distance from the origin then and now. Faces that fail either test, faces sampled
//! adaptively (sharp features, valences beyond the table) and those next to one are sampled
//! again. A face that met no rate (it has the largest) keeps it while the second test holds
//! for every rate, the largest included.
//!
//! `delta` is measured against the neighbourhood as it was when the face was sampled (kept in
//! `f32` about its corner centre, whose rounding is added), after the rigid map that carries the
//! frame of the face's corner diagonals then to their frame now: any map gives a valid bound,
//! and this one is exact for a part of the mesh that moves rigidly. Where it does not keep the
//! rate, the affine map nearest the motion in least squares is tried
//! ([`Neighbourhoods::fitted_residual`]), its translation moved to the middle of the residuals'
//! bounding box (which lowers their largest): a neighbourhood that bends at a joint turns by
//! different angles at its two ends, a shear no rigid map follows and an affine one does, so
//! only what is curved in the motion is left in `delta` (Spot bent by 10 degrees: 553 faces
//! sampled a frame with the rigid maps, 363 with the affine one; docs/benchmarks.md).
//!
//! # Table faces: the difference's own stencil
//!
//! `C_f` bounds the two ends of a distance apart, but the distance is `|sum_i c_i P_i|` with one
//! stencil `c = w - sum_k beta_k v_k` (the sample's less the `L_{f,n}` point's), which
//! annihilates every control net whose limit surface is affine in the face's parameters where
//! the stencils are smooth functions of them: `|c|_1` is second order in `1/n`. Taking as the
//! point of `L_{f,n}` the one at the sample's own parameters (in a corner square, the fan's point
//! in the regular chart of a vertex of four faces, [`super::rates::chart_corner`]), whose
//! distance from the sample is at least the nearest triangle's, a table face keeps `n_f` also
//! when
//!
//! ```text
//! max( (1 + s) max_s |S_f(s) - x_s| + |c|_1 delta,  (1 + s) e_fans + C_f delta ) + margin <= T
//! ```
//!
//! with the first maximum over the samples outside the corner squares of corners without a
//! chart (extraordinary vertices, boundaries) and `e_fans` the largest deviation in those.
//! Where the face and every face sharing a vertex with it are regular B-spline patches, `|c|_1`
//! is the same for every face ([`super::rates::chart_norm`]: 0.50 at rate 1, 0.18 at 2, 0.047
//! at 4) and there are no such corners; elsewhere it is the face's own
//! ([`super::difference_norm`], made the first time a frame needs it, per face and rate).
//!
//! # Refuting samples looked at again
//!
//! A rate is refuted by one sample beyond `T`, often by little (the scan stops at the first), so
//! the second test above fails at small motions. The selection records each smaller candidate's
//! refuting sample; where the bound cannot keep them refuted, the frame measures those samples
//! again at the current positions ([`Selection::sample_deviations`]): beyond `T`, they refute
//! their rates exactly, at the cost of one sample each instead of the face's whole selection.

use std::collections::HashMap;

use std::sync::OnceLock;

use rayon::prelude::*;
use table_format::{PointSet, StencilKind};

use crate::mesh::geometry::{cross, dot, norm, sub};
use crate::mesh::topology::Mesh;
use crate::once::TryOnce;
use crate::scheme::patch::{FacePatch, PatchKind};
use crate::stencil_table::StencilTable;
use crate::tessellate::difference_norm::{difference_norm, Norms};
use crate::tessellate::rates::{
    adaptive_face_list, adaptive_faces, adaptive_grids, check_tolerance, sample_deviations,
    sorted_candidates, with_selection, AdaptiveGrids, FaceChoice, ToleranceRates,
    MAX_SELECTED_RATE, RATIONAL_RATES, SELECTION_GRID,
};
use crate::RuntimeError;

/// A mesh's tolerance selection at its current positions, as [`RateMemory`] reads it: the
/// quad one ([`QuadSelection`]) and the triangle schemes'
/// ([`super::triangle_rates::TriangleSelection`]).
pub(crate) trait Selection: Sync {
    /// The tolerance.
    fn tolerance(&self) -> f64;
    /// The candidate rates, ascending.
    fn candidates(&self) -> &[u32];
    /// Every point the stencils read (the isolated vertices, then any phantoms).
    fn control(&self) -> &[[f64; 3]];
    /// How many faces.
    fn faces(&self) -> usize;
    /// Face `f`'s corners (indices into [`Selection::control`]): its frame.
    fn corners(&self, f: usize) -> &[u32];
    /// Whether face `f` is a hole (no surface, nothing sampled).
    fn hole(&self, f: usize) -> bool;
    /// Per face, the points its deviations read, and per rate `n` (at `n`) the bound of the
    /// stencils of its samples plus the largest of `L_{f,m}`'s for the candidates `m <= n`
    /// ([`StencilBound::NONE`] where the face cannot be kept).
    #[allow(clippy::type_complexity)]
    fn neighbourhoods(&self) -> Result<Vec<(Vec<u32>, Vec<StencilBound>)>, RuntimeError>;
    /// The choices of `faces` at the current positions; `previous`, where given, every face's
    /// last choice, whose refutations the quad selection scans from.
    fn choose(
        &self,
        faces: &[usize],
        previous: Option<&[FaceChoice]>,
    ) -> Result<Vec<FaceChoice>, RuntimeError>;
    /// The deviations at the current positions of `(face, rate, sample)` (a sample's index as in
    /// [`super::rates::Refutation`]): the samples that refuted a face's smaller rates, looked
    /// at again. Only selections that record their refutations are asked.
    fn sample_deviations(&self, checks: &[(usize, u32, usize)]) -> Result<Vec<f64>, RuntimeError>;
    /// Where face `f`'s deviations at rate `n` outside its uncharted corners have a stencil of
    /// their own ([`super::rates::ChartBound`] without a norm), the largest norm of those
    /// stencils ([`super::difference_norm`], taken from `norms` where a face of the same shape
    /// made it); `None` where there is none to use.
    fn difference_norm(&self, _f: usize, _n: u32, _norms: &Norms) -> Option<f64> {
        None
    }
}

/// Rates chosen for a tolerance, and what lets the next frame keep them.
#[derive(Debug)]
pub(crate) struct RateMemory {
    tolerance: f64,
    candidates: Vec<u32>,
    choices: Vec<FaceChoice>,
    /// Where every face was sampled.
    sampled_at: SampledAt,
    /// Faces sampled by the last selection (all of them by the first).
    sampled: usize,
    /// Faces whose rates the last frame kept once it looked at their refuting samples again.
    looked_again: usize,
}

/// Where the faces were sampled: the first selection's control points, until the first frame
/// that reuses the rates makes every face's neighbourhood from them (a single selection, as
/// `subtess tessellate` makes, never pays for the neighbourhoods).
#[derive(Debug)]
enum SampledAt {
    First(Vec<[f64; 3]>),
    Faces(Box<Neighbourhoods>),
}

/// What stencils can do to a distance: the largest `|w|_1` of a set of stencils, and the largest
/// `|sum w - 1|` (the `f32` weights' rounding), each summed over the two ends of a distance.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StencilBound {
    norm: f64,
    sum_error: f64,
}

impl StencilBound {
    pub(crate) const NONE: StencilBound = StencilBound {
        norm: f64::INFINITY,
        sum_error: f64::INFINITY,
    };
    pub(crate) const ZERO: StencilBound = StencilBound {
        norm: 0.0,
        sum_error: 0.0,
    };

    /// The bound of a table section's `points` stencils (`NONE` for an empty or ragged one).
    /// Its norm is never below one: the closed-form samples (B-spline, box spline) have
    /// non-negative weights summing to one, whatever the table's rounding.
    pub(crate) fn of_weights(weights: &[f32], points: usize) -> StencilBound {
        let k = weights.len() / points.max(1);
        if k == 0 || k * points != weights.len() {
            return StencilBound::NONE;
        }
        weights.chunks_exact(k).fold(
            StencilBound {
                norm: 1.0,
                sum_error: 0.0,
            },
            |bound, w| {
                let norm = w.iter().map(|x| f64::from(x.abs())).sum::<f64>();
                let sum = w.iter().map(|&x| f64::from(x)).sum::<f64>();
                bound.max(StencilBound {
                    norm,
                    sum_error: (sum - 1.0).abs(),
                })
            },
        )
    }

    pub(crate) fn max(self, other: StencilBound) -> StencilBound {
        StencilBound {
            norm: self.norm.max(other.norm),
            sum_error: self.sum_error.max(other.sum_error),
        }
    }

    pub(crate) fn plus(self, other: StencilBound) -> StencilBound {
        StencilBound {
            norm: self.norm + other.norm,
            sum_error: self.sum_error + other.sum_error,
        }
    }
}

/// Per face, the control points its deviations read, the bounds of their stencils, and where
/// those points were when the face was last sampled.
#[derive(Debug)]
struct Neighbourhoods {
    /// Face `f`'s points are `points[offsets[f]..offsets[f + 1]]`.
    offsets: Vec<usize>,
    points: Vec<u32>,
    /// Per face, for each rate `n` at `n` (`0` unused): `C_f` and the weights' sum error, its
    /// samples' plus the largest of `L_{f,m}` for `m <= n`; infinite where the face cannot be
    /// kept (sampled adaptively, or next to such a face).
    bounds: Vec<Vec<StencilBound>>,
    /// Per face and rate (`f (MAX_SELECTED_RATE + 1) + n`), the norm of its deviations' own
    /// stencils ([`Selection::difference_norm`]), made when a frame first needs it: it depends
    /// on the topology alone.
    differences: Vec<OnceLock<Option<f64>>>,
    /// Those norms by the shape of the neighbourhood they read, made once per shape.
    norms: Norms,
    /// Per face, as it was sampled: its neighbourhood's points relative to its corner centre
    /// (in `points`' order), that centre and its corner frame.
    sampled: Vec<[f32; 3]>,
    centres: Vec<[f64; 3]>,
    frames: Vec<[[f64; 3]; 3]>,
    /// Per face, as it was sampled: the largest distance of its neighbourhood's points from
    /// the origin (the scale of `f64`'s rounding) and from the corner centre (`sampled`'s
    /// rounding).
    scale: Vec<f64>,
    radius: Vec<f64>,
}

impl RateMemory {
    /// The rates of `selection`: its choices, with the faces that `memory` (the last frame's
    /// selection of the same mesh, tolerance and candidates) proves unchanged kept without
    /// sampling (module docs). `memory` is then this frame's. The deviations of kept faces are
    /// upper bounds of `e_f(n_f)`, not the measured values.
    pub(crate) fn rates(
        memory: &mut Option<RateMemory>,
        selection: &dyn Selection,
    ) -> Result<ToleranceRates, RuntimeError> {
        let (tolerance, candidates) = (selection.tolerance(), selection.candidates());
        match memory {
            Some(m)
                if m.tolerance == tolerance
                    && m.candidates == candidates
                    && m.choices.len() == selection.faces() =>
            {
                m.reuse(selection)
            }
            _ => {
                let faces: Vec<usize> = (0..selection.faces()).collect();
                let choices = selection.choose(&faces, None)?;
                let rates = ToleranceRates::from_choices(&choices);
                *memory = Some(RateMemory {
                    tolerance,
                    candidates: candidates.to_vec(),
                    sampled: choices.len(),
                    looked_again: 0,
                    choices,
                    sampled_at: SampledAt::First(selection.control().to_vec()),
                });
                Ok(rates)
            }
        }
    }

    /// How many faces the last call sampled (the others kept their rates).
    pub(crate) fn sampled(&self) -> usize {
        self.sampled
    }

    /// How many faces the last call kept after looking at their refuting samples again.
    #[allow(dead_code)] // read by the tests
    pub(crate) fn looked_again(&self) -> usize {
        self.looked_again
    }

    /// A frame after the first: keep what the bound proves, sample the rest.
    fn reuse(&mut self, selection: &dyn Selection) -> Result<ToleranceRates, RuntimeError> {
        let now = selection.control();
        if let SampledAt::First(first) = &self.sampled_at {
            if first.len() != now.len() {
                return Err(RuntimeError::Unsupported(format!(
                    "rates kept for {} control points, the mesh has {}",
                    first.len(),
                    now.len()
                )));
            }
            self.sampled_at = SampledAt::Faces(Box::new(Neighbourhoods::new(selection, first)?));
        }
        let SampledAt::Faces(near) = &mut self.sampled_at else {
            return Err(RuntimeError::Unsupported(
                "internal: the kept rates' neighbourhoods are missing".to_owned(),
            ));
        };
        let tolerance = self.tolerance;
        let tests: Vec<Test> = (0..self.choices.len())
            .into_par_iter()
            .map(|f| {
                let choice = &self.choices[f];
                if selection.hole(f) {
                    return Test::Keep(0.0);
                }
                let bound = near.bounds[f]
                    .get(choice.rate as usize)
                    .copied()
                    .unwrap_or(StencilBound::NONE);
                if !bound.norm.is_finite() {
                    return Test::Sample;
                }
                let test = |moved: &Motion| {
                    // A NaN fails every comparison below, which would keep the rate where the
                    // deviation or a refutation should have sent it to be sampled (the surface
                    // refuses points that are not finite; this covers what overflows).
                    let measured = [
                        moved.residual,
                        moved.stretch,
                        moved.translation,
                        moved.scale,
                    ];
                    if !measured.iter().all(|x| x.is_finite()) {
                        return Test::Sample;
                    }
                    // The weights' sums times the map's translation, and f64's rounding.
                    let margin = bound.sum_error * moved.translation
                        + 1e-12 * bound.norm * (near.scale[f] + moved.scale);
                    let change = bound.norm * moved.residual + margin;
                    // A distance `d` then is at most `(1 + stretch) d` and at least
                    // `(1 - stretch) d` after the map (module docs).
                    let (grown, shrunk) = (1.0 + moved.stretch, 1.0 - moved.stretch);
                    let mut deviation = choice.deviation * grown + change;
                    // The chart's bound: its norm read where it is the same for every face, made
                    // once per face and rate where it is the face's own, the plain bound fails
                    // and the chart's might not (with no norm at all).
                    if let Some(chart) = choice.chart {
                        let fans = chart
                            .fans
                            .map_or(0.0, |d| d * grown + bound.norm * moved.residual);
                        let norm = chart.norm.or_else(|| {
                            let hopeful = (chart.deviation * grown).max(fans) + margin <= tolerance;
                            (deviation > tolerance && hopeful)
                                .then(|| near.difference_norm(f, choice.rate, selection))
                                .flatten()
                        });
                        if let Some(norm) = norm {
                            let charted =
                                (chart.deviation * grown + norm * moved.residual).max(fans);
                            deviation = deviation.min(charted + margin);
                        }
                    }
                    // A face that met no rate keeps the largest while every rate stays refuted.
                    if choice.met && deviation > tolerance {
                        return Test::Sample;
                    }
                    if choice.refuted * shrunk - change > tolerance {
                        return Test::Keep(deviation);
                    }
                    // The refutations the motion may have undone, looked at again, where every
                    // smaller candidate's was recorded.
                    let smaller = self
                        .candidates
                        .iter()
                        .take_while(|&&n| n < choice.rate)
                        .count();
                    if !choice.met || choice.refutations.len() != smaller {
                        return Test::Sample;
                    }
                    Test::LookAgain(
                        deviation,
                        choice
                            .refutations
                            .iter()
                            .filter(|r| r.deviation * shrunk - change <= tolerance)
                            .map(|r| (f, r.rate, r.sample))
                            .collect(),
                    )
                };
                // The corner frames first (exact for a rigid motion, and cheap); where they do
                // not keep the rate, the affine map nearest the motion.
                match test(&near.residual(f, selection.corners(f), now)) {
                    Test::Sample => near
                        .fitted_residual(f, now)
                        .map_or(Test::Sample, |moved| test(&moved)),
                    kept => kept,
                }
            })
            .collect();
        let checks: Vec<(usize, u32, usize)> = tests
            .iter()
            .flat_map(|test| match test {
                Test::LookAgain(_, checks) => checks.as_slice(),
                _ => &[],
            })
            .copied()
            .collect();
        let mut refuted_again = vec![true; tests.len()];
        let mut looked_at = vec![false; tests.len()];
        if !checks.is_empty() {
            let deviations = selection.sample_deviations(&checks)?;
            for (&(f, _, _), deviation) in checks.iter().zip(deviations) {
                looked_at[f] = true;
                // A NaN refutes nothing.
                if deviation.partial_cmp(&tolerance) != Some(std::cmp::Ordering::Greater) {
                    refuted_again[f] = false;
                }
            }
        }
        self.looked_again = (0..tests.len())
            .filter(|&f| looked_at[f] && refuted_again[f])
            .count();
        // Per face that keeps its rate: the bound of its deviation now.
        let kept: Vec<Option<f64>> = tests
            .into_iter()
            .zip(refuted_again)
            .map(|(test, again)| match test {
                Test::Keep(deviation) => Some(deviation),
                Test::LookAgain(deviation, _) if again => Some(deviation),
                _ => None,
            })
            .collect();
        let resample: Vec<usize> = (0..kept.len()).filter(|&f| kept[f].is_none()).collect();
        let fresh = if resample.is_empty() {
            Vec::new()
        } else {
            selection.choose(&resample, Some(&self.choices))?
        };
        for (&f, choice) in resample.iter().zip(fresh) {
            self.choices[f] = choice;
            near.record(f, selection.corners(f), now);
        }
        self.sampled = resample.len();
        let mut rates = ToleranceRates::from_choices(&self.choices);
        for (deviation, bound) in rates.deviations.iter_mut().zip(kept) {
            if let Some(bound) = bound {
                *deviation = bound;
            }
        }
        Ok(rates)
    }
}

/// The quad selection of [`super::rates`] over an isolated Catmull–Clark mesh.
pub(crate) struct QuadSelection<'a> {
    table: &'a StencilTable,
    mesh: &'a Mesh,
    patches: &'a [FacePatch],
    tolerance: f64,
    candidates: Vec<u32>,
    /// The faces sampled adaptively and their grids at these positions, found once for the
    /// frame's choices and its samples looked at again.
    adaptive: OnceLock<AdaptiveGrids<'a>>,
    /// Those faces where a surface keeps them ([`adaptive_face_list`]: the table and the
    /// topology decide them).
    adaptive_faces: Option<&'a [usize]>,
}

impl<'a> QuadSelection<'a> {
    /// `mesh`'s selection for `tolerance` among `candidates` (rates of the table, sorted).
    pub(crate) fn new(
        table: &'a StencilTable,
        mesh: &'a Mesh,
        patches: &'a [FacePatch],
        tolerance: f64,
        candidates: &[u32],
    ) -> Result<Self, RuntimeError> {
        check_tolerance(tolerance)?;
        Ok(QuadSelection {
            table,
            mesh,
            patches,
            tolerance,
            candidates: sorted_candidates(candidates, &RATIONAL_RATES)?,
            adaptive: OnceLock::new(),
            adaptive_faces: None,
        })
    }

    /// This selection with the faces sampled adaptively already found (`faces`:
    /// [`adaptive_face_list`] of the same table, mesh and patches).
    pub(crate) fn knowing(mut self, faces: &'a [usize]) -> Self {
        self.adaptive_faces = Some(faces);
        self
    }
}

impl<'a> QuadSelection<'a> {
    /// [`QuadSelection::adaptive`], found the first time.
    fn adaptive(&self) -> Result<&AdaptiveGrids<'a>, RuntimeError> {
        self.adaptive.get_or_try(|| match self.adaptive_faces {
            Some(faces) => Ok(adaptive_grids(self.mesh, faces)),
            None => adaptive_faces(self.table, self.mesh, self.patches),
        })
    }
}

impl Selection for QuadSelection<'_> {
    fn tolerance(&self) -> f64 {
        self.tolerance
    }

    fn candidates(&self) -> &[u32] {
        &self.candidates
    }

    fn control(&self) -> &[[f64; 3]] {
        &self.mesh.positions
    }

    fn faces(&self) -> usize {
        self.patches.len()
    }

    fn corners(&self, f: usize) -> &[u32] {
        self.mesh.face(f)
    }

    fn hole(&self, f: usize) -> bool {
        self.mesh.holes[f]
    }

    fn choose(
        &self,
        faces: &[usize],
        previous: Option<&[FaceChoice]>,
    ) -> Result<Vec<FaceChoice>, RuntimeError> {
        with_selection(
            self.table,
            self.mesh,
            self.patches,
            self.adaptive()?,
            self.tolerance,
            &self.candidates,
            |choose| {
                faces
                    .par_iter()
                    .map(|&f| {
                        let hints = previous
                            .and_then(|p| p.get(f))
                            .map_or(&[][..], |c| &c.refutations);
                        choose(f, hints)
                    })
                    .collect::<Result<Vec<_>, _>>()
            },
        )
    }

    fn sample_deviations(&self, checks: &[(usize, u32, usize)]) -> Result<Vec<f64>, RuntimeError> {
        sample_deviations(
            self.table,
            self.mesh,
            self.patches,
            self.adaptive()?,
            checks,
        )
    }

    /// Where the norm cannot be made (a table that lacks a grid), the face has none and is
    /// sampled again: the selection reports the error itself.
    fn difference_norm(&self, f: usize, n: u32, norms: &Norms) -> Option<f64> {
        let adaptive = self.adaptive().ok()?;
        difference_norm(
            self.table,
            self.mesh,
            self.patches,
            &adaptive.faces,
            f,
            n,
            norms,
        )
        .ok()
        .flatten()
    }

    /// The control points of every face sharing a vertex with the face (the samples read the
    /// face's own, `L_{f,n}` the rows and corner points of those around it).
    fn neighbourhoods(&self) -> Result<Vec<(Vec<u32>, Vec<StencilBound>)>, RuntimeError> {
        let (table, mesh, patches) = (self.table, self.mesh, self.patches);
        // The faces sampled adaptively, which the bound does not cover.
        let adaptive = adaptive_face_list(table, mesh, patches)?;
        let kind_bounds = by_kind(patches.iter().map(|p| p.kind), |kind| {
            KindBounds::new(table, kind)
        });
        let bounds_of = |g: usize| kind_bounds.get(&patches[g].kind);
        Ok((0..patches.len())
            .into_par_iter()
            .map(|f| {
                let mut around: Vec<usize> = mesh
                    .face(f)
                    .iter()
                    .flat_map(|&v| mesh.fan_iter(v as usize).map(|h| mesh.face_of[h] as usize))
                    .collect();
                around.push(f);
                around.sort_unstable();
                around.dedup();
                let mut points: Vec<u32> = around
                    .iter()
                    .flat_map(|&g| patches[g].points.iter().copied())
                    .collect();
                points.sort_unstable();
                points.dedup();
                let mut bounds = vec![StencilBound::NONE; MAX_SELECTED_RATE as usize + 1];
                let described = around.iter().all(|g| adaptive.binary_search(g).is_err());
                if let (Some(own), true) = (bounds_of(f), described) {
                    for (n, bound) in bounds.iter_mut().enumerate().skip(1) {
                        let local = around
                            .iter()
                            .map(|&g| bounds_of(g).map_or(StencilBound::NONE, |k| k.up_to[n]))
                            .fold(StencilBound::ZERO, StencilBound::max);
                        *bound = own.samples.plus(local);
                    }
                }
                (points, bounds)
            })
            .collect())
    }
}

impl Neighbourhoods {
    /// `selection`'s neighbourhoods, every face sampled at `control`.
    fn new(selection: &dyn Selection, control: &[[f64; 3]]) -> Result<Self, RuntimeError> {
        let per_face = selection.neighbourhoods()?;
        let mut offsets = Vec::with_capacity(per_face.len() + 1);
        offsets.push(0);
        let mut points = Vec::new();
        let mut bounds = Vec::with_capacity(per_face.len());
        for (p, b) in per_face {
            points.extend(p);
            offsets.push(points.len());
            bounds.push(b);
        }
        let faces = bounds.len();
        let slots = faces
            .checked_mul(MAX_SELECTED_RATE as usize + 1)
            .ok_or_else(|| {
                RuntimeError::Unsupported(format!("rates kept for {faces} faces: too many"))
            })?;
        let mut near = Neighbourhoods {
            differences: (0..slots).map(|_| OnceLock::new()).collect(),
            norms: Norms::default(),
            sampled: vec![[0.0; 3]; points.len()],
            offsets,
            points,
            bounds,
            centres: vec![[0.0; 3]; faces],
            frames: vec![[[0.0; 3]; 3]; faces],
            scale: vec![0.0; faces],
            radius: vec![0.0; faces],
        };
        for f in 0..faces {
            near.record(f, selection.corners(f), control);
        }
        Ok(near)
    }

    /// Face `f`'s [`Selection::difference_norm`] at rate `n`, made once.
    fn difference_norm(&self, f: usize, n: u32, selection: &dyn Selection) -> Option<f64> {
        let slot = f
            .checked_mul(MAX_SELECTED_RATE as usize + 1)
            .and_then(|k| k.checked_add(n as usize))
            .and_then(|k| self.differences.get(k))?;
        *slot.get_or_init(|| selection.difference_norm(f, n, &self.norms))
    }

    /// Face `f` (its corners `corners`) sampled at `positions`: where its neighbourhood is.
    fn record(&mut self, f: usize, corners: &[u32], positions: &[[f64; 3]]) {
        let (centre, frame) = corner_frame(corners, positions);
        let range = self.offsets[f]..self.offsets[f + 1];
        let mut squared = LargestSquares::default();
        for (kept, &i) in self.sampled[range.clone()]
            .iter_mut()
            .zip(&self.points[range])
        {
            let p = positions[i as usize];
            let d = sub(p, centre);
            *kept = d.map(|x| x as f32);
            squared.add(d, p);
        }
        let (radius, scale) = squared.roots();
        self.centres[f] = centre;
        self.frames[f] = frame;
        self.scale[f] = scale;
        self.radius[f] = radius;
    }

    /// How face `f`'s neighbourhood moved since it was sampled, measured after the rigid map
    /// `x -> R (x - c) + c'` that takes the face's corner frame then (centre `c`) to its frame
    /// now (centre `c'`).
    fn residual(&self, f: usize, corners: &[u32], now: &[[f64; 3]]) -> Motion {
        let (centre, frame) = corner_frame(corners, now);
        let from = &self.frames[f];
        // R = frame^T from (the frames' rows are their axes).
        let transposed = std::array::from_fn(|r| std::array::from_fn(|k| frame[k][r]));
        let rotation = product(&transposed, from);
        let range = self.offsets[f]..self.offsets[f + 1];
        let mut squared = LargestSquares::default();
        for (kept, &i) in self.sampled[range.clone()].iter().zip(&self.points[range]) {
            let d = kept.map(f64::from);
            let q = now[i as usize];
            let carried = [0, 1, 2].map(|r| centre[r] + dot(rotation[r], d));
            squared.add(sub(q, carried), q);
        }
        let (residual, scale) = squared.roots();
        let turned = [0, 1, 2].map(|r| dot(rotation[r], self.centres[f]));
        Motion {
            // A stored coordinate is within 2^-24 of its size of the f64 one.
            residual: residual + self.radius[f] * 2f64.powi(-23),
            translation: norm(sub(centre, turned)),
            scale,
            stretch: 0.0,
        }
    }

    /// How face `f`'s neighbourhood moved since it was sampled, measured after the affine map
    /// `x -> A (x - p_mean) + q_mean` nearest the motion in least squares, held near a rotation:
    /// `A = R + E`, `R` the rigid fit's rotation (Kabsch: the orthogonal polar factor of the
    /// points' cross-covariance `M`, by Newton's iteration `X -> (X + X^-T) / 2`) and `E` the
    /// least-squares fit of what `R` leaves, `E = (M - R C)(C + lambda I)^-1` with `C` the points'
    /// covariance and `lambda = 1e-6 trace C` (a flat neighbourhood does not determine `A`
    /// across it: there `E` stays near zero instead of following rounding). The translation is
    /// then moved by the middle of the residuals' bounding box, which lowers the largest
    /// residual where they lean to one side (least squares balances their squares, not their
    /// extremes). A neighbourhood that bends turns by different angles at its two ends: the
    /// rigid fit leaves that shear in its residual, the affine one only what is curved in the
    /// motion. `None` where `R` is not a proper rotation ([`polar_rotation`]: a motion that
    /// flips or flattens it).
    fn fitted_residual(&self, f: usize, now: &[[f64; 3]]) -> Option<Motion> {
        let range = self.offsets[f]..self.offsets[f + 1];
        let (then, points) = (&self.sampled[range.clone()], &self.points[range]);
        let count = then.len() as f64;
        let mut mean_then = [0.0; 3];
        let mut mean_now = [0.0; 3];
        for (kept, &i) in then.iter().zip(points) {
            let q = now[i as usize];
            for c in 0..3 {
                mean_then[c] += f64::from(kept[c]) / count;
                mean_now[c] += q[c] / count;
            }
        }
        // M = sum (q - q_mean)(p - p_mean)^T, the rotation maximizing sum (q - q_mean) . R (p -
        // p_mean) its polar factor; C = sum (p - p_mean)(p - p_mean)^T.
        let (mut m, mut c) = ([[0.0; 3]; 3], [[0.0; 3]; 3]);
        for (kept, &i) in then.iter().zip(points) {
            let p = sub(kept.map(f64::from), mean_then);
            let q = sub(now[i as usize], mean_now);
            for r in 0..3 {
                for k in 0..3 {
                    m[r][k] += q[r] * p[k];
                    c[r][k] += p[r] * p[k];
                }
            }
        }
        let rotation = polar_rotation(m)?;
        // E (C + lambda I) = M - R C, solved through the symmetric C + lambda I's inverse.
        let turned = product(&rotation, &c);
        let leftover: [[f64; 3]; 3] =
            std::array::from_fn(|r| std::array::from_fn(|k| m[r][k] - turned[r][k]));
        let lambda = 1e-6 * (c[0][0] + c[1][1] + c[2][2]);
        for (k, row) in c.iter_mut().enumerate() {
            row[k] += lambda;
        }
        let inverse = inverse_transpose(c)?;
        let e = product(&leftover, &inverse);
        let map: [[f64; 3]; 3] =
            std::array::from_fn(|r| std::array::from_fn(|k| rotation[r][k] + e[r][k]));
        let residual_of = |kept: &[f32; 3], i: u32, shift: [f64; 3]| {
            let p = sub(kept.map(f64::from), mean_then);
            let q = now[i as usize];
            let carried = [0, 1, 2].map(|r| mean_now[r] + shift[r] + dot(map[r], p));
            (sub(q, carried), q)
        };
        let (mut low, mut high) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for (kept, &i) in then.iter().zip(points) {
            let (r, _) = residual_of(kept, i, [0.0; 3]);
            for c in 0..3 {
                low[c] = low[c].min(r[c]);
                high[c] = high[c].max(r[c]);
            }
        }
        let shift = [0, 1, 2].map(|c| 0.5 * (low[c] + high[c]));
        let mut squared = LargestSquares::default();
        for (kept, &i) in then.iter().zip(points) {
            let (r, q) = residual_of(kept, i, shift);
            squared.add(r, q);
        }
        let (residual, scale) = squared.roots();
        // x -> A (x - c - p_mean) + q_mean + shift, c the corner centre then: translation
        // q_mean + shift - A (c + p_mean).
        let origin = [0, 1, 2].map(|c| self.centres[f][c] + mean_then[c]);
        let carried = [0, 1, 2].map(|r| dot(map[r], origin) - shift[r]);
        // |A| <= |R| + |E|_F and the smallest singular value of A at least 1 - |E|_F (Weyl);
        // `R` is orthogonal to 1e-14, which the last term covers with `E`'s rounding.
        let stretch = e.iter().flatten().map(|x| x * x).sum::<f64>().sqrt() * (1.0 + 1e-12) + 1e-13;
        Some(Motion {
            // A stored point is within 2^-24 of its length of the f64 one, and `A` stretches
            // that by at most `1 + stretch`.
            residual: residual + self.radius[f] * 2f64.powi(-23) * (1.0 + stretch),
            translation: norm(sub(mean_now, carried)),
            scale,
            stretch,
        })
    }
}

/// The largest squared lengths of a neighbourhood's residuals and of its points: the roots
/// taken once, at the end (a correctly rounded root is monotone, so the root of the largest
/// square is the largest root to the bit).
#[derive(Default)]
struct LargestSquares {
    residual: f64,
    scale: f64,
}

impl LargestSquares {
    fn add(&mut self, residual: [f64; 3], point: [f64; 3]) {
        self.residual = self.residual.max(dot(residual, residual));
        self.scale = self.scale.max(dot(point, point));
    }

    /// The largest residual and the largest point's length.
    fn roots(&self) -> (f64, f64) {
        (self.residual.sqrt(), self.scale.sqrt())
    }
}

/// The rotation nearest `m` (its orthogonal polar factor), or `None` where `m` is singular,
/// reflects, or the iteration does not settle on a rotation to `1e-14` (well inside the
/// `1e-12` of the margin's rounding term, which then also covers the rest).
fn polar_rotation(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let size = m.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let mut x = m.map(|row| row.map(|v| v / size));
    for _ in 0..40 {
        let inverse_transpose = inverse_transpose(x)?;
        let next: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|c| (x[r][c] + inverse_transpose[r][c]) / 2.0)
        });
        let step = (0..3)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .map(|(r, c)| (next[r][c] - x[r][c]).abs())
            .fold(0.0, f64::max);
        x = next;
        if step < 1e-15 {
            break;
        }
    }
    // A proper rotation: orthonormal rows, determinant one.
    let orthogonal = (0..3)
        .all(|r| (0..3).all(|c| (dot(x[r], x[c]) - if r == c { 1.0 } else { 0.0 }).abs() <= 1e-14));
    (orthogonal && dot(cross(x[0], x[1]), x[2]) > 0.0).then_some(x)
}

/// The matrix product `a b`.
fn product(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

/// `(a^-1)^T`, the cofactor matrix over the determinant; `None` for a singular `a`.
fn inverse_transpose(a: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let cofactors = [cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1])];
    let det = dot(a[0], cofactors[0]);
    if !(det.abs() > 1e-300 && det.is_finite()) {
        return None;
    }
    Some(cofactors.map(|row| row.map(|v| v / det)))
}

/// What a frame does with a face's rate ([`RateMemory::rates`]).
enum Test {
    /// Kept, with the bound of its deviation now.
    Keep(f64),
    /// Kept if the samples `(face, rate, sample)` still deviate beyond the tolerance.
    LookAgain(f64, Vec<(usize, u32, usize)>),
    /// Sampled again.
    Sample,
}

/// How a face's neighbourhood moved since the face was sampled ([`Neighbourhoods::residual`]).
struct Motion {
    /// The largest distance of a point from where the map carries its place then.
    residual: f64,
    /// The length of the map's translation, `|c' - A c|`.
    translation: f64,
    /// The largest distance of a point from the origin now.
    scale: f64,
    /// A bound of `|A - R|` for a rotation `R` (zero for a rigid map): distances are at most
    /// `1 + stretch` and at least `1 - stretch` times what they were.
    stretch: f64,
}

/// What `each` makes of every distinct kind of `kinds` (in parallel), by kind.
pub(crate) fn by_kind<T: Send>(
    kinds: impl Iterator<Item = PatchKind>,
    each: impl Fn(&PatchKind) -> T + Sync,
) -> HashMap<PatchKind, T> {
    let mut distinct: Vec<PatchKind> = Vec::new();
    for kind in kinds {
        if !distinct.contains(&kind) {
            distinct.push(kind);
        }
    }
    distinct
        .into_par_iter()
        .map(|kind| {
            let made = each(&kind);
            (kind, made)
        })
        .collect()
}

/// The bounds of a patch kind's position stencils.
#[derive(Debug)]
struct KindBounds {
    /// Over the samples (the primal and dual grids at [`SELECTION_GRID`]).
    samples: StencilBound,
    /// At `n`: over the primal and dual grids of every rate up to `n`.
    up_to: [StencilBound; MAX_SELECTED_RATE as usize + 1],
}

impl KindBounds {
    /// Infinite where the table lacks a grid (a face reading it is not kept).
    fn new(table: &StencilTable, kind: &PatchKind) -> Self {
        let grid = |points: PointSet, n: u32| -> StencilBound {
            let key = kind.section(StencilKind::Position, points, n);
            let Ok(weights) = table.weights(&key) else {
                return StencilBound::NONE;
            };
            let side = match points {
                PointSet::Primal => n + 1,
                _ => n,
            } as usize;
            StencilBound::of_weights(weights, side * side)
        };
        let samples =
            grid(PointSet::Primal, SELECTION_GRID).max(grid(PointSet::Dual, SELECTION_GRID));
        let mut up_to = [StencilBound::NONE; MAX_SELECTED_RATE as usize + 1];
        let mut largest = StencilBound::ZERO;
        for n in 1..=MAX_SELECTED_RATE {
            largest = largest
                .max(grid(PointSet::Dual, n))
                .max(grid(PointSet::Primal, n));
            up_to[n as usize] = largest;
        }
        KindBounds { samples, up_to }
    }
}

/// The centre of a face's corners and an orthonormal frame (rows) from its diagonals (its
/// first two edges for a triangle), the identity where they are degenerate.
fn corner_frame(corners: &[u32], positions: &[[f64; 3]]) -> ([f64; 3], [[f64; 3]; 3]) {
    let at = |k: usize| positions[corners[k % corners.len()] as usize];
    let count = corners.len().max(1) as f64;
    let mut centre = [0.0; 3];
    for k in 0..corners.len() {
        centre = [0, 1, 2].map(|c| centre[c] + at(k)[c] / count);
    }
    let (a, b) = if corners.len() >= 4 {
        (sub(at(2), at(0)), sub(at(3), at(1)))
    } else {
        (sub(at(1), at(0)), sub(at(2), at(0)))
    };
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let normal = cross(a, b);
    let (la, ln) = (norm(a), norm(normal));
    if !(la > 0.0 && ln > 0.0 && la.is_finite() && ln.is_finite()) {
        return (centre, identity);
    }
    let e1 = a.map(|x| x / la);
    let e3 = normal.map(|x| x / ln);
    let e2 = cross(e3, e1);
    (centre, [e1, e2, e3])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `p` turned by `angle` about the axis `(1, 2, 2) / 3` and moved by `shift`.
    #[allow(dead_code)] // without either scheme's feature
    fn rigid(p: [f64; 3], angle: f64, shift: [f64; 3]) -> [f64; 3] {
        let k = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
        let (sin, cos) = angle.sin_cos();
        let across = cross(k, p);
        let along = dot(k, p) * (1.0 - cos);
        [0, 1, 2].map(|c| p[c] * cos + across[c] * sin + k[c] * along + shift[c])
    }

    /// The least-squares rotation of a cloud turned by a known rotation, and stretched along
    /// one axis, is that rotation; a mirror image has none.
    #[test]
    fn the_polar_rotation_is_the_turn() {
        let cloud: Vec<[f64; 3]> = (0..40)
            .map(|k| {
                let t = k as f64;
                [(0.7 * t).sin(), (1.3 * t).cos(), 0.1 * t - 2.0]
            })
            .collect();
        let covariance = |moved: &dyn Fn([f64; 3]) -> [f64; 3]| {
            let mut m = [[0.0; 3]; 3];
            for &p in &cloud {
                let q = moved(p);
                for (r, row) in m.iter_mut().enumerate() {
                    for (c, x) in row.iter_mut().enumerate() {
                        *x += q[r] * p[c];
                    }
                }
            }
            m
        };
        // The rotation's rows: its images of the axes, transposed.
        let axes =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| rigid(e, 0.9, [0.0; 3]));
        let turned = polar_rotation(covariance(&|p| rigid(p, 0.9, [0.0; 3]))).expect("a rotation");
        for r in 0..3 {
            for c in 0..3 {
                assert!((turned[r][c] - axes[c][r]).abs() < 1e-12, "{turned:?}");
            }
        }
        let stretched = polar_rotation(covariance(&|p| {
            rigid([1.5 * p[0], p[1], p[2]], 0.9, [0.0; 3])
        }));
        assert!(stretched.is_some());
        assert!(polar_rotation(covariance(&|p| [-p[0], p[1], p[2]])).is_none());
        assert!(polar_rotation([[0.0; 3]; 3]).is_none());
    }

    /// Frames that keep, turn, move, bend and grow the points `rest` (about 1 across), through
    /// `frame(points, memory) -> (kept, fresh, faces)`: the memory's rates and a fresh
    /// selection's at those points. Their rates are the same every frame, the memory's
    /// deviations at least the measured ones, and few faces are sampled where nothing but a
    /// rigid motion (and rounding) happened. The fresh rates of every frame.
    #[allow(dead_code)] // without either scheme's feature
    fn kept_through_frames(
        rest: &[[f64; 3]],
        tolerance: f64,
        mut frame: impl FnMut(
            &[[f64; 3]],
            &mut Option<RateMemory>,
        ) -> (ToleranceRates, ToleranceRates, usize),
    ) -> Vec<Vec<u32>> {
        // A bump of `height` about the first vertex, which bends the faces around it.
        let bump = |height: f64| -> Vec<[f64; 3]> {
            let centre = rest[0];
            rest.iter()
                .map(|&p| {
                    let d = norm(sub(p, centre));
                    let lift = height * (-(d / 0.4).powi(2)).exp();
                    [p[0], p[1], p[2] + lift]
                })
                .collect()
        };
        let grow = |points: Vec<[f64; 3]>| -> Vec<[f64; 3]> {
            points.into_iter().map(|p| p.map(|c| 1.7 * c)).collect()
        };
        let stretch = |points: Vec<[f64; 3]>| -> Vec<[f64; 3]> {
            points
                .into_iter()
                .map(|p| [1.002 * p[0] + 0.001 * p[1], p[1], 0.999 * p[2]])
                .collect()
        };
        let turn = |points: Vec<[f64; 3]>| -> Vec<[f64; 3]> {
            points
                .into_iter()
                .map(|p| rigid(p, 0.7, [3.0, -1.0, 0.5]))
                .collect()
        };
        let frames: Vec<(&str, Vec<[f64; 3]>)> = vec![
            ("first", rest.to_vec()),
            ("at rest again", rest.to_vec()),
            ("turned and moved", turn(rest.to_vec())),
            ("turned, moved and touched", turn(bump(1e-6 * tolerance))),
            // Stretched by 0.2% and sheared by 0.1%: no rigid map carries a neighbourhood
            // close enough to keep its rates (with the rigid maps alone every face is sampled),
            // the affine map nearest the motion does; the deviations grow by its stretch.
            ("stretched, turned and moved", turn(stretch(rest.to_vec()))),
            ("bumped", bump(0.3)),
            ("grown", rest.iter().map(|p| p.map(|c| 1.7 * c)).collect()),
            // Motions of the order of the tolerance: some faces keep their rates by the
            // bounds, some by their refuting samples looked at again, some are sampled.
            ("grown, nudged", grow(bump(0.1 * tolerance))),
            ("grown, nudged by a third", grow(bump(0.3 * tolerance))),
            ("grown, nudged by half", grow(bump(0.5 * tolerance))),
            ("grown, nudged more", grow(bump(tolerance))),
            ("grown, nudged most", grow(bump(3.0 * tolerance))),
        ];
        let mut memory = None;
        let mut fresh_rates = Vec::new();
        for (label, positions) in frames {
            let (kept, fresh, faces) = frame(&positions, &mut memory);
            assert_eq!(kept.rates, fresh.rates, "{label}: rates at {tolerance}");
            assert_eq!(kept.unmet, fresh.unmet, "{label}: unmet at {tolerance}");
            for (f, (bound, measured)) in kept.deviations.iter().zip(&fresh.deviations).enumerate()
            {
                assert!(
                    bound >= measured,
                    "{label}: face {f}: {bound} below {measured} at {tolerance}"
                );
            }
            let sampled = memory.as_ref().map_or(0, RateMemory::sampled);
            match label {
                "first" => assert_eq!(sampled, faces, "the first frame samples all"),
                "bumped" | "grown" => assert!(sampled > 0, "{label}: nothing sampled"),
                _ if label.starts_with("grown, nudged") => {}
                _ => assert!(
                    sampled * 10 < faces,
                    "{label}: {sampled} of {faces} faces sampled at {tolerance}"
                ),
            }
            fresh_rates.push(fresh.rates);
        }
        fresh_rates
    }

    /// [`kept_through_frames`] at two tolerances, the second met by no rate; `top` the largest
    /// rate.
    #[allow(dead_code)] // without either scheme's feature
    fn check_tolerances(
        rest: &[[f64; 3]],
        top: u32,
        mut frame: impl FnMut(
            &[[f64; 3]],
            f64,
            &mut Option<RateMemory>,
        ) -> (ToleranceRates, ToleranceRates, usize),
    ) {
        let rates = kept_through_frames(rest, 1e-2, |p, m| frame(p, 1e-2, m));
        // The bump and the growth move rates: a memory that kept everything would fail above.
        assert_ne!(rates[4], rates[5], "the bump moves no rate");
        assert_ne!(rates[5], rates[6], "the growth moves no rate");
        // Every face keeps the largest rate while every rate stays refuted.
        let rates = kept_through_frames(rest, 1e-7, |p, m| frame(p, 1e-7, m));
        assert!(rates.iter().flatten().all(|&n| n == top));
    }

    #[test]
    #[cfg(feature = "catmull-clark")]
    fn kept_quad_rates_are_a_fresh_selections() {
        use crate::mesh::test_meshes::{octahedron, quad_torus};
        use crate::scheme::catmull_clark::isolate::isolate;
        use crate::scheme::patch::gather_patches;
        use crate::tessellate::rates::tolerance_rates;
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        // Valence-3 and valence-4 vertices, two isolating steps: table faces of both kinds;
        // and a torus of regular faces (about 2 across), whose bound is the chart's.
        let (octahedron, octahedron_patches, _) = isolate(&octahedron()).expect("isolates");
        let mut torus = quad_torus(8, 6);
        for p in &mut torus.positions {
            *p = p.map(|c| c / 4.0);
        }
        let torus_patches = gather_patches(&torus).expect("patches");
        let (mut charts, mut looked_again, mut own_norms) = (0, 0, 0);
        for (mut mesh, patches) in [(octahedron, octahedron_patches), (torus, torus_patches)] {
            let rest = mesh.positions.clone();
            // Found once, as a surface finds them.
            let adaptive = adaptive_face_list(&table, &mesh, &patches).expect("adaptive faces");
            check_tolerances(&rest, MAX_SELECTED_RATE, |positions, tolerance, memory| {
                mesh.positions = positions.to_vec();
                let selection =
                    QuadSelection::new(&table, &mesh, &patches, tolerance, &RATIONAL_RATES)
                        .expect("selection")
                        .knowing(&adaptive);
                let kept = RateMemory::rates(memory, &selection).expect("kept");
                let fresh = tolerance_rates(&table, &mesh, &patches, tolerance).expect("fresh");
                if let Some(m) = memory.as_ref() {
                    charts += m.choices.iter().filter(|c| c.chart.is_some()).count();
                    looked_again += m.looked_again();
                    if let SampledAt::Faces(near) = &m.sampled_at {
                        own_norms += near
                            .differences
                            .iter()
                            .filter(|d| d.get().is_some())
                            .count();
                    }
                }
                (kept, fresh, patches.len())
            });
        }
        // The charts' bounds (the faces around the valence-3 vertices with their own norms)
        // and the second look were all put to the test.
        assert!(
            charts > 0 && looked_again > 0 && own_norms > 0,
            "{charts} charts, {looked_again} looked again, {own_norms} own norms"
        );
    }

    #[test]
    #[cfg(feature = "loop")]
    fn kept_triangle_rates_are_a_fresh_selections() {
        use crate::mesh::test_meshes::octahedron;
        use crate::scheme::loop_scheme::isolate::isolate_loop;
        use crate::tessellate::triangle_rates::{
            triangle_table_rates, triangle_tolerance_rates, TriangleSampling, TriangleSelection,
        };
        let table = StencilTable::default_loop().expect("embedded table");
        let rates = triangle_table_rates(&table);
        let top = rates.last().copied().expect("rates");
        // Valence-4 vertices, one isolating step: regular and extraordinary triangles.
        let mut iso = isolate_loop(&octahedron()).expect("isolates");
        let rest = iso.mesh.positions.clone();
        // Kept across the frames, as a surface keeps it.
        let sampling = TriangleSampling::new(&table).expect("sampling");
        check_tolerances(&rest, top, |positions, tolerance, memory| {
            iso.mesh.positions = positions.to_vec();
            let selection = TriangleSelection::sharing(&table, &iso, tolerance, &rates, &sampling)
                .expect("selection");
            let kept = RateMemory::rates(memory, &selection).expect("kept");
            let fresh = triangle_tolerance_rates(&table, &iso, tolerance).expect("fresh");
            (kept, fresh, iso.patches.len())
        });
    }
}
