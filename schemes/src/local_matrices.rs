//! The neighbourhood of an extraordinary vertex and one subdivision step on it: the local
//! subdivision matrix `A` and the regular-subpatch picking matrices `R_b` of Schaefer–Warren
//! section 5.2, as exact rationals. Data only (nothing is solved here): `stencilgen` builds its
//! scaling-relation systems from them, the runtime's exact evaluator applies them.
//!
//! Around a vertex with `f` faces and no other extraordinary vertex nearby, the mesh is `f`
//! copies of a quadrant of the regular grid: *sector* `s` holds the points `(a, b)` with
//! `a >= 1, b >= 0` in its own coordinates, its `+a` axis along the edge to `E_{s+1}` and its
//! `+b` axis along the edge to `E_{s+2}`, which is sector `s + 1`'s `+a` axis. So `(a, b)` in
//! sector `s` is `(b, -a)` in sector `s + 1` and `(-b, a)` in sector `s - 1` ([`canonical`]).
//!
//! * An interior vertex of valence `v` has `f = v` sectors glued cyclically.
//! * A boundary vertex with `f` faces has sectors `0..f` and one more half-sector `f` holding
//!   only its axis `(a, 0)`: the boundary runs along sector 0's `+a` axis and sector `f`'s `+a`
//!   axis; there is nothing beyond (`canonical` returns `None`).
//! * A *dart* (Catmull–Clark with infinitely sharp features, DeRose, Kass and Truong 1998
//!   section 3; OpenSubdiv's `Sdc::Crease::RULE_DART`) is an interior vertex of valence `v`
//!   whose sectors are glued as an interior vertex's, with exactly one infinitely sharp edge at
//!   it: sector 0's `+a` axis. The crease runs straight out along that axis, so at every level
//!   the points `(a, 0)`, `a >= 1`, of sector 0 lie on it ([`on_crease`]) and the neighbourhood
//!   is self-similar. The rules there ([`refine_point`]): the dart itself takes the smooth vertex
//!   rule, an edge point on the crease is its edge's midpoint, a vertex on the crease (two sharp
//!   edges) takes the crease rule `(P_prev + 6 P + P_next) / 8` along it (the scheme's boundary
//!   curve rule), everything else is smooth.
//!
//! The patch of sector `s` is the cell `[0,1]^2` of sector `s`, with `u` along `a` and `v` along
//! `b` and the vertex at `(0,0)`. Its control points ([`patch_layout`], Stam's layout for
//! interior vertices; drawn in `docs/algorithms/extraordinary-stencils.md`):
//!
//! ```text
//!   V                     the vertex
//!   E_1 ..= E_e           E_i = sector i-1, (1, 0);      e = v (interior) or f + 1 (boundary)
//!   F_1 ..= F_f           F_i = sector i-1, (1, 1)       (in the face V, E_i, F_i, E_{i+1})
//!   O_1 ..= O_7           (2,-1) (2,0) (2,1) (2,2) (1,2) (0,2) (-1,2) in sector-s coordinates,
//!                         those that exist (a boundary patch lacks the ones beyond the boundary)
//! ```
//!
//! One step of subdivision makes the level-1 points from these; at level 1 (half the spacing)
//! the same layout around the same vertex gives the `K x K` matrix `A` (`P' = A P`), and the
//! three regular sub-patches `[1/2,1]x[0,1/2]`, `[1/2,1]^2`, `[0,1/2]x[1/2,1]` of the patch get
//! `16 x K` matrices `R_b` (the note's `P_b Ā`). Their 16 points are ordered `(p, q)` row by
//! row, `q` outer, `p, q in -1..=2` relative to the sub-patch's lower-left corner. A sub-patch
//! on the boundary is a regular boundary patch: its control points beyond the boundary are the
//! phantom points `P(a, -1) = 2 P(a, 0) - P(a, 1)` (across sector 0's axis; likewise across the
//! last axis), which makes the bicubic (or tensor-product) patch reproduce the boundary curve
//! rules exactly.
//!
//! At a dart the points across the crease exist, but a sub-patch with an edge on the crease
//! does not see them: the surface on each side of an infinitely sharp crease is the one its
//! own side makes with the crease as its boundary (the crease's points read only the crease,
//! and the reflected smooth rules are the crease rules), so such a sub-patch takes the same
//! phantom points from its own side — sub-patch `[1/2,1]x[0,1/2]` of sector 0 reflects across
//! `b = 0`, sub-patch `[0,1/2]x[1/2,1]` of sector `v - 1` across `a = 0` (OpenSubdiv's `Far`
//! makes such faces boundary patches of their side). Every other sub-patch's corners are
//! smooth valence-4 vertices with smooth edges, so it is the plain tensor-product patch of its
//! 16 points even where they include crease points. The sectors of a dart are all different
//! patches; sectors `s` and `v - 1 - s` are mirror images (the reflection that fixes the crease
//! maps `E_i` to `E_{2-i}`), with `u` and `v` exchanged.

