//! Loop subdivision around an interior extraordinary vertex of valence `v`, or next to a
//! boundary vertex ("Boundary vertices" below): the patch layout,
//! the local subdivision matrix `A` and the picking matrices of the three regular
//! sub-triangles (Schaefer–Warren section 5.2, on the triangular lattice of section 5.1), as
//! exact rationals. Data only: `stencilgen::triangle_patch` solves with them.
//!
//! **Sectors.** Around the vertex the mesh is `v` copies of a 60-degree wedge of the lattice
//! of [`crate::triangle`]: sector `s` holds the points `(a, b)`, `a >= 1`, `b >= 0`, in its own
//! skew coordinates, its `+a` axis along the edge to `E_s` and its `+b` axis along the edge to
//! `E_{s+1}`, which is sector `s + 1`'s `+a` axis. Rotating by 60 degrees,
//! `(a, b)` of sector `s` is `(a + b, -a)` of sector `s + 1` and `(-b, a + b)` of sector
//! `s - 1` ([`canonical_triangle_point`]).
//!
//! **The patch** is the triangle `V, E_0, E_1` of sector 0, parameterized barycentrically by
//! `(u, v)`, `u, v >= 0`, `u + v <= 1`, the vertex at `(0, 0)`, `E_0` at `(1, 0)`, `E_1` at
//! `(0, 1)`. Its `K = v + 6` control points ([`triangle_layout`], Stam's layout for Loop):
//!
//! ```text
//!   V                the vertex
//!   E_0 ..= E_{v-1}  E_i = sector i, (1, 0), counter-clockwise
//!   O_0 ..= O_4      (2,-1) (2,0) (1,1) (0,2) (-1,2) in sector-0 coordinates, i.e.
//!                    sector v-1 (1,1), sector 0 (2,0), sector 0 (1,1), sector 1 (2,0),
//!                    sector 1 (1,1)
//! ```
//!
//! One Loop step maps the layout to the same layout at level 1 (`P' = A P`, `K x K`). The
//! level-0 patch is the level-1 triangle `(0,0), (2,0), (0,2)`; besides the sub-triangle at the
//! vertex it holds the three regular triangles [`SUB_TRIANGLES`] (all corners of valence 6),
//! on which the surface is the quartic box spline of the twelve level-1 points of the corners'
//! 1-rings ([`SubTriangle`]), each a row of level-0 weights.
//!
//! **Boundary vertices** ([`TriangleLocalMatrices::boundary`]). A boundary vertex `V` with `k`
//! triangles has neighbours `E_0, ..., E_k` counter-clockwise, `E_0` and `E_k` on the
//! boundary, and sectors `0..k` (sector `i` is the triangle `V, E_i, E_{i+1}`), not glued: a
//! point on the ray towards `E_k` is named in "sector `k`" with `b = 0`, and everything below
//! sector 0's `a` axis or beyond ray `k` is outside the mesh ([`canonical_boundary_point`]).
//! Loop's boundary rules (Hoppe et al. 1994, OpenSubdiv's "smooth boundary"): a boundary edge
//! point is the midpoint of its ends; a boundary vertex is `1/8 B_- + 3/4 V + 1/8 B_+` over
//! its two boundary neighbours, `V` included whatever `k` is; interior points use the rules of
//! the interior case (all interior vertices other than `V` have valence 6). The patch of
//! sector `s` is `V, E_s, E_{s+1}` (`V` at `(0,0)`, `E_s` at `(1,0)`, `E_{s+1}` at `(0,1)`);
//! its layout (a contract: the runtime gathers control points in this order) is
//!
//! ```text
//!   V, E_0, ..., E_k,
//!   then of O_0..O_4 = (2,-1) (2,0) (1,1) (0,2) (-1,2) (sector-s coordinates) those inside:
//!   sector s-1 (1,1) [iff s >= 1], ray s (2,0), sector s (1,1), ray s+1 (2,0),
//!   sector s+1 (1,1) [iff s+1 <= k-1]
//! ```
//!
//! so `K = 1 + (k+1) + 3 + [s >= 1] + [s <= k-2]` ([`triangle_boundary_layout`]). Refining
//! every layout point reads only layout points (`E_s`, `E_{s+1}` are regular: valence 6 inside,
//! 3 triangles on the boundary), which gives `A`. The sub-triangles' points are in sector-`s`
//! level-1 coordinates.
//!
//! *Phantoms.* The three sub-triangles have regular corners, but their twelve-point nets can
//! reach outside the mesh. A net point `p` outside lies across a boundary edge `(c, m)` whose
//! interior triangle is `(c, m, r)`; its phantom is `p = c + m - r`. With phantoms the regular
//! rules reproduce the boundary rules: at a boundary edge `3/8 c + 3/8 m + 1/8 r +
//! 1/8 (c + m - r) = (c + m)/2`; at a boundary vertex `b` with boundary neighbours `b_-, b_+`
//! and interior ones `c, d`, `5/8 b + 1/16 (b_- + b_+ + c + d + (b_- + b - d) + (b + b_+ - c))
//! = 1/8 b_- + 3/4 b + 1/8 b_+`. And the regular rules applied to a phantom-extended net give,
//! at the next level's phantom positions, exactly the phantom formula of the next level's
//! points (a few lines of algebra using only the edge rules and the vertex rule of the
//! regular boundary vertex next to the phantom; `docs/algorithms/triangle-schemes.md`). So
//! the phantom-extended net subdivides like a regular net forever: a triangle with regular
//! corners is the box spline of its phantom-extended twelve-point net, even when one of the
//! net's points is the irregular `V` (its own vertex rule is never used). The row of an
//! outside point is therefore `R[c] + R[m] - R[r]`.

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::{BigRational, Rational64};
use num_traits::Zero;

