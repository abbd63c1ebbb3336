//! Loop subdivision around an interior extraordinary vertex of valence `v`: the patch layout,
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

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::{BigRational, Rational64};
use num_traits::Zero;

use crate::local_matrices::UnsupportedNeighbourhood;
use crate::triangle::{apply_map, lattice_symmetries, NEIGHBOURS};
use crate::{TriangleScheme, TriangleVertexRule};

/// A vertex around the extraordinary vertex, in canonical form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TrianglePoint {
    /// The extraordinary vertex.
    Centre,
    /// Point `(a, b)`, `a >= 1`, `b >= 0`, of sector `s`.
    Sector {
        /// Sector index, `0..v`.
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

/// The local subdivision matrices of Loop around an interior vertex of valence `v`.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleLocalMatrices {
    /// The scheme's name.
    pub scheme: String,
    /// The valence.
    pub valence: u32,
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
            let mut points: Vec<(i64, i64)> = corners
                .iter()
                .flat_map(|&(x, y)| {
                    std::iter::once((x, y))
                        .chain(NEIGHBOURS.iter().map(move |&(dx, dy)| (x + dx, y + dy)))
                })
                .collect();
            points.sort_unstable();
            points.dedup();
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
            layout,
            a,
            sub_triangles,
        })
    }

    /// The number of control points `K = v + 6`.
    pub fn size(&self) -> usize {
        self.layout.len()
    }

    /// Names of the layout's points: `V`, `E0..`, `O0..O4`.
    pub fn names(&self) -> Vec<String> {
        let mut names = vec!["V".to_owned()];
        names.extend((0..self.valence).map(|i| format!("E{i}")));
        names.extend((0..TRIANGLE_OUTER_POINTS.len()).map(|i| format!("O{i}")));
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
}
