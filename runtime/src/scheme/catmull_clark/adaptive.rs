//! Limit stencils by feature-adaptive refinement: the exact limit position and derivatives of
//! any point of a quad face, whatever the features around it (any valence, darts, creases and
//! corners of any sharpness, semi-sharp features in either crease method), as a combination of
//! the mesh's vertices.
//!
//! A face whose 4 x 4 neighbourhood subdivides by the uniform cubic B-spline rules is a
//! B-spline patch (Stam 1998, section 2): its four corners are regular (interior valence 4 with
//! smooth edges, or a crease vertex with two faces on the face's side of an infinitely sharp
//! crease, or a pinned corner of a one-face sector), and nothing around it is semi-sharp. An
//! infinitely sharp edge acts as a boundary: the points beyond it are replaced by reflections
//! (`2 P_0 - P_1`, the "phantom" points of OpenSubdiv's boundary patches), which reproduce the
//! crease rules exactly (a crease vertex `(E_a + 6 V + E_b) / 8`, a crease edge its midpoint).
//!
//! Any other face is refined (`refine`, the one statement of the rules, sharpness decaying by
//! level) and its points handed to the children that contain them, until every point lies in a
//! B-spline patch. A point at distance `d` from the face's irregular corners needs about
//! `log2(1 / d)` levels, plus the levels semi-sharp features take to decay: every point that is
//! not an irregular vertex itself is reached in finitely many. Points exactly at an irregular
//! boundary vertex take the crease or corner limit masks of OpenSubdiv's `Sdc` instead.
//!
//! Only a neighbourhood is refined: at each level the faces within [`RINGS`] vertex rings of the
//! faces still holding points. A vertex's refined position depends on its one-ring only, so the
//! three rings of margin keep every vertex of the next level's patches exact.

use std::collections::{BTreeMap, BTreeSet};

use schemes::crease::{is_infinite, is_sharp, CreaseRule, INFINITE};
use schemes::BoundaryMode;

use rayon::prelude::*;

use crate::mesh::topology::Mesh;
use crate::scheme::catmull_clark::refine::{refine, refined_vertex, LevelEdges};
use crate::scheme::stencil::{Stencil, Weight};
use crate::MeshError;

/// Vertex rings kept around the faces still being refined.
pub const RINGS: usize = 3;

/// At most this many levels are refined below the mesh (a dual point at rate 64 needs 8,
/// sharpness adds at most 10).
pub const MAX_LEVELS: usize = 24;

/// A point to evaluate: face `face` of the mesh, at its parameters `(u, v)` in `[0, 1]^2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitQuery {
    /// The face (a quad).
    pub face: u32,
    /// Parameter along the face's first edge.
    pub u: f64,
    /// Parameter along its last edge, reversed.
    pub v: f64,
}

/// The limit at one point as weights on the mesh's vertices: `(vertex, [position, d/du,
/// d/dv])`, sorted by vertex. At a vertex that is not smooth, `d/du` and `d/dv` are tangents
/// along the face's frame (their cross product is the normal), not derivatives.
pub type LimitStencil = Vec<(u32, [f64; 3])>;

/// The cubic B-spline basis at `t` and its derivative, for control offsets `-1, 0, 1, 2`.
pub(crate) fn bspline(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let (t2, t3) = (t * t, t * t * t);
    (
        [
            s * s * s / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ],
        [
            -s * s / 2.0,
            (3.0 * t2 - 4.0 * t) / 2.0,
            (-3.0 * t2 + 2.0 * t + 1.0) / 2.0,
            t2 / 2.0,
        ],
    )
}

/// A control point of a patch: a vertex, or a reflection across a sharp edge, as `(vertex,
/// weight)` terms in any [`Weight`] (integer weights: exact in f64 and in rationals).
pub(crate) type Combo<W> = Vec<(u32, W)>;

/// Corner `k`'s position in the face's `(s, t)` grid, and its two axes (along the corner's
/// outgoing and incoming edges).
const BASE: [(i32, i32); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];
const AXIS_OUT: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];
const AXIS_IN: [(i32, i32); 4] = [(0, 1), (-1, 0), (0, -1), (1, 0)];

/// Whether sharpness `s` is 0 or infinite: nothing decays any more.
fn settled(s: f32) -> bool {
    !is_sharp(s) || is_infinite(s)
}

/// The 4 x 4 control points (`grid[a + 1][b + 1]` at `(a, b)`, `a` along the face's `u`) of
/// quad `g` if it is a B-spline patch, else `None`; generic over the weight so that the exact
/// evaluation ([`crate::eval::exact_eval::feature`]) takes the same net in rationals.
pub(crate) fn bspline_patch<W: Weight>(mesh: &Mesh, g: usize) -> Option<[[Combo<W>; 4]; 4]> {
    let hs = mesh.face_halfedges(g);
    if hs.len() != 4 {
        return None;
    }
    let corner: Vec<u32> = mesh.face(g).to_vec();
    let sharp = |h: usize| is_infinite(mesh.edge_sharpness[h]);
    let mut grid: [[Combo<W>; 4]; 4] = Default::default();
    let mut put =
        |(x, y): (i32, i32), combo: Combo<W>| grid[(x + 1) as usize][(y + 1) as usize] = combo;
    let int = |k: i64| W::ratio(k, 1);
    let one = |v: u32| vec![(v, int(1))];
    for k in 0..4 {
        let h = hs.start + k;
        let v = corner[k] as usize;
        let edges = mesh.vertex_edges(v);
        if !settled(mesh.vertex_sharpness[v])
            || edges.iter().any(|&e| !settled(mesh.edge_sharpness[e]))
        {
            return None;
        }
        let sharpness: Vec<f32> = edges.iter().map(|&e| mesh.edge_sharpness[e]).collect();
        let rule = CreaseRule::of(mesh.vertex_sharpness[v], &sharpness);
        let (next, prev, opposite) = (
            corner[(k + 1) % 4],
            corner[(k + 3) % 4],
            corner[(k + 2) % 4],
        );
        let (out_sharp, in_sharp) = (sharp(h), sharp(mesh.prev(h)));
        let at = |x: i32, y: i32| {
            (
                BASE[k].0 + x * AXIS_OUT[k].0 + y * AXIS_IN[k].0,
                BASE[k].1 + x * AXIS_OUT[k].1 + y * AXIS_IN[k].1,
            )
        };
        put(at(0, 0), one(v as u32));
        let reflect = |a: u32, b: u32| vec![(a, int(2)), (b, int(-1))];
        match (in_sharp, out_sharp, rule) {
            (false, false, CreaseRule::Smooth) => {
                if mesh.fan_iter(v).count() != 4 {
                    return None;
                }
                let n1 = mesh.twin[mesh.prev(h)] as usize;
                let n2 = mesh.twin[mesh.prev(n1)] as usize;
                put(at(-1, 0), one(mesh.head(n2)));
                put(at(-1, -1), one(mesh.head(mesh.next(n2))));
                put(at(0, -1), one(mesh.head(mesh.next(mesh.next(n2)))));
            }
            (false, true, CreaseRule::Crease) => {
                // The crease runs along the outgoing edge; the face across the incoming edge
                // is the sector's other face, and its far edge at v must be the crease.
                let n1 = mesh.twin[mesh.prev(h)] as usize;
                if !sharp(mesh.prev(n1)) {
                    return None;
                }
                let above_left = mesh.head(mesh.next(n1));
                let left = mesh.head(mesh.next(mesh.next(n1)));
                put(at(-1, 0), one(left));
                put(at(0, -1), reflect(v as u32, prev));
                put(at(-1, -1), reflect(left, above_left));
            }
            (true, false, CreaseRule::Crease) => {
                let m = mesh.twin[h] as usize;
                if !sharp(mesh.next(m)) {
                    return None;
                }
                let down = mesh.head(mesh.next(m));
                let down_right = mesh.head(mesh.next(mesh.next(m)));
                put(at(0, -1), one(down));
                put(at(-1, 0), reflect(v as u32, next));
                put(at(-1, -1), reflect(down, down_right));
            }
            (true, true, CreaseRule::Corner) => {
                put(at(-1, 0), reflect(v as u32, next));
                put(at(0, -1), reflect(v as u32, prev));
                put(
                    at(-1, -1),
                    vec![
                        (v as u32, int(4)),
                        (next, int(-2)),
                        (prev, int(-2)),
                        (opposite, int(1)),
                    ],
                );
            }
            _ => return None,
        }
    }
    Some(grid)
}

