//! Table stencils regrouped for evaluating [`LANES`] points at once, for the faces of both dual
//! grids that take their table stencils ([`crate::tessellate::triangle_dual_grid`], and the
//! quad faces of [`crate::tessellate::dual_grid`] that are not tensor products).
//!
//! A face's point `t` is, as everywhere in the dual grid, three dot products over the patch's
//! `K` control points `q_l` (relative to the first, [`crate::tessellate::kernel::relative`]):
//!
//! ```text
//! P(t) = O + sum_l w_l(t) q_l,   P_u(t) = sum_l u_l(t) q_l,   P_v(t) = sum_l v_l(t) q_l,
//! N(t) = unit(P_u(t) x P_v(t)),
//! ```
//!
//! each sum taken in the order `l = 0..K`. The table stores the weights point by point
//! (`w_0(t) .. w_{K-1}(t)`), so one point at a time is a chain of `3 K` dependent additions per
//! coordinate that the compiler may not reorder (float addition is not associative) and so
//! cannot vectorize. Here the weights of [`LANES`] consecutive output points are interleaved
//! (`[l][position, d/du, d/dv][lane]`), once per table section, face corner and rate when the
//! plan is built: a step `l` is then one vector multiply-add per quantity and coordinate for
//! all the lanes, each lane still summing its own point in the order `l = 0..K`. The result is
//! bit-identical to the point-by-point sums (`tests::stencil_point`, the scalar formula),
//! in about a quarter of the instructions.

use wide::{f32x4, CmpGe, CmpLt};

use std::ops::Range;

use crate::mesh::triangle_mesh::VertexSource;
use crate::tessellate::kernel::{
    cross, for_each_range, patch_origin, relative, total_bytes, unit, vec_bytes, PointPlan,
    Stencils, MAX_PATCH,
};
use crate::RuntimeError;

/// Points evaluated together (SSE's four f32, the baseline x86-64 vector).
pub(crate) const LANES: usize = 4;

/// One step `l` of a group of points: the weights of control point `l` for position, d/du and
/// d/dv, one lane per point (aligned vectors: a multiply takes its weights from memory).
pub(crate) type LaneWeights = [f32x4; 3];

/// A control point's coordinates, each broadcast to every lane once per face (not once per
/// group of points).
pub(crate) type Splat = [f32x4; 3];

/// The stencils of every point of one kind of face (table section, face corner, rate) in the
/// face's output order, `LANES` points a group.
#[derive(Clone, Debug)]
pub(crate) struct LaneStencils {
    /// Control points of the patch (`K`).
    k: usize,
    /// Output points of the face.
    points: usize,
    /// `weights[g * k + l]`: group `g`'s weights of control point `l`. The last group's unused
    /// lanes repeat its last point (evaluated, not written).
    weights: Vec<LaneWeights>,
}

