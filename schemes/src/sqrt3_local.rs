//! √3 subdivision (Kobbelt 2000) around an interior extraordinary vertex of valence `K`: the
//! patch layout, the local subdivision matrix `A` of two √3 steps and the regular tiles of the
//! patch's outer part with their control points as rows of level-0 weights
//! (Schaefer–Warren sections 5.1–5.3: two √3 steps are one ternary step aligned with the
//! original lattice). Data only: `stencilgen::sqrt3_patch` solves with them.
//!
//! **Sectors and the patch** are those of [`crate::triangle_local`]: sector `s` holds the points
//! `(a, b)`, `a >= 1`, `b >= 0`, of its own skew chart, named by
//! [`crate::triangle_local::canonical_triangle_point`];
//! the patch is the triangle `V, E_0, E_1` of sector 0, `(u, v)` barycentric, `V` at `(0, 0)`.
//!
//! **Levels.** "Level `k`" is the ternary level: `2k` √3 steps. In level-`(k+1)` integer skew
//! coordinates (level-`k` coordinates times 3) of a sector's chart, the level-`k` points are
//! the multiples of 3, the points after one more √3 step (the half level) are those with
//! `a = b (mod 3)` (the old vertices and the centroids of the old triangles, the classes
//! `(0,0)`, `(1,1)`, `(2,2)` mod 3: a lattice turned by 30 degrees with spacing `1/√3`), and the
//! level-`(k+1)` points are all integer points:
//!
//! ```text
//!   level-1 coordinates of sector 0 (o level 0, x half level, . level 1 only)
//!
//!           E1  .   .   o          (0,3)  (1,3)  (2,3)  (3,3)
//!         .   .   x   .          (0,2)  (1,2)  (2,2)  (3,2)
//!       .   x   .   .          (0,1)  (1,1)  (2,1)  (3,1)
//!     V   .   .   E0         (0,0)  (1,0)  (2,0)  (3,0)
//! ```
//!
//! The half-level point `(1,1)` is the centroid of `V, E_0, E_1`, `(2,2)` that of
//! `E_0, E_1, (3,3)`; the level-1 point `(1,0)` is the centroid of the half-level triangle
//! `V, (1,1)_0, (1,1)_{K-1}`.
//!
//! **Rules** (Kobbelt 2000). One √3 step: every triangle gets its centroid, and every old
//! vertex of valence `v` moves to `(1 - alpha_v) p + (alpha_v / v) sum` of its `v` neighbours,
//! `alpha_v = (4 - 2 cos(2π/v))/9` ([`crate::TriangleVertexRule::Sqrt3`]); the old edges are flipped.
//! Old vertices keep their valence, centroids have valence 6, so only `V` is extraordinary. At
//! the half level `V`'s neighbours are the `K` centroids `(1,1)_s` (level-`(k+1)` coordinates),
//! at level `k + 1` the `K` centroids `(1,0)_s` on the original edges' directions. Every rule
//! reads a one-ring, which develops into the point's sector chart turned at most one sector
//! either way, so `canonical_triangle_point` names the true vertices at every `K >= 3`. The
//! rules are written in the crate-private `cone_rules`, next to the butterfly's: the shared
//! row machinery of [`crate::cone_local`] applies them, and a shared module must not import the
//! scheme modules built on it.
//!
//! **The layout** is the graph-distance ball of radius [`LAYOUT_RADIUS`] around `{V, E_0, E_1}`
//! on the `K`-valent cone, in this order ([`sqrt3_layout`]):
//!
//! ```text
//!   V                                       the vertex
//!   ring 1: E_0 ..= E_{K-1}                 (1, 0) of sectors 0..K
//!   ring 2: (2,0)_0 (1,1)_0 (2,0)_1 ...     every (a, b), a + b = 2, of every sector
//!   ring 3: (3,0)_0 (2,1)_0 (1,2)_0 (3,0)_1 (2,1)_1 (1,2)_1 (2,1)_{K-1} (1,2)_{K-1}
//! ```
//!
//! each ring counter-clockwise from `E_0`'s direction (sector, then `b`); `3K + 9` points, the
//! butterfly's layout shape. Why radius 2: the regular basis `psi` of the two-step mask is
//! supported on `S = H / 2`, `H` the hull of the mask's 73 indices (a 12-gon with corners
//! `(5,-1)`, `(4,1)` and their turns; `S` reaches `2.25` along the lattice directions and
//! `√21/2 < 2.3` at its corners), so level-0 points at graph distance 2 from the patch influence
//! it and those at distance 3 (at least `3√3/2 > 2.5` away) do not. Both closures are checked when the matrices are built
//! (a rule reading an unlisted point is an error), and radius 1 fails.
//!
//! **A** (`N x N`): row `i` is the level-1 layout point `i` in level-0 layout weights, so
//! `phi(x) = phi(3x) A` for `u + v <= 1/3`.
//!
//! **Regular tiles.** A level-`L` triangle `T` (level-`L` coordinates) is regular — the surface
//! on it is `sum_j psi(y - j) p^L_j` over the unfolded lattice — when `V` is outside
//! `T + int S`: the level-`(L+m)` points influencing `T` lie in `T + int S / 3^m`, their parents
//! in `T + int S / 3^(m-1)` (`S/3 + H/3 = S`), so none of them, and none of the half-level
//! points between (the mask is positive), is `V`, the only point with an irregular rule; and a
//! convex region without `V` spans less than 180 degrees, so it develops into sector 0's chart
//! without overlapping itself (the cone has at least 180 degrees). In integers: `2T` does not
//! meet `int H`. [`ConeLocalMatrices::tile_level`] is the smallest `L` for which every level-`L`
//! triangle of `1/3 <= u + v <= 1` passes: `L = 2` (four √3 steps; the level-1 triangle
//! `(1,0), (1,1), (0,1)` doubled meets `int H`), 72 tiles. Each tile's control points, the
//! level-`L` lattice points `j` with `T ∩ (j + int S)` nonempty, are rows of level-0 layout
//! weights after `L` ternary steps of the true rules.
//!
//! **Numbers.** Every matrix is kept in f64 (the weights' f64 values) and, when `alpha_K` is
//! rational (`K = 3, 4, 6`), also exactly as `BigRational`.
//!
//! The cone ball, its order, point names and the separating-axis test are
//! [`crate::cone`]'s, shared with the butterfly.