use crate::local_matrices::UnsupportedNeighbourhood;
use crate::triangle::{apply_map, lattice_symmetries, NEIGHBOURS};
use crate::{TriangleScheme, TriangleVertexRule};

/// Which vertex sits at the patch corner `(0, 0)`, and which of its sectors the patch is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TriangleNeighbourhood {
    /// An interior vertex; the patch is sector 0.
    Interior {
        /// The number of edges (and triangles) at the vertex.
        valence: u32,
    },
    /// A boundary vertex with `faces` triangles, `faces + 1` edges, `E_0` and `E_faces` on the
    /// boundary; the patch is sector `sector` (`0 <= sector < faces`).
    Boundary {
        /// The number of triangles at the vertex.
        faces: u32,
        /// The patch's sector.
        sector: u32,
    },
}

/// A vertex around the extraordinary vertex, in canonical form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TrianglePoint {
    /// The extraordinary vertex.
    Centre,
    /// Point `(a, b)`, `a >= 1`, `b >= 0`, of sector `s`.
    Sector {
        /// Sector index: `0..v` around an interior vertex, `0..=faces` next to a boundary
        /// vertex (sector `faces` holds only its ray, `b = 0`).
        s: u32,
        /// Coordinate along the sector's first edge.
        a: i64,
        /// Coordinate along the sector's second edge.
        b: i64,
    },
}

/// The canonical name of point `(a, b)` given in sector `s`'s coordinates around a vertex of
/// valence `valence`.
pub fn canonical_triangle_point(valence: u32, s: i64, a: i64, b: i64) -> TrianglePoint {
    let (mut s, mut a, mut b) = (s, a, b);
    loop {
        if a == 0 && b == 0 {
            return TrianglePoint::Centre;
        }
        if a >= 1 && b >= 0 {
            return TrianglePoint::Sector {
                s: s.rem_euclid(i64::from(valence)) as u32,
                a,
                b,
            };
        }
        // Each branch keeps the other coordinate's sign right, so this ends within 6 turns.
        if b < 0 {
            (s, a, b) = (s - 1, -b, a + b);
        } else {
            (s, a, b) = (s + 1, a + b, -a);
        }
    }
}

/// The outer points of the layout, in sector-0 coordinates.
pub const TRIANGLE_OUTER_POINTS: [(i64, i64); 5] = [(2, -1), (2, 0), (1, 1), (0, 2), (-1, 2)];

/// The regular sub-triangles of the once-refined patch, by their corners in level-1 sector-0
/// coordinates: next to `E_0`, the middle ("down") triangle, next to `E_1`.
pub const SUB_TRIANGLES: [[(i64, i64); 3]; 3] = [
    [(1, 0), (2, 0), (1, 1)],
    [(1, 0), (1, 1), (0, 1)],
    [(0, 1), (1, 1), (0, 2)],
];

/// The patch's control points in table order (see the module docs).
pub fn triangle_layout(valence: u32) -> Vec<TrianglePoint> {
    let mut points = vec![TrianglePoint::Centre];
    points.extend((0..valence).map(|s| TrianglePoint::Sector { s, a: 1, b: 0 }));
    points.extend(
        TRIANGLE_OUTER_POINTS
            .iter()
            .map(|&(a, b)| canonical_triangle_point(valence, 0, a, b)),
    );
    points
}

/// The canonical name of point `(a, b)` given in sector `s`'s coordinates around a boundary
/// vertex with `faces` triangles, or `None` when the point lies outside the mesh.
///
/// The sectors `0..faces` are not glued cyclically: the point is rotated (as in
/// [`canonical_triangle_point`], without wrapping the sector index) until `a >= 1, b >= 0`,
/// and it is inside iff its sector is `0..faces`, or it is on the last ray (sector `faces`,
/// `b = 0`). For `faces >= 6` the sectors cover more than a full turn; they are still distinct
/// mesh points, since nothing is identified across the boundary.
pub fn canonical_boundary_point(faces: u32, s: i64, a: i64, b: i64) -> Option<TrianglePoint> {
    let (mut s, mut a, mut b) = (s, a, b);
    loop {
        if a == 0 && b == 0 {
            return Some(TrianglePoint::Centre);
        }
        if a >= 1 && b >= 0 {
            let k = i64::from(faces);
            let inside = (0..k).contains(&s) || (s == k && b == 0);
            return u32::try_from(s)
                .ok()
                .filter(|_| inside)
                .map(|s| TrianglePoint::Sector { s, a, b });
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a + b);
        } else {
            (s, a, b) = (s + 1, a + b, -a);
        }
    }
}

