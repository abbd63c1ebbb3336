//! The dual-grid kernel the quad grid ([`crate::tessellate::dual_grid`]) and the triangle grid
//! ([`crate::tessellate::triangle_dual_grid`]) share: table stencil rows and their evaluation,
//! the points evaluated one by one (limit points, boundary curves), and the connectivity of a
//! plan (face interiors, strips along edges, polygons around vertices) written in parallel at
//! precomputed offsets.

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

pub(crate) use crate::mesh::geometry::{cross, normalize as unit};
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};
use crate::mesh::Mesh;
use crate::scheme::patch::{is_table_patch, FacePatch};
use crate::scheme::stencil::Stencil;
use crate::RuntimeError;
use table_format::TableError;

/// The largest patch (control points) the evaluator takes: an interior quad vertex of valence
/// `v` has `2v + 8`, a boundary vertex with `k` faces `2k + 8`; a triangle patch at most 40.
pub(crate) const MAX_PATCH: usize = 40;

/// Whether the tessellators evaluate face `face` from its table patch: a patch the tables
/// describe ([`is_table_patch`]: nothing sharp at its corners, a dart's, or a crease sector's)
/// and the kernels take (at most [`MAX_PATCH`] points). Every other face is evaluated by
/// feature-adaptive refinement, and so is a face whose patch the table lacks.
pub(crate) fn table_may_describe(mesh: &Mesh, patch: &FacePatch, face: usize) -> bool {
    is_table_patch(mesh, face) && patch.points.len() <= MAX_PATCH
}

/// A table lookup for a face the table may describe, where a section the table does not have
/// is `None` (the face is then refined adaptively, like one beyond the table) and any other
/// failure, a malformed user table for one, is the error it is: a table that cannot be read is
/// refused, not silently bypassed.
pub(crate) fn unless_absent<T>(lookup: Result<T, RuntimeError>) -> Result<Option<T>, RuntimeError> {
    match lookup {
        Ok(found) => Ok(Some(found)),
        Err(RuntimeError::Table(TableError::MissingSection { .. })) => Ok(None),
        Err(e) => Err(e),
    }
}

/// Timings of one tessellation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TessellationTime {
    /// Seconds spent building the plan (table lookups, patches' connectivity records).
    pub plan_seconds: f64,
    /// Seconds spent evaluating and connecting (the per-frame work).
    pub seconds: f64,
}

/// The three stencils of one point set of one patch: `points x K` weights each, point-major.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stencils<'t> {
    pub(crate) position: &'t [f32],
    pub(crate) du: &'t [f32],
    pub(crate) dv: &'t [f32],
}

/// A point evaluated on its own (the boundary curve, limit points): its position, d/du and
/// d/dv weights (`control.len()` each, one block after the other), copied from a table row or
/// computed when the plan is built.
#[derive(Clone, Debug)]
pub(crate) struct PointPlan {
    pub(crate) weights: Vec<f32>,
    pub(crate) control: Range<u32>,
    pub(crate) source: VertexSource,
}

/// The heap bytes of `v`'s buffer: its capacity, not its length (a plan's weight,
/// [`GridPlan::heap_bytes`]).
pub(crate) fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity().saturating_mul(std::mem::size_of::<T>())
}

/// The sum of `parts` (heap bytes), saturating.
pub(crate) fn total_bytes(parts: impl IntoIterator<Item = usize>) -> usize {
    parts.into_iter().fold(0, usize::saturating_add)
}

impl PointPlan {
    /// Its weights' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        vec_bytes(&self.weights)
    }

    /// The point of row `row` of `s` (a patch of `k` control points).
    pub(crate) fn from_row(
        s: &Stencils,
        row: usize,
        k: usize,
        control: Range<u32>,
        source: VertexSource,
    ) -> Self {
        let rows = row * k..(row + 1) * k;
        let mut weights = Vec::with_capacity(3 * k);
        for block in [s.position, s.du, s.dv] {
            weights.extend_from_slice(&block[rows.clone()]);
        }
        PointPlan {
            weights,
            control,
            source,
        }
    }
}