use crate::cone::layout_ball;
pub use crate::cone::{layout_key, point_name, LAYOUT_RADIUS};
pub use crate::cone_local::{ConeLocalMatrices, RegularTile};
pub use crate::cone_rules::HALF_LEVEL_STEPS;

use crate::triangle_local::TrianglePoint;

/// The layout of valence `valence` in table order (see the module docs): the ball of graph
/// radius [`LAYOUT_RADIUS`] around the patch.
pub fn sqrt3_layout(valence: u32) -> Vec<TrianglePoint> {
    layout_ball(valence, LAYOUT_RADIUS)
}

/// One regular tile of the patch's outer part at level [`ConeLocalMatrices::tile_level`]
/// (the shared type, [`RegularTile`]).
pub type Sqrt3Tile = RegularTile;

/// The local subdivision matrices of √3 around an interior vertex of valence `K`, two √3
/// steps at a time (see the module docs): [`ConeLocalMatrices`] built by √3's rules,
/// dilation 3.
pub type Sqrt3LocalMatrices = ConeLocalMatrices;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cone::{big, interiors_meet};
    use crate::cone_local::{support_scaled, ConeFamily};
    use crate::TriangleScheme;
    use num_rational::{BigRational, Rational64};
    use num_traits::One;
    use num_traits::Zero;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
    }

    #[test]
    fn layout_is_the_radius_two_ball_with_3k_plus_9_points() {
        for k in 3..=8u32 {
            let m = Sqrt3LocalMatrices::new(&sqrt3(), k).expect("builds");
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
        let names = Sqrt3LocalMatrices::new(&sqrt3(), 5)
            .expect("builds")
            .names();
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
            let e = Sqrt3LocalMatrices::with_radius(&sqrt3(), k, 1).expect_err("too small");
            assert!(e.reason.contains("not in the layout"), "{}", e.reason);
        }
    }

    #[test]
    fn hull_is_the_twelve_gon_and_tiles_are_level_two() {
        let m = Sqrt3LocalMatrices::new(&sqrt3(), 5).expect("builds");
        // Two √3 steps of delta_0 reach (5,-1) (a vertex step (3,0) then a half-level step
        // (2,-1)) and (4,1): twelve corners, the turns of these two.
        let mut hull = m.hull.clone();
        hull.sort_unstable();
        let mut expected = vec![
            (5, -1),
            (4, 1),
            (1, 4),
            (-1, 5),
            (-4, 5),
            (-5, 4),
            (-5, 1),
            (-4, -1),
            (-1, -4),
            (1, -5),
            (4, -5),
            (5, -4),
        ];
        expected.sort_unstable();
        assert_eq!(hull, expected);
        assert_eq!(m.tile_level, 2);
        assert_eq!(m.tiles.len(), 72);
        // The level-1 triangle (1,0), (1,1), (0,1) has V in T + int S: level 1 is not regular.
        assert!(interiors_meet(
            &support_scaled(ConeFamily::Sqrt3, &[(1, 0), (1, 1), (0, 1)]),
            &m.hull
        ));
        // Every point of the outer part, on the rate-27 grid, is in a tile.
        for j in 0..=27i64 {
            for i in 0..=27 - j {
                if 3 * (i + j) >= 27 {
                    assert!(m.tile_containing((i, j), 3).is_some(), "({i}, {j})/27");
                }
            }
        }
    }

    #[test]
    fn rows_are_affine() {
        for k in 3..=8u32 {
            let m = Sqrt3LocalMatrices::new(&sqrt3(), k).expect("builds");
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
    fn the_vertex_row_is_two_vertex_rules() {
        // Written from Kobbelt's rules: V' = (1 - a) V + (a/K) sum E_s, the centroids
        // c_s = (V + E_s + E_{s+1})/3 with sum c_s = (K V + 2 sum E)/3, and
        // V'' = (1 - a) V' + (a/K) sum c_s, so V weighs (1 - a)^2 + a/3 and each E_s
        // (1 - a) a / K + 2 a / (3 K); a = (4 - 2 cos(2 pi / K))/9 = 5/9, 4/9, 1/3.
        for k in [3u32, 4, 6] {
            let m = Sqrt3LocalMatrices::new(&sqrt3(), k).expect("builds");
            let a = m.a_exact.as_ref().expect("rational");
            let alpha = match k {
                3 => Rational64::new(5, 9),
                4 => Rational64::new(4, 9),
                _ => Rational64::new(1, 3),
            };
            let one = Rational64::one();
            let kk = Rational64::from_integer(i64::from(k));
            assert_eq!(
                a[0][0],
                big((one - alpha) * (one - alpha) + alpha / 3),
                "K = {k}"
            );
            let e = big((one - alpha) * alpha / kk + alpha * 2 / (kk * 3));
            assert!(a[0][1..=k as usize].iter().all(|w| *w == e), "K = {k}");
            assert!(a[0][k as usize + 1..].iter().all(Zero::is_zero));
        }
    }

    #[test]
    fn mirror_is_an_involution_fixing_v() {
        for k in 3..=8u32 {
            let m = Sqrt3LocalMatrices::new(&sqrt3(), k).expect("builds");
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
        assert!(Sqrt3LocalMatrices::new(&loop_, 5).is_err());
        assert!(Sqrt3LocalMatrices::new(&sqrt3(), 2).is_err());
    }
}
