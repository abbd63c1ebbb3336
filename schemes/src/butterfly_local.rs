//! The modified butterfly (Zorin, Schröder and Sweldens 1996) around an interior extraordinary
//! vertex of valence `K`: the patch layout, the local subdivision matrix `A` and the regular
//! tiles of the patch's outer half with their control points as rows of level-0 weights
//! (Schaefer–Warren sections 5.2–5.3 on the triangular lattice of section 5.1). Data only:
//! `stencilgen::cone_patch` solves with them.
//!
//! **Sectors and the patch** are those of [`crate::triangle_local`]: sector `s` holds the points
//! `(a, b)`, `a >= 1`, `b >= 0`, of its own skew chart, named by
//! [`crate::triangle_local::canonical_triangle_point`];
//! the patch is the triangle `V, E_0, E_1` of sector 0, `(u, v)` barycentric, `V` at `(0, 0)`.
//!
//! **Rules.** The butterfly is interpolatory: a vertex keeps its value, `V' = V`. A new point on
//! an edge `V E_s` incident to the extraordinary vertex (`K != 6`) is
//! `3/4 V + sum_j s_j E_{s+j}` (ZSS 1996; [`TriangleScheme::butterfly_extraordinary`], `s_j`
//! counter-clockwise from the edge's other end, `s_j = (1/4 + cos(2πj/K) + cos(4πj/K)/2)/K` for
//! `K >= 5`, irrational for `K = 5, 7, 8`). Every other edge — both ends regular — takes the
//! regular eight-point rule `1/2, 1/2, 1/8, 1/8, -1/16 x 4` (the scheme's `TriangleRefinement`),
//! read in the chart of the new point's own sector. A stencil of such an edge reaches at most
//! the chart sectors `-1..=2` around the point (checked: [`stencil_sector_span`]); its six
//! triangles then develop into the chart without crossing its cut at 180 degrees, so
//! `canonical_triangle_point` names the true vertices even at `K = 3`, where both wings of the
//! edge `E_0 E_1` are `E_2`. The rules are written in the crate-private `cone_rules`, next to
//! √3's: the shared row machinery of [`crate::cone_local`] applies them, and a shared module
//! must not import the scheme modules built on it.
//!
//! **The layout** is the graph-distance ball of radius [`LAYOUT_RADIUS`] around `{V, E_0, E_1}`
//! on the `K`-valent cone, in this order ([`butterfly_layout`]):
//!
//! ```text
//!   V                                       the vertex
//!   ring 1: E_0 ..= E_{K-1}                 (1, 0) of sectors 0..K
//!   ring 2: (2,0)_0 (1,1)_0 (2,0)_1 ...     every (a, b), a + b = 2, of every sector
//!   ring 3: (3,0)_0 (2,1)_0 (1,2)_0 (3,0)_1 (2,1)_1 (1,2)_1 (2,1)_{K-1} (1,2)_{K-1}
//! ```
//!
//! each ring counter-clockwise from `E_0`'s direction (sector by sector, then by `b`). Ring 3
//! holds only the eight points within distance 2 of `E_0` or `E_1`. `3K + 9` points. Why radius
//! 2 suffices: the regular basis function `psi` is supported on the hull `H` of the mask's
//! indices (the fixed set of `S = (S + H)/2`), inside the hexagon of radius 3, so a control
//! point influences the patch only if it is less than 3 away from it (ball 2); and a level-1
//! point reads level-0 points in `(c + H)/2`, which keeps the ball closed under `A`. Both are
//! checked when the matrices are built (an unlisted point is an error), and radius 1 fails.
//!
//! **Regular tiles.** The relation `phi(x) = phi(2x) A` covers `u + v <= 1/2`. The outer half
//! `1/2 <= u + v <= 1` is *not* regular after one step, unlike Loop's: the butterfly's support
//! has radius 3, so the level-1 triangles next to `E_0` still feel the level-2 points on the
//! edges at `V`, made by the extraordinary rule. A level-`L` triangle `T` is regular — the
//! surface on it is `sum_j psi(y - j) p^L_j` over the unfolded lattice, `y` its level-`L`
//! coordinates — when `V` is outside `T + int H`: every point that influences `T` at any deeper
//! level then lies in `T + int H` (parents of `c` are in `c + H/2`, halving per level), so no
//! rule there reads `V`. [`ConeLocalMatrices::tile_level`] is the smallest `L` for which
//! every level-`L` triangle of the outer half passes (`L = 3`: 48 tiles, since `H` reaches
//! `(2, 0)` in its interior but no point of hex norm 4). Each tile's control points, the
//! level-`L` lattice points `j` with `T ∩ (j + int H)` nonempty, are rows of level-0 layout
//! weights after `L` steps of the true rules.
//!
//! **Numbers.** Every matrix is kept in f64 (the weights' f64 values) and, when all weights are
//! rational (`K = 3, 4, 6`), also exactly as `BigRational`.

use crate::cone::layout_ball;
pub use crate::cone::{chart_sector, layout_key, point_name, LAYOUT_RADIUS};
pub use crate::cone_local::{ConeLocalMatrices, RegularTile};

use crate::cone_rules::edge_of;
use crate::triangle::{apply_map, lattice_symmetries, TriangleRefinement};
use crate::triangle_local::TrianglePoint;
use crate::TriangleScheme;

