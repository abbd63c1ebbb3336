//! Globalization (Lai–Cheng section 5): one global id per marked point, and the ring of marked
//! points around each leaf square.
//!
//! A marked point's place is exact: a mesh vertex (a face corner), a mesh edge and the dyadic
//! parameter along it (inside a face side), or a face and its dyadic `(u, v)`. The ids are
//! assigned from that structure, face by face in parallel, with no global map: a point
//! belongs to the first face (in face order) that marks it — a face's own interior points to
//! it, an edge point to the lower of the edge's two faces that marks it, a vertex to the lowest
//! face around it — and each face numbers the points it owns in the order it first marked them,
//! after the points of all lower faces (a prefix sum of the faces' counts). That is the order
//! of a single pass over the faces that gives every new place the next id ("first evaluation
//! wins"), so the ids, positions and normals are that pass's, computed in parallel.

use rayon::prelude::*;

use super::marks::FaceMarks;
use super::{Leaf, GRID};
use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_mesh::VertexSource;
use crate::tessellate::kernel::{for_each_range, prefix_sums, resize_to_overwrite};
use crate::RuntimeError;

/// The fewest faces a job of a per-face stage takes when the work a face is a few
/// nanoseconds: handing a job to the other thread costs some microseconds (on the development
/// host, 5 µs a stage on the 112-face cage against 1 µs of work, docs/benchmarks.md).
const FACES_PER_JOB: usize = 1024;

/// Where a point of a face's grid lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// Corner `k` (the face's `k`-th vertex).
    Corner(usize),
    /// Inside side `side` (counter-clockwise from corner `side`), at parameter `t` along it.
    Side(usize, u32),
    /// Inside the face.
    Interior,
}

/// The place of the face grid point `(u, v)` (corners first, then sides, counter-clockwise).
fn place(u: u32, v: u32) -> Place {
    match (u, v) {
        (0, 0) => Place::Corner(0),
        (GRID, 0) => Place::Corner(1),
        (GRID, GRID) => Place::Corner(2),
        (0, GRID) => Place::Corner(3),
        (_, 0) => Place::Side(0, u),
        (GRID, _) => Place::Side(1, v),
        (_, GRID) => Place::Side(2, GRID - u),
        (0, _) => Place::Side(3, GRID - v),
        _ => Place::Interior,
    }
}

/// The mesh edge of a face side: whether the side's parameter flips on the canonical
/// half-edge (the pair's smaller index), and the other face with its side, if any.
#[derive(Clone, Copy, Debug)]
struct SideEdge {
    flip: bool,
    twin: Option<(usize, usize)>,
}

impl SideEdge {
    fn new(mesh: &Mesh, face: usize, side: usize) -> Self {
        let h = mesh.face_halfedges(face).start + side;
        let t = mesh.twin[h];
        if t == NONE {
            return SideEdge {
                flip: false,
                twin: None,
            };
        }
        let g = mesh.face_of[t as usize] as usize;
        SideEdge {
            flip: (t as usize) < h,
            twin: Some((g, t as usize - mesh.face_halfedges(g).start)),
        }
    }

    /// The parameter along the canonical half-edge of the side's own parameter `t`.
    fn canonical(&self, t: u32) -> u32 {
        if self.flip {
            GRID - t
        } else {
            t
        }
    }
}

/// A sorted list's pairs `(key, id)` with keys strictly between `lo` and `hi`, each given with
/// its own entry's index in the list ([`NONE`] where it has none): the pairs are then the run
/// between the two entries, and a binary search is needed only where neither end is listed.
/// `None` where an index is past the list (a broken invariant).
fn between<K: Ord + Copy>(
    sorted: &[(K, u32)],
    (lo, lo_at): (K, u32),
    (hi, hi_at): (K, u32),
) -> Option<&[(K, u32)]> {
    let (lo_at, hi_at) = (lo_at as usize, hi_at as usize);
    let listed = NONE as usize;
    let start = if lo_at != listed {
        lo_at + 1
    } else if hi_at != listed {
        let above = sorted.get(..hi_at)?;
        hi_at - above.iter().rev().take_while(|x| x.0 > lo).count()
    } else {
        sorted.partition_point(|x| x.0 <= lo)
    };
    let end = if hi_at != listed {
        hi_at
    } else {
        start + sorted.get(start..)?.iter().take_while(|x| x.0 < hi).count()
    };
    sorted.get(start..end.max(start))
}

