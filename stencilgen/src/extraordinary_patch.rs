//! The neighbourhood of an extraordinary vertex and one subdivision step on it.
//!
//! Around an extraordinary vertex (EV) of valence `v`, with no other EV nearby, the mesh is `v`
//! copies of a quadrant of the regular grid glued cyclically: *sector* `s` holds the points
//! `(a, b)` with `a >= 1, b >= 0` in its own coordinates, its `+a` axis along the edge to
//! `E_{s+1}` and its `+b` axis along the edge to `E_{s+2}`, which is sector `s + 1`'s `+a` axis.
//! So `(a, b)` in sector `s` is `(b, -a)` in sector `s + 1` and `(-b, a)` in sector `s - 1`
//! ([`canonical`]). The patch `[0,1]^2` with the EV at `(0,0)` is sector 0's first cell: `u`
//! runs along `E_1`, `v` along `E_2`.
//!
//! Control points of the patch (`K = 2v + 8`, Stam's layout; drawn in
//! `docs/algorithms/extraordinary-stencils.md`):
//!
//! ```text
//!   index 0            V  = the EV
//!   index 1 ..= v      E_i = sector i-1, (1, 0)
//!   index v+1 ..= 2v   F_i = sector i-1, (1, 1)   (in the face V, E_i, F_i, E_{i+1})
//!   index 2v+1 ..      the outer points, in sector-0 coordinates
//!                      (2,-1) (2,0) (2,1) (2,2) (1,2) (0,2) (-1,2)
//! ```
//!
//! One step of subdivision makes the level-1 points from these; at level 1 (half the spacing)
//! the same layout around the same EV gives the `K x K` matrix `A` (`P' = A P`), and the three
//! regular sub-patches `[1/2,1]x[0,1/2]`, `[1/2,1]^2`, `[0,1/2]x[1/2,1]` of the patch get
//! `16 x K` matrices `R_b` (the note's `P_b Ā`). Their 16 points are ordered `(p, q)` row by
//! row, `q` outer, `p, q in -1..=2` relative to the sub-patch's lower-left corner.

use std::collections::HashMap;

use num_bigint::BigInt;
use num_rational::{BigRational, Rational64};
use num_traits::Zero;
use schemes::QuadScheme;

/// A vertex of the EV neighbourhood, in canonical form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum GridPoint {
    /// The extraordinary vertex.
    Centre,
    /// Point `(a, b)`, `a >= 1`, `b >= 0`, of sector `s`.
    Sector {
        /// Sector index in `0..v`.
        s: u32,
        /// Coordinate along the sector's first edge.
        a: i64,
        /// Coordinate along the sector's second edge.
        b: i64,
    },
}

/// The canonical name of point `(a, b)` given in sector `s`'s coordinates (any integers near the
/// sector), in a neighbourhood of valence `v`.
pub fn canonical(v: u32, s: i64, a: i64, b: i64) -> GridPoint {
    let (mut s, mut a, mut b) = (s, a, b);
    loop {
        if a == 0 && b == 0 {
            return GridPoint::Centre;
        }
        if a >= 1 && b >= 0 {
            return GridPoint::Sector {
                s: s.rem_euclid(i64::from(v)) as u32,
                a,
                b,
            };
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a);
        } else {
            (s, a, b) = (s + 1, b, -a);
        }
    }
}

/// The `K = 2v + 8` control points of the EV patch, in table order.
pub fn patch_layout(v: u32) -> Vec<GridPoint> {
    let mut points = vec![GridPoint::Centre];
    points.extend((0..v).map(|s| GridPoint::Sector { s, a: 1, b: 0 }));
    points.extend((0..v).map(|s| GridPoint::Sector { s, a: 1, b: 1 }));
    points.extend(OUTER_POINTS.iter().map(|&(a, b)| canonical(v, 0, a, b)));
    points
}

/// The outer points of the layout, in sector-0 coordinates.
pub const OUTER_POINTS: [(i64, i64); 7] =
    [(2, -1), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (-1, 2)];

/// Lower-left corners, in level-1 sector-0 coordinates, of the three regular sub-patches.
pub const SUB_PATCH_ORIGINS: [(i64, i64); 3] = [(1, 0), (1, 1), (0, 1)];

/// A linear combination of level-0 points.
type Combination = Vec<(GridPoint, Rational64)>;