/// The control points of the patch of sector `sector` next to a boundary vertex with `faces`
/// triangles, in table order (the runtime gathers them in exactly this order):
/// `V, E_0, ..., E_faces`, then those of the interior layout's outer points
/// [`TRIANGLE_OUTER_POINTS`] `(2,-1), (2,0), (1,1), (0,2), (-1,2)` (sector-`sector`
/// coordinates) that lie inside the mesh: sector `sector - 1`'s `(1,1)` (iff `sector >= 1`),
/// ray `sector`'s `(2,0)`, sector `sector`'s `(1,1)`, ray `sector + 1`'s `(2,0)`, sector
/// `sector + 1`'s `(1,1)` (iff `sector + 1 <= faces - 1`). So
/// `K = 1 + (faces + 1) + 3 + [sector >= 1] + [sector <= faces - 2]`.
/// `None` unless `faces >= 1` and `sector < faces`.
pub fn triangle_boundary_layout(faces: u32, sector: u32) -> Option<Vec<TrianglePoint>> {
    if faces == 0 || sector >= faces {
        return None;
    }
    let mut points = vec![TrianglePoint::Centre];
    points.extend((0..=faces).map(|s| TrianglePoint::Sector { s, a: 1, b: 0 }));
    points.extend(
        TRIANGLE_OUTER_POINTS
            .iter()
            .filter_map(|&(a, b)| canonical_boundary_point(faces, i64::from(sector), a, b)),
    );
    Some(points)
}

/// The indices into [`TRIANGLE_OUTER_POINTS`] of the outer points a boundary layout keeps,
/// in layout order (for names: `O0` is present iff `sector >= 1`, `O4` iff
/// `sector + 1 <= faces - 1`).
fn boundary_outer_indices(faces: u32, sector: u32) -> Vec<usize> {
    (0..TRIANGLE_OUTER_POINTS.len())
        .filter(|&i| {
            let (a, b) = TRIANGLE_OUTER_POINTS[i];
            canonical_boundary_point(faces, i64::from(sector), a, b).is_some()
        })
        .collect()
}

/// The twelve level-1 lattice points (unfolded, sector coordinates) of a regular
/// sub-triangle: the union of its corners' 1-rings, sorted. The order of
/// [`SubTriangle::points`] and so of the rows of a compact Loop table's sub-triangle matrices,
/// which the runtime recomputes with this function.
pub fn sub_triangle_points(corners: [(i64, i64); 3]) -> Vec<(i64, i64)> {
    let mut points: Vec<(i64, i64)> = corners
        .iter()
        .flat_map(|&(x, y)| {
            std::iter::once((x, y)).chain(NEIGHBOURS.iter().map(move |&(dx, dy)| (x + dx, y + dy)))
        })
        .collect();
    points.sort_unstable();
    points.dedup();
    points
}

/// A linear combination of points.
pub type TriangleCombination = Vec<(TrianglePoint, Rational64)>;

/// The rules of one Loop-type scheme at one valence, in exact rationals.
#[derive(Clone, Debug)]
struct LoopRules {
    valence: u32,
    /// `(centre, beta)` at the extraordinary vertex.
    extraordinary: (Rational64, Rational64),
    /// `(centre, beta)` at valence 6.
    regular: (Rational64, Rational64),
    /// The edge rule of the edge `(0,0)-(1,0)`.
    edge: Vec<((i64, i64), Rational64)>,
}

impl LoopRules {
    fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, UnsupportedNeighbourhood> {
        let unsupported = |reason: String| UnsupportedNeighbourhood {
            scheme: scheme.name.to_owned(),
            reason,
        };
        if !matches!(
            scheme.vertex,
            TriangleVertexRule::LoopWarren | TriangleVertexRule::LoopOriginal
        ) {
            return Err(unsupported(
                "extraordinary-vertex systems are implemented for Loop only (butterfly and sqrt3 need their own local matrices)".to_owned(),
            ));
        }
        if valence < 3 {
            return Err(unsupported(format!(
                "an interior vertex needs valence >= 3, not {valence}"
            )));
        }
        let crate::triangle::TriangleRefinement::Dyadic {
            edge,
            edge_denominator,
        } = scheme.refinement
        else {
            return Err(unsupported("the scheme is not dyadic".to_owned()));
        };
        let exact = |v: u32| {
            let (c, b) = scheme.vertex.weights(v);
            match (c.exact, b.exact) {
                (Some(c), Some(b)) => Ok((c, b)),
                _ => Err(unsupported(format!(
                    "its vertex weight at valence {v} is irrational (cos(2 pi / {v})), so exact local matrices do not exist; use `loop` (Warren's rational weights)"
                ))),
            }
        };
        Ok(LoopRules {
            valence,
            extraordinary: exact(valence)?,
            regular: exact(6)?,
            edge: edge
                .iter()
                .map(|&(o, w)| (o, Rational64::new(w, edge_denominator)))
                .collect(),
        })
    }