/// The ids of one face's marked points, and the points marked inside its sides by it and by
/// the faces across.
#[derive(Default)]
pub(super) struct FaceIds {
    /// Per point of the face ([`FaceMarks::places`]), its id.
    ids: Vec<u32>,
    /// Per point inside a side of the face, its index in that side's `edges` list; [`NONE`]
    /// for the others.
    at_edge: Vec<u32>,
    /// Per side, every point marked inside it by this face or the face across it, by the
    /// side's own parameter, with its id.
    edges: [Vec<(u32, u32)>; 4],
}

/// The global ids of a tessellation's marked points.
pub(super) struct GlobalIds {
    /// Per face, its points' ids (the lists of the frame before refilled, [`assign`]).
    pub(super) faces: Vec<FaceIds>,
}

/// A broken invariant of the marking (every marked point has an id), as an error, not a panic.
pub(super) fn internal(what: String) -> RuntimeError {
    RuntimeError::Unsupported(format!("internal: {what}"))
}

/// Where each face's range starts in a list ranged by `ends`.
pub(super) fn start(ends: &[usize], f: usize) -> usize {
    f.checked_sub(1).map_or(0, |g| ends[g])
}

/// Give every marked point of `work` (per face: leaves and their corners) its id, from 0, and
/// make `positions`, `normals` and `sources` the points' in id order (module documentation);
/// the faces' ids refill `faces` (one a face, the lists of a frame before, their memory kept).
///
/// Every list of the stages is one flat list for all faces, ranged by face (a list a face and
/// stage was some thirty allocations a face, and their frees at the end, on the thread that
/// had not made them, took a quarter of the pass on two threads: docs/benchmarks.md).
pub(super) fn assign(
    mesh: &Mesh,
    work: &[FaceMarks],
    mut faces: Vec<FaceIds>,
    positions: &mut Vec<[f64; 3]>,
    normals: &mut Vec<[f64; 3]>,
    sources: &mut Vec<VertexSource>,
) -> Result<GlobalIds, RuntimeError> {
    let edges: Vec<[SideEdge; 4]> = (0..work.len())
        .into_par_iter()
        .with_min_len(FACES_PER_JOB)
        .map(|f| std::array::from_fn(|s| SideEdge::new(mesh, f, s)))
        .collect();
    // Per face, how many points it marks inside each side, and its corners' points.
    let outline: Vec<([usize; 4], [u32; 4])> = work
        .par_iter()
        .map(|marks| {
            let (mut counts, mut corners) = ([0; 4], [NONE; 4]);
            for (p, &(u, v)) in (0u32..).zip(&marks.places) {
                match place(u, v) {
                    Place::Side(s, _) => counts[s] += 1,
                    Place::Corner(k) => corners[k] = p,
                    Place::Interior => {}
                }
            }
            (counts, corners)
        })
        .collect();
    // Per face and side, the points marked inside it by canonical parameter, `(t, point)`.
    let side_ends = prefix_sums(outline.iter().map(|(c, _)| c.iter().sum()));
    let side_range = |f: usize, s: usize| {
        let first = start(&side_ends, f) + outline[f].0[..s].iter().sum::<usize>();
        first..first + outline[f].0[s]
    };
    let mut sides = vec![(0u32, 0u32); side_ends.last().copied().unwrap_or(0)];
    for_each_range(&side_ends, &mut sides[..], |f, list| {
        let counts = outline[f].0;
        let mut next = [
            0,
            counts[0],
            counts[0] + counts[1],
            counts[0] + counts[1] + counts[2],
        ];
        let firsts = next;
        for (p, &(u, v)) in (0u32..).zip(&work[f].places) {
            if let Place::Side(s, t) = place(u, v) {
                list[next[s]] = (edges[f][s].canonical(t), p);
                next[s] += 1;
            }
        }
        for s in 0..4 {
            list[firsts[s]..next[s]].sort_unstable();
        }
    });
    // The lowest face marking each vertex (every face with leaves marks its four corners).
    let mut vertex_owner = vec![NONE; mesh.positions.len()];
    for (f, marks) in work.iter().enumerate() {
        if marks.places.is_empty() {
            continue;
        }
        for &v in mesh.face(f) {
            if let Some(owner) = vertex_owner.get_mut(v as usize) {
                if *owner == NONE {
                    *owner = f as u32;
                }
            }
        }
    }
    // Per point, its rank among the points its face owns (NONE: owned by a lower face).
    let point_ends = prefix_sums(work.iter().map(|marks| marks.places.len()));
    let mut ranks = vec![NONE; point_ends.last().copied().unwrap_or(0)];
    for_each_range(&point_ends, &mut ranks[..], |f, ranks| {
        let mut next = 0;
        for (rank, &(u, v)) in ranks.iter_mut().zip(&work[f].places) {
            let owned = match place(u, v) {
                Place::Interior => true,
                Place::Corner(k) => vertex_owner[mesh.face(f)[k] as usize] == f as u32,
                Place::Side(s, t) => match edges[f][s].twin {
                    Some((g, side)) if g < f => sides[side_range(g, side)]
                        .binary_search_by_key(&edges[f][s].canonical(t), |x| x.0)
                        .is_err(),
                    _ => true,
                },
            };
            if owned {
                *rank = next;
                next += 1;
            }
        }
    });
    let rank = |f: usize, p: u32| ranks[start(&point_ends, f) + p as usize];
    // Ids are `u32`: the count is checked (the polygon budget keeps it far below).
    let too_many = || internal("more than u32::MAX marked points".to_owned());
    // A face's owned points are ranked 0, 1, ... in order: their count is the last rank plus
    // one (the last point is mostly one the face owns).
    let owned_counts: Vec<usize> = (0..work.len())
        .map(|f| {
            ranks[start(&point_ends, f)..point_ends[f]]
                .iter()
                .rev()
                .find(|&&r| r != NONE)
                .map_or(0, |&r| r as usize + 1)
        })
        .collect();
    let mut base = Vec::with_capacity(work.len());
    let mut total = 0u32;
    for &owned in &owned_counts {
        base.push(total);
        let owned = u32::try_from(owned).map_err(|_| too_many())?;
        total = total.checked_add(owned).ok_or_else(too_many)?;
    }
    // A point's id: its face's first plus its rank (`NONE` for a point a lower face owns; an
    // id is below the checked total, so never `NONE`).
    let id = |f: usize, p: u32| match rank(f, p) {
        NONE => NONE,
        r => base[f] + r,
    };
    // The owned points' vertices, face by face in parallel into their places (ids are
    // consecutive within a face): the output's pages are first written on both threads, where
    // pushing them one by one took 15 ms on one (Spot at `8.248e-5`, 359,558 points). Into
    // the output's lists, emptied and grown in place: a caller that keeps its lists from frame
    // to frame (`Surface::tessellate_adaptive_into`) writes pages it has written before.
    let owned_ends = prefix_sums(owned_counts.into_iter());
    let count = owned_ends.last().copied().unwrap_or(0);
    for list in [&mut *positions, &mut *normals] {
        resize_to_overwrite(list, count, [0.0; 3]);
    }
    resize_to_overwrite(sources, count, VertexSource::default());
    let out = (&mut positions[..], &mut normals[..], &mut sources[..]);
    for_each_range(&owned_ends, out, |f, (p, n, s)| {
        let marks = &work[f];
        let first = start(&point_ends, f);
        let owned = (0..marks.places.len()).filter(|&point| ranks[first + point] != NONE);
        for (k, point) in owned.enumerate() {
            p[k] = marks.positions[point];
            n[k] = marks.normals[point];
            let (u, v) = marks.places[point];
            let shift = (u | v | GRID).trailing_zeros();
            s[k] = VertexSource {
                face: f as u32,
                u: u >> shift,
                v: v >> shift,
                denominator: GRID >> shift,
                subface: 0,
            };
        }
    });
    // Each mesh vertex's id, from the face that owns it.
    let mut vertices = vec![NONE; mesh.positions.len()];
    for (f, (_, corners)) in outline.iter().enumerate() {
        for (k, &p) in corners.iter().enumerate() {
            if p != NONE && id(f, p) != NONE {
                vertices[mesh.face(f)[k] as usize] = id(f, p);
            }
        }
    }
    faces.truncate(work.len());
    faces.resize_with(work.len(), FaceIds::default);
    faces
        .par_iter_mut()
        .zip(work.par_iter())
        .enumerate()
        .map(|(f, (face, marks))| -> Result<(), RuntimeError> {
            let no_id =
                |(u, v): (u32, u32)| internal(format!("face {f} point ({u}, {v}) has no id"));
            // Per side, its points and those of the side across, in this side's parameter,
            // each with the id of the face that owns it (the other entry has none: `NONE`
            // sorts after it and the first of equal keys is kept).
            for (s, all) in face.edges.iter_mut().enumerate() {
                let edge = edges[f][s];
                let listed = |(g, side): (usize, usize)| {
                    let by_id = move |&(tc, p): &(u32, u32)| (edge.canonical(tc), id(g, p));
                    sides[side_range(g, side)].iter().map(by_id)
                };
                all.clear();
                all.extend(listed((f, s)));
                if let Some(across) = edge.twin {
                    all.extend(listed(across));
                }
                all.sort_unstable();
                all.dedup_by_key(|x| x.0);
            }
            let FaceIds {
                ids,
                at_edge,
                edges,
            } = face;
            at_edge.clear();
            at_edge.resize(marks.places.len(), NONE);
            ids.clear();
            for (p, (&(u, v), at)) in (0u32..).zip(marks.places.iter().zip(at_edge.iter_mut())) {
                let owned = Some(id(f, p)).filter(|&i| i != NONE);
                let found = match place(u, v) {
                    Place::Interior => owned,
                    Place::Corner(k) => owned.or(Some(vertices[mesh.face(f)[k] as usize])),
                    Place::Side(s, t) => {
                        let k = edges[s].partition_point(|x| x.0 < t);
                        let entry = edges[s].get(k).filter(|x| x.0 == t);
                        let entry = entry.ok_or_else(|| no_id((u, v)))?;
                        *at = k as u32;
                        owned.or(Some(entry.1))
                    }
                };
                let found = found.filter(|&i| i != NONE).ok_or_else(|| no_id((u, v)))?;
                ids.push(found);
            }
            Ok(())
        })
        .collect::<Result<(), _>>()?;
    Ok(GlobalIds { faces })
}