/// The level-0 combination that one subdivision step of `scheme` assigns to the level-1 point
/// `point` (named in level-1 coordinates, which have the same sector structure).
pub fn refine_point(scheme: &QuadScheme, v: u32, point: GridPoint) -> Combination {
    let (alpha, beta, gamma) = scheme.vertex.weights(v);
    let GridPoint::Sector { s, a, b } = point else {
        let mut c = vec![(GridPoint::Centre, alpha)];
        c.extend((0..v).map(|s| (GridPoint::Sector { s, a: 1, b: 0 }, beta)));
        c.extend((0..v).map(|s| (GridPoint::Sector { s, a: 1, b: 1 }, gamma)));
        return c;
    };
    let s = i64::from(s);
    let at = |a: i64, b: i64| canonical(v, s, a, b);
    let quarter = Rational64::new(1, 4);
    match (a.rem_euclid(2), b.rem_euclid(2)) {
        (0, 0) => {
            // Vertex point of a regular vertex (every vertex but the centre has valence 4).
            let (alpha, beta, gamma) = scheme.vertex.weights(4);
            let (x, y) = (a / 2, b / 2);
            let mut c = vec![(at(x, y), alpha)];
            c.extend([(1, 0), (-1, 0), (0, 1), (0, -1)].map(|(dx, dy)| (at(x + dx, y + dy), beta)));
            c.extend(
                [(1, 1), (-1, 1), (1, -1), (-1, -1)].map(|(dx, dy)| (at(x + dx, y + dy), gamma)),
            );
            c
        }
        (1, 0) => {
            let (x, y) = ((a - 1) / 2, b / 2);
            let mut c = vec![(at(x, y), scheme.edge_end), (at(x + 1, y), scheme.edge_end)];
            c.extend(
                [(0, 1), (0, -1), (1, 1), (1, -1)]
                    .map(|(dx, dy)| (at(x + dx, y + dy), scheme.edge_side)),
            );
            c
        }
        (0, 1) => {
            let (x, y) = (a / 2, (b - 1) / 2);
            let mut c = vec![(at(x, y), scheme.edge_end), (at(x, y + 1), scheme.edge_end)];
            c.extend(
                [(1, 0), (-1, 0), (1, 1), (-1, 1)]
                    .map(|(dx, dy)| (at(x + dx, y + dy), scheme.edge_side)),
            );
            c
        }
        _ => {
            let (x, y) = ((a - 1) / 2, (b - 1) / 2);
            [(0, 0), (1, 0), (1, 1), (0, 1)]
                .map(|(dx, dy)| (at(x + dx, y + dy), quarter))
                .to_vec()
        }
    }
}

/// The local subdivision matrices of one scheme at one valence.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalMatrices {
    /// Valence.
    pub valence: u32,
    /// `A` (K x K): level-1 layout points from level-0 layout points.
    pub a: Vec<Vec<BigRational>>,
    /// `R_b` (16 x K), b = 0, 1, 2 for the sub-patches at [`SUB_PATCH_ORIGINS`].
    pub sub_patches: [Vec<Vec<BigRational>>; 3],
}

impl LocalMatrices {
    /// Build `A` and the `R_b` of `scheme` at valence `v` (`3 <= v`).
    pub fn new(scheme: &QuadScheme, v: u32) -> Self {
        let layout = patch_layout(v);
        let index: HashMap<GridPoint, usize> =
            layout.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        let row = |point: GridPoint| -> Vec<BigRational> {
            let mut r = vec![BigRational::zero(); layout.len()];
            for (p, w) in refine_point(scheme, v, point) {
                let i = *index.get(&p).unwrap_or_else(|| {
                    unreachable!("a patch point's rule reads only the 2-ring: {p:?}")
                });
                r[i] += BigRational::new(BigInt::from(*w.numer()), BigInt::from(*w.denom()));
            }
            r
        };
        let a = layout.iter().map(|&p| row(p)).collect();
        let sub_patches = SUB_PATCH_ORIGINS.map(|(a0, b0)| {
            (-1..=2)
                .flat_map(|q| (-1..=2).map(move |p| (p, q)))
                .map(|(p, q)| row(canonical(v, 0, a0 + p, b0 + q)))
                .collect()
        });
        LocalMatrices {
            valence: v,
            a,
            sub_patches,
        }
    }

    /// `K = 2v + 8`.
    pub fn size(&self) -> usize {
        self.a.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_traits::One;

    #[test]
    fn canonical_names_wrap_around_the_vertex() {
        // (0, 2) in sector 0 is (2, 0) in sector 1; (2, -1) is (1, 2) in sector v - 1.
        assert_eq!(
            canonical(5, 0, 0, 2),
            GridPoint::Sector { s: 1, a: 2, b: 0 }
        );
        assert_eq!(
            canonical(5, 0, 2, -1),
            GridPoint::Sector { s: 4, a: 1, b: 2 }
        );
        assert_eq!(
            canonical(3, 0, -1, 0),
            GridPoint::Sector { s: 2, a: 1, b: 0 }
        );
        assert_eq!(canonical(6, 2, 0, 0), GridPoint::Centre);
    }

    #[test]
    fn layout_has_2v_plus_8_distinct_points() {
        for v in 3..=8 {
            let layout = patch_layout(v);
            assert_eq!(layout.len(), 2 * v as usize + 8);
            let mut sorted = layout.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), layout.len(), "valence {v}");
        }
    }

    #[test]
    fn every_row_is_an_affine_combination() {
        for name in schemes::quad::QUAD_SCHEME_NAMES {
            let scheme = QuadScheme::by_name(name).expect("catalogued");
            for v in 3..=8 {
                let m = LocalMatrices::new(&scheme, v);
                for row in m.a.iter().chain(m.sub_patches.iter().flatten()) {
                    assert_eq!(
                        row.iter().sum::<BigRational>(),
                        BigRational::one(),
                        "{name} v = {v}"
                    );
                }
            }
        }
    }
}