use std::collections::HashMap;

use crate::{BoundaryMode, QuadScheme};
use num_bigint::BigInt;
use num_rational::{BigRational, Rational64};
use num_traits::{CheckedAdd, CheckedMul, Zero};

/// A neighbourhood (or sector) that a scheme has no rules for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnsupportedNeighbourhood {
    /// The scheme.
    pub scheme: String,
    /// Why.
    pub reason: String,
}

impl std::fmt::Display for UnsupportedNeighbourhood {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "scheme `{}` cannot be used here: {}",
            self.scheme, self.reason
        )
    }
}

impl std::error::Error for UnsupportedNeighbourhood {}

/// The combinatorial neighbourhood of the vertex at the patch corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Neighbourhood {
    /// Number of faces around the vertex (the valence, for an interior vertex).
    pub faces: u32,
    /// `None` for an interior vertex; the boundary interpolation mode for a boundary vertex.
    pub boundary: Option<BoundaryMode>,
    /// An interior vertex with one infinitely sharp edge, sector 0's `+a` axis, the crease
    /// continuing straight out along it (the module docs). Only with `boundary == None`.
    pub dart: bool,
}

impl Neighbourhood {
    /// An interior vertex of valence `v`.
    pub fn interior(v: u32) -> Self {
        Neighbourhood {
            faces: v,
            boundary: None,
            dart: false,
        }
    }

    /// A dart of valence `v`: an interior vertex whose one infinitely sharp edge is sector 0's
    /// `+a` axis.
    pub fn dart(v: u32) -> Self {
        Neighbourhood {
            faces: v,
            boundary: None,
            dart: true,
        }
    }

    /// A boundary vertex with `faces` faces.
    pub fn boundary(faces: u32, mode: BoundaryMode) -> Self {
        Neighbourhood {
            faces,
            boundary: Some(mode),
            dart: false,
        }
    }

    /// Number of edges at the vertex: `v`, or `f + 1` on the boundary.
    pub fn edges(self) -> u32 {
        self.faces + u32::from(self.boundary.is_some())
    }

    /// Whether the vertex is a pinned corner (one face, "edge and corner" mode).
    pub fn is_corner(self) -> bool {
        self.faces == 1 && self.boundary == Some(BoundaryMode::EdgeAndCorner)
    }

    /// Whether the patch at this vertex is a plain tensor-product patch: valence 4 (not a
    /// dart), a boundary vertex with two faces, or a pinned corner (phantom points in both
    /// directions).
    pub fn is_regular(self) -> bool {
        match self.boundary {
            None => self.faces == 4 && !self.dart,
            Some(_) => self.faces == 2 || self.is_corner(),
        }
    }

    /// The patches it has: sectors `0..faces` (interior patches are all alike; only sector 0
    /// is used for them; a dart's differ by their place relative to the crease).
    pub fn sectors(self) -> u32 {
        if self.boundary.is_some() || self.dart {
            self.faces
        } else {
            1
        }
    }

    /// Check the neighbourhood against what a scheme supports.
    pub fn validate(
        self,
        scheme: &QuadScheme,
        sector: u32,
    ) -> Result<(), UnsupportedNeighbourhood> {
        let unsupported = |reason: String| UnsupportedNeighbourhood {
            scheme: scheme.name.to_owned(),
            reason,
        };
        match self.boundary {
            None if self.faces < 3 => Err(unsupported(format!(
                "an interior vertex needs valence >= 3, not {}",
                self.faces
            ))),
            Some(_) if self.faces == 0 => Err(unsupported(
                "a boundary vertex needs at least one face".to_owned(),
            )),
            Some(_) if scheme.boundary.is_none() => {
                Err(unsupported("it has no boundary rules".to_owned()))
            }
            Some(_) if self.dart => Err(unsupported(
                "a dart is an interior vertex, not a boundary vertex".to_owned(),
            )),
            None if self.dart && scheme.boundary.is_none() => Err(unsupported(
                "a dart's crease needs boundary (crease) rules, and it has none".to_owned(),
            )),
            _ if sector >= self.sectors() => Err(unsupported(format!(
                "sector {sector} does not exist at a vertex with {} patch(es)",
                self.sectors()
            ))),
            _ => Ok(()),
        }
    }
}