impl GlobalIds {
    /// The ring of marked points around leaf `index` of `face`, whose marks are `marks`: face
    /// grid points and ids, into `ring`: its corners and every marked point on its sides,
    /// counter-clockwise (section 5: "output in order all the marked points between corners of
    /// the base quadrilateral"). The points inside a side are the leaf's own side points
    /// ([`FaceMarks::sides`]) where the side is inside the face, else those of the face side's
    /// merged list between the leaf's corners.
    pub(super) fn leaf_ring(
        &self,
        (face, index, leaf): (usize, usize, &Leaf),
        marks: &FaceMarks,
        ring: &mut Vec<((u32, u32), u32)>,
    ) -> Result<(), RuntimeError> {
        let broken = || internal(format!("face {face} leaf {index} has no ring"));
        let ids = self.faces.get(face).ok_or_else(broken)?;
        let corners = marks.corners.get(index).ok_or_else(broken)?;
        let ends = marks.side_ends.get(index).ok_or_else(broken)?;
        let point = |p: u32| -> Result<((u32, u32), u32), RuntimeError> {
            let place = marks.places.get(p as usize).ok_or_else(broken)?;
            let id = ids.ids.get(p as usize).ok_or_else(broken)?;
            Ok((*place, *id))
        };
        let at_edge = |k: usize| {
            ids.at_edge
                .get(corners[k] as usize)
                .copied()
                .ok_or_else(broken)
        };
        let on_face_side = leaf.on_face_side();
        let mut from = match index.checked_sub(1) {
            Some(before) => marks.side_ends.get(before).ok_or_else(broken)?[3],
            None => 0,
        };
        ring.clear();
        for s in 0..4 {
            ring.push(point(corners[s])?);
            let inside = marks
                .side_points
                .get(from as usize..ends[s] as usize)
                .ok_or_else(broken)?;
            for &p in inside {
                ring.push(point(p)?);
            }
            from = ends[s];
            if let Some((lo, hi)) = on_face_side[s] {
                let lo = (lo, at_edge(s)?);
                let hi = (hi, at_edge((s + 1) % 4)?);
                let side = between(&ids.edges[s], lo, hi).ok_or_else(broken)?;
                ring.extend(side.iter().map(|&(t, id)| {
                    let place = match s {
                        0 => (t, 0),
                        1 => (GRID, t),
                        2 => (GRID - t, GRID),
                        _ => (0, GRID - t),
                    };
                    (place, id)
                }));
            }
        }
        Ok(())
    }
}