    fn at(&self, s: i64, a: i64, b: i64) -> TrianglePoint {
        canonical_triangle_point(self.valence, s, a, b)
    }

    /// The level-0 combination of the level-1 point `point`.
    fn refine(&self, point: TrianglePoint) -> TriangleCombination {
        let TrianglePoint::Sector { s, a, b } = point else {
            let (c, beta) = self.extraordinary;
            let mut out = vec![(TrianglePoint::Centre, c)];
            out.extend((0..self.valence).map(|s| (TrianglePoint::Sector { s, a: 1, b: 0 }, beta)));
            return out;
        };
        let s = i64::from(s);
        match (a.rem_euclid(2), b.rem_euclid(2)) {
            (0, 0) => {
                let (x, y) = (a / 2, b / 2);
                let (c, beta) = self.regular;
                let mut out = vec![(self.at(s, x, y), c)];
                out.extend(
                    NEIGHBOURS
                        .iter()
                        .map(|&(dx, dy)| (self.at(s, x + dx, y + dy), beta)),
                );
                out
            }
            parity => {
                // The edge from p in direction e = R^k (1, 0).
                let (p, k) = match parity {
                    (1, 0) => (((a - 1) / 2, b / 2), 0),
                    (0, 1) => ((a / 2, (b - 1) / 2), 1),
                    _ => (((a - 1) / 2, (b + 1) / 2), 5),
                };
                let map = lattice_symmetries()[k];
                self.edge
                    .iter()
                    .map(|&(o, w)| {
                        let o = apply_map(map, o);
                        (self.at(s, p.0 + o.0, p.1 + o.1), w)
                    })
                    .collect()
            }
        }
    }
}

/// Loop's boundary vertex rule (Hoppe et al. 1994, the "smooth boundary" rule OpenSubdiv
/// uses): `V' = 1/8 B_- + 3/4 V + 1/8 B_+` over the vertex's two boundary neighbours, for any
/// number of triangles at `V`. Returns `(neighbour weight, vertex weight)`. (Together with the
/// boundary edge rule, the midpoint, this is cubic B-spline subdivision of the boundary
/// polygon, which reads only boundary points.)
fn boundary_vertex_weights() -> (Rational64, Rational64) {
    (Rational64::new(1, 8), Rational64::new(3, 4))
}

/// The rules of Loop next to a boundary vertex with `faces` triangles, in exact rationals.
/// Every vertex but `V` is regular (valence 6 inside, 3 triangles on the boundary).
#[derive(Clone, Debug)]
struct BoundaryLoopRules {
    faces: u32,
    /// `(centre, beta)` at an interior vertex of valence 6.
    regular: (Rational64, Rational64),
    /// The regular edge rule of the edge `(0,0)-(1,0)` (its ends are offsets `(0,0)`, `(1,0)`).
    edge: Vec<((i64, i64), Rational64)>,
}

impl BoundaryLoopRules {
    fn new(scheme: &TriangleScheme, faces: u32) -> Result<Self, UnsupportedNeighbourhood> {
        if faces == 0 {
            return Err(UnsupportedNeighbourhood {
                scheme: scheme.name.to_owned(),
                reason: "a boundary vertex needs at least one triangle".to_owned(),
            });
        }
        // Only valence-6 interior vertices occur (besides V, which follows the boundary rule),
        // so the scheme's rules at valence 6 are all that is needed: `loop` and
        // `loop-original` agree there (beta = 1/16).
        let interior = LoopRules::new(scheme, 6)?;
        Ok(BoundaryLoopRules {
            faces,
            regular: interior.regular,
            edge: interior.edge,
        })
    }

    fn at(&self, s: i64, a: i64, b: i64) -> Option<TrianglePoint> {
        canonical_boundary_point(self.faces, s, a, b)
    }