/// A vertex of the neighbourhood, in canonical form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum GridPoint {
    /// The vertex at the patch corner.
    Centre,
    /// Point `(a, b)`, `a >= 1`, `b >= 0`, of sector `s`.
    Sector {
        /// Sector index.
        s: u32,
        /// Coordinate along the sector's first edge.
        a: i64,
        /// Coordinate along the sector's second edge.
        b: i64,
    },
}

/// The canonical name of point `(a, b)` given in sector `s`'s coordinates, or `None` if it lies
/// beyond the boundary.
pub fn canonical(nb: Neighbourhood, s: i64, a: i64, b: i64) -> Option<GridPoint> {
    let (mut s, mut a, mut b) = (s, a, b);
    let f = i64::from(nb.faces);
    loop {
        if a == 0 && b == 0 {
            return Some(GridPoint::Centre);
        }
        if a >= 1 && b >= 0 {
            let s = match nb.boundary {
                None => s.rem_euclid(f),
                Some(_) if s < f || (s == f && b == 0) => s,
                Some(_) => return None,
            };
            return Some(GridPoint::Sector { s: s as u32, a, b });
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a);
        } else {
            (s, a, b) = (s + 1, b, -a);
        }
        if nb.boundary.is_some() && !(0..=f).contains(&s) {
            return None;
        }
    }
}

/// Whether the canonical point `p` lies on `nb`'s crease: a dart's points `(a, 0)`, `a >= 1`,
/// of sector 0 (at every level: the crease is self-similar).
pub fn on_crease(nb: Neighbourhood, p: GridPoint) -> bool {
    nb.dart && matches!(p, GridPoint::Sector { s: 0, b: 0, .. })
}

/// The outer points of a patch layout, in the patch sector's coordinates.
pub const OUTER_POINTS: [(i64, i64); 7] =
    [(2, -1), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (-1, 2)];

/// Lower-left corners, in level-1 sector coordinates, of the three regular sub-patches.
pub const SUB_PATCH_ORIGINS: [(i64, i64); 3] = [(1, 0), (1, 1), (0, 1)];

/// The control points of the patch of `sector`, in table order.
pub fn patch_layout(nb: Neighbourhood, sector: u32) -> Vec<GridPoint> {
    let mut points = vec![GridPoint::Centre];
    points.extend((0..nb.edges()).map(|s| GridPoint::Sector { s, a: 1, b: 0 }));
    points.extend((0..nb.faces).map(|s| GridPoint::Sector { s, a: 1, b: 1 }));
    points.extend(
        OUTER_POINTS
            .iter()
            .filter_map(|&(a, b)| canonical(nb, i64::from(sector), a, b)),
    );
    points
}

/// A linear combination of points.
type Combination = Vec<(GridPoint, Rational64)>;

fn exists(nb: Neighbourhood, s: i64, a: i64, b: i64) -> GridPoint {
    canonical(nb, s, a, b)
        .unwrap_or_else(|| unreachable!("rule reads a point beyond the boundary: ({s}; {a}, {b})"))
}