/// The 4 x 4 control grid of quad `g` (`grid[a + 1][b + 1]` at `(a, b)`, `a` along the face's
/// `u`) as mesh vertices, when the face is a B-spline patch ([`bspline_patch`]), and its sides
/// with phantom points beyond, a bit per side `k` (the edge from corner `k` to corner `k + 1`:
/// 0 `v = 0`, 1 `u = 1`, 2 `v = 1`, 3 `u = 0`): its infinitely sharp sides (boundary edges
/// included). Beyond those sides the net's points are reflections, `2 P_0 - P_1` through the
/// side's row and `4 P_00 - 2 P_10 - 2 P_01 + P_11` beyond two sides at a pinned corner, which the
/// evaluation makes from the grid's other cells; the grid holds the face's first corner there.
/// Why the reflections are the limit: the crease and boundary rules are the B-spline rules of the
/// reflected net (`bspline_patch`).
pub(crate) fn phantom_grid(mesh: &Mesh, g: usize) -> Option<([[u32; 4]; 4], u8)> {
    let net = bspline_patch::<f64>(mesh, g)?;
    let sides = mesh.face_halfedges(g);
    let phantoms = (0..4)
        .filter(|&k| is_infinite(mesh.edge_sharpness[sides.start + k]))
        .fold(0u8, |bits, k| bits | 1 << k);
    // Cell (a, b) lies beyond side 0 at b = 0, side 1 at a = 3, side 2 at b = 3, side 3 at a = 0.
    let beyond = |a: usize, b: usize| {
        let side = |k: u8| phantoms & (1 << k) != 0;
        (b == 0 && side(0)) || (a == 3 && side(1)) || (b == 3 && side(2)) || (a == 0 && side(3))
    };
    let placeholder = *mesh.face(g).first()?;
    let mut grid = [[placeholder; 4]; 4];
    for (a, column) in net.iter().enumerate() {
        for (b, combo) in column.iter().enumerate() {
            match combo.as_slice() {
                _ if beyond(a, b) => {}
                &[(v, 1.0)] => grid[a][b] = v,
                // A reflected point inside the grid: not a net the evaluation makes.
                _ => return None,
            }
        }
    }
    Some((grid, phantoms))
}

/// How the limit position at a vertex is known exactly ([`vertex_limit`]).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LimitPosition {
    /// A mask of rational weights `(vertex, numerator, denominator)`: OpenSubdiv's `Sdc` limit
    /// masks (corner `V`; crease `(E_a + 4 V + E_b) / 6`; smooth
    /// `(n^2 V + 4 sum E + sum F) / (n (n + 5))`).
    Mask(Vec<(u32, i64, i64)>),
    /// The left eigenvector `l = l S`, `l . 1 = 1`, of the stationary local subdivision matrix
    /// `S` of `shape` ([`stationary_step`]) over the one-ring `ids` (its slot order): a dart,
    /// whose limit no closed-form mask gives.
    Stationary {
        /// The neighbourhood's shape.
        shape: Stationary,
        /// The vertex, its edge neighbours and its faces' opposite vertices, in fan order.
        ids: Vec<u32>,
    },
}

/// The limit at a vertex ([`vertex_limit`]): f64 position and tangent masks, and how the
/// position is known exactly.
#[derive(Clone, Debug)]
pub(crate) struct VertexLimit {
    /// `(vertex, [position, tangent 1, tangent 2])`, an index possibly repeated.
    pub masks: Vec<(u32, [f64; 3])>,
    /// The exact position (the same limit as the masks' first column).
    pub position: LimitPosition,
}

/// The f64 masks of a rational position mask and `(vertex, [tangent 1, tangent 2])` terms:
/// the position column is the rational mask itself, stated once.
fn with_position(position: &[(u32, i64, i64)], tangents: Vec<(u32, [f64; 2])>) -> VertexLimit {
    let masks = position
        .iter()
        .map(|&(v, p, q)| (v, [f64::ratio(p, q), 0.0, 0.0]))
        .chain(tangents.into_iter().map(|(v, [a, b])| (v, [0.0, a, b])))
        .collect();
    VertexLimit {
        masks,
        position: LimitPosition::Mask(position.to_vec()),
    }
}

/// The fan of vertex `v` rotated to start at its half-edge `h`: the edge neighbours `E_i` and the
/// faces' opposite vertices `F_i`, in fan order (`None` if `h` does not leave `v`).
fn fan_rings(mesh: &Mesh, v: usize, h: usize) -> Option<(Vec<u32>, Vec<u32>)> {
    let fan = mesh.fan(v);
    let n = fan.len();
    let j = fan.iter().position(|&e| e == h)?;
    let ring = (0..n).map(|i| mesh.head(fan[(j + i) % n])).collect();
    let opposite = (0..n)
        .map(|i| mesh.head(mesh.next(fan[(j + i) % n])))
        .collect();
    Some((ring, opposite))
}

/// OpenSubdiv's smooth tangent masks at an interior vertex of valence `n` (`Sdc`'s Catmull–Clark
/// limit tangents, after Halstead et al.): `t_1 = sum_i 4 cos(i theta) E_i + (cos(i theta) +
/// cos((i + 1) theta)) / (4 lambda - 1) F_i`, `theta = 2 pi / n`, `lambda` the subdominant
/// eigenvalue, and `t_2` the same turned back by one edge, so that `t_1 x t_2` follows the
/// face's orientation; `(vertex, [t_1, t_2])` terms over `ring` (`E_i`) and `opposite` (`F_i`).
fn smooth_tangents(ring: &[u32], opposite: &[u32]) -> Vec<(u32, [f64; 2])> {
    let n = ring.len();
    let k = n as f64;
    let theta = 2.0 * std::f64::consts::PI / k;
    let lambda = 5.0 / 16.0
        + (theta.cos() + (theta / 2.0).cos() * (2.0 * (9.0 + theta.cos())).sqrt()) / 16.0;
    let face_scale = 1.0 / (4.0 * lambda - 1.0);
    let tangent = |i: usize| {
        let (c0, c1) = ((i as f64 * theta).cos(), ((i + 1) as f64 * theta).cos());
        (4.0 * c0, face_scale * (c0 + c1))
    };
    let mut tangents = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (e1, f1) = tangent(i);
        let (e2, f2) = tangent((i + n - 1) % n);
        tangents.push((ring[i], [e1, e2]));
        tangents.push((opposite[i], [f1, f2]));
    }
    tangents
}