impl LaneStencils {
    /// Its weights' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        vec_bytes(&self.weights)
    }

    /// The stencils of the face's `points` points, point `t` being row `row(t).1` of the
    /// stencils `row(t).0` (`k` weights a row); `None` if a row is out of range.
    pub(crate) fn new<'a>(
        k: usize,
        points: usize,
        row: impl Fn(usize) -> (&'a Stencils<'a>, usize),
    ) -> Option<Self> {
        let groups = points.div_ceil(LANES);
        let mut weights = vec![[[0.0f32; LANES]; 3]; groups * k];
        for g in 0..groups {
            for lane in 0..LANES {
                let t = (g * LANES + lane).min(points.checked_sub(1)?);
                let (s, r) = row(t);
                let rows = r * k..(r + 1) * k;
                let (wp, wu, wv) = (
                    s.position.get(rows.clone())?,
                    s.du.get(rows.clone())?,
                    s.dv.get(rows)?,
                );
                for l in 0..k {
                    let w = &mut weights[g * k + l];
                    w[0][lane] = wp[l];
                    w[1][lane] = wu[l];
                    w[2][lane] = wv[l];
                }
            }
        }
        let weights = weights.into_iter().map(|w| w.map(f32x4::new)).collect();
        Some(LaneStencils { k, points, weights })
    }

    /// Control points of the patch.
    pub(crate) fn control_points(&self) -> usize {
        self.k
    }

    /// Every point from the patch whose control points are the vertices `points` of `control`
    /// (made [`relative`] to the first as they are broadcast; nothing if they are not `K`), into
    /// `positions[t]`, `normals[t]`.
    pub(crate) fn evaluate_patch(
        &self,
        points: &[u32],
        control: &[[f64; 3]],
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        if points.len() != self.k {
            return;
        }
        let origin = patch_origin(points, control);
        self.evaluate_with(
            |l| relative(control[points[l] as usize], origin),
            origin.map(|c| c as f32),
            |t| t,
            positions,
            normals,
        );
    }

    /// Every point of a face from its control points `point(0..K)`, relative to `origin`
    /// ([`relative`]).
    ///
    /// Why the common patch sizes get their own copies: the control points sit in fixed stack
    /// slots, written once as they are broadcast (no buffer cleared first, no loop counter
    /// over `K`): Loop's regular 12, Catmull–Clark's `2N + 8` at valences 3, 5 and 6 (14, 18,
    /// 20), the butterfly's and √3's 27. The copies for 14, 18 and 20 took a rate-4 frame of
    /// the triangulated Spot, half of its faces at those valences, from 13.9 to 13.2 ms
    /// (docs/benchmarks.md); the rest share one.
    ///
    /// The group of points `t..t + LANES` goes to `place(t)..` of `positions` and `normals`
    /// (the identity for a face's own points; rows of a block of a larger grid for the
    /// quarter of a split face, `crate::tessellate::sub_patches`).
    #[inline(always)]
    pub(crate) fn evaluate_with(
        &self,
        point: impl Fn(usize) -> [f32; 3],
        origin: [f32; 3],
        place: impl Fn(usize) -> usize,
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        match self.k {
            12 => self.evaluate_fixed::<12>(point, origin, place, positions, normals),
            14 => self.evaluate_fixed::<14>(point, origin, place, positions, normals),
            18 => self.evaluate_fixed::<18>(point, origin, place, positions, normals),
            20 => self.evaluate_fixed::<20>(point, origin, place, positions, normals),
            27 => self.evaluate_fixed::<27>(point, origin, place, positions, normals),
            _ => self.evaluate_any(point, origin, place, positions, normals),
        }
    }

    #[inline(always)]
    fn evaluate_fixed<const K: usize>(
        &self,
        point: impl Fn(usize) -> [f32; 3],
        origin: [f32; 3],
        place: impl Fn(usize) -> usize,
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        let q: [Splat; K] = std::array::from_fn(|l| point(l).map(f32x4::splat));
        let mut sums = [[[f32x4::ZERO; 3]; 3]; CHUNK];
        for (c, weights) in self.weights.chunks(K * CHUNK).enumerate() {
            chunk_sums_fixed::<K>(weights, &q, origin, &mut sums);
            self.write(
                c * CHUNK,
                &sums[..weights.len() / K],
                &place,
                positions,
                normals,
            );
        }
    }

    fn evaluate_any(
        &self,
        point: impl Fn(usize) -> [f32; 3],
        origin: [f32; 3],
        place: impl Fn(usize) -> usize,
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        // Feature-adaptive stencils can be wider than MAX_PATCH (729 points next to a
        // valence-360 vertex).
        let mut fixed = [[f32x4::ZERO; 3]; MAX_PATCH];
        let mut wide = Vec::new();
        let q = if self.k <= MAX_PATCH {
            &mut fixed[..self.k]
        } else {
            wide.resize(self.k, [f32x4::ZERO; 3]);
            &mut wide[..]
        };
        for (l, q) in q.iter_mut().enumerate() {
            *q = point(l).map(f32x4::splat);
        }
        let mut sums = [[[f32x4::ZERO; 3]; 3]; CHUNK];
        for (c, weights) in self.weights.chunks(self.k * CHUNK).enumerate() {
            chunk_sums_any(self.k, weights, q, origin, &mut sums);
            self.write(
                c * CHUNK,
                &sums[..weights.len() / self.k],
                &place,
                positions,
                normals,
            );
        }
    }

    /// Groups `first..` from their sums: positions and unit normals.
    #[inline(always)]
    fn write(
        &self,
        first: usize,
        sums: &[LaneSums],
        place: &impl Fn(usize) -> usize,
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        for (g, &[p, du, dv]) in sums.iter().enumerate() {
            let normal = unit_cross_x4(du, dv);
            let start = (first + g) * LANES;
            let count = self.points.min(start + LANES) - start;
            let at = place(start);
            store_points(p, &mut positions[at..at + count]);
            store_points(normal, &mut normals[at..at + count]);
        }
    }
}

