//! √3's boundary patches (Kobbelt's boundary rules): which triangles of an isolated mesh the
//! boundary shapes, the fan that charts each, and its control points.
//!
//! A triangle whose corners all lie [`REGULAR_ROW`] `= 4` edges or more from every boundary
//! vertex is certified regular at level 0 (`schemes::sqrt3_boundary_surface`): the interior
//! patches of [`crate::scheme::triangle::region_patch`] evaluate it. Every other triangle is a
//! **boundary patch**, charted in the fan of one boundary vertex `V`
//! (`schemes::sqrt3_boundary`'s charts): the nearest boundary vertex with other than three
//! triangles within [`FAN_REACH`] edges of a corner, else the nearest boundary vertex, whose fan
//! of three is the half-plane; the first of the two charts that is the mesh near the triangle
//! wins. A half-plane patch is a **strip** patch: its stencils are translation invariant along
//! the line, so its kind is the triangle's row and orientation alone.
//!
//! A level-1 row reads level-0 points within `5/3` units, so a basis function's support has
//! radius `(3/2)(5/3) = 2.5`, as the regular `psi`'s: the weights on a triangle reach two edges
//! from its corners (measured over every kind of a lattice parallelogram at rates up to 24).
//! The patch's **layout** is every fan point within [`LAYOUT_RADIUS`] `= 3` edges of a corner
//! (breadth first in the fan), ascending; a weight outside it is refused when the grids are
//! made. The rules that make the surface there read the mesh about as far, so a triangle is a
//! patch only where its chart is the mesh within [`CHECK_RADIUS`] `= 4` edges of its corners:
//! every fan point there is a vertex with the fan's boundary flag and number of triangles (six
//! inside, three on the boundary, `K` at `V`), and neighbouring points are neighbouring
//! vertices. Where that fails the isolation refines again (its steps triple the distances
//! between boundary vertices of other than three triangles, extraordinary interior vertices
//! and the boundary).

use std::collections::{BTreeSet, HashMap, HashSet, VecDeque};

use schemes::sqrt3_boundary::{BoundaryFan, FanPoint, V};
use schemes::sqrt3_boundary_surface::REGULAR_ROW;

use crate::mesh::topology::{Mesh, NONE};
use crate::mesh::triangle_topology::neighbours;
use crate::scheme::patch::PatchKind;
use crate::scheme::triangle::patch::TrianglePatch;
use crate::{MeshError, RuntimeError};

/// A boundary patch's layout: the fan points within this many edges of a corner (module
/// docs; the weights reach two).
pub const LAYOUT_RADIUS: u32 = 3;

/// The mesh must be the fan within this many edges of a boundary patch's corners.
pub const CHECK_RADIUS: u32 = 4;

/// A boundary vertex with other than three triangles within this many edges of a triangle's
/// corner is the first chart tried: beside a corner of one triangle (a 60-degree wedge) the
/// other side comes within [`CHECK_RADIUS`] of a strip triangle up to about ten edges out.
pub const FAN_REACH: u32 = 12;

/// Points of a chart at most this far from its vertex `V` (`a + b` in their sectors) are named:
/// a patch's corners lie within `FAN_REACH + 1` of `V`, its checked points
/// [`CHECK_RADIUS`] further.
const CHART_RADIUS: i64 = (FAN_REACH + 1 + CHECK_RADIUS) as i64;

/// The six unit steps of the lattice.
const STEPS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// Which boundary patch a triangle is: the fan (`faces = 3`: the half-plane, a strip patch),
/// the sector whose chart holds the triangle, and the triangle there, `(a, b), (a+1, b),
/// (a, b+1)` (up) or `(a+1, b), (a+1, b+1), (a, b+1)` (down); a strip patch has sector 0 and
/// `a = 0` (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BoundaryPatch {
    /// `K`, the number of triangles at the fan's vertex.
    pub faces: u32,
    /// The sector whose chart holds the triangle.
    pub sector: u32,
    /// Whether the triangle points down in the chart.
    pub down: bool,
    /// Its lowest corner's `a` (up) or `a + 1` less one (down).
    pub a: i64,
    /// Its lowest row.
    pub b: i64,
}

/// The packed fields' ranges: `a` in `-64..64`, `b` in `0..128`, the sector below 64.
const A_BIAS: i64 = 64;

impl BoundaryPatch {
    /// Whether this is a half-plane patch.
    pub fn is_strip(&self) -> bool {
        self.faces == 3
    }

