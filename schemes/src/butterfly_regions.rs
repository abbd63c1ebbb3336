//! Every triangle of one sector whose surface the extraordinary vertex `V` of the modified
//! butterfly affects: the **regions** of a valence-`K` vertex, each with its layout, its regular
//! tiles and their control points as rows of level-0 weights (Schaefer–Warren sections 5.2–5.3
//! on the triangular lattice of section 5.1). Data only: `stencilgen::butterfly_regions`
//! evaluates them.
//!
//! **Why more than the corner.** The butterfly's regular basis function `psi` is supported on
//! the hull `H` of its mask (a 12-gon of hex radius 3, [`crate::butterfly_local`]). A triangle
//! `T` of the mesh is regular — its surface is `sum_j psi(y - j) p_j` over the unfolded lattice
//! — only if no rule used at any level near `T` is the extraordinary one; the points that
//! influence `T` at level `k` lie in `T + int H / 2^k`... at level 0 in `T + int H`. So every
//! triangle with `V` in `T + int H` is irregular at level 0, and at every level some of its
//! sub-triangles are (they shrink towards `V`'s side, see the tile levels below).
//!
//! **Triangles of sector 0** in sector-0 skew coordinates (`a, b >= 0`):
//! `up(a,b)` = corners `(a,b), (a+1,b), (a,b+1)`; `down(a,b)` = `(a+1,b), (a+1,b+1), (a,b+1)`.
//! A region's barycentric frame `(u, v)` puts its first corner at `(0,0)`, the second at
//! `(1,0)`, the third at `(0,1)`: the chart point of `(u, v)` is `c0 + u (c1 - c0) + v (c2 -
//! c0)` ([`RegionTriangle::chart_point`]). Points with `a = 0` are named in the next sector
//! ([`crate::triangle_local::canonical_triangle_point`]).
//!
//! **The regions** are the sector-0 triangles `T` with `V ∈ T + int H`; since `H = -H` that is
//! `T ∩ int H ≠ ∅` (the separating-axis test of the corner's tiles). Nine, whatever `K` (a sector's triangles do not depend
//! on `K`), in this order — band (the ring of the corner nearest `V`), then counter-clockwise
//! from `E_0`'s side:
//!
//! ```text
//!   region  triangle   band  tile level L        the strip b..b+1 of sector 0, left to right
//!   0       up(0,0)    0     3 (outer half;      (a = 0 at the left, up and down alternate):
//!                              A inside)
//!   1       up(1,0)    1     2                   b = 2:  up(0,2)=8
//!   2       down(0,0)  1     2                   b = 1:  up(0,1)=3 down(0,1)=7 up(1,1)=6
//!   3       up(0,1)    1     2                   b = 0:  up(0,0)=0 down(0,0)=2 up(1,0)=1
//!   4       up(2,0)    2     1                           down(1,0)=5 up(2,0)=4
//!   5       down(1,0)  2     1
//!   6       up(1,1)    2     1
//!   7       down(0,1)  2     1
//!   8       up(0,2)    2     1
//! ```
//!
//! Band 1 is the strip between rings 1 and 2 (3 triangles), band 2 the one between rings 2
//! and 3 (5 triangles). Region 0 is the corner `V, E_0, E_1`: exactly
//! the EV patch of [`crate::butterfly_local::ButterflyLocalMatrices`] (same frame, layout
//! [`crate::butterfly_local::butterfly_layout`], `A`).
//! No triangle of band 3 qualifies: `H` meets the line `a + b = 3` only at its vertices
//! `(2,1), (1,2)`, so `int H` stays below it.
//!
//! **Tile level.** A non-corner region `T` is cut into its `4^L` level-`L` triangles, `L` the
//! smallest level at which every one of them is regular (`V ∉ T' + int H`, level-`L` units):
//! `L = 2` for band 1 (`2T` still has the triangles at `(2,0), (1,1), (0,2)` whose interiors
//! meet `H`), `L = 1` for band 2 (`2T` lies in `a + b >= 4`). Each tile's control points are
//! the level-`L` lattice points `j` with `T' ∩ (j + int H)` nonempty, unfolded in sector 0's
//! chart, as rows of level-0 weights after `L` steps of the true rules — the same
//! [`crate::butterfly_local`] machinery as the corner's outer half.
//!
//! **Layouts.** A non-corner region's layout is the closure of what its rows read: every
//! level-0 point reached through nonzero rule weights, ordered like
//! [`crate::butterfly_local::butterfly_layout`] (`V` first if present, then ring `a + b`,
//! sector, `b`: [`crate::cone::layout_key`]). The rows are then built over exactly that
//! layout, so a point the rules read but the layout lacks is an error.
//!
//! Sizes (layout points / level-`L` tile points / tiles), regions 0..=8:
//!
//! ```text
//!   K = 3:  18/93/48  23/57/16  21/57/16  23/57/16  27/36/4  26/36/4  26/36/4  26/36/4  27/36/4
//!   K = 4:  21/93/48  25/57/16  24/57/16  25/57/16  27/36/4 (x5)
//!   K = 5:  24/93/48  26/57/16 (x3)                 27/36/4 (x5)
//!   K = 6:  27/93/48  27/57/16 (x3)                 27/36/4 (x5)
//!   K = 7:  30/93/48  28/57/16 (x3)                 27/36/4 (x5)
//!   K = 8:  33/93/48  29/57/16 (x3)                 27/36/4 (x5)
//! ```
//!
//! Every layout holds `V` (band-2 tiles still read level-1 points whose wings are `V`).
//!
//! **Rotation contract (how the runtime gathers).** The same region in sector `s` of a mesh —
//! the triangle whose corners are those of region `r` rotated by `s` sectors around `V` — is
//! region `r` with every layout point `(a, b)_t` read as `(a, b)_{(t + s) mod K}` and `V` as
//! `V`. The rules are invariant under rotation by a sector, so the weights are the same.
//!
//! **Numbers.** f64 always; exactly (`BigRational`) when every weight is rational
//! (`K = 3, 4, 6`).

