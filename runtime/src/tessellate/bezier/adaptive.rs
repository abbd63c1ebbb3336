//! The adaptive tessellator (Espino et al., section 2): the 18-triangle coarse tessellation of
//! every patch is refined by splitting edges at their parametric midpoints, with the
//! Chung–Field patterns (one split edge: 2 triangles, two: 3, three: 4) applied recursively.
//!
//! Every decision is made in the parameter domain, on an exact dyadic grid of denominator
//! `D = 3 · 2^max_depth`, and is keyed by the edge's identity, so it is made **once**:
//!
//! * an edge inside a patch is `(patch, a, b)` with sorted grid points;
//! * an edge on a patch side is `(curve, t0, t1)`, where `curve` is the class of boundary
//!   curves with exactly equal control points (possibly reversed, [`SharedCurves`]) and `t` is
//!   measured in the class's canonical direction; it is decided in the class's first patch.
//!
//! Output vertices are keyed the same way (a patch corner and any point of a collapsed side by
//! its exact control point), so neighbouring patches share vertices by construction, never by
//! welding distances. With a map test every decision precedes every vertex evaluation; the
//! vertices are evaluated once each at the end.

use std::collections::HashMap;

use super::bicubic::{BicubicPatch, SurfacePoint};
use super::displacement_map::{coarse_triangles, DisplacementMap, COARSE_SEGMENTS};
use super::edge_tests::{flat_test, map_test, EdgeTest};
use super::patch_input::BezierPatches;
use crate::mesh::triangle_mesh::{TriangleMesh, VertexSource};

/// A point of the parameter grid: `(u, v) = (g[0] / D, g[1] / D)`.
pub type GridPoint = [u32; 2];

/// The exact bits of a point (`-0.0` read as `0.0`), its identity as a shared vertex.
type PointBits = [u64; 3];

fn bits(p: [f64; 3]) -> PointBits {
    p.map(|x| (x + 0.0).to_bits())
}

/// One side of one patch, as a member of a [`CurveClass`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SideRef {
    /// The class of the side's boundary curve.
    pub class: u32,
    /// Whether the side's parameter runs against the class's canonical direction.
    pub reversed: bool,
}

/// Patch sides whose boundary curves have exactly equal control points (in the same or the
/// reverse order): one curve of the surface.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CurveClass {
    /// `(patch, side, reversed)` of each member, by increasing patch; the first decides.
    pub members: Vec<(u32, u8, bool)>,
    /// Whether the curve is a single point (a collapsed row).
    pub collapsed: bool,
}

/// The boundary curves of a patch set and which patch sides share them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedCurves {
    /// Per patch, its four sides (order of [`BicubicPatch::side_points`]).
    pub sides: Vec<[SideRef; 4]>,
    /// The classes.
    pub classes: Vec<CurveClass>,
}

impl SharedCurves {
    /// Group the sides of `patches` by exact equality of their control rows.
    pub fn new(patches: &BezierPatches) -> SharedCurves {
        let mut by_key: HashMap<[PointBits; 4], u32> = HashMap::new();
        let mut classes: Vec<CurveClass> = Vec::new();
        let mut sides = Vec::with_capacity(patches.len());
        for (p, patch) in patches.patches.iter().enumerate() {
            let mut refs = [SideRef {
                class: 0,
                reversed: false,
            }; 4];
            for (s, r) in refs.iter_mut().enumerate() {
                let fwd = patch.side_points(s).map(bits);
                let mut rev = fwd;
                rev.reverse();
                let reversed = rev < fwd;
                let key = if reversed { rev } else { fwd };
                let class = *by_key.entry(key).or_insert_with(|| {
                    classes.push(CurveClass {
                        members: Vec::new(),
                        collapsed: key.iter().all(|&q| q == key[0]),
                    });
                    (classes.len() - 1) as u32
                });
                classes[class as usize]
                    .members
                    .push((p as u32, s as u8, reversed));
                *r = SideRef { class, reversed };
            }
            sides.push(refs);
        }
        SharedCurves { sides, classes }
    }

    /// The sides no other side shares (excluding collapsed ones): the open seams.
    pub fn open_sides(&self) -> Vec<(u32, u8)> {
        self.classes
            .iter()
            .filter(|c| c.members.len() == 1 && !c.collapsed)
            .map(|c| (c.members[0].0, c.members[0].1))
            .collect()
    }