/// Run `work(item, slice)` for every item in parallel, where item `i` owns
/// `out[ends[i-1]..ends[i]]` (`ends` are prefix sums). Items are grouped into contiguous chunks of
/// about equal output so that the split costs little next to the work.
pub(crate) fn for_each_range<T: SplitSlices + Send>(
    ends: &[usize],
    out: T,
    work: impl Fn(usize, T) + Sync + Send,
) {
    for_each_range_with(ends, out, || (), |(), i, slice| work(i, slice));
}

/// [`for_each_range`] with a scratch value made once per chunk of items (`make`) and lent to
/// every item of the chunk: what a buffer cleared per item would cost, paid a few dozen times.
pub(crate) fn for_each_range_with<T: SplitSlices + Send, S>(
    ends: &[usize],
    out: T,
    make: impl Fn() -> S + Sync + Send,
    work: impl Fn(&mut S, usize, T) + Sync + Send,
) {
    let total = ends.last().copied().unwrap_or(0);
    let chunks = (rayon::current_num_threads() * 16).max(1);
    let target = total.div_ceil(chunks).max(1);
    // Chunk boundaries in items: [item_start, item_end), with their output ranges.
    let mut pieces = Vec::with_capacity(chunks + 1);
    let mut rest = out;
    let (mut item, mut consumed) = (0usize, 0usize);
    while item < ends.len() {
        let start_item = item;
        let start = consumed;
        while item < ends.len() && (ends[item] - start < target || item == start_item) {
            item += 1;
        }
        let end = ends[item - 1];
        let (piece, tail) = rest.split_at(end - start);
        rest = tail;
        consumed = end;
        pieces.push((start_item..item, start, piece));
    }
    pieces
        .into_par_iter()
        .for_each(|(items, start, mut piece)| {
            let mut scratch = make();
            let mut at = start;
            for i in items {
                let (mine, tail) = piece.split_at(ends[i] - at);
                piece = tail;
                at = ends[i];
                work(&mut scratch, i, mine);
            }
        });
}

/// Run `work(scratch, item)` on every item of `items`, dealt in their order: each thread takes
/// the next item not yet taken (one shared counter: self-scheduling) and works on it with a
/// scratch value of its own (`make`); the first error stops the dealing and is returned (one of
/// them, where two threads fail).
///
/// Why not rayon's halving of the list: it makes a tree of joins, and a thread that waits at one
/// for longer than it spins goes to sleep, which on the development host costs tens of µs to
/// wake (the cage, pass 1 of Lai–Cheng: docs/benchmarks.md). Dealt one at a time, with
/// the costly items first, the threads end within one cheap item of each other and meet once.
pub(crate) fn for_each_dealt<T: Send, S, E: Send>(
    items: &mut [T],
    make: impl Fn() -> S + Sync,
    work: impl Fn(&mut S, &mut T) -> Result<(), E> + Sync,
) -> Result<(), E> {
    // Each item is taken once: its lock is never waited for.
    let slots: Vec<Mutex<&mut T>> = items.iter_mut().map(Mutex::new).collect();
    let next = AtomicUsize::new(0);
    let deal = || -> Result<(), E> {
        let mut scratch = make();
        while let Some(slot) = slots.get(next.fetch_add(1, Ordering::Relaxed)) {
            let mut item = slot.lock().unwrap_or_else(PoisonError::into_inner);
            if let Err(error) = work(&mut scratch, &mut item) {
                next.store(slots.len(), Ordering::Relaxed);
                return Err(error);
            }
        }
        Ok(())
    };
    (0..rayon::current_num_threads())
        .into_par_iter()
        .with_max_len(1)
        .try_for_each(|_| deal())
}

/// Mutable slices (or tuples of them, split in step) that [`for_each_range`] hands out.
pub(crate) trait SplitSlices: Sized {
    fn split_at(self, mid: usize) -> (Self, Self);
}