    /// The fan it is charted in.
    pub fn fan(&self) -> BoundaryFan {
        BoundaryFan::new(self.faces)
    }

    /// Its corners in its sector's chart, counter-clockwise, the first at the patch's `(0,0)`.
    pub fn corners(&self) -> [(i64, i64); 3] {
        let (a, b) = (self.a, self.b);
        if self.down {
            [(a + 1, b), (a + 1, b + 1), (a, b + 1)]
        } else {
            [(a, b), (a + 1, b), (a, b + 1)]
        }
    }

    /// The table key's `sector` field for this patch (`faces` goes in `faces`, `boundary` is
    /// set): `sector << 15 | down << 14 | (a + 64) << 7 | b`; `None` out of those ranges.
    pub fn packed(&self) -> Option<u32> {
        let a = u32::try_from(self.a + A_BIAS).ok().filter(|&a| a < 128)?;
        let b = u32::try_from(self.b).ok().filter(|&b| b < 128)?;
        (self.sector < 64).then_some(self.sector << 15 | u32::from(self.down) << 14 | a << 7 | b)
    }

    /// The patch of a table key's `faces` and packed `sector` ([`BoundaryPatch::packed`]).
    pub fn unpacked(faces: u32, packed: u32) -> Self {
        BoundaryPatch {
            faces,
            sector: packed >> 15,
            down: packed >> 14 & 1 == 1,
            a: i64::from(packed >> 7 & 127) - A_BIAS,
            b: i64::from(packed & 127),
        }
    }

    /// The kind a triangle patch carries.
    pub fn kind(&self) -> Option<PatchKind> {
        Some(PatchKind {
            boundary: true,
            feature: table_format::Feature::None,
            faces: self.faces,
            sector: self.packed()?,
        })
    }

    /// The patch's corners as fan points.
    pub fn corner_points(&self) -> [FanPoint; 3] {
        let fan = self.fan();
        self.corners()
            .map(|c| fan.canonical(i64::from(self.sector), c).unwrap_or(V))
    }

    /// The layout: every fan point within [`LAYOUT_RADIUS`] edges of a corner, ascending.
    pub fn layout(&self) -> Vec<FanPoint> {
        let mut out: Vec<FanPoint> = within(self.fan(), &self.corner_points(), LAYOUT_RADIUS)
            .into_iter()
            .collect();
        out.sort_unstable();
        out
    }
}

/// The neighbours of a fan point: the `K + 1` points `E_s` of `V`, else its six lattice
/// neighbours that lie in the fan (a point on `E_K`'s ray is read in sector `K - 1`'s chart).
pub fn fan_neighbours(fan: BoundaryFan, p: FanPoint) -> Vec<FanPoint> {
    if p == V {
        return (0..=fan.faces).map(|s| (s, 1, 0)).collect();
    }
    let (s, a, b) = p;
    let (sector, at) = if s == fan.faces {
        (i64::from(s) - 1, (0, a))
    } else {
        (i64::from(s), (a, b))
    };
    STEPS
        .iter()
        .filter_map(|d| fan.canonical(sector, (at.0 + d.0, at.1 + d.1)))
        .collect()
}

/// The fan points within `radius` edges of `from` (breadth-first).
fn within(fan: BoundaryFan, from: &[FanPoint], radius: u32) -> HashSet<FanPoint> {
    let mut seen: HashSet<FanPoint> = from.iter().copied().collect();
    let mut queue: VecDeque<(FanPoint, u32)> = from.iter().map(|&p| (p, 0)).collect();
    while let Some((p, d)) = queue.pop_front() {
        if d == radius {
            continue;
        }
        for q in fan_neighbours(fan, p) {
            if seen.insert(q) {
                queue.push_back((q, d + 1));
            }
        }
    }
    seen
}

/// `(a, b)` of a point's sector `from` read in sector `to`'s chart (sectors a few apart).
fn turned((a, b): (i64, i64), from: i64, to: i64) -> (i64, i64) {
    let mut q = (a, b);
    let mut s = from;
    while s > to {
        q = (-q.1, q.0 + q.1);
        s -= 1;
    }
    while s < to {
        q = (q.0 + q.1, -q.0);
        s += 1;
    }
    q
}

/// A fan point's coordinates in sector `to`'s chart.
fn in_chart(p: FanPoint, to: i64) -> (i64, i64) {
    if p == V {
        (0, 0)
    } else {
        turned((p.1, p.2), i64::from(p.0), to)
    }
}