/// The level-0 combination that one subdivision step of `scheme` assigns to the level-1 point
/// `point` (named in level-1 coordinates, which have the same sector structure).
///
/// At a dart (OpenSubdiv's `Sdc` rules for infinitely sharp edges): the dart itself is smooth;
/// a level-1 point on the crease ([`on_crease`]) with even coordinates is the vertex point of a
/// crease vertex (two sharp edges), the scheme's boundary curve rule along the crease; with an
/// odd `a` it is the edge point of a sharp edge, its midpoint.
pub fn refine_point(scheme: &QuadScheme, nb: Neighbourhood, point: GridPoint) -> Combination {
    let boundary = scheme.boundary;
    let GridPoint::Sector { s, a, b } = point else {
        return match (nb.boundary, boundary) {
            (Some(_), _) if nb.is_corner() => {
                vec![(GridPoint::Centre, Rational64::from_integer(1))]
            }
            (Some(_), Some(rules)) => vec![
                (GridPoint::Centre, rules.vertex_centre),
                (GridPoint::Sector { s: 0, a: 1, b: 0 }, rules.vertex_end),
                (
                    GridPoint::Sector {
                        s: nb.faces,
                        a: 1,
                        b: 0,
                    },
                    rules.vertex_end,
                ),
            ],
            _ => {
                let (alpha, beta, gamma) = scheme.vertex.weights(nb.faces);
                let mut c = vec![(GridPoint::Centre, alpha)];
                c.extend((0..nb.faces).map(|s| (GridPoint::Sector { s, a: 1, b: 0 }, beta)));
                c.extend((0..nb.faces).map(|s| (GridPoint::Sector { s, a: 1, b: 1 }, gamma)));
                c
            }
        };
    };
    let crease = on_crease(nb, point);
    let s = i64::from(s);
    let at = |a: i64, b: i64| canonical(nb, s, a, b);
    let quarter = Rational64::new(1, 4);
    let half = Rational64::new(1, 2);
    match (a.rem_euclid(2), b.rem_euclid(2)) {
        (0, 0) => {
            let (x, y) = (a / 2, b / 2);
            let ring: Vec<Option<GridPoint>> = [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (-1, 1),
                (1, -1),
                (-1, -1),
            ]
            .iter()
            .map(|&(dx, dy)| at(x + dx, y + dy))
            .collect();
            if ring.iter().all(Option::is_some) && !crease {
                // A regular interior vertex (every vertex but the centre has valence 4).
                let (alpha, beta, gamma) = scheme.vertex.weights(4);
                let mut c = vec![(exists(nb, s, x, y), alpha)];
                c.extend(ring[..4].iter().flatten().map(|&p| (p, beta)));
                c.extend(ring[4..].iter().flatten().map(|&p| (p, gamma)));
                c
            } else {
                // A regular boundary vertex on an axis, or a vertex on a dart's crease: the
                // boundary curve rule along the axis.
                let Some(GridPoint::Sector { s, a: x, .. }) = at(x, y) else {
                    unreachable!("the centre is not refined here")
                };
                let rules = boundary
                    .unwrap_or_else(|| unreachable!("validated: the scheme has boundary rules"));
                let s = i64::from(s);
                vec![
                    (exists(nb, s, x, 0), rules.vertex_centre),
                    (exists(nb, s, x - 1, 0), rules.vertex_end),
                    (exists(nb, s, x + 1, 0), rules.vertex_end),
                ]
            }
        }
        (1, 0) | (0, 1) => {
            // Edge from (x, y) to (x, y) + d; its side points are offset by o.
            let (x, y, d, o) = if a.rem_euclid(2) == 1 {
                ((a - 1) / 2, b / 2, (1, 0), (0, 1))
            } else {
                (a / 2, (b - 1) / 2, (0, 1), (1, 0))
            };
            let ends = [exists(nb, s, x, y), exists(nb, s, x + d.0, y + d.1)];
            let sides: Vec<Option<GridPoint>> = [(0, 1), (0, -1), (1, 1), (1, -1)]
                .iter()
                .map(|&(along, across)| {
                    at(
                        x + along * d.0 + across * o.0,
                        y + along * d.1 + across * o.1,
                    )
                })
                .collect();
            if sides.iter().all(Option::is_some) && !crease {
                let mut c: Combination = ends.iter().map(|&p| (p, scheme.edge_end)).collect();
                c.extend(sides.iter().flatten().map(|&p| (p, scheme.edge_side)));
                c
            } else {
                // A boundary edge, or a sharp edge on a dart's crease: its midpoint.
                ends.iter().map(|&p| (p, half)).collect()
            }
        }
        _ => {
            let (x, y) = ((a - 1) / 2, (b - 1) / 2);
            [(0, 0), (1, 0), (1, 1), (0, 1)]
                .map(|(dx, dy)| (exists(nb, s, x + dx, y + dy), quarter))
                .to_vec()
        }
    }
}