impl<T> SplitSlices for &mut [T] {
    fn split_at(self, mid: usize) -> (Self, Self) {
        self.split_at_mut(mid)
    }
}

impl<A, B> SplitSlices for (&mut [A], &mut [B]) {
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split_at_mut(mid);
        let (b0, b1) = self.1.split_at_mut(mid);
        ((a0, b0), (a1, b1))
    }
}

impl<A, B, C> SplitSlices for (&mut [A], &mut [B], &mut [C]) {
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split_at_mut(mid);
        let (b0, b1) = self.1.split_at_mut(mid);
        let (c0, c1) = self.2.split_at_mut(mid);
        ((a0, b0, c0), (a1, b1, c1))
    }
}

/// Merge two rows running along an edge into triangles, in order of their parameters
/// `param_a(i) / den_a` and `param_b(j) / den_b`; `b` lies to the right of the edge.
pub(crate) fn merge_rows(
    a: impl Fn(u32) -> u32,
    na: u32,
    param_a: impl Fn(u32) -> u64,
    b: impl Fn(u32) -> u32,
    nb: u32,
    param_b: impl Fn(u32) -> u64,
    out: &mut [[u32; 3]],
) {
    let (mut i, mut j, mut k) = (0, 0, 0);
    while i + 1 < na || j + 1 < nb {
        let advance_a = j + 1 == nb || (i + 1 < na && param_a(i + 1) <= param_b(j + 1));
        if advance_a {
            out[k] = [b(j), a(i + 1), a(i)];
            i += 1;
        } else {
            out[k] = [b(j), b(j + 1), a(i)];
            j += 1;
        }
        k += 1;
    }
}

/// The origin of a patch whose control points are `control[points[l]]`: its first point (zero
/// for none); see [`relative`].
#[inline(always)]
pub(crate) fn patch_origin(points: &[u32], control: &[[f64; 3]]) -> [f64; 3] {
    points.first().map_or([0.0; 3], |&v| control[v as usize])
}

/// `points` appended to a plan's control-point indices `control`, and where they lie there;
/// refused when the indices would pass `u32` (billions of patch corners).
pub(crate) fn append_control(
    control: &mut Vec<u32>,
    points: &[u32],
) -> Result<Range<u32>, RuntimeError> {
    let start = control.len();
    let end = start.saturating_add(points.len());
    let (Ok(first), Ok(last)) = (u32::try_from(start), u32::try_from(end)) else {
        return Err(RuntimeError::OverBudget {
            what: "the tessellation's plan".to_owned(),
            estimate: format!("{end} control-point indices for its patches"),
            limit: format!("{} indices", u32::MAX),
            raise: "the plan's indices are 32-bit".to_owned(),
        });
    };
    control.extend_from_slice(points);
    Ok(first..last)
}

/// Control point `p` relative to `origin` (a patch's, [`patch_origin`]), in f32: the difference
/// is taken in f64 and rounded once, so it carries the f32 precision of the patch's own extent,
/// whatever `origin`'s distance from the coordinate origin (docs/reliability.md, *Precision*).
///
/// Why every evaluation sums relative points: a derivative stencil's weights sum to zero, so
/// `sum w_l P_l = sum w_l (P_l - O)` for any `O`, but in f32 the left side's rounding grows with
/// `|P|`, the distance from the coordinate origin, while the right side's grows with
/// `|P_l - O|`, the patch's size. Tangents and normals are therefore computed from relative
/// points only, which makes them independent of where the mesh sits: a small face far from the
/// origin gets the normals it would get at the origin. Position stencils sum to one: the
/// position is `O + sum w_l (P_l - O)`, its sum started at `O` rounded to f32 (free, and rounded
/// at the scale of `|O|` as the output itself is).
#[inline(always)]
pub(crate) fn relative(p: [f64; 3], origin: [f64; 3]) -> [f32; 3] {
    [0, 1, 2].map(|x| (p[x] - origin[x]) as f32)
}