/// The mesh vertices around a boundary vertex named by fan points (within [`CHART_RADIUS`]),
/// grown face by face from its fan, breadth first.
#[derive(Clone, Debug)]
struct FanChart {
    fan: BoundaryFan,
    of_point: HashMap<FanPoint, u32>,
    of_vertex: HashMap<u32, FanPoint>,
}

impl FanChart {
    fn new(mesh: &Mesh, centre: usize) -> Self {
        let fan_halfedges = mesh.fan(centre);
        let fan = BoundaryFan::new(fan_halfedges.len().max(1) as u32);
        let mut chart = FanChart {
            fan,
            of_point: HashMap::new(),
            of_vertex: HashMap::new(),
        };
        chart.name(centre as u32, V);
        for (s, &e) in neighbours(mesh, centre).iter().enumerate() {
            chart.name(e, (s as u32, 1, 0));
        }
        // Breadth first, so that where the mesh is not the fan (around an extraordinary vertex
        // or another boundary) the fronts meet beyond it, as seen from V.
        let mut seen_face = HashSet::new();
        let mut queue: VecDeque<usize> = fan_halfedges.into();
        while let Some(h) = queue.pop_front() {
            let f = mesh.face_of[h] as usize;
            if !seen_face.insert(f) {
                continue;
            }
            let (p, q) = (mesh.face_vertices[h], mesh.head(h));
            let r = mesh.head(mesh.next(h));
            let Some(point) = chart.third(p, q) else {
                continue;
            };
            if point != V && point.1 + point.2 > CHART_RADIUS {
                continue;
            }
            chart.name(r, point);
            for g in [mesh.next(h), mesh.prev(h)] {
                let t = mesh.twin[g];
                if t != NONE && !seen_face.contains(&(mesh.face_of[t as usize] as usize)) {
                    queue.push_back(t as usize);
                }
            }
        }
        chart
    }

    /// Name `vertex` `point`, each keeping its first name or vertex: where the mesh is not the
    /// fan the two disagree, which a patch's check finds where it matters
    /// ([`patch_in`]); where the mesh wraps onto itself they disagree harmlessly.
    fn name(&mut self, vertex: u32, point: FanPoint) {
        self.of_vertex.entry(vertex).or_insert(point);
        self.of_point.entry(point).or_insert(vertex);
    }

    /// The name of the third corner of the counter-clockwise triangle `(p, q, r)`: in `p`'s
    /// sector chart (`q`'s if `p` is `V`), `r = p + R (q - p)`, `R` the 60-degree turn.
    fn third(&self, p: u32, q: u32) -> Option<FanPoint> {
        let (p, q) = (*self.of_vertex.get(&p)?, *self.of_vertex.get(&q)?);
        let last = i64::from(self.fan.faces) - 1;
        let sector = i64::from(if p == V { q.0 } else { p.0 }).min(last);
        let (pa, pb) = in_chart(p, sector);
        let (qa, qb) = in_chart(q, sector);
        let (da, db) = (qa - pa, qb - pb);
        self.fan.canonical(sector, (pa - db, pb + da + db))
    }

    /// The vertex named `p`.
    fn vertex(&self, p: FanPoint) -> Option<u32> {
        self.of_point.get(&p).copied()
    }
}

/// Breadth-first graph distances (up to `limit`) from `sources`, with the source each comes
/// from.
fn distances(mesh: &Mesh, sources: &[u32], limit: u32) -> (Vec<u32>, Vec<u32>) {
    let n = mesh.positions.len();
    let (mut dist, mut from) = (vec![u32::MAX; n], vec![NONE; n]);
    let mut queue = VecDeque::new();
    for &s in sources {
        dist[s as usize] = 0;
        from[s as usize] = s;
        queue.push_back(s);
    }
    while let Some(v) = queue.pop_front() {
        let d = dist[v as usize];
        if d >= limit {
            continue;
        }
        for w in neighbours(mesh, v as usize) {
            if dist[w as usize] == u32::MAX {
                dist[w as usize] = d + 1;
                from[w as usize] = from[v as usize];
                queue.push_back(w);
            }
        }
    }
    (dist, from)
}