/// The limit position and tangents at vertex `v`, the corner of face `g` at half-edge `h`, by
/// OpenSubdiv's limit masks, where they are exact: a settled crease vertex (the sector of `g`
/// between its two sharp edges) or a corner. `None` elsewhere (smooth vertices are reached by
/// refinement or lie inside B-spline patches).
pub(crate) fn vertex_limit(mesh: &Mesh, h: usize) -> Option<VertexLimit> {
    let v = mesh.face_vertices[h] as usize;
    let edges = mesh.vertex_edges(v);
    let sharpness: Vec<f32> = edges.iter().map(|&e| mesh.edge_sharpness[e]).collect();
    if !settled(mesh.vertex_sharpness[v]) || sharpness.iter().any(|&s| !settled(s)) {
        return None;
    }
    let rule = CreaseRule::of(mesh.vertex_sharpness[v], &sharpness);
    let me = v as u32;
    match rule {
        CreaseRule::Corner if mesh.is_cone_tip(v) => {
            // A cone's tip has no tangent plane, so its normal is a choice: the smooth masks'
            // tangents (rotation-invariant combinations of the ring), whose normal is the same
            // from every face and, by symmetry, the cone's axis where it has one (the diagonal
            // at a cube's corner), rather than one face's corner normal.
            let (ring, opposite) = fan_rings(mesh, v, h)?;
            Some(with_position(
                &[(me, 1, 1)],
                smooth_tangents(&ring, &opposite),
            ))
        }
        CreaseRule::Corner => {
            // Tangents along the face's own edges at v: the normal of its corner.
            let (out, into) = (mesh.head(h), mesh.face_vertices[mesh.prev(h)]);
            Some(with_position(
                &[(me, 1, 1)],
                vec![(me, [-1.0, -1.0]), (out, [1.0, 0.0]), (into, [0.0, 1.0])],
            ))
        }
        CreaseRule::Crease => {
            // The sector of h: the faces between the sharp edge at or before h and the next,
            // edge i of the fan lying before face i (on the boundary, edge n after the last).
            let fan = mesh.fan(v);
            let n = fan.len();
            let boundary = mesh.is_boundary_vertex(v);
            let edge_count = if boundary { n + 1 } else { n };
            let edge = |i: usize| {
                if boundary && i == n {
                    mesh.prev(fan[n - 1])
                } else {
                    fan[i % n]
                }
            };
            let sharp_edge = |i: usize| is_infinite(mesh.edge_sharpness[edge(i % edge_count)]);
            let j = fan.iter().position(|&e| e == h)?;
            let start = (0..edge_count)
                .map(|back| (j + edge_count - back) % edge_count)
                .find(|&i| sharp_edge(i))?;
            let len = (1..=edge_count).find(|&d| sharp_edge(start + d))?;
            let ring: Vec<u32> = (0..=len)
                .map(|i| mesh.opposite(edge((start + i) % edge_count), v))
                .collect();
            let opposite: Vec<u32> = (0..len)
                .map(|i| mesh.head(mesh.next(fan[(start + i) % n])))
                .collect();
            let (e_first, e_last) = (ring[0], ring[len]);
            let mut terms = vec![(e_first, [0.5, 0.0]), (e_last, [-0.5, 0.0])];
            // Across the crease into the sector (OpenSubdiv's crease tangent mask, after
            // Biermann, Levin and Zorin 2000), face weights on the faces' opposite vertices.
            let interior = len - 1;
            let mut across = |vertex: u32, w: f64| terms.push((vertex, [0.0, w]));
            match interior {
                0 => {
                    across(me, -6.0);
                    across(e_first, 3.0);
                    across(e_last, 3.0);
                }
                1 => {
                    across(me, -4.0 / 6.0);
                    across(e_first, -1.0 / 6.0);
                    across(ring[1], 4.0 / 6.0);
                    across(e_last, -1.0 / 6.0);
                    across(opposite[0], 1.0 / 6.0);
                    across(opposite[1], 1.0 / 6.0);
                }
                _ => {
                    let k = (interior + 1) as f64;
                    let theta = std::f64::consts::PI / k;
                    let (cos, sin) = (theta.cos(), theta.sin());
                    let denominator = 1.0 / (k * (3.0 + cos));
                    let r = (cos + 1.0) / sin;
                    across(me, 4.0 * r * (cos - 1.0) * denominator);
                    across(e_first, -r * (1.0 + 2.0 * cos) * denominator);
                    across(e_last, -r * (1.0 + 2.0 * cos) * denominator);
                    across(opposite[0], sin * denominator);
                    for i in 1..=interior {
                        let (si, si1) = ((i as f64 * theta).sin(), ((i + 1) as f64 * theta).sin());
                        across(ring[i], 4.0 * si * denominator);
                        across(opposite[i], (si + si1) * denominator);
                    }
                }
            }
            // The crease's limit point depends on the crease alone (its cubic B-spline).
            let limit = with_position(&[(me, 2, 3), (e_first, 1, 6), (e_last, 1, 6)], terms);
            if interior >= 2 {
                // The crease point is exact; the tangent across is Biermann et al.'s start.
                let masks = stationary_limit(
                    Stationary::Sector { faces: len },
                    me,
                    &ring,
                    &opposite,
                    &limit.masks,
                    true,
                )?;
                return Some(VertexLimit { masks, ..limit });
            }
            Some(limit)
        }
        CreaseRule::Smooth | CreaseRule::Dart if !mesh.is_boundary_vertex(v) => {
            // OpenSubdiv's smooth limit masks, the fan rotated to start at h so that the
            // tangents follow the face's frame; face weights on the faces' opposite vertices.
            // A dart starts from them and converges to its own (`dart_limit`).
            let fan = mesh.fan(v);
            let n = fan.len();
            let j = fan.iter().position(|&e| e == h)?;
            let (ring, opposite) = fan_rings(mesh, v, h)?;
            let nn = i64::try_from(n).ok()?;
            let face = nn.checked_mul(nn.checked_add(5)?)?;
            let mut position = vec![(me, nn, nn + 5)];
            for i in 0..n {
                position.push((ring[i], 4, face));
                position.push((opposite[i], 1, face));
            }
            let limit = if n == 2 {
                // The mask's derivation (the left fixed vector of the rules on the fan's
                // rotation-invariant part) holds at valence 2 too: the points approaching the
                // vertex converge to it (`a_valence_two_limit_is_the_limit_of_the_points_
                // approaching_it`), not to `V` (OpenSubdiv's `Sdc` mask there, Hbr's, exact
                // only at the level it is applied). The subdominant eigenvalue is 1/4 and its
                // face weights vanish; the tangents are the face's own edges.
                with_position(
                    &position,
                    vec![
                        (me, [-1.0, -1.0]),
                        (ring[0], [1.0, 0.0]),
                        (ring[1], [0.0, 1.0]),
                    ],
                )
            } else {
                with_position(&position, smooth_tangents(&ring, &opposite))
            };
            if rule == CreaseRule::Dart {
                let sharp = (0..n).find(|&i| is_infinite(mesh.edge_sharpness[fan[(j + i) % n]]))?;
                let shape = Stationary::Dart { n, sharp };
                let masks = stationary_limit(shape, me, &ring, &opposite, &limit.masks, false)?;
                let ids = std::iter::once(me)
                    .chain(ring.iter().copied())
                    .chain(opposite.iter().copied())
                    .collect();
                return Some(VertexLimit {
                    masks,
                    position: LimitPosition::Stationary { shape, ids },
                });
            }
            Some(limit)
        }
        _ => None,
    }
}

/// The shape of a vertex's neighbourhood whose features are settled, so that its local
/// subdivision matrix is the same at every level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stationary {
    /// An interior vertex of valence `n` with one infinitely sharp edge, the one to ring
    /// neighbour `sharp`: the whole fan.
    Dart { n: usize, sharp: usize },
    /// `faces` faces between two infinitely sharp edges (a sector of a crease vertex, which
    /// subdivides independently of the vertex's other sector: the crease's points depend on
    /// the crease only).
    Sector { faces: usize },
}