/// The weighted sum `sum_l row[l] control[l]` in f64, its terms added in the order of the
/// control points.
pub(crate) fn weighted_sum(control: &[[f64; 3]], row: &[f32]) -> [f64; 3] {
    weighted_sums(control, [row])[0]
}

/// The weighted sums of `control` by `M` rows of weights at once: `M` independent chains of
/// additions, where one sum alone waits on its own additions. Each sum adds its terms in the
/// order of the control points, so a point comes out bit for bit the same whichever rows it is
/// computed with ([`weighted_sum`] alone included).
#[inline]
pub(crate) fn weighted_sums<const M: usize>(
    control: &[[f64; 3]],
    rows: [&[f32]; M],
) -> [[f64; 3]; M] {
    let mut out = [[0.0; 3]; M];
    for (l, q) in control.iter().enumerate() {
        for (p, row) in out.iter_mut().zip(&rows) {
            let w = f64::from(row[l]);
            for c in 0..3 {
                p[c] += w * q[c];
            }
        }
    }
    out
}

/// The weighted sums of `control` by every row of `rows`, appended to `out` in order, four at a
/// time ([`weighted_sums`]).
pub(crate) fn extend_weighted_sums<'w>(
    control: &[[f64; 3]],
    mut rows: impl Iterator<Item = &'w [f32]>,
    out: &mut Vec<[f64; 3]>,
) {
    while let Some(first) = rows.next() {
        let mut four = [first; 4];
        let mut m = 1;
        while m < 4 {
            match rows.next() {
                Some(row) => four[m] = row,
                None => break,
            }
            m += 1;
        }
        if m == 4 {
            out.extend_from_slice(&weighted_sums(control, four));
        } else {
            // The last few one at a time, rather than sums of repeated rows.
            out.extend(four[..m].iter().map(|&row| weighted_sum(control, row)));
        }
    }
}

/// `list` made `len` entries long for a pass that overwrites every entry: only the entries
/// beyond its current length are filled with `fill`. A list kept from frame to frame keeps its
/// entries, stale until overwritten; emptying it first made each frame write all of it twice,
/// a serial `memset` of the whole output (Lai–Cheng's vertices and polygons, docs/benchmarks.md).
pub(crate) fn resize_to_overwrite<T: Clone>(list: &mut Vec<T>, len: usize, fill: T) {
    list.truncate(len);
    list.resize(len, fill);
}

/// Running totals of `counts`: item `i` owns `[ends[i-1], ends[i])`.
pub(crate) fn prefix_sums(counts: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut total = 0;
    counts
        .map(|c| {
            total += c;
            total
        })
        .collect()
}

/// The triangles of a plan in three groups, each item writing a disjoint slice: face interiors,
/// strips along edges, and the polygons around vertices (fanned from their first entry).
#[derive(Clone, Debug)]
pub(crate) struct Connectivity {
    /// Vertex polygons, concatenated; `polygon_offsets[v]..polygon_offsets[v+1]`.
    pub(crate) polygons: Vec<u32>,
    pub(crate) polygon_offsets: Vec<u32>,
    /// Triangle offsets: faces, then strips, then polygons (prefix sums, one past each item).
    face_triangles: Vec<usize>,
    strip_triangles: Vec<usize>,
    polygon_triangles: Vec<usize>,
}

impl Default for Connectivity {
    fn default() -> Self {
        Connectivity {
            polygons: Vec::new(),
            polygon_offsets: vec![0],
            face_triangles: Vec::new(),
            strip_triangles: Vec::new(),
            polygon_triangles: Vec::new(),
        }
    }
}

impl Connectivity {
    /// Its vectors' heap bytes.
    pub(crate) fn heap_bytes(&self) -> usize {
        total_bytes([
            vec_bytes(&self.polygons),
            vec_bytes(&self.polygon_offsets),
            vec_bytes(&self.face_triangles),
            vec_bytes(&self.strip_triangles),
            vec_bytes(&self.polygon_triangles),
        ])
    }