/// Point `(a, b)` of sector `s`, as a net point of one of sector `s`'s sub-patches, as a
/// combination of existing points: itself, or a phantom point extrapolated linearly across the
/// boundary, or the dart's crease, that it lies beyond.
fn with_phantoms(nb: Neighbourhood, s: i64, a: i64, b: i64) -> Combination {
    // Only the sub-patches beside the crease reach across it: sector 0's with b = -1 (the
    // crease is its b = 0 axis) and sector v - 1's with a = -1 (its a = 0 axis).
    let across_crease = nb.dart && ((s == 0 && b < 0) || (s == i64::from(nb.faces) - 1 && a < 0));
    if !across_crease {
        if let Some(p) = canonical(nb, s, a, b) {
            return vec![(p, Rational64::from_integer(1))];
        }
    }
    // Beyond sector 0's axis (the line b = 0 of sector 0) reflect in b; beyond the last axis
    // (the line a = 0 of sector f - 1) reflect in a. A corner patch has both.
    let (near, far) = if s == 0 && b < 0 {
        (
            with_phantoms(nb, s, a, b + 1),
            with_phantoms(nb, s, a, b + 2),
        )
    } else {
        (
            with_phantoms(nb, s, a + 1, b),
            with_phantoms(nb, s, a + 2, b),
        )
    };
    let two = Rational64::from_integer(2);
    near.into_iter()
        .map(|(p, w)| (p, w * two))
        .chain(far.into_iter().map(|(p, w)| (p, -w)))
        .collect()
}

/// The row of length `len` whose entry `i` is the sum of `w * w1` over the terms `(i, w, w1)`,
/// exactly.
///
/// Why two paths: the weights' denominators are small (`4 N^2` and powers of two), so the sums
/// almost always fit in `i64` ratios, whose arithmetic needs no allocation, where every
/// `BigRational` sum allocates and reduces: that made the operators of four patch kinds about
/// a millisecond of a Lai–Cheng run (docs/benchmarks.md). A product or sum that would overflow
/// sends the whole row to `BigRational`; either way the entries are the same exact numbers.
fn exact_row(len: usize, terms: &[(usize, Rational64, Rational64)]) -> Vec<BigRational> {
    let small = || -> Option<Vec<Rational64>> {
        let mut r = vec![Rational64::zero(); len];
        for &(i, w, w1) in terms {
            r[i] = r[i].checked_add(&w.checked_mul(&w1)?)?;
        }
        Some(r)
    };
    let big = |w: Rational64| BigRational::new(BigInt::from(*w.numer()), BigInt::from(*w.denom()));
    match small() {
        // `Rational64`'s arithmetic keeps it reduced with a positive denominator, as
        // `new_raw` requires.
        Some(r) => r
            .into_iter()
            .map(|w| BigRational::new_raw(BigInt::from(*w.numer()), BigInt::from(*w.denom())))
            .collect(),
        None => {
            let mut r = vec![BigRational::zero(); len];
            for &(i, w, w1) in terms {
                r[i] += big(w) * big(w1);
            }
            r
        }
    }
}

/// The local subdivision matrices of one scheme around one neighbourhood, for one sector's patch.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalMatrices {
    /// The neighbourhood.
    pub neighbourhood: Neighbourhood,
    /// The sector whose patch this is.
    pub sector: u32,
    /// The patch's control points.
    pub layout: Vec<GridPoint>,
    /// `A` (K x K): level-1 layout points from level-0 layout points.
    pub a: Vec<Vec<BigRational>>,
    /// `R_b` (16 x K), b = 0, 1, 2 for the sub-patches at [`SUB_PATCH_ORIGINS`].
    pub sub_patches: [Vec<Vec<BigRational>>; 3],
}

impl LocalMatrices {
    /// Build `A` and the `R_b` of `scheme` around `nb` for the patch of `sector`.
    pub fn new(
        scheme: &QuadScheme,
        nb: Neighbourhood,
        sector: u32,
    ) -> Result<Self, UnsupportedNeighbourhood> {
        nb.validate(scheme, sector)?;
        let layout = patch_layout(nb, sector);
        let index: HashMap<GridPoint, usize> =
            layout.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        let row = |combination: Combination| -> Vec<BigRational> {
            let mut terms = Vec::new();
            for (level1, w1) in combination {
                for (p, w) in refine_point(scheme, nb, level1) {
                    let i = *index.get(&p).unwrap_or_else(|| {
                        unreachable!("a patch point's rule reads only the patch's points: {p:?}")
                    });
                    terms.push((i, w, w1));
                }
            }
            exact_row(layout.len(), &terms)
        };
        let one = Rational64::from_integer(1);
        let a = layout.iter().map(|&p| row(vec![(p, one)])).collect();
        let s = i64::from(sector);
        let sub_patches = SUB_PATCH_ORIGINS.map(|(a0, b0)| {
            (-1..=2)
                .flat_map(|q| (-1..=2).map(move |p| (p, q)))
                .map(|(p, q)| row(with_phantoms(nb, s, a0 + p, b0 + q)))
                .collect()
        });
        Ok(LocalMatrices {
            neighbourhood: nb,
            sector,
            layout,
            a,
            sub_patches,
        })
    }