    /// Pairs of patches that share a curve but traverse it in the same direction along their
    /// counter-clockwise boundaries (inconsistent orientation; empty for the teapot and teacup).
    pub fn inconsistent_orientations(&self) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for c in self.classes.iter().filter(|c| !c.collapsed) {
            let dir = |&(_, s, rev): &(u32, u8, bool)| (s < 2) != rev;
            for (k, a) in c.members.iter().enumerate() {
                for b in &c.members[k + 1..] {
                    if dir(a) == dir(b) {
                        out.push((a.0, b.0));
                    }
                }
            }
        }
        out
    }
}

/// The identity of an output vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum VertexKey {
    /// A patch corner or a point of a collapsed side: its exact position.
    Point(PointBits),
    /// A point inside a shared (or open) boundary curve, at canonical parameter `t`.
    Curve { class: u32, t: u32 },
    /// A point inside a patch.
    Interior { patch: u32, g: GridPoint },
}

/// The identity of an edge, for its split decision.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum EdgeKey {
    Curve {
        class: u32,
        t0: u32,
        t1: u32,
    },
    Interior {
        patch: u32,
        a: GridPoint,
        b: GridPoint,
    },
}

/// A vertex evaluated once: position, normal and where.
#[derive(Clone, Copy, Debug)]
struct Evaluated {
    point: SurfacePoint,
    source: VertexSource,
}

/// What one refinement did.
#[derive(Clone, Debug, Default)]
pub(crate) struct RefineCounts {
    /// Edges whose test was run.
    pub edges_tested: usize,
    /// Of those, the ones split.
    pub edges_split: usize,
    /// Edges that would have been tested but are at the grid's finest level.
    pub edges_capped: usize,
    /// Surface evaluations made (positions + normals).
    pub evaluations: usize,
}

/// The result of the decision phase: triangles in the parameter domain.
pub(crate) struct Refinement {
    pub triangles: Vec<(u32, [GridPoint; 3])>,
    pub counts: RefineCounts,
    cache: HashMap<VertexKey, Evaluated>,
}

/// The triangle budget was exceeded.
pub(crate) struct TooMany;

/// Everything that does not depend on the test's threshold: curves and maps.
pub(crate) struct Prepared<'a> {
    pub patches: &'a [BicubicPatch],
    pub curves: SharedCurves,
    pub maps: Vec<DisplacementMap>,
    pub denominator: u32,
}

/// Side `s` contains grid point `g`.
fn on_side(g: GridPoint, s: usize, d: u32) -> bool {
    match s {
        0 => g[1] == 0,
        1 => g[0] == d,
        2 => g[1] == d,
        _ => g[0] == 0,
    }
}

/// The parameter of `g` along side `s`.
fn along(g: GridPoint, s: usize) -> u32 {
    if s % 2 == 0 {
        g[0]
    } else {
        g[1]
    }
}

/// The grid point at parameter `t` of side `s`.
fn side_point(s: usize, t: u32, d: u32) -> GridPoint {
    match s {
        0 => [t, 0],
        1 => [d, t],
        2 => [t, d],
        _ => [0, t],
    }
}

fn mid(a: GridPoint, b: GridPoint) -> GridPoint {
    [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]
}

fn dist2(a: GridPoint, b: GridPoint) -> u64 {
    let du = u64::from(a[0].abs_diff(b[0]));
    let dv = u64::from(a[1].abs_diff(b[1]));
    du * du + dv * dv
}