/// The limit masks at a vertex with a stationary neighbourhood, from approximate masks
/// `start` on its one-ring (`me`, the edge neighbours `ring` and the faces' opposite vertices
/// `opposite`, in fan order), iterated to the exact ones; the position is kept as given where
/// `exact_position` (a sector's crease point is exact already).
///
/// The local subdivision matrix `S` (the one-ring's children as combinations of the one-ring)
/// does not change from level to level once the features are settled. The limit position is
/// its left eigenvector `l = l S` of eigenvalue 1 (`l . 1 = 1`); the tangents span the left
/// invariant subspace of the two largest eigenvalues below 1, whose eigenvectors the points
/// approaching the vertex follow. Both are reached by iterating from the start (power and
/// orthogonal subspace iteration, Golub and Van Loan section 7.3): each step is one more level
/// of refinement before the mask, the error shrinking by the ratio of the next eigenvalue to
/// the last one kept. Positive Gram–Schmidt keeps the tangents' orientation, so their cross
/// product is still the face's outward normal; their lengths and directions within the
/// tangent plane are not the face's derivatives.
///
/// OpenSubdiv's masks are the start: the smooth masks at a dart (whose sharp edge refines to
/// its midpoint, so they are not its own), and Biermann, Levin and Zorin's crease tangent across
/// a sector of three faces or more (made for their modified rules; under the standard rules
/// the sector's matrix has other eigenvectors). `None` when the one-ring repeats a vertex (a
/// valence-2 neighbour): one level of refinement separates it.
fn stationary_limit(
    shape: Stationary,
    me: u32,
    ring: &[u32],
    opposite: &[u32],
    start: &[(u32, [f64; 3])],
    exact_position: bool,
) -> Option<Vec<(u32, [f64; 3])>> {
    let ids: Vec<u32> = std::iter::once(me)
        .chain(ring.iter().copied())
        .chain(opposite.iter().copied())
        .collect();
    let slot: BTreeMap<u32, usize> = ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    if slot.len() != ids.len() {
        return None;
    }
    let step = stationary_step::<f64>(shape)?;
    if step.len() != ids.len() {
        return None;
    }
    let mut masks = [
        vec![0.0; ids.len()],
        vec![0.0; ids.len()],
        vec![0.0; ids.len()],
    ];
    for (id, w) in start {
        for (mask, w) in masks.iter_mut().zip(w) {
            mask[*slot.get(id)?] += w;
        }
    }
    let times = |x: &[f64]| {
        let mut out = vec![0.0; x.len()];
        for (row, &xj) in step.iter().zip(x) {
            for &(k, w) in row {
                out[k] += xj * w;
            }
        }
        out
    };
    let [mut position, mut t1, mut t2] = masks;
    for _ in 0..STATIONARY_ITERATIONS {
        let mut change = 0.0;
        if !exact_position {
            let next = times(&position);
            change = next
                .iter()
                .zip(&position)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            position = next;
        }
        // Rounding leaks the eigenvalue-1 component into the tangents (weights that do not
        // sum to 0), which the iteration would amplify: keep them in the invariant subspace
        // of masks summing to 0.
        let (a, b) = (sum_free(times(&t1)), sum_free(times(&t2)));
        let a = normalized(a);
        let along = dot(&b, &a);
        let b = normalized(b.iter().zip(&a).map(|(b, a)| b - along * a).collect());
        let turned = 1.0 - dot(&a, &t1).abs().min(dot(&b, &t2).abs());
        (t1, t2) = (a, b);
        if change < 1e-16 && turned < 1e-15 {
            break;
        }
    }
    Some(
        ids.iter()
            .enumerate()
            .map(|(k, &id)| (id, [position[k], t1[k], t2[k]]))
            .collect(),
    )
}

/// Iterations of [`stationary_limit`] at most: the errors shrink by the eigenvalue ratios
/// (at most about 0.9 a step for the sectors and darts of valence up to 24), so 400 reach
/// f64's precision.
const STATIONARY_ITERATIONS: usize = 400;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `x` less its mean: the mask's weights summing to 0, a tangent's.
fn sum_free(x: Vec<f64>) -> Vec<f64> {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.into_iter().map(|c| c - mean).collect()
}

fn normalized(x: Vec<f64>) -> Vec<f64> {
    let length = dot(&x, &x).sqrt();
    x.into_iter().map(|c| c / length).collect()
}

/// The local subdivision matrix of `shape`, as rows over the one-ring's slots (0 the vertex,
/// then the edge neighbours, then the faces' opposite vertices, in fan order): row `k` is the
/// child in slot `k` (the vertex point, the edge points, the face points). Derived from the one
/// statement of the rules ([`refined_vertex`]) on the one-ring alone, which holds every vertex
/// these children read; a sector's two sharp edges are the one-ring's boundary.
pub(crate) fn stationary_step<W: Weight>(shape: Stationary) -> Option<Vec<Vec<(usize, W)>>> {
    let (faces, edges) = match shape {
        Stationary::Dart { n, .. } => (n, n),
        Stationary::Sector { faces } => (faces, faces + 1),
    };
    let quads: Vec<Vec<i64>> = (0..faces)
        .map(|i| {
            [0, 1 + i, 1 + edges + i, 1 + (i + 1) % edges]
                .into_iter()
                .map(|x| x as i64)
                .collect()
        })
        .collect();
    let mut one_ring = Mesh::new(
        vec![[0.0; 3]; 1 + edges + faces],
        &quads,
        &[],
        BoundaryMode::EdgeOnly,
    )
    .ok()?;
    if let Stationary::Dart { sharp, .. } = shape {
        one_ring.set_edge_sharpness(0, 1 + sharp, INFINITE).ok()?;
    }
    let level = LevelEdges::new(&one_ring);
    let (nv, ne) = (one_ring.positions.len(), level.halfedge.len());
    let mut children = vec![0];
    for i in 0..edges {
        let h = *one_ring.find_halfedges(0, 1 + i).first()?;
        children.push(nv + level.of_halfedge[h] as usize);
    }
    children.extend((0..faces).map(|i| nv + ne + i));
    let rows = children
        .into_iter()
        .map(|child| {
            refined_vertex::<W>(&one_ring, &level, child)
                .into_iter()
                .map(|(k, w)| (k as usize, w))
                .collect()
        })
        .collect();
    Some(rows)
}

/// Where a query stands: on face `face` of the current level, at `(s, t)`, and `jacobian =
/// d(s, t) / d(u, v)` back to the query's face parameters.
#[derive(Clone, Copy, Debug)]
struct Pending {
    query: usize,
    s: f64,
    t: f64,
    jacobian: [[f64; 2]; 2],
}

impl Pending {
    /// The child of a refined quad that holds the point, and the point in the child's own
    /// parameters: child `c` covers the quarter at corner `c` and runs from it
    /// ([`crate::scheme::catmull_clark::isolate::Isolation::input_source`]).
    fn descend(self) -> (usize, Pending) {
        let (right, up) = (self.s > 0.5, self.t > 0.5);
        let (c, s, t, m) = match (right, up) {
            (false, false) => (0, 2.0 * self.s, 2.0 * self.t, [[2.0, 0.0], [0.0, 2.0]]),
            (true, false) => (
                1,
                2.0 * self.t,
                2.0 - 2.0 * self.s,
                [[0.0, 2.0], [-2.0, 0.0]],
            ),
            (true, true) => (
                2,
                2.0 - 2.0 * self.s,
                2.0 - 2.0 * self.t,
                [[-2.0, 0.0], [0.0, -2.0]],
            ),
            (false, true) => (
                3,
                2.0 - 2.0 * self.t,
                2.0 * self.s,
                [[0.0, -2.0], [2.0, 0.0]],
            ),
        };
        let j = self.jacobian;
        let jacobian = [
            [
                m[0][0] * j[0][0] + m[0][1] * j[1][0],
                m[0][0] * j[0][1] + m[0][1] * j[1][1],
            ],
            [
                m[1][0] * j[0][0] + m[1][1] * j[1][0],
                m[1][0] * j[0][1] + m[1][1] * j[1][1],
            ],
        ];
        (
            c,
            Pending {
                query: self.query,
                s,
                t,
                jacobian,
            },
        )
    }