/// The points evaluated on their own (boundary curves, limit points, their seam copies), in
/// runs of consecutive points over the same control points, each run's stencils in lanes.
///
/// Why: a point planned on its own reads its patch's `K` control points and makes each
/// relative ([`relative`]) for one point, which costs as much as its sums; the `n - 1`
/// curve points of an edge come from one face's patch, so one gather serves them all, and their
/// sums run four at a time. Each point is still its own stencil summed in its own order from the
/// run's first control point, the origin it had alone: bit-identical.
#[derive(Clone, Debug, Default)]
pub(crate) struct PointGroups {
    /// Every run's control points (a range of the plan's indices) and stencils.
    runs: Vec<(Range<u32>, LaneStencils)>,
    /// Points up to the end of each run (prefix sums).
    ends: Vec<usize>,
    /// Where every point lies, in order.
    sources: Vec<VertexSource>,
}

impl PointGroups {
    /// Its runs', ends' and sources' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        total_bytes(
            self.runs
                .iter()
                .map(|(_, lanes)| lanes.heap_bytes())
                .chain([
                    vec_bytes(&self.runs),
                    vec_bytes(&self.ends),
                    vec_bytes(&self.sources),
                ]),
        )
    }

    /// The runs of `plans` (point `i` over `indices[plans[i].control]`, its position, d/du and
    /// d/dv weights one block after the other); an error if a plan's weights are not three
    /// blocks as long as its control points.
    pub(crate) fn new(plans: &[PointPlan], indices: &[u32]) -> Result<Self, RuntimeError> {
        Self::runs(plans, indices).ok_or_else(|| {
            RuntimeError::Unsupported("a point's stencil is not its patch's".to_owned())
        })
    }

    /// Where every point lies, in order.
    pub(crate) fn sources(&self) -> &[VertexSource] {
        &self.sources
    }

    fn runs(plans: &[PointPlan], indices: &[u32]) -> Option<Self> {
        let control =
            |plan: &PointPlan| indices.get(plan.control.start as usize..plan.control.end as usize);
        let mut groups = PointGroups::default();
        let mut start = 0;
        while start < plans.len() {
            let first = control(&plans[start])?;
            let mut end = start + 1;
            while end < plans.len() && control(&plans[end])? == first {
                end += 1;
            }
            let k = first.len();
            let stencils = plans[start..end]
                .iter()
                .map(|plan| {
                    let (position, rest) = plan.weights.split_at_checked(k)?;
                    let (du, dv) = rest.split_at_checked(k)?;
                    (dv.len() == k).then_some(Stencils { position, du, dv })
                })
                .collect::<Option<Vec<_>>>()?;
            let lanes = LaneStencils::new(k, end - start, |t| (&stencils[t], 0))?;
            groups.runs.push((plans[start].control.clone(), lanes));
            groups.ends.push(end);
            start = end;
        }
        groups.sources = plans.iter().map(|p| p.source).collect();
        Some(groups)
    }

    /// Every point from the vertices `control` (the plan's `indices` name them), into
    /// `positions[i]`, `normals[i]`, the runs in parallel.
    pub(crate) fn evaluate(
        &self,
        indices: &[u32],
        control: &[[f64; 3]],
        positions: &mut [[f32; 3]],
        normals: &mut [[f32; 3]],
    ) {
        for_each_range(&self.ends, (positions, normals), |r, (p, q)| {
            let (range, lanes) = &self.runs[r];
            let points = &indices[range.start as usize..range.end as usize];
            lanes.evaluate_patch(points, control, p, q);
        });
    }
}