/// The boundary patch of every triangle the boundary shapes (module docs), `None` for the
/// others; an error names the first triangle that is not a patch yet.
pub fn gather_boundary_patches(mesh: &Mesh) -> Result<Vec<Option<TrianglePatch>>, RuntimeError> {
    let boundary: Vec<u32> = (0..mesh.positions.len())
        .filter(|&v| mesh.is_boundary_vertex(v))
        .map(|v| v as u32)
        .collect();
    let irregular: Vec<u32> = boundary
        .iter()
        .copied()
        .filter(|&v| mesh.fan_iter(v as usize).count() != 3)
        .collect();
    let (to_boundary, nearest) = distances(mesh, &boundary, REGULAR_ROW as u32);
    let (to_irregular, nearest_irregular) = distances(mesh, &irregular, FAN_REACH);
    let mut charts: HashMap<u32, FanChart> = HashMap::new();
    let mut layouts: HashMap<BoundaryPatch, Vec<FanPoint>> = HashMap::new();
    let mut patches = vec![None; mesh.faces()];
    for (f, slot) in patches.iter_mut().enumerate() {
        let corners: Vec<u32> = mesh.face(f).to_vec();
        let closest = |d: &[u32]| {
            corners
                .iter()
                .copied()
                .min_by_key(|&c| d[c as usize])
                .filter(|&c| d[c as usize] != u32::MAX)
        };
        let Some(near) = closest(&to_boundary) else {
            continue;
        };
        if to_boundary[near as usize] >= REGULAR_ROW as u32 {
            continue;
        }
        // The nearest boundary vertex with other than three triangles, then the nearest
        // boundary vertex's half-plane: the first chart the mesh around the triangle is.
        let candidates = closest(&to_irregular)
            .map(|c| nearest_irregular[c as usize])
            .into_iter()
            .chain([nearest[near as usize]]);
        let mut last = String::new();
        for centre in candidates {
            let chart = charts
                .entry(centre)
                .or_insert_with(|| FanChart::new(mesh, centre as usize));
            match patch_in(mesh, chart, &corners, &mut layouts) {
                Ok(patch) => {
                    *slot = Some(patch);
                    break;
                }
                Err(reason) => {
                    last = format!("in the fan of boundary vertex {centre}: {reason}");
                }
            }
        }
        if slot.is_none() {
            return Err(MeshError::NotIsolated {
                face: f,
                reason: last,
            }
            .into());
        }
    }
    Ok(patches)
}

/// The patch of the triangle with `corners` (counter-clockwise) in `chart`, if the mesh is the
/// chart's fan within [`CHECK_RADIUS`] of them (module docs); else why not.
fn patch_in(
    mesh: &Mesh,
    chart: &FanChart,
    corners: &[u32],
    layouts: &mut HashMap<BoundaryPatch, Vec<FanPoint>>,
) -> Result<TrianglePatch, String> {
    let names: Vec<FanPoint> = corners
        .iter()
        .map(|&c| chart.of_vertex.get(&c).copied())
        .collect::<Option<_>>()
        .ok_or("the chart does not reach it")?;
    if names
        .iter()
        .zip(corners)
        .any(|(&p, &c)| chart.vertex(p) != Some(c))
    {
        return Err("its corners have two names in the chart".to_owned());
    }
    let (patch, corner, shift) = place(chart.fan, &names).ok_or("it is no triangle of the fan")?;
    // The chart is a local isomorphism there: every point near it is a vertex with the fan's
    // boundary flag and triangle count, and neighbouring points are neighbouring vertices.
    let region = within(chart.fan, &names, CHECK_RADIUS);
    for &p in &region {
        let v = chart
            .vertex(p)
            .ok_or_else(|| format!("its point {p:?} is no vertex of the chart"))?;
        let ring = neighbours(mesh, v as usize);
        for q in fan_neighbours(chart.fan, p) {
            let w = chart.vertex(q);
            if region.contains(&q) && !w.is_some_and(|w| ring.contains(&w)) {
                return Err(format!(
                    "the points {p:?} and {q:?} near it are not neighbouring vertices"
                ));
            }
        }
        let faces = mesh.fan_iter(v as usize).count();
        let on = chart.fan.on_boundary(p);
        let want = if p == V {
            chart.fan.faces as usize
        } else if on {
            3
        } else {
            6
        };
        if mesh.is_boundary_vertex(v as usize) != on || faces != want {
            return Err(format!(
                "vertex {v} near it has {faces} triangles{} where the fan has {want}{}",
                if mesh.is_boundary_vertex(v as usize) {
                    " on the boundary"
                } else {
                    ""
                },
                if on { " on the boundary" } else { "" }
            ));
        }
    }
    let layout = layouts.entry(patch).or_insert_with(|| patch.layout());
    let points = layout
        .iter()
        .map(|&p| {
            let at = if patch.is_strip() {
                let (x, y) = BoundaryFan::in_sector_zero(p);
                chart.fan.canonical(0, (x + shift, y))
            } else {
                Some(p)
            };
            at.and_then(|q| chart.vertex(q))
                .ok_or_else(|| format!("its layout point {p:?} is beyond the chart"))
        })
        .collect::<Result<Vec<u32>, _>>()?;
    let kind = patch
        .kind()
        .ok_or("it lies too far from the fan's vertex for a boundary patch")?;
    Ok(TrianglePatch {
        kind,
        points,
        corner,
    })
}

