//! Exact evaluation on Catmull–Clark meshes with sharp features (OpenSubdiv's tags: creases and
//! corners of any sharpness, both crease methods, darts, holes, `interpolateboundary`): the
//! limit position at any rational `(u, v)` of a face, exact and rounded once to f64, wherever
//! the rules are rational; the first derivatives likewise inside B-spline and table patches.
//!
//! # Method: feature-adaptive descent in rationals
//!
//! The same descent as [`crate::scheme::catmull_clark::adaptive`] (its f64 twin), with exact
//! control points:
//!
//! 1. Only a neighbourhood is refined: the faces within
//!    [`RINGS`] vertex rings of the face holding
//!    the point. Each level's vertices are recomputed exactly from the previous level's with the
//!    one statement of the rules ([`refined_vertex`] in [`BigRational`]: semi-sharp blends,
//!    sharpness decay by either crease method and the fractional vertex weights are dyadic, so
//!    every refined point is an exact rational).
//! 2. At each level the piece holding the point stops the descent when it is
//!    * a **B-spline patch** in the feature-aware sense (`adaptive::bspline_patch`: regular corners,
//!      nothing semi-sharp, control points beyond an infinitely sharp edge replaced by the
//!      reflections `2 P_0 - P_1`, taken in rationals): the bicubic B-spline `psi(s, t) N P` is
//!      evaluated exactly (an infinitely sharp crease is then the cubic B-spline of its
//!      vertices, DeRose, Kass and Truong 1998);
//!    * a **table patch with no sharp feature on its support** ([`face_patch`] and
//!      [`is_smooth_patch`]: only the edges and vertices at the face's corners decide the rules
//!      of its refined neighbourhoods): Schaefer–Warren substitution, exactly as on untagged
//!      meshes ([`super`]); so is a face at an infinitely sharp crease vertex, the boundary
//!      patch of its sector ([`crease_sector`]: the sector subdivides as a boundary vertex with
//!      its faces);
//!    * the point **at a corner** whose settled rule has a limit mask (`adaptive::vertex_limit`): the
//!      position by OpenSubdiv's `Sdc` masks, rational — corner `V`, crease
//!      `(E_a + 4 V + E_b) / 6`, smooth `(n^2 V + 4 sum E + sum F) / (n (n + 5))` — and at a
//!      dart, whose limit no closed form gives, the left eigenvector `l = l S`, `l . 1 = 1` of
//!      its stationary local subdivision matrix `S` (`adaptive::stationary_step` in rationals), solved
//!      exactly as a rational null vector.
//!
//!    Otherwise the point goes to the quarter holding it (`exact_eval::descend`) and the neighbourhood is
//!    refined once more. A point at distance `d` from the irregular features needs about
//!    `log2(1 / d)` levels plus the levels its semi-sharp features take to decay (at most
//!    [`MAX_LEVELS`] in all: parameters have at most 64-bit denominators, sharpness at most 10).
//!
//! # What is f64
//!
//! * the tangents at an extraordinary vertex of a table patch (as on untagged meshes);
//! * the tangents at a feature vertex (corner, crease, dart, crease sector, smooth vertex of a
//!   face next to features): OpenSubdiv's tangent masks, and at a dart or a crease sector of
//!   three or more faces their eigen-iteration ([`crate::scheme::catmull_clark::adaptive`]),
//!   applied exactly to the exact points and rounded once. They are tangents along the frame of
//!   the face the descent ended in (their cross product is the normal), not parametric
//!   derivatives.
//!
//! # Not a surface
//!
//! A hole face (a `hole` tag, or a face at the boundary under `interpolateboundary 0`, which
//! OpenSubdiv makes a hole) has no limit surface: evaluating it is an error.

use std::iter::once;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, ToPrimitive, Zero};

use super::{
    bicubic, check_query, descend, int, ratio, solve_exact, to_corner, Derivatives, ExactEvaluator,
    LimitPoint, Point, Scaled,
};
use crate::mesh::topology::Mesh;
use crate::scheme::catmull_clark::adaptive::{
    bspline_patch, neighbourhood, stationary_step, submesh, vertex_limit, LimitPosition, RINGS,
};
use crate::scheme::catmull_clark::refine::{refine, refined_vertex, LevelEdges};
use crate::scheme::patch::{crease_sector, face_patch, is_smooth_patch};
use crate::{MeshError, RuntimeError};

/// At most this many levels are refined below the input mesh for one point: a parameter's
/// denominator has at most 64 bits ([`super::MAX_RATIONAL_BITS`]), so a point lies
/// at least `2^-64` from a feature vertex it is not on, plus 10 levels for a semi-sharp feature
/// to decay (OpenSubdiv's largest finite sharpness) and margin.
pub const MAX_LEVELS: usize = 80;

/// A matrix `d(current parameters) / d(face parameters)`: signed permutations times powers of
/// two, exact in f64.
type Jacobian = [[f64; 2]; 2];