/// One group's sums: `[position, d/du, d/dv][coordinate]`, a point per lane.
pub(crate) type LaneSums = [[f32x4; 3]; 3];

/// Groups whose sums are made by one call of [`chunk_sums_fixed`] or [`chunk_sums_any`].
///
/// Why 4: the buffer of sums is cleared once per face, and a rate-4 face is four groups;
/// eight cleared twice what a rate-4 face used (the triangulated Spot's rate-4 frame 13.1 ->
/// 12.7 ms with four, docs/benchmarks.md).
pub(crate) const CHUNK: usize = 4;

/// The sums of up to [`CHUNK`] groups (`weights`, `K` steps a group) over the control points
/// `q`.
///
/// Why a function of its own, not inlined: where the sums are transposed into points right
/// after (`[x, y, z]` a lane), the compiler's vectorizer groups the multiply-adds by coordinate
/// instead of by lane, shuffling every step (measured: three times the instructions); made
/// apart and stored whole, every step is one vector multiply-add per quantity and coordinate.
#[inline(never)]
pub(crate) fn chunk_sums_fixed<const K: usize>(
    weights: &[LaneWeights],
    q: &[Splat; K],
    origin: [f32; 3],
    out: &mut [LaneSums; CHUNK],
) {
    for (out, weights) in out.iter_mut().zip(weights.chunks_exact(K)) {
        *out = sums(weights, q, origin);
    }
}

/// [`chunk_sums_fixed`] for any patch size `k`.
#[inline(never)]
fn chunk_sums_any(
    k: usize,
    weights: &[LaneWeights],
    q: &[Splat],
    origin: [f32; 3],
    out: &mut [LaneSums; CHUNK],
) {
    for (out, weights) in out.iter_mut().zip(weights.chunks_exact(k)) {
        *out = sums(weights, q, origin);
    }
}

/// One group's sums over the control points `q`, the position's started at `origin`, each in
/// the order of `q`.
#[inline(always)]
fn sums(weights: &[LaneWeights], q: &[Splat], origin: [f32; 3]) -> LaneSums {
    let mut p = origin.map(f32x4::splat);
    let mut du = [f32x4::ZERO; 3];
    let mut dv = [f32x4::ZERO; 3];
    for (w, q) in weights.iter().zip(q) {
        for x in 0..3 {
            p[x] += w[0] * q[x];
            du[x] += w[1] * q[x];
            dv[x] += w[2] * q[x];
        }
    }
    [p, du, dv]
}

/// `unit(cross(a, b))` lane by lane, with [`cross`] and [`unit`](fn@unit)'s operations in their order
/// (bit-identical), the square root and division vectorized where every lane's squared length
/// is a normal float.
#[inline(always)]
pub(crate) fn unit_cross(a: [[f32; LANES]; 3], b: [[f32; LANES]; 3]) -> [[f32; 3]; LANES] {
    let [x, y, z] = unit_cross_x4(a.map(f32x4::new), b.map(f32x4::new)).map(f32x4::to_array);
    std::array::from_fn(|k| [x[k], y[k], z[k]])
}

/// [`unit_cross`] on vectors (`[coordinate]`, a lane per pair), the result the same way.
#[inline(always)]
pub(crate) fn unit_cross_x4(a: [f32x4; 3], b: [f32x4; 3]) -> [f32x4; 3] {
    let m = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let squared = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    // `is_normal` in every lane: finite, not zero and not subnormal (NaN fails both).
    let normal = squared.cmp_ge(f32x4::splat(f32::MIN_POSITIVE))
        & squared.cmp_lt(f32x4::splat(f32::INFINITY));
    if normal.all() {
        let length = squared.sqrt();
        m.map(|c| c / length)
    } else {
        // A degenerate or tiny tangent pair somewhere: unit's careful path, lane by lane.
        let (a, b) = (a.map(f32x4::to_array), b.map(f32x4::to_array));
        let units: [[f32; 3]; LANES] = std::array::from_fn(|k| {
            unit(cross(
                [a[0][k], a[1][k], a[2][k]],
                [b[0][k], b[1][k], b[2][k]],
            ))
        });
        std::array::from_fn(|c| f32x4::new(units.map(|u| u[c])))
    }
}