    /// For a neighbourhood whose patch is itself a regular (boundary) tensor-product patch
    /// ([`Neighbourhood::is_regular`]): its 4 x 4 net at level 0 (`16 x K`, points `(p, q)`,
    /// `p, q in -1..=2`, `q` outer), phantom points beyond the boundary included, so that
    /// the patch is `psi(u, v) N` on all of `[0,1]^2` without subdividing. `None` otherwise.
    pub fn regular_net(&self) -> Option<Vec<Vec<BigRational>>> {
        if !self.neighbourhood.is_regular() {
            return None;
        }
        let index: HashMap<GridPoint, usize> = self
            .layout
            .iter()
            .enumerate()
            .map(|(i, &p)| (p, i))
            .collect();
        let s = i64::from(self.sector);
        let nb = self.neighbourhood;
        (-1..=2)
            .flat_map(|q| (-1..=2).map(move |p| (p, q)))
            .map(|(p, q)| {
                let one = Rational64::from_integer(1);
                let terms = with_phantoms(nb, s, p, q)
                    .into_iter()
                    .map(|(point, w)| Some((*index.get(&point)?, w, one)))
                    .collect::<Option<Vec<_>>>()?;
                Some(exact_row(self.layout.len(), &terms))
            })
            .collect()
    }

    /// The number of control points `K`.
    pub fn size(&self) -> usize {
        self.a.len()
    }