    /// Close the plan: the triangles of every face and every strip (the polygons' follow from
    /// their lengths, a `k`-gon giving `k - 2`).
    pub(crate) fn count(
        &mut self,
        face_triangles: impl Iterator<Item = usize>,
        strip_triangles: impl Iterator<Item = usize>,
    ) {
        self.face_triangles = prefix_sums(face_triangles);
        self.strip_triangles = prefix_sums(strip_triangles);
        self.polygon_triangles = prefix_sums(
            self.polygon_offsets
                .windows(2)
                .map(|w| (w[1] - w[0]).saturating_sub(2) as usize),
        );
    }

    /// Number of triangles.
    pub(crate) fn triangle_count(&self) -> usize {
        [
            &self.face_triangles,
            &self.strip_triangles,
            &self.polygon_triangles,
        ]
        .iter()
        .map(|v| v.last().copied().unwrap_or(0))
        .sum()
    }

    /// Write every triangle: `face(f, out)` and `strip(s, out)` fill their items' slices, the
    /// polygons are fanned here; all three groups in parallel.
    pub(crate) fn connect(
        &self,
        triangles: &mut [[u32; 3]],
        face: impl Fn(usize, &mut [[u32; 3]]) + Sync + Send,
        strip: impl Fn(usize, &mut [[u32; 3]]) + Sync + Send,
    ) {
        let faces_end = self.face_triangles.last().copied().unwrap_or(0);
        let strips_end = faces_end + self.strip_triangles.last().copied().unwrap_or(0);
        let (faces, rest) = triangles.split_at_mut(faces_end);
        let (strips, polygons) = rest.split_at_mut(strips_end - faces_end);
        rayon::join(
            || for_each_range(&self.face_triangles, faces, &face),
            || {
                rayon::join(
                    || for_each_range(&self.strip_triangles, strips, &strip),
                    || {
                        for_each_range(&self.polygon_triangles, polygons, |v, out| {
                            let ring = &self.polygons[self.polygon_offsets[v] as usize
                                ..self.polygon_offsets[v + 1] as usize];
                            for (i, t) in out.iter_mut().enumerate() {
                                *t = [ring[0], ring[i + 1], ring[i + 2]];
                            }
                        })
                    },
                )
            },
        );
    }
}

/// What a dual-grid plan does per frame, for quads ([`crate::tessellate::dual_grid::DualGrid`])
/// and triangles ([`crate::tessellate::triangle_dual_grid::TriangleDualGrid`]) alike: the plan
/// is built once per mesh and rates; a frame evaluates every output vertex from the control
/// points and, where the topology changed, writes the triangles.
pub trait GridPlan: Sync + Send + std::fmt::Debug {
    /// Output vertices per frame.
    fn vertex_count(&self) -> usize;

    /// Output triangles per frame.
    fn triangle_count(&self) -> usize;

    /// Where every output vertex is evaluated, in output order, in the tessellated mesh's faces:
    /// `out`'s contents replaced (a surface fills the vector of its last frame,
    /// [`crate::Surface::tessellator`]).
    fn sources_into(&self, out: &mut Vec<VertexSource>);

    /// [`GridPlan::sources_into`] a new vector.
    fn sources(&self) -> Vec<VertexSource> {
        let mut out = Vec::new();
        self.sources_into(&mut out);
        out
    }

    /// Evaluate every output vertex from the control points `control` (the tessellated mesh's
    /// vertex positions): limit positions and unit normals, `vertex_count()` each.
    ///
    /// The control points are f64 so that the tangents, computed from every patch's points
    /// relative to one of them, keep the precision of the patch's size wherever the mesh sits
    /// (an isolated mesh's points rounded to f32 would already have lost it); the outputs are
    /// f32.
    fn evaluate(&self, control: &[[f64; 3]], positions: &mut [[f32; 3]], normals: &mut [[f32; 3]]);

