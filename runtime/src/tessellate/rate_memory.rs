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
//! square, the distance from `S_f(s)` to the nearest of a set of such triangles. Both are
//! invariant under a rigid motion of the control points (the weights sum to one), and if every
//! control point of the face's neighbourhood moves by at most `delta` after a rigid motion, a
//! sample moves by at most `|w|_1 delta` and a point of `L_{f,n}` by at most the largest `|w|_1`
//! of the points it combines, so each distance changes by at most `C_f delta`, with
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
//! e_f(n_f) + C_f delta + margin <= T   and   min_m d_m - C_f delta - margin > T
//! ```
//!
//! (the first keeps `n_f` within `T` at every sample; the second keeps a sample beyond `T` at
//! every smaller rate, which refutes it whatever the other samples give). `margin` covers
//! rounding: the table's `f32` weights sum to one only to a few units in their last place, so
//! the computed deviations are rigid-invariant only up to the largest `|sum w - 1|` of the
//! stencils (both ends of a distance, measured per patch kind) times the length of the rigid
//! map's translation; plus, for `f64`'s own rounding, `1e-12 C_f` times the neighbourhood's
//! largest distance from the origin then and now. Faces that fail either test, faces sampled
//! adaptively (sharp features, valences beyond the table) and those next to one are sampled
//! again. A face that met no rate (it has the largest) keeps it while the second test holds
//! for every rate, the largest included.
//!
//! `delta` is measured against the neighbourhood as it was when the face was sampled (kept in
//! `f32` about its corner centre, whose rounding is added), after the rigid map that carries the
//! frame of the face's corner diagonals then to their frame now: any rigid map gives a valid
//! bound, and this one is exact for a part of the mesh that moves rigidly.

use std::collections::HashMap;

use rayon::prelude::*;
use table_format::{PointSet, StencilKind};

use crate::mesh::geometry::{cross, dot, norm, sub};
use crate::mesh::topology::Mesh;
use crate::scheme::patch::{FacePatch, PatchKind};
use crate::stencil_table::StencilTable;
use crate::tessellate::rates::{
    adaptive_face_list, sorted_candidates, with_selection, FaceChoice, ToleranceRates,
    MAX_SELECTED_RATE, RATIONAL_RATES, SELECTION_GRID,
};
use crate::RuntimeError;

/// Rates chosen for a tolerance, and what lets the next frame keep them.
#[derive(Debug)]
pub(crate) struct RateMemory {
    tolerance: f64,
    candidates: Vec<u32>,
    choices: Vec<FaceChoice>,
    /// Every face's neighbourhood as it was sampled, made by the first frame that reuses the
    /// rates; until then the isolated control points of the first selection.
    neighbourhoods: Result<Neighbourhoods, Vec<[f64; 3]>>,
    /// Faces sampled by the last selection (all of them by the first).
    sampled: usize,
}

/// What stencils can do to a distance: the largest `|w|_1` of a set of stencils, and the largest
/// `|sum w - 1|` (the `f32` weights' rounding), each summed over the two ends of a distance.
#[derive(Clone, Copy, Debug)]
struct StencilBound {
    norm: f64,
    sum_error: f64,
}

impl StencilBound {
    const NONE: StencilBound = StencilBound {
        norm: f64::INFINITY,
        sum_error: f64::INFINITY,
    };
    const ZERO: StencilBound = StencilBound {
        norm: 0.0,
        sum_error: 0.0,
    };

    fn max(self, other: StencilBound) -> StencilBound {
        StencilBound {
            norm: self.norm.max(other.norm),
            sum_error: self.sum_error.max(other.sum_error),
        }
    }