    /// A short description for messages: `valence 5`, `dart, valence 4, sector 2`,
    /// `boundary, 3 faces, sector 1`.
    pub fn describe(&self) -> String {
        match self.neighbourhood.boundary {
            None if self.neighbourhood.dart => format!(
                "dart, valence {}, sector {}",
                self.neighbourhood.faces, self.sector
            ),
            None => format!("valence {}", self.neighbourhood.faces),
            Some(mode) => format!(
                "boundary ({mode:?}), {} faces, sector {}",
                self.neighbourhood.faces, self.sector
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_traits::One;

    #[test]
    fn exact_rows_past_i64_are_big_rationals() {
        let r = |n: i64, d: i64| Rational64::new(n, d);
        let tiny = r(1, 1 << 40);
        // Small terms: i64 ratios throughout.
        let small = exact_row(2, &[(1, r(1, 3), r(3, 4)), (1, r(1, 4), r(1, 1))]);
        assert_eq!(small[0], BigRational::zero());
        assert_eq!(small[1], BigRational::new(BigInt::from(1), BigInt::from(2)));
        // 2^-40 * 2^-40 overflows i64: the whole row is summed in big rationals.
        let big = exact_row(
            2,
            &[(0, tiny, tiny), (0, tiny, tiny), (1, r(3, 7), r(2, 1))],
        );
        let two_to_79 = BigInt::from(1) << 79usize;
        assert_eq!(big[0], BigRational::new(BigInt::from(1), two_to_79));
        assert_eq!(big[1], BigRational::new(BigInt::from(6), BigInt::from(7)));
    }

    #[test]
    fn canonical_names_wrap_around_the_vertex() {
        let nb = Neighbourhood::interior(5);
        assert_eq!(
            canonical(nb, 0, 0, 2),
            Some(GridPoint::Sector { s: 1, a: 2, b: 0 })
        );
        assert_eq!(
            canonical(nb, 0, 2, -1),
            Some(GridPoint::Sector { s: 4, a: 1, b: 2 })
        );
        assert_eq!(
            canonical(Neighbourhood::interior(3), 0, -1, 0),
            Some(GridPoint::Sector { s: 2, a: 1, b: 0 })
        );
        assert_eq!(
            canonical(Neighbourhood::interior(6), 2, 0, 0),
            Some(GridPoint::Centre)
        );
    }

    #[test]
    fn boundary_points_beyond_the_edges_do_not_exist() {
        let nb = Neighbourhood::boundary(2, BoundaryMode::EdgeOnly);
        assert_eq!(canonical(nb, 0, 2, -1), None);
        assert_eq!(
            canonical(nb, 0, 2, 0),
            Some(GridPoint::Sector { s: 0, a: 2, b: 0 })
        );
        // (0, 2) of sector 1 is the last axis; (-1, 2) of sector 1 is beyond it.
        assert_eq!(
            canonical(nb, 1, 0, 2),
            Some(GridPoint::Sector { s: 2, a: 2, b: 0 })
        );
        assert_eq!(canonical(nb, 1, -1, 2), None);
    }

    #[test]
    fn interior_layout_has_2v_plus_8_distinct_points() {
        for v in 3..=8 {
            let layout = patch_layout(Neighbourhood::interior(v), 0);
            assert_eq!(layout.len(), 2 * v as usize + 8);
            let mut sorted = layout.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), layout.len(), "valence {v}");
        }
    }

    #[test]
    fn every_row_is_an_affine_combination() {
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        let sw = QuadScheme::by_name("sw-nonpoly-quad").expect("catalogued");
        let mut cases: Vec<(QuadScheme, Neighbourhood, u32)> = Vec::new();
        for v in 3..=8 {
            cases.push((cc.clone(), Neighbourhood::interior(v), 0));
            cases.push((sw.clone(), Neighbourhood::interior(v), 0));
            for s in 0..v {
                cases.push((cc.clone(), Neighbourhood::dart(v), s));
            }
        }
        for f in 1..=6 {
            for mode in [BoundaryMode::EdgeOnly, BoundaryMode::EdgeAndCorner] {
                for s in 0..f {
                    cases.push((cc.clone(), Neighbourhood::boundary(f, mode), s));
                }
            }
        }
        for (scheme, nb, s) in cases {
            let m = LocalMatrices::new(&scheme, nb, s).expect("valid neighbourhood");
            for row in m.a.iter().chain(m.sub_patches.iter().flatten()) {
                assert_eq!(
                    row.iter().sum::<BigRational>(),
                    BigRational::one(),
                    "{} {}",
                    scheme.name,
                    m.describe()
                );
            }
        }
    }

    /// The mirror image of a canonical point of a dart of valence `v`: `(a, b)` of sector `s`
    /// is `(b, a)` of sector `v - 1 - s` (the reflection that fixes the crease).
    fn mirrored(nb: Neighbourhood, p: GridPoint) -> GridPoint {
        match p {
            GridPoint::Centre => GridPoint::Centre,
            GridPoint::Sector { s, a, b } => {
                canonical(nb, i64::from(nb.faces) - 1 - i64::from(s), b, a)
                    .expect("an interior vertex's points all exist")
            }
        }
    }

    /// Sectors `s` and `v - 1 - s` of a dart are mirror images: `A` and the sub-patch matrices
    /// of one are those of the other with the points mirrored, sub-patch `[1/2,1]x[0,1/2]`
    /// exchanged with `[0,1/2]x[1/2,1]` and `(p, q)` with `(q, p)`. This checks the crease's
    /// rules and which side's phantoms each sub-patch takes.
    #[test]
    fn dart_sectors_mirror_each_other() {
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        for v in 3..=6 {
            let nb = Neighbourhood::dart(v);
            for s in 0..v {
                let here = LocalMatrices::new(&cc, nb, s).expect("valid");
                let there = LocalMatrices::new(&cc, nb, v - 1 - s).expect("valid");
                let index: HashMap<GridPoint, usize> = there
                    .layout
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| (p, i))
                    .collect();
                let m: Vec<usize> = here
                    .layout
                    .iter()
                    .map(|&p| index[&mirrored(nb, p)])
                    .collect();
                for i in 0..here.size() {
                    for j in 0..here.size() {
                        assert_eq!(here.a[i][j], there.a[m[i]][m[j]], "v {v} sector {s}");
                    }
                }
                for (b, mirror_b) in [(0, 2), (1, 1), (2, 0)] {
                    for p in 0..4 {
                        for q in 0..4 {
                            for (j, &mj) in m.iter().enumerate() {
                                assert_eq!(
                                    here.sub_patches[b][4 * q + p][j],
                                    there.sub_patches[mirror_b][4 * p + q][mj],
                                    "v {v} sector {s} sub-patch {b} ({p}, {q})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// The dart's rows by hand (OpenSubdiv's `Sdc` rules): at level 1 the dart is the smooth
    /// vertex point, `(1, 0)` of sector 0 the sharp edge's midpoint `(V + E_1) / 2`, `(2, 0)`
    /// the crease rule `(V + 6 E_1 + P(2, 0)) / 8`, `(1, 0)` of sector 1 the smooth edge point;
    /// sector 0's lower sub-patch reflects across the crease, `P(1, -1) = 2 P(1, 0) - P(1, 1)`.
    #[test]
    fn dart_rules_by_hand() {
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        let nb = Neighbourhood::dart(5);
        let m = LocalMatrices::new(&cc, nb, 0).expect("valid");
        let r = |p: i64, q: i64| BigRational::new(BigInt::from(p), BigInt::from(q));
        let at = |p: GridPoint| {
            m.layout
                .iter()
                .position(|&x| x == p)
                .expect("in the layout")
        };
        let point = |s: u32, a: i64, b: i64| GridPoint::Sector { s, a, b };
        let row_of = |p: GridPoint| {
            let mut row = vec![BigRational::zero(); m.size()];
            for (x, w) in refine_point(&cc, nb, p) {
                row[at(x)] += BigRational::new(BigInt::from(*w.numer()), BigInt::from(*w.denom()));
            }
            row
        };
        let expect = |terms: &[(GridPoint, BigRational)]| {
            let mut row = vec![BigRational::zero(); m.size()];
            for (p, w) in terms {
                row[at(*p)] += w;
            }
            row
        };
        let v = GridPoint::Centre;
        // Smooth vertex rule at valence 5: 13/20 V + 3/50 sum E + 1/100 sum F.
        let mut smooth = vec![(v, r(13, 20))];
        smooth.extend((0..5).map(|s| (point(s, 1, 0), r(3, 50))));
        smooth.extend((0..5).map(|s| (point(s, 1, 1), r(1, 100))));
        assert_eq!(row_of(v), expect(&smooth));
        assert_eq!(
            row_of(point(0, 1, 0)),
            expect(&[(v, r(1, 2)), (point(0, 1, 0), r(1, 2))])
        );
        assert_eq!(
            row_of(point(0, 2, 0)),
            expect(&[
                (v, r(1, 8)),
                (point(0, 1, 0), r(6, 8)),
                (point(0, 2, 0), r(1, 8))
            ])
        );
        assert_eq!(
            row_of(point(1, 1, 0)),
            expect(&[
                (v, r(3, 8)),
                (point(1, 1, 0), r(3, 8)),
                (point(0, 1, 0), r(1, 16)),
                (point(0, 1, 1), r(1, 16)),
                (point(1, 1, 1), r(1, 16)),
                (point(2, 1, 0), r(1, 16)),
            ])
        );
        // Sub-patch 0 (origin (1, 0)), net point (p, q) = (0, -1) + (1, 0): level-1 (1, -1).
        let phantom = &m.sub_patches[0][1];
        let (near, far) = (row_of(point(0, 1, 0)), row_of(point(0, 1, 1)));
        let expected: Vec<BigRational> = near
            .iter()
            .zip(&far)
            .map(|(n, f)| n * r(2, 1) - f)
            .collect();
        assert_eq!(phantom, &expected);
        // Sector 1's neighbourhood reaches across nothing: its (1, -1) is sector 0's (1, 1).
        let m1 = LocalMatrices::new(&cc, nb, 1).expect("valid");
        assert!(m1.sub_patches[0][1]
            .iter()
            .all(|w| *w >= BigRational::zero()));
    }

    #[test]
    fn unsupported_neighbourhoods_are_errors() {
        let sw = QuadScheme::by_name("sw-nonpoly-quad").expect("catalogued");
        assert!(
            LocalMatrices::new(&sw, Neighbourhood::boundary(2, BoundaryMode::EdgeOnly), 0).is_err()
        );
        let cc = QuadScheme::by_name("catmull-clark").expect("catalogued");
        assert!(LocalMatrices::new(&cc, Neighbourhood::interior(2), 0).is_err());
        assert!(LocalMatrices::new(&cc, Neighbourhood::dart(2), 0).is_err());
        assert!(LocalMatrices::new(&cc, Neighbourhood::dart(4), 4).is_err());
        assert!(LocalMatrices::new(&sw, Neighbourhood::dart(4), 0).is_err());
        assert!(
            LocalMatrices::new(&cc, Neighbourhood::boundary(3, BoundaryMode::EdgeOnly), 3).is_err()
        );
    }
}