pub use crate::cone_regions::{
    region_tile_level, region_triangles, ConeRegion, ConeRegions, RegionShape, RegionTriangle,
};

/// One region of the butterfly: a triangle of sector 0 whose surface `V` affects, with what
/// evaluating it needs (the shared type, [`ConeRegion`]).
pub type ButterflyRegion = ConeRegion;

/// Every region of the modified butterfly around an interior vertex of valence `K`:
/// [`ConeRegions`] built by the butterfly's rules (`ButterflyRegions::new(&butterfly, K)`).
pub type ButterflyRegions = ConeRegions;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::butterfly_local::ButterflyLocalMatrices;
    use crate::cone::{interiors_meet, layout_key};
    use crate::cone_local::ConeFamily;
    use crate::triangle_local::canonical_triangle_point;
    use crate::triangle_local::TrianglePoint;
    use crate::TriangleScheme;
    use num_rational::BigRational;
    use num_traits::One;

    fn butterfly() -> TriangleScheme {
        TriangleScheme::by_name("butterfly").expect("catalogued")
    }

    fn up(a: i64, b: i64) -> RegionTriangle {
        RegionTriangle {
            shape: RegionShape::Up,
            a,
            b,
        }
    }

    fn down(a: i64, b: i64) -> RegionTriangle {
        RegionTriangle {
            shape: RegionShape::Down,
            a,
            b,
        }
    }

    #[test]
    fn the_regions_are_the_nine_documented_triangles() {
        // Expected list by hand from the hull's vertices (docs/algorithms/butterfly.md).
        let expected = vec![
            up(0, 0),
            up(1, 0),
            down(0, 0),
            up(0, 1),
            up(2, 0),
            down(1, 0),
            up(1, 1),
            down(0, 1),
            up(0, 2),
        ];
        let hull = butterfly().regular_mask().hull();
        assert_eq!(region_triangles(ConeFamily::Butterfly, &hull), expected);
        // A brute search over a much larger sector (the centroid-free definition: V in
        // T + int H iff T meets int H, H symmetric) finds exactly these.
        let mut found = Vec::new();
        for b in 0..12 {
            for a in 0..12 {
                for t in [up(a, b), down(a, b)] {
                    if interiors_meet(&t.corners(), &hull) {
                        found.push(t);
                    }
                }
            }
        }
        assert_eq!(found.len(), expected.len());
        assert!(found.iter().all(|t| expected.contains(t)));
        let levels: Vec<Option<u32>> = expected
            .iter()
            .map(|t| region_tile_level(ConeFamily::Butterfly, t, &hull))
            .collect();
        assert_eq!(levels[0], None);
        assert_eq!(&levels[1..4], [Some(2); 3]);
        assert_eq!(&levels[4..], [Some(1); 5]);
    }

    #[test]
    fn sub_triangles_tile_the_region() {
        for t in [up(1, 0), down(0, 0), up(0, 2), down(1, 0)] {
            for level in 1..=3 {
                let subs = t.sub_triangles(level);
                assert_eq!(subs.len(), 1 << (2 * level), "{t:?} level {level}");
            }
        }
    }

    #[test]
    fn region_zero_is_the_ev_patch() {
        for k in 3..=8u32 {
            let r = ButterflyRegions::new(&butterfly(), k).expect("builds");
            let m = ButterflyLocalMatrices::new(&butterfly(), k).expect("builds");
            assert_eq!(r.regions.len(), 9);
            let zero = &r.regions[0];
            assert!(zero.is_corner());
            assert_eq!(zero.triangle.corners(), [(0, 0), (1, 0), (0, 1)]);
            assert_eq!(zero.layout, m.layout);
            assert_eq!(zero.regular_rows, m.regular_rows);
            assert_eq!(zero.tiles, m.tiles);
            assert_eq!(r.corner, m);
        }
    }

    #[test]
    fn layouts_start_with_v_and_are_sorted_and_closed() {
        for k in 3..=8u32 {
            let r = ButterflyRegions::new(&butterfly(), k).expect("builds");
            for (i, region) in r.regions.iter().enumerate() {
                let mut sorted = region.layout.clone();
                sorted.sort_by_key(|&p| layout_key(p));
                sorted.dedup();
                assert_eq!(sorted, region.layout, "K = {k} region {i}");
                // Every layout point is used by some row (the layout is no bigger than the
                // closure), except at the corner, whose layout is the documented ball.
                if i > 0 {
                    for c in 0..region.size() {
                        assert!(
                            region.regular_rows.iter().any(|row| row[c] != 0.0),
                            "K = {k} region {i}: column {c} unused"
                        );
                    }
                }
            }
            // Every region reads V: its level-1 points next to the edges at V are made by the
            // extraordinary rule, or are wings of V (band 2); the corner's layout starts with it.
            for (i, region) in r.regions.iter().enumerate() {
                assert_eq!(region.layout[0], TrianglePoint::Centre, "K = {k} {i}");
            }
        }
    }

    #[test]
    fn rows_sum_to_one() {
        for k in 3..=8u32 {
            let r = ButterflyRegions::new(&butterfly(), k).expect("builds");
            assert_eq!(r.is_rational(), matches!(k, 3 | 4 | 6));
            for region in &r.regions {
                for row in &region.regular_rows {
                    assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-13, "K = {k}");
                }
                if let Some(rows) = &region.regular_rows_exact {
                    for row in rows {
                        assert!(row.iter().sum::<BigRational>().is_one(), "K = {k}");
                    }
                }
            }
        }
    }

    /// The plane position of a point of the 6-valent cone (the lattice itself): sector `s`
    /// is sector 0 turned by `s` sixths, `(a, b) -> (-b, a + b)` per turn.
    fn plane(p: TrianglePoint) -> (i64, i64) {
        match p {
            TrianglePoint::Centre => (0, 0),
            TrianglePoint::Sector { s, a, b } => {
                let (mut x, mut y) = (a, b);
                for _ in 0..s {
                    (x, y) = (-y, x + y);
                }
                (x, y)
            }
        }
    }

    #[test]
    fn valence_six_rows_reproduce_the_plane() {
        let r = ButterflyRegions::new(&butterfly(), 6).expect("builds");
        for (i, region) in r.regions.iter().enumerate() {
            let rows = region
                .regular_rows_exact
                .as_ref()
                .expect("rational at K = 6");
            let scale = 1i64 << region.tile_level;
            for (&(j1, j2), row) in region.regular_points.iter().zip(rows) {
                // Level-L point j sits at j / 2^L; an affine function f(x, y) = 3x - 5y + 7
                // of the level-0 positions must come back exactly.
                let f = |x: BigRational, y: BigRational| {
                    BigRational::from_integer(3.into()) * x
                        - BigRational::from_integer(5.into()) * y
                        + BigRational::from_integer(7.into())
                };
                let got: BigRational = region
                    .layout
                    .iter()
                    .zip(row)
                    .map(|(&p, w)| {
                        let (x, y) = plane(p);
                        w * f(
                            BigRational::from_integer(x.into()),
                            BigRational::from_integer(y.into()),
                        )
                    })
                    .sum();
                let want = f(
                    BigRational::new(j1.into(), scale.into()),
                    BigRational::new(j2.into(), scale.into()),
                );
                assert_eq!(got, want, "region {i} point ({j1}, {j2})");
            }
        }
    }

    #[test]
    fn every_tile_point_is_named_and_tiles_cover_their_region() {
        for k in [3u32, 5] {
            let r = ButterflyRegions::new(&butterfly(), k).expect("builds");
            for region in &r.regions[1..] {
                let m = 1i64 << region.tile_level;
                assert_eq!(region.tiles.len() as i64, m * m);
                for t in &region.tiles {
                    assert!(!t.points.is_empty());
                }
                // Grid points of the region at rate 12 all lie in a tile.
                for j in 0..=12i64 {
                    for i in 0..=12 - j {
                        let c = region.triangle.chart_point(i, j, 12);
                        assert!(
                            region.tile_containing((m * c.0, m * c.1), 12).is_some(),
                            "{:?} ({i}, {j})/12",
                            region.triangle
                        );
                    }
                }
                for &(j1, j2) in &region.regular_points {
                    assert_ne!(
                        canonical_triangle_point(k, 0, j1, j2),
                        TrianglePoint::Centre,
                        "a non-corner tile never needs V at level L >= 1 as a tile point \
                         at ({j1}, {j2})"
                    );
                }
            }
        }
    }

    #[test]
    fn other_schemes_are_errors() {
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        assert!(ButterflyRegions::new(&loop_, 5).is_err());
    }
}