    /// The face corner the point sits on, if any.
    fn corner(&self) -> Option<usize> {
        match (self.s, self.t) {
            (s, t) if s == 0.0 && t == 0.0 => Some(0),
            (s, t) if s == 1.0 && t == 0.0 => Some(1),
            (s, t) if s == 1.0 && t == 1.0 => Some(2),
            (s, t) if s == 0.0 && t == 1.0 => Some(3),
            _ => None,
        }
    }
}

/// The point's stencil on the current level's vertices from a B-spline patch.
fn patch_terms(grid: &[[Combo<f64>; 4]; 4], p: &Pending) -> Vec<(u32, [f64; 3])> {
    let (bs, ds) = bspline(p.s);
    let (bt, dt) = bspline(p.t);
    let j = p.jacobian;
    let mut terms = Vec::with_capacity(16);
    for a in 0..4 {
        for b in 0..4 {
            let (w, ws, wt) = (bs[a] * bt[b], ds[a] * bt[b], bs[a] * dt[b]);
            // d/du = ds/du d/ds + dt/du d/dt; d/dv alike.
            let (du, dv) = (j[0][0] * ws + j[1][0] * wt, j[0][1] * ws + j[1][1] * wt);
            for &(vertex, c) in &grid[a][b] {
                terms.push((vertex, [c * w, c * du, c * dv]));
            }
        }
    }
    terms
}

/// A dense accumulator over the input vertices, reset after each use by its touched list.
struct Accumulator {
    sum: Vec<[f64; 3]>,
    touched: Vec<u32>,
}

impl Accumulator {
    fn new(columns: usize) -> Self {
        Accumulator {
            sum: vec![[0.0; 3]; columns],
            touched: Vec::new(),
        }
    }

    /// Compose terms on the current level's vertices with `to_input` (its rows: the level's
    /// vertices over the input's): the stencil on the input vertices, sorted, zeros dropped.
    fn on_input(&mut self, terms: &[(u32, [f64; 3])], to_input: &Stencil<f64>) -> LimitStencil {
        for &(local, w) in terms {
            let (js, ws) = to_input.row(local as usize);
            for (&j, &x) in js.iter().zip(ws) {
                let e = &mut self.sum[j as usize];
                if *e == [0.0; 3] {
                    self.touched.push(j);
                }
                for c in 0..3 {
                    e[c] += w[c] * x;
                }
            }
        }
        self.touched.sort_unstable();
        self.touched.dedup();
        let out = self
            .touched
            .iter()
            .map(|&j| (j, std::mem::replace(&mut self.sum[j as usize], [0.0; 3])))
            .filter(|(_, w)| w.iter().any(|&x| x != 0.0))
            .collect();
        self.touched.clear();
        out
    }
}

/// The faces within `rings` vertex rings of `seeds`.
pub(crate) fn neighbourhood(
    mesh: &Mesh,
    seeds: impl Iterator<Item = usize>,
    rings: usize,
) -> BTreeSet<usize> {
    let mut faces: BTreeSet<usize> = seeds.collect();
    let mut frontier: Vec<usize> = faces.iter().copied().collect();
    for _ in 0..rings {
        let mut next = Vec::new();
        for &f in &frontier {
            for &v in mesh.face(f) {
                for h in mesh.fan(v as usize) {
                    let g = mesh.face_of[h] as usize;
                    if faces.insert(g) {
                        next.push(g);
                    }
                }
            }
        }
        frontier = next;
    }
    faces
}

/// The sub-mesh of `faces` (sharpness, holes and options kept; positions are not needed), the
/// mesh vertex of each of its vertices, and its face of each mesh face. Vertices whose faces
/// here form several fans (the rim of the neighbourhood) get one copy per fan.
pub(crate) fn submesh(
    mesh: &Mesh,
    faces: &BTreeSet<usize>,
) -> (Mesh, Vec<u32>, BTreeMap<usize, usize>) {
    let mut index = BTreeMap::new();
    let mut vertices: Vec<u32> = Vec::new();
    let mut lists: Vec<Vec<i64>> = Vec::with_capacity(faces.len());
    let mut face_of = BTreeMap::new();
    for (i, &f) in faces.iter().enumerate() {
        face_of.insert(f, i);
        lists.push(
            mesh.face(f)
                .iter()
                .map(|&v| {
                    *index.entry(v).or_insert_with(|| {
                        vertices.push(v);
                        vertices.len() as i64 - 1
                    })
                })
                .collect(),
        );
    }
    crate::mesh::topology::split_fans(&mut lists, &mut vertices);
    let positions = vec![[0.0; 3]; vertices.len()];
    let mut sub = Mesh::new(positions, &lists, &[], mesh.boundary).unwrap_or_else(|e| {
        unreachable!("a neighbourhood of a valid mesh, split into fans, is valid: {e}")
    });
    for (i, &f) in faces.iter().enumerate() {
        for (h, g) in sub.face_halfedges(i).zip(mesh.face_halfedges(f)) {
            sub.edge_sharpness[h] = mesh.edge_sharpness[g];
        }
        sub.holes[i] = mesh.holes[f];
    }
    for (s, &v) in sub.vertex_sharpness.iter_mut().zip(&vertices) {
        *s = mesh.vertex_sharpness[v as usize];
    }
    sub.creasing = mesh.creasing;
    sub.smooth_triangles = mesh.smooth_triangles;
    (sub, vertices, face_of)
}

/// The limit position, `d/du` and `d/dv` of `stencil` (one of [`limit_stencils`]' answers) on
/// the positions of the mesh it was computed on.
pub fn limit_of(stencil: &[(u32, [f64; 3])], mesh: &Mesh) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for &(v, w) in stencil {
        let p = mesh.positions[v as usize];
        for (k, row) in out.iter_mut().enumerate() {
            for c in 0..3 {
                row[c] += w[k] * p[c];
            }
        }
    }
    out
}

/// The limit stencils of `queries` on an all-quad mesh, in order.
pub fn limit_stencils(mesh: &Mesh, queries: &[LimitQuery]) -> Result<Vec<LimitStencil>, MeshError> {
    descend::<Stencil<f64>>(mesh, queries)
}

/// The limit position, `d/du` and `d/dv` of `queries` on an all-quad mesh, in order: the
/// values of [`limit_stencils`]' stencils on the mesh's positions ([`limit_of`]), by the same
/// descent carrying each level's positions instead of its vertices' stencils (cheaper when
/// the stencils are wide: a point next to a valence-360 vertex has 729 weights).
pub fn limit_points(mesh: &Mesh, queries: &[LimitQuery]) -> Result<Vec<[[f64; 3]; 3]>, MeshError> {
    descend::<LevelPositions>(mesh, queries)
}