    fn plus(self, other: StencilBound) -> StencilBound {
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
    bounds: Vec<[StencilBound; MAX_SELECTED_RATE as usize + 1]>,
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
    /// The rates for `tolerance` among `candidates` at the mesh's current positions: those of
    /// [`super::rates::tolerance_rates_among`], with the faces that `memory` (the last frame's
    /// selection of the same mesh, tolerance and candidates) proves unchanged kept without
    /// sampling (module docs). `memory` is then this frame's. The deviations of kept faces are
    /// upper bounds of `e_f(n_f)`, not the measured values.
    pub(crate) fn rates(
        memory: &mut Option<RateMemory>,
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
        tolerance: f64,
        candidates: &[u32],
    ) -> Result<ToleranceRates, RuntimeError> {
        let sorted = sorted_candidates(candidates, &RATIONAL_RATES)?;
        match memory {
            Some(m)
                if m.tolerance == tolerance
                    && m.candidates == sorted
                    && m.choices.len() == patches.len() =>
            {
                m.reuse(table, mesh, patches)
            }
            _ => {
                let faces: Vec<usize> = (0..patches.len()).collect();
                let choices = choose(table, mesh, patches, tolerance, &sorted, &faces)?;
                let rates = ToleranceRates::from_choices(&choices);
                *memory = Some(RateMemory {
                    tolerance,
                    candidates: sorted,
                    sampled: choices.len(),
                    choices,
                    neighbourhoods: Err(mesh.positions.clone()),
                });
                Ok(rates)
            }
        }
    }

    /// How many faces the last call sampled (the others kept their rates).
    pub(crate) fn sampled(&self) -> usize {
        self.sampled
    }

    /// A frame after the first: keep what the bound proves, sample the rest.
    fn reuse(
        &mut self,
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
    ) -> Result<ToleranceRates, RuntimeError> {
        if let Err(first) = &self.neighbourhoods {
            if first.len() != mesh.positions.len() {
                return Err(RuntimeError::Unsupported(format!(
                    "rates kept for {} control points, the mesh has {}",
                    first.len(),
                    mesh.positions.len()
                )));
            }
            self.neighbourhoods = Ok(Neighbourhoods::new(table, mesh, patches, first)?);
        }
        let Ok(near) = &mut self.neighbourhoods else {
            return Err(RuntimeError::Unsupported(
                "internal: the kept rates' neighbourhoods are missing".to_owned(),
            ));
        };
        let tolerance = self.tolerance;
        let now = &mesh.positions;
        // Per face: what the motion since it was sampled may add to its deviations, when that
        // keeps its rate.
        let kept: Vec<Option<f64>> = (0..patches.len())
            .into_par_iter()
            .map(|f| {
                let choice = &self.choices[f];
                if mesh.holes[f] {
                    return Some(0.0);
                }
                let bound = near.bounds[f][choice.rate as usize];
                if !bound.norm.is_finite() {
                    return None;
                }
                let moved = near.residual(f, mesh.face(f), now);
                // The weights' sums times the rigid map's translation, and f64's rounding.
                let margin = bound.sum_error * moved.translation
                    + 1e-12 * bound.norm * (near.scale[f] + moved.scale);
                let change = bound.norm * moved.residual + margin;
                // A face that met no rate keeps the largest while every rate stays refuted.
                let within = !choice.met || choice.deviation + change <= tolerance;
                (within && choice.refuted - change > tolerance).then_some(change)
            })
            .collect();
        let resample: Vec<usize> = (0..patches.len()).filter(|&f| kept[f].is_none()).collect();
        let fresh = if resample.is_empty() {
            Vec::new()
        } else {
            choose(table, mesh, patches, tolerance, &self.candidates, &resample)?
        };
        for (&f, choice) in resample.iter().zip(fresh) {
            self.choices[f] = choice;
            near.record(f, mesh.face(f), now);
        }
        self.sampled = resample.len();
        let mut rates = ToleranceRates::from_choices(&self.choices);
        for (deviation, change) in rates.deviations.iter_mut().zip(kept) {
            *deviation += change.unwrap_or(0.0);
        }
        Ok(rates)
    }
}

/// The choices of `faces` at the mesh's current positions.
fn choose(
    table: &StencilTable,
    mesh: &Mesh,
    patches: &[FacePatch],
    tolerance: f64,
    sorted: &[u32],
    faces: &[usize],
) -> Result<Vec<FaceChoice>, RuntimeError> {
    with_selection(table, mesh, patches, tolerance, sorted, |choose| {
        faces
            .par_iter()
            .map(|&f| choose(f))
            .collect::<Result<Vec<_>, _>>()
    })
}

impl Neighbourhoods {
    /// Per face the control points of every face sharing a vertex with it (the samples read
    /// the face's own, `L_{f,n}` the rows and corner points of those around it) and the bounds
    /// of their stencils.
    fn new(
        table: &StencilTable,
        mesh: &Mesh,
        patches: &[FacePatch],
        positions: &[[f64; 3]],
    ) -> Result<Self, RuntimeError> {
        // The faces sampled adaptively, which the bound does not cover.
        let adaptive = adaptive_face_list(table, mesh, patches)?;
        let mut index: HashMap<PatchKind, usize> = HashMap::new();
        let mut kinds = Vec::new();
        for patch in patches {
            index.entry(patch.kind).or_insert_with(|| {
                kinds.push(patch.kind);
                kinds.len() - 1
            });
        }
        let kind_bounds = kinds
            .par_iter()
            .map(|kind| KindBounds::new(table, kind))
            .collect::<Vec<_>>();
        let bounds_of = |g: usize| index.get(&patches[g].kind).map(|&k| &kind_bounds[k]);
        let per_face = (0..patches.len())
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
                let mut bounds = [StencilBound::NONE; MAX_SELECTED_RATE as usize + 1];
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
            .collect::<Vec<_>>();
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
        let mut near = Neighbourhoods {
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
            near.record(f, mesh.face(f), positions);
        }
        Ok(near)
    }