    /// The level-0 combination of the level-1 point `point` (inside the mesh), or `None` if
    /// its rule would read a point outside the mesh (it never does: see the module docs).
    fn refine(&self, point: TrianglePoint) -> Option<TriangleCombination> {
        let (side, centre) = boundary_vertex_weights();
        let k = self.faces;
        let TrianglePoint::Sector { s, a, b } = point else {
            return Some(vec![
                (TrianglePoint::Centre, centre),
                (TrianglePoint::Sector { s: 0, a: 1, b: 0 }, side),
                (TrianglePoint::Sector { s: k, a: 1, b: 0 }, side),
            ]);
        };
        let s = i64::from(s);
        match (a.rem_euclid(2), b.rem_euclid(2)) {
            (0, 0) => {
                let (x, y) = (a / 2, b / 2);
                if y == 0 && (s == 0 || s == i64::from(k)) {
                    // An old boundary vertex: its boundary neighbours lie on its own ray.
                    return Some(vec![
                        (self.at(s, x - 1, 0)?, side),
                        (self.at(s, x, 0)?, centre),
                        (self.at(s, x + 1, 0)?, side),
                    ]);
                }
                let (c, beta) = self.regular;
                let mut out = vec![(self.at(s, x, y)?, c)];
                for &(dx, dy) in &NEIGHBOURS {
                    out.push((self.at(s, x + dx, y + dy)?, beta));
                }
                Some(out)
            }
            parity => {
                let (p, rot) = match parity {
                    (1, 0) => (((a - 1) / 2, b / 2), 0),
                    (0, 1) => ((a / 2, (b - 1) / 2), 1),
                    _ => (((a - 1) / 2, (b + 1) / 2), 5),
                };
                let map = lattice_symmetries()[rot];
                let terms: Vec<((i64, i64), Option<TrianglePoint>, Rational64)> = self
                    .edge
                    .iter()
                    .map(|&(o, w)| {
                        let q = apply_map(map, o);
                        (o, self.at(s, p.0 + q.0, p.1 + q.1), w)
                    })
                    .collect();
                if terms.iter().all(|(_, q, _)| q.is_some()) {
                    return terms.into_iter().map(|(_, q, w)| Some((q?, w))).collect();
                }
                // An opposite vertex is missing: a boundary edge, whose new point is the
                // midpoint of its ends (the mask's offsets (0,0) and (1,0)).
                let half = Rational64::new(1, 2);
                terms
                    .into_iter()
                    .filter(|(o, _, _)| *o == (0, 0) || *o == (1, 0))
                    .map(|(_, q, _)| Some((q?, half)))
                    .collect()
            }
        }
    }

    /// The interior triangles `[c, m, r]` across whose boundary edge `(c, m)` the outside
    /// level-1 point `p` (sector-`s` coordinates, next to a corner of `corners`) lies, so that
    /// its phantom is `c + m - r`. Every candidate names the same edge and triangle (tested);
    /// the first is used.
    fn phantom_triangles(
        &self,
        s: i64,
        corners: [(i64, i64); 3],
        p: (i64, i64),
    ) -> Vec<[TrianglePoint; 3]> {
        let adjacent = |x: (i64, i64), y: (i64, i64)| NEIGHBOURS.contains(&(y.0 - x.0, y.1 - x.1));
        let mut out = Vec::new();
        for c in corners.into_iter().filter(|&c| adjacent(c, p)) {
            for m in NEIGHBOURS
                .iter()
                .map(|&(dx, dy)| (c.0 + dx, c.1 + dy))
                .filter(|&m| adjacent(m, p))
            {
                let r = (c.0 + m.0 - p.0, c.1 + m.1 - p.1);
                if let (Some(c), Some(m), Some(r)) = (
                    self.at(s, c.0, c.1),
                    self.at(s, m.0, m.1),
                    self.at(s, r.0, r.1),
                ) {
                    out.push([c, m, r]);
                }
            }
        }
        out
    }
}

/// One regular sub-triangle of the once-refined patch.
#[derive(Clone, Debug, PartialEq)]
pub struct SubTriangle {
    /// Its corners, level-1 sector-0 skew coordinates.
    pub corners: [(i64, i64); 3],
    /// The twelve level-1 lattice points (sector-0 coordinates, unfolded: two may name the same
    /// vertex at valence 3) whose box splines are nonzero on it: the corners' 1-rings.
    pub points: Vec<(i64, i64)>,
    /// For each of `points`, its level-0 weights over the layout (`12 x K`): the picking
    /// matrix times one subdivision step.
    pub rows: Vec<Vec<BigRational>>,
}

/// The local subdivision matrices of Loop around an interior vertex of valence `v`
/// ([`TriangleLocalMatrices::new`]) or next to a boundary vertex
/// ([`TriangleLocalMatrices::boundary`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleLocalMatrices {
    /// The scheme's name.
    pub scheme: String,
    /// The number of edges at `V`: the valence of an interior vertex, `faces + 1` at a boundary
    /// vertex with `faces` triangles (for messages; [`Self::neighbourhood`] says which).
    pub valence: u32,
    /// The vertex's neighbourhood and the patch's sector.
    pub neighbourhood: TriangleNeighbourhood,
    /// The control points.
    pub layout: Vec<TrianglePoint>,
    /// `A` (`K x K`): level-1 layout points from level-0 layout points.
    pub a: Vec<Vec<BigRational>>,
    /// The three regular sub-triangles, in the order of [`SUB_TRIANGLES`].
    pub sub_triangles: [SubTriangle; 3],
}

fn big(r: Rational64) -> BigRational {
    BigRational::new(BigInt::from(*r.numer()), BigInt::from(*r.denom()))
}