/// What [`descend`] carries from level to level: how each vertex of the current level's
/// neighbourhood is known, and what a point's terms on those vertices become.
trait Carried: Sized + Sync {
    /// A finished point.
    type Out: Clone + Default + Send;
    /// Per-worker scratch space for [`Carried::finish`].
    type Scratch;
    /// Level 0: the mesh's vertices `vertices`.
    fn select(mesh: &Mesh, vertices: &[u32]) -> Self;
    /// The next level: `step`'s rows over this level's vertices.
    fn then(self, step: &Stencil<f64>) -> Self;
    fn scratch(mesh: &Mesh) -> Self::Scratch;
    /// A point from its `(vertex, [position, d/du, d/dv])` terms on this level's vertices.
    fn finish(&self, scratch: &mut Self::Scratch, terms: &[(u32, [f64; 3])]) -> Self::Out;
}

/// The stencils on the input vertices ([`limit_stencils`]).
impl Carried for Stencil<f64> {
    type Out = LimitStencil;
    type Scratch = Accumulator;
    fn select(mesh: &Mesh, vertices: &[u32]) -> Self {
        let mut to_input = Stencil::<f64>::new(mesh.positions.len());
        for &v in vertices {
            to_input.push_row(vec![(v, 1.0)]);
        }
        to_input
    }
    fn then(self, step: &Stencil<f64>) -> Self {
        Stencil::then(&self, step)
    }
    fn scratch(mesh: &Mesh) -> Accumulator {
        Accumulator::new(mesh.positions.len())
    }
    fn finish(&self, acc: &mut Accumulator, terms: &[(u32, [f64; 3])]) -> LimitStencil {
        acc.on_input(terms, self)
    }
}

/// The positions of a level's vertices ([`limit_points`]).
struct LevelPositions(Vec<[f64; 3]>);

impl Carried for LevelPositions {
    type Out = [[f64; 3]; 3];
    type Scratch = ();
    fn select(mesh: &Mesh, vertices: &[u32]) -> Self {
        LevelPositions(
            vertices
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect(),
        )
    }
    fn then(self, step: &Stencil<f64>) -> Self {
        let next = (0..step.rows())
            .into_par_iter()
            .map(|i| {
                let (js, ws) = step.row(i);
                let mut p = [0.0; 3];
                for (&j, &w) in js.iter().zip(ws) {
                    let q = self.0[j as usize];
                    for c in 0..3 {
                        p[c] += w * q[c];
                    }
                }
                p
            })
            .collect();
        LevelPositions(next)
    }
    fn scratch(_: &Mesh) {}
    fn finish(&self, _: &mut (), terms: &[(u32, [f64; 3])]) -> [[f64; 3]; 3] {
        let mut out = [[0.0; 3]; 3];
        for &(v, w) in terms {
            let p = self.0[v as usize];
            for (k, row) in out.iter_mut().enumerate() {
                for c in 0..3 {
                    row[c] += w[k] * p[c];
                }
            }
        }
        out
    }
}

/// One face's points at one level of [`descend`]: those finished, `(query, value)`, and those
/// handed to a child face, `(child, point)`.
type Outcome<T> = (Vec<(usize, T)>, Vec<(usize, Pending)>);

/// The feature-adaptive descent of `queries` (module docs), carrying `C`.
fn descend<C: Carried>(mesh: &Mesh, queries: &[LimitQuery]) -> Result<Vec<C::Out>, MeshError> {
    // No queried face, no neighbourhood: the submesh of none is not a mesh.
    if queries.is_empty() {
        return Ok(Vec::new());
    }
    let mut out: Vec<C::Out> = vec![C::Out::default(); queries.len()];
    let mut pending: BTreeMap<usize, Vec<Pending>> = BTreeMap::new();
    for (query, q) in queries.iter().enumerate() {
        let face = q.face as usize;
        if face >= mesh.faces()
            || mesh.face(face).len() != 4
            || !(0.0..=1.0).contains(&q.u)
            || !(0.0..=1.0).contains(&q.v)
        {
            return Err(MeshError::NotIsolated {
                face,
                reason: format!(
                    "limit query at ({}, {}) needs a quad and parameters in [0, 1]",
                    q.u, q.v
                ),
            });
        }
        pending.entry(face).or_default().push(Pending {
            query,
            s: q.u,
            t: q.v,
            jacobian: [[1.0, 0.0], [0.0, 1.0]],
        });
    }
    // Level 0: the neighbourhood of the queried faces, its vertices selected from the input.
    let faces = neighbourhood(mesh, pending.keys().copied(), RINGS);
    let (mut level, vertices, face_of) = submesh(mesh, &faces);
    let mut carried = C::select(mesh, &vertices);
    pending = pending.into_iter().map(|(f, p)| (face_of[&f], p)).collect();
    for depth in 0..=MAX_LEVELS {
        // Each face's points either lie in a B-spline patch (or at a vertex with a limit
        // mask) and are done, or go to the children that hold them: faces in parallel.
        let faces: Vec<(usize, Vec<Pending>)> = std::mem::take(&mut pending).into_iter().collect();
        let outcomes: Vec<Outcome<C::Out>> = faces
            .into_par_iter()
            .map_init(
                || C::scratch(mesh),
                |acc, (g, points)| {
                    let (mut done, mut descended) = (Vec::new(), Vec::new());
                    if let Some(grid) = bspline_patch::<f64>(&level, g) {
                        for p in points {
                            done.push((p.query, carried.finish(acc, &patch_terms(&grid, &p))));
                        }
                        return (done, descended);
                    }
                    for p in points {
                        let at_vertex = p
                            .corner()
                            .and_then(|k| vertex_limit(&level, level.face_halfedges(g).start + k));
                        if let Some(limit) = at_vertex {
                            done.push((p.query, carried.finish(acc, &limit.masks)));
                            continue;
                        }
                        let (c, child) = p.descend();
                        // Child c of face g is numbered by g's half-edge c (`refine`).
                        descended.push((level.face_halfedges(g).start + c, child));
                    }
                    (done, descended)
                },
            )
            .collect();
        let mut next: BTreeMap<usize, Vec<Pending>> = BTreeMap::new();
        for (done, descended) in outcomes {
            for (query, stencil) in done {
                out[query] = stencil;
            }
            for (face, p) in descended {
                next.entry(face).or_default().push(p);
            }
        }
        if next.is_empty() {
            return Ok(out);
        }
        if depth == MAX_LEVELS {
            pending = next;
            break;
        }
        let step = refine(&level);
        let faces = neighbourhood(&step.mesh, next.keys().copied(), RINGS);
        let (sub, vertices, face_of) = submesh(&step.mesh, &faces);
        carried = carried.then(&step.stencil.select(&vertices));
        level = sub;
        pending = next.into_iter().map(|(f, p)| (face_of[&f], p)).collect();
    }
    let face = pending.keys().next().copied().unwrap_or(0);
    Err(MeshError::NotIsolated {
        face,
        reason: format!("a limit point is not reached after {MAX_LEVELS} levels of refinement (an irregular vertex of a rule without a limit mask)"),
    })
}

#[cfg(test)]
// One test compares with the embedded Catmull–Clark table; without it, its helpers go unused.
#[cfg_attr(not(feature = "catmull-clark"), allow(unused))]
mod tests {
    use super::*;
    use crate::scheme::catmull_clark::isolate::isolate_with_origins;
    use crate::scheme::patch::dual_positions;
    use crate::stencil_table::StencilTable;

    /// A bumpy `m x m` grid of quads (boundary), or with `closed` a torus.
    fn grid(m: i64, mode: BoundaryMode) -> Mesh {
        let positions = (0..=m)
            .flat_map(|j| {
                (0..=m).map(move |i| {
                    let (x, y) = (i as f64, j as f64);
                    [x, y, (1.3 * x).sin() * (0.7 * y).cos() + 0.1 * x * y]
                })
            })
            .collect();
        let faces: Vec<Vec<i64>> = (0..m)
            .flat_map(|j| {
                (0..m).map(move |i| {
                    let v = j * (m + 1) + i;
                    vec![v, v + 1, v + m + 2, v + m + 1]
                })
            })
            .collect();
        Mesh::new(positions, &faces, &[], mode).expect("a valid grid")
    }