impl<'a> Prepared<'a> {
    pub fn new(
        patches: &'a BezierPatches,
        maps: Vec<DisplacementMap>,
        max_depth: u32,
    ) -> Prepared<'a> {
        Prepared {
            patches: &patches.patches,
            curves: SharedCurves::new(patches),
            maps,
            denominator: (COARSE_SEGMENTS as u32) << max_depth,
        }
    }

    fn uv(&self, g: GridPoint) -> (f64, f64) {
        let d = f64::from(self.denominator);
        (f64::from(g[0]) / d, f64::from(g[1]) / d)
    }

    pub(crate) fn vertex_key(&self, patch: u32, g: GridPoint) -> VertexKey {
        let d = self.denominator;
        let corner_u = g[0] == 0 || g[0] == d;
        let corner_v = g[1] == 0 || g[1] == d;
        let p = &self.patches[patch as usize];
        if corner_u && corner_v {
            let i = if g[1] == 0 { 0 } else { 3 };
            let j = if g[0] == 0 { 0 } else { 3 };
            return VertexKey::Point(bits(p.control_point(i, j)));
        }
        for s in 0..4 {
            if on_side(g, s, d) {
                let side = self.curves.sides[patch as usize][s];
                if self.curves.classes[side.class as usize].collapsed {
                    return VertexKey::Point(bits(p.side_points(s)[0]));
                }
                let t = along(g, s);
                let t = if side.reversed { d - t } else { t };
                return VertexKey::Curve {
                    class: side.class,
                    t,
                };
            }
        }
        VertexKey::Interior { patch, g }
    }

    /// The edge's identity and the patch and grid points it is decided in; `None` for an edge
    /// on a collapsed side (zero length: never split).
    fn edge_key(
        &self,
        patch: u32,
        a: GridPoint,
        b: GridPoint,
    ) -> Option<(EdgeKey, u32, GridPoint, GridPoint)> {
        let d = self.denominator;
        for s in 0..4 {
            if on_side(a, s, d) && on_side(b, s, d) {
                let side = self.curves.sides[patch as usize][s];
                let class = &self.curves.classes[side.class as usize];
                if class.collapsed {
                    return None;
                }
                let canon = |t: u32| if side.reversed { d - t } else { t };
                let (t0, t1) = (canon(along(a, s)), canon(along(b, s)));
                let (t0, t1) = (t0.min(t1), t0.max(t1));
                let (cp, cs, crev) = class.members[0];
                let member = |t: u32| side_point(cs as usize, if crev { d - t } else { t }, d);
                return Some((
                    EdgeKey::Curve {
                        class: side.class,
                        t0,
                        t1,
                    },
                    cp,
                    member(t0),
                    member(t1),
                ));
            }
        }
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        Some((
            EdgeKey::Interior {
                patch,
                a: lo,
                b: hi,
            },
            patch,
            lo,
            hi,
        ))
    }

    /// Evaluate the vertex at `g` of `patch` (once per identity; a curve point is evaluated in
    /// its class's first patch).
    fn evaluate(
        &self,
        cache: &mut HashMap<VertexKey, Evaluated>,
        counts: &mut RefineCounts,
        patch: u32,
        g: GridPoint,
    ) -> Evaluated {
        let key = self.vertex_key(patch, g);
        if let Some(e) = cache.get(&key) {
            return *e;
        }
        let (patch, g) = match key {
            VertexKey::Curve { class, t } => {
                let (cp, cs, crev) = self.curves.classes[class as usize].members[0];
                let d = self.denominator;
                (cp, side_point(cs as usize, if crev { d - t } else { t }, d))
            }
            _ => (patch, g),
        };
        let (u, v) = self.uv(g);
        let e = Evaluated {
            point: self.patches[patch as usize].evaluate(u, v),
            source: VertexSource {
                face: patch,
                u: g[0],
                v: g[1],
                denominator: self.denominator,
                subface: 0,
            },
        };
        counts.evaluations += 1;
        cache.insert(key, e);
        e
    }

    /// The decision phase: refine every patch's coarse tessellation with `test` at threshold
    /// `th`, each edge decided once. Fails when more than `max_triangles` would result.
    pub fn refine(
        &self,
        test: EdgeTest,
        th: f64,
        max_triangles: usize,
    ) -> Result<Refinement, TooMany> {
        let d = self.denominator;
        let third = d / COARSE_SEGMENTS as u32;
        let mut decisions: HashMap<EdgeKey, bool> = HashMap::new();
        let mut cache: HashMap<VertexKey, Evaluated> = HashMap::new();
        let mut counts = RefineCounts::default();
        let mut out: Vec<(u32, [GridPoint; 3])> = Vec::new();
        let mut split =
            |patch: u32, a: GridPoint, b: GridPoint, counts: &mut RefineCounts| -> bool {
                let Some((key, cp, a, b)) = self.edge_key(patch, a, b) else {
                    return false;
                };
                if (a[0] + b[0]) % 2 != 0 || (a[1] + b[1]) % 2 != 0 {
                    counts.edges_capped += 1;
                    return false;
                }
                if let Some(&s) = decisions.get(&key) {
                    return s;
                }
                let s = match test {
                    EdgeTest::Flat => {
                        let ea = self.evaluate(&mut cache, counts, cp, a).point.position;
                        let eb = self.evaluate(&mut cache, counts, cp, b).point.position;
                        let m = self.evaluate(&mut cache, counts, cp, mid(a, b)).point;
                        flat_test(ea, eb, &m, th)
                    }
                    _ => map_test(test, &self.maps[cp as usize], self.uv(a), self.uv(b), th),
                };
                counts.edges_tested += 1;
                counts.edges_split += usize::from(s);
                decisions.insert(key, s);
                s
            };
        let mut stack: Vec<[GridPoint; 3]> = Vec::new();
        for patch in 0..self.patches.len() as u32 {
            for t in coarse_triangles() {
                stack.push(t.map(|[j, i]| [j as u32 * third, i as u32 * third]));
                while let Some(tri) = stack.pop() {
                    if out.len() + stack.len() > max_triangles {
                        return Err(TooMany);
                    }
                    let [a, b, c] = tri;
                    let s = [
                        split(patch, a, b, &mut counts),
                        split(patch, b, c, &mut counts),
                        split(patch, c, a, &mut counts),
                    ];
                    match s {
                        [false, false, false] => out.push((patch, tri)),
                        [true, false, false] => {
                            let m = mid(a, b);
                            stack.extend([[a, m, c], [m, b, c]]);
                        }
                        [false, true, false] => {
                            let m = mid(b, c);
                            stack.extend([[b, m, a], [m, c, a]]);
                        }
                        [false, false, true] => {
                            let m = mid(c, a);
                            stack.extend([[c, m, b], [m, a, b]]);
                        }
                        [true, true, true] => {
                            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                            stack.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
                        }
                        _ => {
                            // Two split edges: rotate so that they are (p, q) and (q, r).
                            let [p, q, r] = match s {
                                [true, true, false] => [a, b, c],
                                [false, true, true] => [b, c, a],
                                _ => [c, a, b],
                            };
                            let (pq, qr) = (mid(p, q), mid(q, r));
                            stack.push([pq, q, qr]);
                            // The quad p, pq, qr, r: cut by its shorter diagonal.
                            if dist2(p, qr) <= dist2(pq, r) {
                                stack.extend([[p, pq, qr], [p, qr, r]]);
                            } else {
                                stack.extend([[p, pq, r], [pq, qr, r]]);
                            }
                        }
                    }
                }
            }
        }
        Ok(Refinement {
            triangles: out,
            counts,
            cache,
        })
    }

    /// Triangles of a refinement that are not collapsed (three distinct vertex identities).
    pub fn surviving(&self, refinement: &Refinement) -> usize {
        refinement
            .triangles
            .iter()
            .filter(|(p, t)| {
                let k = t.map(|g| self.vertex_key(*p, g));
                k[0] != k[1] && k[1] != k[2] && k[2] != k[0]
            })
            .count()
    }

    /// The evaluation phase: one vertex per identity (reusing those the decisions evaluated),
    /// collapsed triangles dropped. Returns the mesh, each triangle's patch, and the counts.
    pub fn assemble(&self, refinement: Refinement) -> (TriangleMesh, Vec<u32>, RefineCounts) {
        let Refinement {
            triangles,
            mut counts,
            mut cache,
        } = refinement;
        let mut mesh = TriangleMesh::default();
        let mut patch_of = Vec::with_capacity(triangles.len());
        let mut index: HashMap<VertexKey, u32> = HashMap::new();
        for (patch, tri) in triangles {
            let keys = tri.map(|g| self.vertex_key(patch, g));
            if keys[0] == keys[1] || keys[1] == keys[2] || keys[2] == keys[0] {
                continue;
            }
            let mut ids = [0u32; 3];
            for k in 0..3 {
                ids[k] = match index.get(&keys[k]) {
                    Some(&i) => i,
                    None => {
                        let e = self.evaluate(&mut cache, &mut counts, patch, tri[k]);
                        let i = mesh.positions.len() as u32;
                        mesh.positions.push(e.point.position.map(|x| x as f32));
                        mesh.normals.push(e.point.normal.map(|x| x as f32));
                        mesh.sources.push(e.source);
                        index.insert(keys[k], i);
                        i
                    }
                };
            }
            mesh.triangles.push(ids);
            patch_of.push(patch);
        }
        (mesh, patch_of, counts)
    }
}