fn times(a: [[i64; 2]; 2], b: Jacobian) -> Jacobian {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] as f64 * b[0][j] + a[i][1] as f64 * b[1][j];
        }
    }
    c
}

/// Derivatives in the current parameters `(s, t)` back to the face's: `d/du = J^T d/d(s, t)`.
fn to_face(j: Jacobian, (position, ds, dt): Derivatives) -> LimitPoint {
    let combine = |a: f64, b: f64| -> [f64; 3] { std::array::from_fn(|c| a * ds[c] + b * dt[c]) };
    LimitPoint {
        position,
        du: combine(j[0][0], j[1][0]),
        dv: combine(j[0][1], j[1][1]),
    }
}

/// The exact point of f64 coordinates (finite: the mesh is validated).
fn exact(p: [f64; 3]) -> Point {
    std::array::from_fn(|c| BigRational::from_float(p[c]).unwrap_or_else(BigRational::zero))
}

/// `sum w_i P_i` over `(index, weight)` terms.
fn combine<'a>(
    terms: impl IntoIterator<Item = (usize, &'a BigRational)>,
    points: &[Point],
) -> Point {
    let mut sum: Point = std::array::from_fn(|_| BigRational::zero());
    for (j, w) in terms {
        for (s, x) in sum.iter_mut().zip(&points[j]) {
            *s += w * x;
        }
    }
    sum
}

fn round(p: &Point) -> [f64; 3] {
    std::array::from_fn(|c| p[c].to_f64().unwrap_or(f64::NAN))
}

/// One level of the descent: a neighbourhood mesh (positions unused) and its exact points.
struct Level {
    mesh: Mesh,
    points: Vec<Point>,
}

/// Position and derivatives of sub-face `corner` of face `face` of the evaluator's mesh (which
/// has sharp features) at `(u, v)` (module documentation).
pub(crate) fn evaluate(
    evaluator: &ExactEvaluator,
    face: usize,
    corner: usize,
    u: &BigRational,
    v: &BigRational,
) -> Result<LimitPoint, RuntimeError> {
    let mesh = evaluator.mesh();
    let sides = check_query(mesh, face, corner, u, v)?;
    if mesh.holes[face] {
        return Err(RuntimeError::InvalidParameter {
            name: format!("`face {face}`"),
            reason: "it is a hole (a `hole` tag, or a face at the boundary under \
                     `interpolateboundary 0`): it has no limit surface, as in OpenSubdiv"
                .to_owned(),
        });
    }
    let faces = neighbourhood(mesh, once(face), RINGS);
    let (sub, vertices, face_of) = submesh(mesh, &faces);
    let mut level = Level {
        points: vertices
            .iter()
            .map(|&v| exact(mesh.positions[v as usize]))
            .collect(),
        mesh: sub,
    };
    let mut g = face_of[&face];
    // The masks and nets read the faces around a vertex as quads: a neighbourhood with other
    // polygons is refined once first (its children are all quads).
    let quads = (0..level.mesh.faces()).all(|f| level.mesh.face(f).len() == 4);
    let (mut s, mut t) = (u.clone(), v.clone());
    let mut jacobian: Jacobian = [[1.0, 0.0], [0.0, 1.0]];
    for depth in 0..=MAX_LEVELS {
        let child = if depth == 0 && sides != 4 {
            // An n-gon's sub-face `corner` is its child at that corner, in the same parameters.
            level.mesh.face_halfedges(g).start + corner
        } else {
            if depth > 0 || quads {
                if let Some(point) = stop(evaluator, face, &level, g, &s, &t, depth, jacobian)? {
                    return Ok(point);
                }
            }
            let (c, ns, nt, map) = descend(&s, &t);
            (s, t) = (ns, nt);
            jacobian = times(map, jacobian);
            // Child c of face g is numbered by g's half-edge c (`refine`).
            level.mesh.face_halfedges(g).start + c
        };
        if depth == MAX_LEVELS {
            break;
        }
        let step = refine(&level.mesh);
        let edges = LevelEdges::new(&level.mesh);
        let faces = neighbourhood(&step.mesh, once(child), RINGS);
        let (sub, vertices, face_of) = submesh(&step.mesh, &faces);
        let points = vertices
            .iter()
            .map(|&v| {
                let terms = refined_vertex::<BigRational>(&level.mesh, &edges, v as usize);
                combine(terms.iter().map(|(j, w)| (*j as usize, w)), &level.points)
            })
            .collect();
        level = Level { mesh: sub, points };
        g = face_of[&child];
    }
    Err(MeshError::NotIsolated {
        face,
        reason: format!(
            "the limit at ({u}, {v}) is not reached after {MAX_LEVELS} levels of refinement (a feature vertex of a rule without a limit mask)"
        ),
    }
    .into())
}