impl TriangleLocalMatrices {
    /// Build `A` and the sub-triangle rows of a Loop scheme (`loop`, or `loop-original` at the
    /// valences where its weight is rational) around an interior vertex of valence `valence`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, UnsupportedNeighbourhood> {
        let rules = LoopRules::new(scheme, valence)?;
        let layout = triangle_layout(valence);
        let index: HashMap<TrianglePoint, usize> =
            layout.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        let row = |point: TrianglePoint| -> Vec<BigRational> {
            let mut r = vec![BigRational::zero(); layout.len()];
            for (p, w) in rules.refine(point) {
                let i = *index.get(&p).unwrap_or_else(|| {
                    unreachable!("a patch point's rule reads only the patch's points: {p:?}")
                });
                r[i] += big(w);
            }
            r
        };
        let a = layout.iter().map(|&p| row(p)).collect();
        let sub_triangles = SUB_TRIANGLES.map(|corners| {
            let points = sub_triangle_points(corners);
            let rows = points
                .iter()
                .map(|&(x, y)| row(canonical_triangle_point(valence, 0, x, y)))
                .collect();
            SubTriangle {
                corners,
                points,
                rows,
            }
        });
        Ok(TriangleLocalMatrices {
            scheme: scheme.name.to_owned(),
            valence,
            neighbourhood: TriangleNeighbourhood::Interior { valence },
            layout,
            a,
            sub_triangles,
        })
    }

    /// Build `A` and the sub-triangle rows of a Loop scheme (`loop` or `loop-original`, which
    /// agree here: only regular interior vertices occur besides `V`) for the patch of sector
    /// `sector` next to a boundary vertex with `faces` triangles, with Loop's boundary rules
    /// (Hoppe et al. 1994): boundary edge points are midpoints, boundary vertices
    /// `1/8, 3/4, 1/8`, `V` included whatever `faces` is.
    ///
    /// The layout is [`triangle_boundary_layout`]. `A` is `K x K` as in the interior case. Each
    /// regular sub-triangle's twelve points are in sector-`sector` level-1 coordinates; a point
    /// outside the mesh is the *phantom* `c + m - r` across the boundary edge `(c, m)` whose
    /// interior triangle is `(c, m, r)`, so its row is `R[c] + R[m] - R[r]` (why this makes the
    /// sub-triangle a box-spline patch: the module docs).
    pub fn boundary(
        scheme: &TriangleScheme,
        faces: u32,
        sector: u32,
    ) -> Result<Self, UnsupportedNeighbourhood> {
        let rules = BoundaryLoopRules::new(scheme, faces)?;
        let layout =
            triangle_boundary_layout(faces, sector).ok_or_else(|| UnsupportedNeighbourhood {
                scheme: scheme.name.to_owned(),
                reason: format!(
                    "a boundary vertex with {faces} triangles has sectors 0..{faces}, not {sector}"
                ),
            })?;
        let index: HashMap<TrianglePoint, usize> =
            layout.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        let row = |point: TrianglePoint| -> Vec<BigRational> {
            let mut r = vec![BigRational::zero(); layout.len()];
            let combination = rules.refine(point).unwrap_or_else(|| {
                unreachable!("an inside point's rule reads only inside points: {point:?}")
            });
            for (p, w) in combination {
                let i = *index.get(&p).unwrap_or_else(|| {
                    unreachable!("a patch point's rule reads only the patch's points: {p:?}")
                });
                r[i] += big(w);
            }
            r
        };
        let a = layout.iter().map(|&p| row(p)).collect();
        let s = i64::from(sector);
        let sub_triangles = SUB_TRIANGLES.map(|corners| {
            let points = sub_triangle_points(corners);
            let rows = points
                .iter()
                .map(|&(x, y)| match rules.at(s, x, y) {
                    Some(p) => row(p),
                    None => {
                        let [c, m, r] = *rules
                            .phantom_triangles(s, corners, (x, y))
                            .first()
                            .unwrap_or_else(|| {
                                unreachable!(
                                    "an outside net point lies across a boundary edge: ({x}, {y})"
                                )
                            });
                        let (rc, rm, rr) = (row(c), row(m), row(r));
                        rc.iter()
                            .zip(&rm)
                            .zip(&rr)
                            .map(|((c, m), r)| c + m - r)
                            .collect()
                    }
                })
                .collect();
            SubTriangle {
                corners,
                points,
                rows,
            }
        });
        Ok(TriangleLocalMatrices {
            scheme: scheme.name.to_owned(),
            valence: faces + 1,
            neighbourhood: TriangleNeighbourhood::Boundary { faces, sector },
            layout,
            a,
            sub_triangles,
        })
    }

    /// The number of control points: `K = v + 6` around an interior vertex of valence `v`,
    /// `K = 1 + (faces + 1) + 3 + [sector >= 1] + [sector <= faces - 2]` next to a boundary
    /// vertex.
    pub fn size(&self) -> usize {
        self.layout.len()
    }

    /// Names of the layout's points: `V`, `E0..`, then `O0..O4` (interior), or the `O{i}` of
    /// [`TRIANGLE_OUTER_POINTS`] a boundary layout keeps (`O1, O2, O3` always, `O0` iff
    /// `sector >= 1`, `O4` iff `sector <= faces - 2`).
    pub fn names(&self) -> Vec<String> {
        let mut names = vec!["V".to_owned()];
        let (edges, outer) = match self.neighbourhood {
            TriangleNeighbourhood::Interior { valence } => {
                (valence, (0..TRIANGLE_OUTER_POINTS.len()).collect())
            }
            TriangleNeighbourhood::Boundary { faces, sector } => {
                (faces + 1, boundary_outer_indices(faces, sector))
            }
        };
        names.extend((0..edges).map(|i| format!("E{i}")));
        names.extend(outer.into_iter().map(|i: usize| format!("O{i}")));
        names
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_traits::One;

    #[test]
    fn canonical_names_wrap_around_the_vertex() {
        assert_eq!(
            canonical_triangle_point(5, 0, 0, 1),
            TrianglePoint::Sector { s: 1, a: 1, b: 0 }
        );
        assert_eq!(
            canonical_triangle_point(5, 0, 2, -1),
            TrianglePoint::Sector { s: 4, a: 1, b: 1 }
        );
        assert_eq!(
            canonical_triangle_point(3, 0, -1, 0),
            TrianglePoint::Sector { s: 0, a: 1, b: 0 }
        );
        assert_eq!(
            canonical_triangle_point(6, 0, -1, 0),
            TrianglePoint::Sector { s: 3, a: 1, b: 0 }
        );
    }

    #[test]
    fn layout_has_v_plus_6_distinct_points_and_rows_are_affine() {
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        for v in 3..=8 {
            let m = TriangleLocalMatrices::new(&loop_, v).expect("valid");
            assert_eq!(m.size(), v as usize + 6);
            let mut sorted = m.layout.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), m.size(), "valence {v}");
            for r in
                m.a.iter()
                    .chain(m.sub_triangles.iter().flat_map(|t| &t.rows))
            {
                assert_eq!(r.iter().sum::<BigRational>(), BigRational::one());
            }
            assert!(m.sub_triangles.iter().all(|t| t.points.len() == 12));
        }
    }

    #[test]
    fn non_loop_and_irrational_cases_are_errors() {
        let butterfly = TriangleScheme::by_name("butterfly").expect("catalogued");
        assert!(TriangleLocalMatrices::new(&butterfly, 5).is_err());
        let original = TriangleScheme::by_name("loop-original").expect("catalogued");
        assert!(TriangleLocalMatrices::new(&original, 5).is_err());
        assert!(TriangleLocalMatrices::new(&original, 4).is_ok());
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        assert!(TriangleLocalMatrices::new(&loop_, 2).is_err());
    }

    fn loop_() -> TriangleScheme {
        TriangleScheme::by_name("loop").expect("catalogued")
    }

    #[test]
    fn boundary_names_stop_at_the_boundary() {
        let ray = |s, a| Some(TrianglePoint::Sector { s, a, b: 0 });
        assert_eq!(canonical_boundary_point(1, 0, 0, 1), ray(1, 1));
        assert_eq!(canonical_boundary_point(1, 0, 0, 2), ray(1, 2));
        assert_eq!(canonical_boundary_point(1, 0, -1, 2), None);
        assert_eq!(
            canonical_boundary_point(2, 0, -1, 2),
            Some(TrianglePoint::Sector { s: 1, a: 1, b: 1 })
        );
        assert_eq!(canonical_boundary_point(3, 0, 2, -1), None);
        assert_eq!(canonical_boundary_point(3, 0, 1, -1), None);
        assert_eq!(
            canonical_boundary_point(3, 1, 2, -1),
            Some(TrianglePoint::Sector { s: 0, a: 1, b: 1 })
        );
        assert_eq!(canonical_boundary_point(3, 2, 0, 1), ray(3, 1));
        assert_eq!(canonical_boundary_point(3, 2, -1, 1), None);
        assert_eq!(canonical_boundary_point(3, 2, -1, 2), None);
        // Seven triangles cover more than a full turn; nothing wraps.
        assert_eq!(canonical_boundary_point(7, 6, -1, 0), None);
        assert_eq!(canonical_boundary_point(7, 6, 0, 1), ray(7, 1));
        assert_eq!(
            canonical_boundary_point(3, 0, 0, 0),
            Some(TrianglePoint::Centre)
        );
    }

    #[test]
    fn boundary_layout_sizes_distinct_points_and_affine_rows() {
        for k in 1..=12u32 {
            for s in 0..k {
                let m = TriangleLocalMatrices::boundary(&loop_(), k, s).expect("valid");
                let expected = 1 + (k + 1) + 3 + u32::from(s >= 1) + u32::from(s + 2 <= k);
                assert_eq!(m.size(), expected as usize, "k = {k}, s = {s}");
                assert_eq!(m.names().len(), m.size());
                let mut sorted = m.layout.clone();
                sorted.sort();
                sorted.dedup();
                assert_eq!(sorted.len(), m.size(), "k = {k}, s = {s}");
                for r in
                    m.a.iter()
                        .chain(m.sub_triangles.iter().flat_map(|t| &t.rows))
                {
                    assert_eq!(r.len(), m.size());
                    assert_eq!(r.iter().sum::<BigRational>(), BigRational::one());
                }
                assert!(m.sub_triangles.iter().all(|t| t.points.len() == 12));
                assert_eq!(m.valence, k + 1);
            }
        }
    }

    #[test]
    fn boundary_refinement_is_closed_and_phantoms_are_unambiguous() {
        // Closure: every layout point and every inside point of a sub-triangle net refines
        // from layout points only; every outside net point has exactly one phantom relation
        // (all candidate triangles give the same combination).
        for k in 1..=12u32 {
            let rules = BoundaryLoopRules::new(&loop_(), k).expect("valid");
            for s in 0..k {
                let layout = triangle_boundary_layout(k, s).expect("valid sector");
                let inside = |p: &TrianglePoint| layout.contains(p);
                let reads_layout = |p: TrianglePoint| {
                    rules
                        .refine(p)
                        .is_some_and(|c| c.iter().all(|(q, _)| inside(q)))
                };
                assert!(layout.iter().all(|&p| reads_layout(p)), "k = {k}, s = {s}");
                let si = i64::from(s);
                for corners in SUB_TRIANGLES {
                    for (x, y) in sub_triangle_points(corners) {
                        match rules.at(si, x, y) {
                            Some(p) => assert!(reads_layout(p), "k = {k} s = {s} ({x}, {y})"),
                            None => {
                                let candidates = rules.phantom_triangles(si, corners, (x, y));
                                assert!(!candidates.is_empty(), "k = {k} s = {s} ({x}, {y})");
                                let mut sets: Vec<Vec<TrianglePoint>> = candidates
                                    .iter()
                                    .map(|t| {
                                        let mut e = vec![t[0], t[1]];
                                        e.sort();
                                        e.push(t[2]);
                                        e
                                    })
                                    .collect();
                                sets.dedup();
                                assert_eq!(sets.len(), 1, "k = {k} s = {s} ({x}, {y})");
                                assert!(candidates[0].iter().all(|&q| reads_layout(q)));
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn boundary_rows_are_hoppes_rules() {
        let q = |p: i64, r: i64| big(Rational64::new(p, r));
        for k in 1..=6u32 {
            let m = TriangleLocalMatrices::boundary(&loop_(), k, 0).expect("valid");
            let e = |i: usize| 1 + i;
            let kk = k as usize;
            // V' = 1/8 E_0 + 3/4 V + 1/8 E_k.
            let mut v = vec![BigRational::zero(); m.size()];
            v[0] = q(3, 4);
            v[e(0)] = q(1, 8);
            v[e(kk)] += q(1, 8);
            assert_eq!(m.a[0], v, "k = {k}");
            // Boundary edge points are midpoints; interior ones 3/8, 3/8, 1/8, 1/8.
            for i in [0, kk] {
                let mut w = vec![BigRational::zero(); m.size()];
                w[0] = q(1, 2);
                w[e(i)] = q(1, 2);
                assert_eq!(m.a[e(i)], w, "k = {k}, E_{i}");
            }
            for i in 1..kk {
                let mut w = vec![BigRational::zero(); m.size()];
                w[0] = q(3, 8);
                w[e(i)] = q(3, 8);
                w[e(i - 1)] = q(1, 8);
                w[e(i + 1)] = q(1, 8);
                assert_eq!(m.a[e(i)], w, "k = {k}, E_{i}");
            }
        }
    }

    #[test]
    fn boundary_matrices_are_the_same_for_both_loops_and_bad_input_is_an_error() {
        let original = TriangleScheme::by_name("loop-original").expect("catalogued");
        for k in [1, 2, 5] {
            let a = TriangleLocalMatrices::boundary(&loop_(), k, k - 1).expect("valid");
            let b = TriangleLocalMatrices::boundary(&original, k, k - 1).expect("valid");
            assert_eq!((a.a, a.sub_triangles), (b.a, b.sub_triangles));
        }
        let butterfly = TriangleScheme::by_name("butterfly").expect("catalogued");
        assert!(TriangleLocalMatrices::boundary(&butterfly, 3, 0).is_err());
        assert!(TriangleLocalMatrices::boundary(&loop_(), 0, 0).is_err());
        assert!(TriangleLocalMatrices::boundary(&loop_(), 3, 3).is_err());
        let names = TriangleLocalMatrices::boundary(&loop_(), 3, 0)
            .expect("valid")
            .names();
        assert_eq!(
            names,
            ["V", "E0", "E1", "E2", "E3", "O1", "O2", "O3", "O4"].map(str::to_owned)
        );
    }
}