/// Write the points `[x, y, z]` (a point per lane) to `out`, the first `out.len()` lanes (at
/// most [`LANES`]).
///
/// Why: built lane by lane, a group's points went through the stack in pieces the next loads
/// could not take from the store buffer (15% of a rate-16 frame stalled on one such load);
/// transposed in registers, a whole group leaves in four stores, each point's fourth lane
/// spilling onto the next point's first coordinate, which that point's own store then writes.
#[inline(always)]
pub(crate) fn store_points(v: [f32x4; 3], out: &mut [[f32; 3]]) {
    store_lanes::<false>(v, out);
}

/// [`store_points`] with the lanes in reverse order: lane 3 at `out[0]`, ..., lane 0 at
/// `out[3]` (`out` holds all four), the same four stores (the lanes reversed before the store
/// went through the stack in pieces, as above).
#[inline(always)]
pub(crate) fn store_points_reversed(v: [f32x4; 3], out: &mut [[f32; 3]]) {
    store_lanes::<true>(v, out);
}

/// [`store_points`], lane `k` at `out[k]`, or at `out[3 - k]` when `REVERSED`.
#[inline(always)]
fn store_lanes<const REVERSED: bool>(v: [f32x4; 3], out: &mut [[f32; 3]]) {
    let t = f32x4::transpose([v[0], v[1], v[2], f32x4::ZERO]).map(f32x4::to_array);
    let lane = |k: usize| if REVERSED { LANES - 1 - k } else { k };
    if let Ok(out) = <&mut [[f32; 3]; LANES]>::try_from(&mut *out) {
        let flat = out.as_flattened_mut();
        flat[0..4].copy_from_slice(&t[lane(0)]);
        flat[3..7].copy_from_slice(&t[lane(1)]);
        flat[6..10].copy_from_slice(&t[lane(2)]);
        flat[9..12].copy_from_slice(&t[lane(3)][..3]);
    } else if !REVERSED {
        for (o, t) in out.iter_mut().zip(&t) {
            *o = [t[0], t[1], t[2]];
        }
    }
}