    fn dual_queries(f: usize, n: usize) -> Vec<LimitQuery> {
        (0..n * n)
            .map(|p| LimitQuery {
                face: f as u32,
                u: (2 * (p % n) + 1) as f64 / (2 * n) as f64,
                v: (2 * (p / n) + 1) as f64 / (2 * n) as f64,
            })
            .collect()
    }

    /// Away from sharp features the tables (Schaefer–Warren's scaling relation, solved by
    /// `stencilgen`) and adaptive refinement are two independent routes to the same limit:
    /// extraordinary vertices (the octahedron's valence 4 after isolation is regular; the
    /// tetrahedron's 3), boundaries in both modes.
    #[test]
    fn no_query_has_no_stencil() {
        let mesh = grid(4, BoundaryMode::EdgeOnly);
        assert_eq!(limit_stencils(&mesh, &[]), Ok(Vec::new()));
    }

    #[test]
    #[cfg(feature = "catmull-clark")]
    fn adaptive_limits_equal_the_table_patches() {
        let n = 5;
        let meshes = [
            (
                crate::mesh::test_meshes::tetrahedron(),
                BoundaryMode::EdgeOnly,
            ),
            (grid(3, BoundaryMode::EdgeOnly), BoundaryMode::EdgeOnly),
            (
                grid(3, BoundaryMode::EdgeAndCorner),
                BoundaryMode::EdgeAndCorner,
            ),
        ];
        for (mesh, mode) in meshes {
            let iso = isolate_with_origins(&mesh).expect("isolates");
            let table = StencilTable::default_for(mode).expect("embedded table");
            for (f, patch) in iso.patches.iter().enumerate() {
                let expected =
                    dual_positions(&table, &iso.mesh, patch, n as u32).expect("in the table");
                let stencils = limit_stencils(&iso.mesh, &dual_queries(f, n)).expect("reached");
                for (p, s) in expected.iter().zip(&stencils) {
                    let got = limit_of(s, &iso.mesh)[0];
                    let d = (0..3).map(|c| (got[c] - p[c]).abs()).fold(0.0, f64::max);
                    assert!(
                        d < 2e-6,
                        "{mode:?} face {f} ({:?}): {got:?} vs {p:?}",
                        patch.kind
                    );
                }
            }
        }
    }

    /// An infinitely sharp crease is a cubic B-spline curve of its vertices (DeRose et al.
    /// 1998): on a bumpy grid with a crease along row 2, the faces above it meet the curve
    /// along their first edge, and its tangent there is the curve's.
    /// The descent carrying positions gives the values of the descent carrying stencils, on a
    /// grid with an infinitely sharp crease, a semi-sharp edge, a dart and a pinned corner, at
    /// dual points, corners and edge points.
    #[test]
    fn limit_points_are_the_values_of_the_limit_stencils() {
        let m = 6;
        let mut mesh = grid(m, BoundaryMode::EdgeAndCorner);
        let at = |i: i64, j: i64| (j * (m + 1) + i) as usize;
        for i in 0..m {
            mesh.set_edge_sharpness(at(i, 2), at(i + 1, 2), INFINITE)
                .expect("an edge");
        }
        mesh.set_edge_sharpness(at(2, 4), at(3, 4), 1.5)
            .expect("an edge");
        mesh.set_edge_sharpness(at(3, 4), at(3, 5), INFINITE)
            .expect("an edge");
        mesh.set_vertex_sharpness(at(4, 4), INFINITE)
            .expect("a vertex");
        let queries: Vec<LimitQuery> = (0..mesh.faces() as u32)
            .flat_map(|face| {
                [
                    (0.0, 0.0),
                    (0.5, 0.0),
                    (1.0 / 6.0, 5.0 / 6.0),
                    (0.3, 0.7),
                    (1.0, 1.0),
                ]
                .map(|(u, v)| LimitQuery { face, u, v })
            })
            .collect();
        let points = limit_points(&mesh, &queries).expect("reached");
        let stencils = limit_stencils(&mesh, &queries).expect("reached");
        assert_eq!(points.len(), queries.len());
        for ((q, p), s) in queries.iter().zip(&points).zip(&stencils) {
            let expected = limit_of(s, &mesh);
            for k in 0..3 {
                for c in 0..3 {
                    assert!(
                        (p[k][c] - expected[k][c]).abs() <= 1e-12 * (1.0 + expected[k][c].abs()),
                        "{q:?} column {k}: {:?} vs {:?}",
                        p[k],
                        expected[k]
                    );
                }
            }
        }
    }

    #[test]
    fn a_sharp_crease_is_the_cubic_b_spline_of_its_vertices() {
        let m = 6;
        let mut mesh = grid(m, BoundaryMode::EdgeOnly);
        let row = |i: i64| (2 * (m + 1) + i) as usize;
        for i in 0..m {
            mesh.set_edge_sharpness(row(i), row(i + 1), INFINITE)
                .expect("an edge");
        }
        for i in 1..m - 1 {
            // Face (i, 2): its first edge runs from row(i) to row(i + 1).
            let face = (2 * m + i) as u32;
            for t in [0.0, 0.25, 0.5, 0.8] {
                let q = LimitQuery { face, u: t, v: 0.0 };
                let [p, du, _] = limit_of(&limit_stencils(&mesh, &[q]).expect("reached")[0], &mesh);
                let (b, db) = bspline(t);
                let mut curve = [0.0; 3];
                let mut tangent = [0.0; 3];
                for a in 0..4 {
                    let x = mesh.positions[row(i - 1 + a as i64)];
                    for c in 0..3 {
                        curve[c] += b[a] * x[c];
                        tangent[c] += db[a] * x[c];
                    }
                }
                for c in 0..3 {
                    assert!(
                        (p[c] - curve[c]).abs() < 1e-12,
                        "face {face} t {t}: {p:?} vs {curve:?}"
                    );
                    assert!(
                        (du[c] - tangent[c]).abs() < 1e-11,
                        "face {face} t {t}: {du:?} vs {tangent:?}"
                    );
                }
            }
        }
    }

    /// Sharpness 1 is one infinitely sharp step, then smooth limits: the same points from the
    /// mesh with an edge of sharpness 1, and from one step of the mesh with that edge
    /// infinitely sharp whose children are then made smooth.
    #[test]
    fn sharpness_one_is_one_sharp_step_then_smooth() {
        let m = 5;
        let edge = |mesh: &mut Mesh, s: f32| {
            for (a, b) in [(8, 9), (9, 10), (15, 9)] {
                mesh.set_edge_sharpness(a, b, s).expect("an edge");
            }
            mesh.set_vertex_sharpness(20, s).expect("a vertex");
        };
        let mut semi = grid(m, BoundaryMode::EdgeOnly);
        edge(&mut semi, 1.0);
        let mut sharp = grid(m, BoundaryMode::EdgeOnly);
        edge(&mut sharp, INFINITE);
        let mut stepped = refine(&sharp).mesh;
        for h in 0..stepped.twin.len() {
            if stepped.twin[h] != crate::mesh::NONE {
                stepped.edge_sharpness[h] = 0.0;
            }
        }
        stepped.vertex_sharpness.iter_mut().for_each(|s| *s = 0.0);
        for f in 0..semi.faces() {
            // Face f's child at corner 0 is face offsets[f] of the refined mesh, the quarter
            // [0, 1/2]^2 in f's parameters.
            let child = semi.face_halfedges(f).start as u32;
            for (u, v) in [(0.1, 0.2), (0.3, 0.45), (0.25, 0.05)] {
                let a = limit_of(
                    &limit_stencils(
                        &semi,
                        &[LimitQuery {
                            face: f as u32,
                            u,
                            v,
                        }],
                    )
                    .expect("reached")[0],
                    &semi,
                )[0];
                let q = LimitQuery {
                    face: child,
                    u: 2.0 * u,
                    v: 2.0 * v,
                };
                let b = limit_of(
                    &limit_stencils(&stepped, &[q]).expect("reached")[0],
                    &stepped,
                )[0];
                for c in 0..3 {
                    assert!(
                        (a[c] - b[c]).abs() < 1e-12,
                        "face {f} ({u}, {v}): {a:?} vs {b:?}"
                    );
                }
            }
        }
    }