    /// Face `f` (its corners `corners`) sampled at `positions`: where its neighbourhood is.
    fn record(&mut self, f: usize, corners: &[u32], positions: &[[f64; 3]]) {
        let (centre, frame) = corner_frame(corners, positions);
        let range = self.offsets[f]..self.offsets[f + 1];
        let (mut scale, mut radius) = (0.0f64, 0.0f64);
        for (kept, &i) in self.sampled[range.clone()]
            .iter_mut()
            .zip(&self.points[range])
        {
            let p = positions[i as usize];
            let d = sub(p, centre);
            *kept = d.map(|x| x as f32);
            scale = scale.max(norm(p));
            radius = radius.max(norm(d));
        }
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
        let mut rotation = [[0.0; 3]; 3];
        for (r, row) in rotation.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = (0..3).map(|k| frame[k][r] * from[k][c]).sum();
            }
        }
        let range = self.offsets[f]..self.offsets[f + 1];
        let (mut residual, mut scale) = (0.0f64, 0.0f64);
        for (kept, &i) in self.sampled[range.clone()].iter().zip(&self.points[range]) {
            let d = kept.map(f64::from);
            let q = now[i as usize];
            let carried = [0, 1, 2].map(|r| centre[r] + dot(rotation[r], d));
            residual = residual.max(norm(sub(q, carried)));
            scale = scale.max(norm(q));
        }
        let turned = [0, 1, 2].map(|r| dot(rotation[r], self.centres[f]));
        Motion {
            // A stored coordinate is within 2^-24 of its size of the f64 one.
            residual: residual + self.radius[f] * 2f64.powi(-23),
            translation: norm(sub(centre, turned)),
            scale,
        }
    }
}

/// How a face's neighbourhood moved since the face was sampled ([`Neighbourhoods::residual`]).
struct Motion {
    /// The largest distance of a point from where the rigid map carries its place then.
    residual: f64,
    /// The length of the rigid map's translation, `|c' - R c|`.
    translation: f64,
    /// The largest distance of a point from the origin now.
    scale: f64,
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
            let k = weights.len() / (side * side).max(1);
            if k == 0 {
                return StencilBound::NONE;
            }
            // A norm never below one: the closed-form B-spline samples have non-negative weights
            // summing to one, whatever the table's rounding.
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

// The embedded Catmull–Clark table's.
#[cfg(all(test, feature = "catmull-clark"))]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::octahedron;
    use crate::scheme::catmull_clark::isolate::isolate;
    use crate::tessellate::rates::tolerance_rates;

    /// `p` turned by `angle` about the axis `(1, 2, 2) / 3` and moved by `shift`.
    fn rigid(p: [f64; 3], angle: f64, shift: [f64; 3]) -> [f64; 3] {
        let k = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
        let (sin, cos) = angle.sin_cos();
        let across = cross(k, p);
        let along = dot(k, p) * (1.0 - cos);
        [0, 1, 2].map(|c| p[c] * cos + across[c] * sin + k[c] * along + shift[c])
    }

    /// The rates of the memory and of a fresh selection through frames that stay, turn, move,
    /// bend and grow an isolated octahedron: the same every frame, the memory's deviations at
    /// least the measured ones, and few faces sampled where nothing but a rigid motion (and
    /// rounding) happened. The fresh rates of every frame.
    fn kept_through_frames(tolerance: f64) -> Vec<Vec<u32>> {
        let table = StencilTable::default_catmull_clark().expect("embedded table");
        // Valence-3 and valence-4 vertices, two isolating steps: table faces of both kinds.
        let (mut mesh, patches, _) = isolate(&octahedron()).expect("isolates");
        let rest = mesh.positions.clone();
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
        let turn = |points: Vec<[f64; 3]>| -> Vec<[f64; 3]> {
            points
                .into_iter()
                .map(|p| rigid(p, 0.7, [3.0, -1.0, 0.5]))
                .collect()
        };
        let frames: Vec<(&str, Vec<[f64; 3]>)> = vec![
            ("first", rest.clone()),
            ("at rest again", rest.clone()),
            ("turned and moved", turn(rest.clone())),
            ("turned, moved and touched", turn(bump(1e-6 * tolerance))),
            ("bumped", bump(0.3)),
            ("grown", rest.iter().map(|p| p.map(|c| 1.7 * c)).collect()),
        ];
        let mut memory = None;
        let mut fresh_rates = Vec::new();
        for (label, positions) in frames {
            mesh.positions = positions;
            let kept = RateMemory::rates(
                &mut memory,
                &table,
                &mesh,
                &patches,
                tolerance,
                &RATIONAL_RATES,
            )
            .expect("kept");
            let fresh = tolerance_rates(&table, &mesh, &patches, tolerance).expect("fresh");
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
                "first" => assert_eq!(sampled, patches.len(), "the first frame samples all"),
                "bumped" | "grown" => assert!(sampled > 0, "{label}: nothing sampled"),
                _ => assert!(
                    sampled * 10 < patches.len(),
                    "{label}: {sampled} of {} faces sampled at {tolerance}",
                    patches.len()
                ),
            }
            fresh_rates.push(fresh.rates);
        }
        fresh_rates
    }

    #[test]
    fn kept_rates_are_a_fresh_selections() {
        let rates = kept_through_frames(1e-2);
        // The bump and the growth move rates: a memory that kept everything would fail above.
        assert_ne!(rates[3], rates[4], "the bump moves no rate");
        assert_ne!(rates[4], rates[5], "the growth moves no rate");
        // No rate meets this one: every face keeps the largest while every rate stays refuted.
        let rates = kept_through_frames(1e-7);
        assert!(rates.iter().flatten().all(|&n| n == MAX_SELECTED_RATE));
    }
}