/// The limit at `(s, t)` of quad `g` of `level`, `depth` levels below the input face, if the
/// descent stops here (module documentation, step 2).
#[allow(clippy::too_many_arguments)]
fn stop(
    evaluator: &ExactEvaluator,
    face: usize,
    level: &Level,
    g: usize,
    s: &BigRational,
    t: &BigRational,
    depth: usize,
    jacobian: Jacobian,
) -> Result<Option<LimitPoint>, RuntimeError> {
    let mesh = &level.mesh;
    if let Some(grid) = bspline_patch::<BigRational>(mesh, g) {
        // `bicubic` takes the net with `v` outer: point `b * 4 + a` is `grid[a][b]`.
        let net: Vec<Point> = (0..4)
            .flat_map(|b| (0..4).map(move |a| (a, b)))
            .map(|(a, b)| {
                combine(
                    grid[a][b].iter().map(|(j, w)| (*j as usize, w)),
                    &level.points,
                )
            })
            .collect();
        let [position, ds, dt] = bicubic(&Scaled::new(&net), s, t, &BigInt::one());
        return Ok(Some(to_face(jacobian, (position, ds, dt))));
    }
    // A smooth patch, or a crease vertex's sector as a boundary patch: the scaling relation's
    // exact operators of the patch (any sector size, not only the table's).
    if is_smooth_patch(mesh, g) || crease_sector(mesh, g).is_some() {
        if let Ok(patch) = face_patch(mesh, g) {
            let points: Vec<Point> = patch
                .points
                .iter()
                .map(|&p| level.points[p as usize].clone())
                .collect();
            let (pu, pv, rotation) = to_corner(patch.corner, s, t);
            let derivatives = evaluator.table_patch(face, &patch, &points, &pu, &pv, depth)?;
            return Ok(Some(to_face(times(rotation, jacobian), derivatives)));
        }
    }
    let corner = match (s.is_zero(), t.is_zero(), s.is_one(), t.is_one()) {
        (true, true, _, _) => 0,
        (_, true, true, _) => 1,
        (_, _, true, true) => 2,
        (true, _, _, true) => 3,
        _ => return Ok(None),
    };
    let Some(limit) = vertex_limit(mesh, mesh.face_halfedges(g).start + corner) else {
        return Ok(None);
    };
    let position = match &limit.position {
        LimitPosition::Mask(terms) => {
            let weights: Vec<(usize, BigRational)> = terms
                .iter()
                .map(|&(j, p, q)| (j as usize, ratio(p, q)))
                .collect();
            combine(weights.iter().map(|(j, w)| (*j, w)), &level.points)
        }
        LimitPosition::Stationary { shape, ids } => {
            let mask = stationary_position(*shape, ids.len()).ok_or_else(|| {
                RuntimeError::Unsupported(format!(
                    "face {face}: the limit at a vertex ({shape:?}): no unique eigenvector of eigenvalue 1"
                ))
            })?;
            combine(
                ids.iter().zip(&mask).map(|(&j, w)| (j as usize, w)),
                &level.points,
            )
        }
    };
    // The f64 tangent masks applied exactly, rounded once.
    let tangent = |k: usize| -> [f64; 3] {
        let weights: Vec<(usize, BigRational)> = limit
            .masks
            .iter()
            .filter(|(_, w)| w[k] != 0.0)
            .map(|&(j, w)| {
                (
                    j as usize,
                    BigRational::from_float(w[k]).unwrap_or_else(BigRational::zero),
                )
            })
            .collect();
        round(&combine(
            weights.iter().map(|(j, w)| (*j, w)),
            &level.points,
        ))
    };
    Ok(Some(LimitPoint {
        position: round(&position),
        du: tangent(1),
        dv: tangent(2),
    }))
}

/// The limit mask of a stationary neighbourhood over its `size` one-ring slots: the left
/// eigenvector `l S = l` of eigenvalue 1 of its local subdivision matrix ([`stationary_step`],
/// the rules in rationals), normalized by `l . 1 = 1`, solved exactly; `None` if the matrix
/// does not match the slots or the eigenvector is not unique.
fn stationary_position(
    shape: crate::scheme::catmull_clark::adaptive::Stationary,
    size: usize,
) -> Option<Vec<BigRational>> {
    let step = stationary_step::<BigRational>(shape)?;
    if step.len() != size {
        return None;
    }
    // Column j of l (S - I) = 0: sum_k l_k S[k][j] - l_j = 0.
    let mut rows: Vec<(Vec<BigRational>, BigRational)> = (0..size)
        .map(|_| (vec![BigRational::zero(); size], BigRational::zero()))
        .collect();
    for (k, row) in step.iter().enumerate() {
        for (j, w) in row {
            rows[*j].0[k] += w;
        }
    }
    for (j, (row, _)) in rows.iter_mut().enumerate() {
        row[j] -= int(1);
    }
    rows.push((vec![int(1); size], int(1)));
    solve_exact(rows, size)
}