/// Deterministic pseudo-random numbers in `[-1/2, 1/2)` (a linear congruential sequence from
/// `seed`), for the tests that compare lanes with scalar sums.
#[cfg(test)]
pub(crate) fn test_numbers(seed: u32) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The point-by-point formula the lanes must reproduce: position and unit normal of row
    /// `point` of `s`, a stencil of `k` weights a point, over the control points `q(0..k)`,
    /// relative to `origin` ([`relative`]): the position `origin + sum w q`, and the
    /// cross product of the two derivatives `sum w_u q`, `sum w_v q`.
    fn stencil_point(
        s: &Stencils,
        k: usize,
        point: usize,
        origin: [f32; 3],
        q: impl Fn(usize) -> [f32; 3],
    ) -> ([f32; 3], [f32; 3]) {
        let rows = point * k..(point + 1) * k;
        let (wp, wu, wv) = (&s.position[rows.clone()], &s.du[rows.clone()], &s.dv[rows]);
        let mut p = [origin, [0.0; 3], [0.0; 3]];
        for l in 0..k {
            let q = q(l);
            for x in 0..3 {
                p[0][x] += wp[l] * q[x];
                p[1][x] += wu[l] * q[x];
                p[2][x] += wv[l] * q[x];
            }
        }
        (p[0], unit(cross(p[1], p[2])))
    }

    /// Points planned one by one come out as each alone would: runs of equal control points
    /// (also from different ranges of the indices) share a gather, other points do not, and a
    /// patch wider than [`MAX_PATCH`] is taken too.
    #[test]
    fn point_groups_are_each_point_alone_bit_for_bit() {
        let mut next = test_numbers(0x9e37_79b9);
        let vertices: Vec<[f64; 3]> = (0..60)
            .map(|_| [0, 1, 2].map(|_| f64::from(next()) * 10.0 + 1000.0))
            .collect();
        let wide: Vec<u32> = (0..45).collect();
        let mut indices = Vec::new();
        let mut plans = Vec::new();
        for (points, count) in [
            (vec![3u32, 7, 1, 9, 12], 3),
            (vec![3, 7, 1, 9, 12], 2),
            (vec![20, 21, 22, 5, 6, 7, 8], 1),
            (wide, 5),
            (vec![3, 7, 1, 9, 12], 1),
        ] {
            for _ in 0..count {
                let start = indices.len() as u32;
                indices.extend_from_slice(&points);
                let weights = (0..3 * points.len()).map(|_| next()).collect();
                plans.push(PointPlan {
                    weights,
                    control: start..indices.len() as u32,
                    source: VertexSource::default(),
                });
            }
        }
        let groups = PointGroups::new(&plans, &indices).expect("three blocks a plan");
        assert_eq!(groups.sources().len(), plans.len());
        assert_eq!(groups.ends, [5, 6, 11, 12], "runs of equal control points");
        let mut positions = vec![[0.0f32; 3]; plans.len()];
        let mut normals = vec![[0.0f32; 3]; plans.len()];
        groups.evaluate(&indices, &vertices, &mut positions, &mut normals);
        for (i, plan) in plans.iter().enumerate() {
            let points = &indices[plan.control.start as usize..plan.control.end as usize];
            let k = points.len();
            let s = Stencils {
                position: &plan.weights[..k],
                du: &plan.weights[k..2 * k],
                dv: &plan.weights[2 * k..],
            };
            let origin = vertices[points[0] as usize];
            let (p, n) = stencil_point(&s, k, 0, origin.map(|c| c as f32), |l| {
                let v = vertices[points[l] as usize];
                [0, 1, 2].map(|x| (v[x] - origin[x]) as f32)
            });
            assert_eq!(
                positions[i].map(f32::to_bits),
                p.map(f32::to_bits),
                "point {i}"
            );
            assert_eq!(
                normals[i].map(f32::to_bits),
                n.map(f32::to_bits),
                "point {i}"
            );
        }
    }

    /// The lanes give the point-by-point sums bit for bit, for every count of points (full and
    /// short last groups) and patch size (the unrolled ones and others).
    #[test]
    fn lanes_are_the_point_by_point_sums_bit_for_bit() {
        let mut next = test_numbers(0x2545_f491);
        for k in [5, 12, 13, 14, 18, 20, 27, 33] {
            for points in [1, 3, 4, 7, 19] {
                let block = |next: &mut dyn FnMut() -> f32| -> Vec<f32> {
                    (0..points * k).map(|_| next()).collect()
                };
                let (wp, wu, wv) = (block(&mut next), block(&mut next), block(&mut next));
                let s = Stencils {
                    position: &wp,
                    du: &wu,
                    dv: &wv,
                };
                let local: Vec<[f32; 3]> = (0..k).map(|_| [next(), next(), next()]).collect();
                let origin = [next() * 100.0, next(), -3.0];
                // Rows in reverse order, as a rotated face reads them.
                let lanes =
                    LaneStencils::new(k, points, |t| (&s, points - 1 - t)).expect("rows in range");
                let mut positions = vec![[0.0f32; 3]; points];
                let mut normals = vec![[0.0f32; 3]; points];
                lanes.evaluate_with(|l| local[l], origin, |t| t, &mut positions, &mut normals);
                for t in 0..points {
                    let (p, n) = stencil_point(&s, k, points - 1 - t, origin, |l| local[l]);
                    assert_eq!(positions[t].map(f32::to_bits), p.map(f32::to_bits));
                    assert_eq!(normals[t].map(f32::to_bits), n.map(f32::to_bits));
                }
            }
        }
    }

    #[test]
    fn degenerate_tangents_take_units_path() {
        let zero = [[0.0f32; LANES]; 3];
        let mut a = zero;
        let mut b = zero;
        a[0] = [1.0, 0.0, 1e-30, 2.0];
        b[1] = [1.0, 0.0, 1e-30, 3.0];
        let out = unit_cross(a, b);
        for k in 0..LANES {
            let want = unit(cross(
                [a[0][k], a[1][k], a[2][k]],
                [b[0][k], b[1][k], b[2][k]],
            ));
            assert_eq!(out[k].map(f32::to_bits), want.map(f32::to_bits));
        }
    }
}