/// The boundary patch of a triangle whose corners (counter-clockwise) have the fan names
/// `names`, the face corner at the patch's first corner, and (strip patches) how far along the
/// line the triangle lies.
fn place(fan: BoundaryFan, names: &[FanPoint]) -> Option<(BoundaryPatch, usize, i64)> {
    let strip = fan.faces == 3;
    let sectors: BTreeSet<i64> = if strip {
        BTreeSet::from([0])
    } else {
        (0..i64::from(fan.faces)).collect()
    };
    for sector in sectors {
        let c: Vec<(i64, i64)> = names
            .iter()
            .map(|&p| {
                if strip {
                    BoundaryFan::in_sector_zero(p)
                } else {
                    in_chart(p, sector)
                }
            })
            .collect();
        for down in [false, true] {
            for corner in 0..3 {
                let (x, y) = c[corner];
                let (a, b) = if down { (x - 1, y) } else { (x, y) };
                let (shift, a) = if strip { (a, 0) } else { (0, a) };
                let patch = BoundaryPatch {
                    faces: fan.faces,
                    sector: sector as u32,
                    down,
                    a,
                    b,
                };
                let want = patch.corners();
                let matches = (0..3).all(|i| {
                    let (wa, wb) = want[i];
                    c[(corner + i) % 3] == (wa + shift, wb)
                });
                let in_wedge = strip || want.iter().all(|&(wa, wb)| wa >= 0 && wb >= 0);
                if matches && in_wedge && b >= 0 {
                    return Some((patch, corner, shift));
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lattice parallelogram `0..=m` squared, vertex `(a, b)` numbered `a + (m + 1) b`.
    fn parallelogram(m: i64) -> Mesh {
        let index = |a: i64, b: i64| a + (m + 1) * b;
        let positions = (0..(m + 1) * (m + 1))
            .map(|k| [(k % (m + 1)) as f64, (k / (m + 1)) as f64, 0.0])
            .collect();
        let mut faces = Vec::new();
        for b in 0..m {
            for a in 0..m {
                faces.push(vec![index(a, b), index(a + 1, b), index(a, b + 1)]);
                faces.push(vec![index(a + 1, b), index(a + 1, b + 1), index(a, b + 1)]);
            }
        }
        Mesh::new(positions, &faces, &[], schemes::BoundaryMode::EdgeOnly).expect("a valid mesh")
    }

    /// Charts name the lattice: at the corner with one triangle sector 0's chart is the
    /// lattice itself; at a straight side's vertex the half-plane is the lattice moved there;
    /// at the corner with two triangles the boundary turns by 120 degrees.
    #[test]
    fn charts_name_the_lattice() {
        let m = 12;
        let mesh = parallelogram(m);
        let lattice = |v: u32| (i64::from(v) % (m + 1), i64::from(v) / (m + 1));
        for (centre, origin) in [(0u32, (0, 0)), (6, (6, 0)), (12, (12, 0))] {
            let chart = FanChart::new(&mesh, centre as usize);
            for (&v, p) in &chart.of_vertex {
                assert_eq!(chart.vertex(*p), Some(v), "{centre}: {p:?}");
            }
            for (&v, &p) in &chart.of_vertex {
                let (x, y) = lattice(v);
                let rel = (x - origin.0, y - origin.1);
                let want = match chart.fan.faces {
                    // E_0 = (0, 1), E_1 = (-1, 1): lattice (x, y) is chart (x + y, -x).
                    2 => chart.fan.canonical(0, (rel.0 + rel.1, -rel.0)),
                    _ => chart.fan.canonical(0, rel),
                };
                assert_eq!(Some(p), want, "centre {centre}, vertex {v} at {rel:?}");
            }
        }
    }
}