    /// Write every triangle (`triangle_count()` of them).
    fn connect(&self, triangles: &mut [[u32; 3]]);

    /// How many faces take a polynomial fast path: for quads the separable (tensor-product)
    /// bicubic, for Loop triangles one quartic per face.
    fn separable_faces(&self) -> usize {
        0
    }

    /// How many faces are evaluated by feature-adaptive refinement (sharp features the tables
    /// do not describe, a valence or patch beyond the table): the slow path.
    fn refined_faces(&self) -> usize {
        0
    }

    /// About the plan's heap memory (its vectors' capacities, the stencils' weights included):
    /// what a surface weighs before keeping the plan for its next frame
    /// ([`crate::Surface::tessellator`]).
    fn heap_bytes(&self) -> usize;

    /// Output vertices repeating another's position across a face-varying seam, `[copy,
    /// original]` (none unless the plan has a face-varying channel).
    fn seam_copies(&self) -> &[[u32; 2]] {
        &[]
    }

    /// The plan's own map from the input points to the control points its
    /// [`GridPlan::evaluate`] reads, where it has one: the map's rows, then the input points
    /// themselves (which the regular input faces it evaluates whole read). `None`: it reads the
    /// isolated mesh's points, all of them.
    fn control_map(&self) -> Option<&Stencil<f64>> {
        None
    }

    /// Evaluate and connect in one go into a fresh [`TriangleMesh`] (with sources in the
    /// tessellated mesh's faces), from `mesh`'s own positions.
    fn tessellate(&self, mesh: &Mesh) -> TriangleMesh {
        let vertices = self.vertex_count();
        let mut out = TriangleMesh {
            positions: vec![[0.0; 3]; vertices],
            normals: vec![[0.0; 3]; vertices],
            sources: self.sources(),
            triangles: vec![[0; 3]; self.triangle_count()],
            uvs: Vec::new(),
            seam_copies: self.seam_copies().to_vec(),
        };
        // Every vertex of the mesh is a control point, copies of split vertices included.
        self.evaluate(&mesh.positions, &mut out.positions, &mut out.normals);
        self.connect(&mut out.triangles);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every item is worked on once, each with the scratch of the thread that took it, on a
    /// pool of several threads; an error stops the dealing and comes back.
    #[test]
    fn dealt_items_are_each_worked_on_once_and_an_error_stops_them() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("a pool of three threads");
        pool.install(|| {
            let mut items: Vec<(usize, u32)> = (0..1000).map(|i| (i, 0)).collect();
            let scratches = AtomicUsize::new(0);
            let make = || scratches.fetch_add(1, Ordering::Relaxed);
            let visit = |_: &mut usize, item: &mut (usize, u32)| -> Result<(), usize> {
                item.1 += 1;
                Ok(())
            };
            assert_eq!(for_each_dealt(&mut items, make, visit), Ok(()));
            assert!(items.iter().all(|&(_, visits)| visits == 1));
            // One scratch a thread, made once however many items it takes.
            assert_eq!(scratches.load(Ordering::Relaxed), 3);

            let failing = |_: &mut (), item: &mut (usize, u32)| -> Result<(), usize> {
                if item.0 == 10 {
                    Err(item.0)
                } else {
                    Ok(())
                }
            };
            assert_eq!(for_each_dealt(&mut items, || (), failing), Err(10));
        });
        // On one thread, nothing after the failing item is dealt.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a pool of one thread");
        let mut items: Vec<u32> = vec![0; 20];
        let result = one.install(|| {
            for_each_dealt(
                &mut items,
                || 0,
                |count: &mut u32, item: &mut u32| {
                    *count += 1;
                    *item = *count;
                    if *count == 5 {
                        Err(())
                    } else {
                        Ok(())
                    }
                },
            )
        });
        assert_eq!(result, Err(()));
        assert_eq!(items[..6], [1, 2, 3, 4, 5, 0]);
    }
}