/// The chart sectors (smallest, largest) that the regular edge stencil of the level-1 point
/// `(a, b)` (`a >= 1, b >= 0`, not both even, not `(1, 0)`) reaches in its own sector's chart,
/// `V` left out; `None` for a vertex point or the edge at `V`. The butterfly's stencils stay in
/// `-1..=2` (see the module docs).
pub fn stencil_sector_span(scheme: &TriangleScheme, a: i64, b: i64) -> Option<(i64, i64)> {
    let TriangleRefinement::Dyadic { edge, .. } = scheme.refinement else {
        return None;
    };
    let (p, k) = edge_of(a, b)?;
    if p == (0, 0) && k == 0 {
        return None;
    }
    let map = lattice_symmetries()[k];
    edge.iter()
        .map(|&(o, _)| apply_map(map, o))
        .map(|o| (p.0 + o.0, p.1 + o.1))
        .filter(|&q| q != (0, 0))
        .map(|q| chart_sector(q.0, q.1))
        .fold(None, |acc, s| match acc {
            None => Some((s, s)),
            Some((lo, hi)) => Some((lo.min(s), hi.max(s))),
        })
}

/// The layout of valence `valence` in table order (see the module docs): the ball of graph
/// radius [`LAYOUT_RADIUS`] around the patch.
pub fn butterfly_layout(valence: u32) -> Vec<TrianglePoint> {
    layout_ball(valence, LAYOUT_RADIUS)
}

/// One regular tile of the patch's outer half at level [`ConeLocalMatrices::tile_level`]
/// (the shared type, [`RegularTile`]).
pub type ButterflyTile = RegularTile;

/// The local subdivision matrices of the modified butterfly around an interior vertex of
/// valence `K` (see the module docs): [`ConeLocalMatrices`] built by the butterfly's rules,
/// dilation 2.
pub type ButterflyLocalMatrices = ConeLocalMatrices;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cone::interiors_meet;
    use num_rational::BigRational;
    use num_traits::One;

    fn butterfly() -> TriangleScheme {
        TriangleScheme::by_name("butterfly").expect("catalogued")
    }

    #[test]
    fn layout_is_the_radius_two_ball_with_3k_plus_9_points() {
        for k in 3..=8u32 {
            let m = ButterflyLocalMatrices::new(&butterfly(), k).expect("builds");
            assert_eq!(m.size(), 3 * k as usize + 9, "K = {k}");
            assert_eq!(m.layout[0], TrianglePoint::Centre);
            for s in 0..k {
                assert_eq!(
                    m.layout[1 + s as usize],
                    TrianglePoint::Sector { s, a: 1, b: 0 }
                );
            }
            let mut sorted = m.layout.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), m.size());
            assert_eq!(m.is_rational(), matches!(k, 3 | 4 | 6));
        }
    }

    #[test]
    fn ring_three_is_in_the_documented_order() {
        let m = ButterflyLocalMatrices::new(&butterfly(), 5).expect("builds");
        let names = m.names();
        assert_eq!(&names[..4], ["V", "(1,0)_0", "(1,0)_1", "(1,0)_2"]);
        assert_eq!(&names[6..10], ["(2,0)_0", "(1,1)_0", "(2,0)_1", "(1,1)_1"]);
        assert_eq!(
            &names[16..],
            [
                "(3,0)_0", "(2,1)_0", "(1,2)_0", "(3,0)_1", "(2,1)_1", "(1,2)_1", "(2,1)_4",
                "(1,2)_4"
            ]
        );
    }

    #[test]
    fn radius_one_is_too_small() {
        for k in 3..=8u32 {
            assert!(ButterflyLocalMatrices::with_radius(&butterfly(), k, 1).is_err());
        }
    }

    #[test]
    fn rows_are_affine() {
        for k in 3..=8u32 {
            let m = ButterflyLocalMatrices::new(&butterfly(), k).expect("builds");
            for r in m.a.iter().chain(&m.regular_rows) {
                assert!((r.iter().sum::<f64>() - 1.0).abs() < 1e-13, "K = {k}");
            }
            if let (Some(a), Some(rows)) = (&m.a_exact, &m.regular_rows_exact) {
                for r in a.iter().chain(rows) {
                    assert!(r.iter().sum::<BigRational>().is_one(), "K = {k}");
                }
            }
        }
    }

    #[test]
    fn tiles_are_level_three_and_cover_the_outer_half() {
        let m = ButterflyLocalMatrices::new(&butterfly(), 5).expect("builds");
        assert_eq!(m.tile_level, 3);
        assert_eq!(m.tiles.len(), 48);
        // The level-2 triangle (2,0),(3,0),(2,1) meets int H: level 2 is not regular.
        assert!(interiors_meet(&[(2, 0), (3, 0), (2, 1)], &m.hull));
        // Every point of the outer half, on the rate-16 grid, is in a tile.
        for j in 0..=16i64 {
            for i in 0..=16 - j {
                if 2 * (i + j) >= 16 {
                    assert!(m.tile_containing((i, j), 2).is_some(), "({i}, {j})/16");
                }
            }
        }
    }

    #[test]
    fn regular_edge_stencils_stay_inside_the_chart() {
        let b = butterfly();
        for a in 1..12 {
            for bb in 0..12 {
                if let Some((lo, hi)) = stencil_sector_span(&b, a, bb) {
                    assert!(lo >= -1 && hi <= 2, "({a}, {bb}): {lo}..{hi}");
                }
            }
        }
    }

    #[test]
    fn mirror_is_an_involution_fixing_v() {
        for k in 3..=8u32 {
            let m = ButterflyLocalMatrices::new(&butterfly(), k).expect("builds");
            assert_eq!(m.mirror(0), Some(0));
            assert_eq!(m.mirror(1), Some(2));
            for i in 0..m.size() {
                let j = m.mirror(i).expect("the layout is symmetric");
                assert_eq!(m.mirror(j), Some(i));
            }
        }
    }

    #[test]
    fn other_schemes_are_errors() {
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        assert!(ButterflyLocalMatrices::new(&loop_, 5).is_err());
        assert!(ButterflyLocalMatrices::new(&butterfly(), 2).is_err());
    }
}