    /// Checks that the limit at a vertex, from each face's corner there (`(face, u, v)`), is
    /// the limit of the surface's points and normals approaching it: the points at `e` along
    /// each face's diagonal, reached by refinement down to B-spline patches (an independent
    /// route), converge to the vertex's masks like `e^(3/4)` or faster (the largest eigenvalue
    /// below 1 is at most 0.6 here), the normals like `e^normal_rate` (the ratio of the third
    /// eigenvalue to the second decides it; `None`: the positions only).
    fn check_approached(mesh: &Mesh, corners: &[(u32, f64, f64)], normal_rate: Option<f64>) {
        let normal = |d: [[f64; 3]; 3]| {
            let [_, a, b] = d;
            let n = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            n.map(|c| c / l)
        };
        for &(f, u0, v0) in corners {
            let q = |e: f64| LimitQuery {
                face: f,
                u: u0 + e * (1.0 - 2.0 * u0),
                v: v0 + e * (1.0 - 2.0 * v0),
            };
            let stencil = &limit_stencils(mesh, &[q(0.0)]).expect("reached")[0];
            let at_vertex = limit_of(stencil, mesh);
            let sum: f64 = stencil.iter().map(|(_, w)| w[0]).sum();
            assert!((sum - 1.0).abs() < 1e-12, "face {f}: weights sum to {sum}");
            let mut previous = f64::INFINITY;
            for k in [10, 14, 18, 22] {
                let e = (0.5f64).powi(k);
                let near = limit_of(&limit_stencils(mesh, &[q(e)]).expect("reached")[0], mesh);
                let d = (0..3)
                    .map(|c| (near[0][c] - at_vertex[0][c]).abs())
                    .fold(0.0, f64::max);
                println!("face {f} e 2^-{k}: position {d:.2e}");
                assert!(
                    d < 2.0 * e.powf(0.75),
                    "face {f} e 2^-{k}: {d:.2e} from the vertex's limit"
                );
                assert!(d < previous, "face {f}: not converging");
                previous = d;
                if let Some(rate) = normal_rate {
                    let (a, b) = (normal(near), normal(at_vertex));
                    let angle = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
                        .clamp(-1.0, 1.0)
                        .acos();
                    println!("face {f} e 2^-{k}: normal {angle:.2e} rad");
                    assert!(
                        angle < 0.6 * e.powf(rate),
                        "face {f} e 2^-{k}: normal off by {angle:.2e}"
                    );
                }
            }
        }
    }

    /// A dart (one infinitely sharp edge ending at an interior vertex) is the limit of the
    /// points approaching it. The smooth masks (OpenSubdiv's at a dart, exact only on its last
    /// level) miss the limit here by 8.6e-4 and the normal by 1e-2 rad at level 0, and fail
    /// both bounds.
    #[test]
    fn a_dart_is_the_limit_of_the_points_approaching_it() {
        let m = 6;
        let mut mesh = grid(m, BoundaryMode::EdgeOnly);
        let at = |i: i64, j: i64| (j * (m + 1) + i) as usize;
        // A crease from the boundary at (0, 3) ending in a dart at (3, 3).
        for i in 0..3 {
            mesh.set_edge_sharpness(at(i, 3), at(i + 1, 3), INFINITE)
                .expect("an edge");
        }
        let face = |i: i64, j: i64| (j * m + i) as u32;
        // The faces around (3, 3), and the corner of each at the dart.
        check_approached(
            &mesh,
            &[
                (face(3, 3), 0.0, 0.0),
                (face(2, 3), 1.0, 0.0),
                (face(2, 2), 1.0, 1.0),
                (face(3, 2), 0.0, 1.0),
            ],
            Some(0.5),
        );
    }

    /// At an interior vertex of valence 2 the smooth limit mask `(4 V + 4 sum E + sum F) / 14`
    /// is the limit of the points approaching it (OpenSubdiv's `Sdc` mask there, `V` itself,
    /// is not: 0.61 away at vertex 0 of this pillow, whose sides are about 1). Two quads back to back, every vertex of
    /// valence 2, not planar; positions only (the normals at such a vertex depend on the face).
    #[test]
    fn a_valence_two_limit_is_the_limit_of_the_points_approaching_it() {
        check_approached(
            &pillow(),
            &[(0, 0.0, 0.0), (0, 1.0, 1.0), (1, 0.0, 1.0)],
            None,
        );
    }

    /// A dart of valence 2: the pillow with edge 1-2 infinitely sharp, so that vertices 1 and
    /// 2 keep one sharp edge each. Their limit is the dart's (the stationary matrix's fixed
    /// vector), not the smooth valence-2 mask, which missed the points approaching them by
    /// 2.4e-2 of a unit square pillow (found against OpenSubdiv on random tags,
    /// `opensubdiv_random_tags`).
    #[test]
    fn a_valence_two_dart_is_the_limit_of_the_points_approaching_it() {
        let mut mesh = pillow();
        mesh.set_edge_sharpness(1, 2, INFINITE).expect("an edge");
        check_approached(&mesh, &[(0, 1.0, 0.0), (0, 1.0, 1.0), (1, 0.0, 0.0)], None);
    }

    /// Two quads back to back, every vertex of valence 2, not planar.
    fn pillow() -> Mesh {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.3],
            [1.1, 1.0, 0.0],
            [0.0, 0.9, 0.2],
        ];
        Mesh::new(
            positions,
            &[vec![0, 1, 2, 3], vec![3, 2, 1, 0]],
            &[],
            BoundaryMode::EdgeOnly,
        )
        .expect("a pillow")
    }

    /// A crease vertex with three faces on one side (a loop of infinitely sharp edges around
    /// the middle face of a 3 x 3 grid): the tangent across that sector is the limit of the
    /// normals approaching it, slowly (eigenvalues 0.58, 0.5, 0.41 below 1: about
    /// `e^0.29`; 4.7e-3 rad at `e = 2^-22`). Biermann, Levin and Zorin's mask (OpenSubdiv's
    /// Sdc mask) was made for their modified rules: under the standard ones it misses the
    /// limit by about 4.5e-2 rad, as OpenSubdiv's own patches on `catmark_fvar_project0` show,
    /// and fails the bound.
    #[test]
    fn an_irregular_crease_sector_is_the_limit_of_the_points_approaching_it() {
        let mut mesh = grid(3, BoundaryMode::EdgeAndCorner);
        for (a, b) in [(5, 6), (6, 10), (10, 9), (9, 5)] {
            mesh.set_edge_sharpness(a, b, INFINITE).expect("an edge");
        }
        // Vertex 5 = (1, 1): faces 0, 1 and 3 on the loop's outer side.
        check_approached(
            &mesh,
            &[(0, 1.0, 1.0), (1, 0.0, 1.0), (3, 1.0, 0.0)],
            Some(0.25),
        );
    }
}
