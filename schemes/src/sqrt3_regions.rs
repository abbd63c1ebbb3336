//! Every triangle of one sector whose surface the extraordinary vertex `V` of √3 affects: the
//! **regions** of a valence-`K` vertex, each with its layout, its regular tiles and their control
//! points as rows of level-0 weights (Schaefer–Warren sections 5.1–5.3, two √3 steps as one
//! ternary step, [`crate::sqrt3_local`]). Data only: `stencilgen::sqrt3_regions` evaluates them.
//! The structure is the butterfly's ([`crate::butterfly_regions`]), with ternary levels.
//!
//! **Why more than the corner.** √3's regular basis `psi` (two steps) is supported on
//! `S = H/2`, `H` the 12-gon hull of the two-step mask (corners `(5,-1), (4,1)` and their turns),
//! which reaches hex norm 2.5: wider than one ring. A triangle `T` is regular at level 0 only if
//! `V ∉ T + int S`, so every sector-0 triangle with `V ∈ T + int S` needs its own stencils.
//!
//! **Triangles and frames** are [`RegionTriangle`]'s (the butterfly's type, reused): `up(a,b)`
//! = `(a,b), (a+1,b), (a,b+1)`, `down(a,b)` = `(a+1,b), (a+1,b+1), (a,b+1)`, `(u, v)` from the
//! first corner along `c1 - c0` and `c2 - c0`.
//!
//! **The regions** are the sector-0 triangles with `V ∈ T + int S`, i.e. (`S = -S`)
//! `2T ∩ int H ≠ ∅`. Nine, the butterfly's nine, in the same order (band, then
//! counter-clockwise; [`region_triangles`]):
//!
//! ```text
//!   region  triangle   band  tile level L (ternary)
//!   0       up(0,0)    0     2 (outer part 1/3 <= u + v <= 1; A inside)
//!   1       up(1,0)    1     1
//!   2       down(0,0)  1     1
//!   3       up(0,1)    1     1
//!   4       up(2,0)    2     1
//!   5       down(1,0)  2     1
//!   6       up(1,1)    2     1
//!   7       down(0,1)  2     1
//!   8       up(0,2)    2     1
//! ```
//!
//! Band 2 qualifies because `S` holds `(2,0)` and `(1,1)` in its interior (`(2.25, 0)` and
//! `a + b = 2.5` are on its boundary); band 3 does not (hex norm 3 > 2.5).
//!
//! **Tile level.** A non-corner region is cut into its `9^L` level-`L` triangles, `L` the
//! smallest ternary level at which every one keeps `V` outside `T' + int S` (level-`L` units):
//! `L = 1` for every band (a band-1 triangle scaled by 3 has hex norm at least 3). Each tile's
//! control points are the level-`L` lattice points `j` with `T' ∩ (j + int S)` nonempty,
//! unfolded in sector 0's chart (`T' + S` is convex without `V`, so spans less than 180
//! degrees, and it stays within chart sectors `-1..=2`: checked), as rows of level-0 weights
//! after `L` ternary steps of the true rules — [`crate::sqrt3_local`]'s row machinery.
//!
//! **Layouts.** Region 0's is [`crate::sqrt3_local::sqrt3_layout`]. Every other region's is the
//! closure of what its rows read, ordered by [`crate::cone::layout_key`] (`V` first, then
//! ring `a + b`, sector, `b`); the rows are built over exactly that layout.
//!
//! Sizes (layout points / level-`L` tile points / tiles), regions 0..=8 (unit test
//! `documented_sizes`):
//!
//! ```text
//!   K = 3:  18/115/72  23/46/9  21/46/9  23/46/9  27/46/9  26/46/9  26/46/9  26/46/9  27/46/9
//!   K = 4:  21/115/72  25/46/9  24/46/9  25/46/9  27/46/9 (x5)
//!   K = 5:  24/115/72  26/46/9 (x3)                27/46/9 (x5)
//!   K = 6:  27/115/72  27/46/9 (x3)                27/46/9 (x5)
//!   K = 7:  30/115/72  28/46/9 (x3)                27/46/9 (x5)
//!   K = 8:  33/115/72  29/46/9 (x3)                27/46/9 (x5)
//! ```
//!
//! Every layout holds `V`: a level-1 point next to `V` is a centroid of a half-level triangle
//! at `V` (band 1), or reads the half-level neighbours that `V`'s rule moved (band 2).
//!
//! **Rotation contract.** As the butterfly's: region `r` in sector `s` reads layout point
//! `(a, b)_t` as `(a, b)_{(t + s) mod K}` and `V` as `V`.
//!
//! **Numbers.** f64 always; exactly (`BigRational`) when `alpha_K` is rational (`K = 3, 4, 6`).

pub use crate::cone_regions::{
    region_tile_level, region_triangles, ConeRegion, ConeRegions, RegionShape, RegionTriangle,
};

/// One region of √3: a triangle of sector 0 whose surface `V` affects, with what evaluating it
/// needs (the shared type, [`ConeRegion`]).
pub type Sqrt3Region = ConeRegion;

/// Every region of √3 around an interior vertex of valence `K`: [`ConeRegions`] built by √3's
/// rules (`Sqrt3Regions::new(&sqrt3, K)`).
pub type Sqrt3Regions = ConeRegions;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cone::{interiors_meet, layout_key};
    use crate::cone_local::{support_scaled, ConeFamily};
    use crate::sqrt3_local::Sqrt3LocalMatrices;
    use crate::triangle::{apply_map, lattice_symmetries};
    use crate::triangle_local::canonical_triangle_point;
    use crate::triangle_local::TrianglePoint;
    use crate::TriangleScheme;
    use num_rational::BigRational;
    use num_traits::One;

    fn sqrt3() -> TriangleScheme {
        TriangleScheme::by_name("sqrt3").expect("catalogued")
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
        // By hand from S = H/2 (hex norm 2.5, module docs): bands 0, 1, 2 entirely.
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
        let hull = sqrt3().regular_mask().hull();
        assert_eq!(region_triangles(ConeFamily::Sqrt3, &hull), expected);
        // Brute force over a larger sector: T meets int S iff 2T meets int H (H = -H here).
        let mut found = 0;
        for b in 0..12 {
            for a in 0..12 {
                for t in [up(a, b), down(a, b)] {
                    if interiors_meet(&support_scaled(ConeFamily::Sqrt3, &t.corners()), &hull) {
                        assert!(expected.contains(&t), "{t:?}");
                        found += 1;
                    }
                }
            }
        }
        assert_eq!(found, expected.len());
        let levels: Vec<Option<u32>> = expected
            .iter()
            .map(|t| region_tile_level(ConeFamily::Sqrt3, t, &hull))
            .collect();
        assert_eq!(levels[0], None);
        assert_eq!(&levels[1..], [Some(1); 8]);
    }

    #[test]
    fn region_zero_is_the_ev_patch() {
        for k in 3..=8u32 {
            let r = Sqrt3Regions::new(&sqrt3(), k).expect("builds");
            let m = Sqrt3LocalMatrices::new(&sqrt3(), k).expect("builds");
            assert_eq!(r.regions.len(), 9);
            let zero = &r.regions[0];
            assert!(zero.is_corner());
            assert_eq!(zero.layout, m.layout);
            assert_eq!(zero.regular_rows, m.regular_rows);
            assert_eq!(zero.tiles, m.tiles);
            assert_eq!(r.corner, m);
        }
    }

    #[test]
    fn layouts_are_sorted_closed_and_rows_sum_to_one() {
        for k in 3..=8u32 {
            let r = Sqrt3Regions::new(&sqrt3(), k).expect("builds");
            assert_eq!(r.is_rational(), matches!(k, 3 | 4 | 6));
            for (i, region) in r.regions.iter().enumerate() {
                let mut sorted = region.layout.clone();
                sorted.sort_by_key(|&p| layout_key(p));
                sorted.dedup();
                assert_eq!(sorted, region.layout, "K = {k} region {i}");
                assert_eq!(
                    region.layout[0],
                    TrianglePoint::Centre,
                    "K = {k} region {i}"
                );
                if i > 0 {
                    for c in 0..region.size() {
                        assert!(
                            region.regular_rows.iter().any(|row| row[c] != 0.0),
                            "K = {k} region {i}: column {c} unused"
                        );
                    }
                }
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

    #[test]
    fn tiles_cover_their_regions_and_never_need_v() {
        for k in [3u32, 5] {
            let r = Sqrt3Regions::new(&sqrt3(), k).expect("builds");
            for region in &r.regions[1..] {
                let m = 3i64.pow(region.tile_level);
                assert_eq!(region.tiles.len() as i64, m * m);
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
                        TrianglePoint::Centre
                    );
                }
            }
        }
    }

    #[test]
    fn valence_six_rows_reproduce_the_plane() {
        // An affine function of the level-0 positions comes back exactly at every level-L point
        // (√3 reproduces linear functions); positions: sector s is sector 0 turned s sixths.
        let r = Sqrt3Regions::new(&sqrt3(), 6).expect("builds");
        let plane = |p: TrianglePoint| match p {
            TrianglePoint::Centre => (0, 0),
            TrianglePoint::Sector { s, a, b } => {
                apply_map(lattice_symmetries()[s as usize], (a, b))
            }
        };
        let q = |x: i64, d: i64| BigRational::new(x.into(), d.into());
        for (i, region) in r.regions.iter().enumerate() {
            let rows = region.regular_rows_exact.as_ref().expect("rational");
            let scale = 3i64.pow(region.tile_level);
            for (&(j1, j2), row) in region.regular_points.iter().zip(rows) {
                let f = |x: BigRational, y: BigRational| q(3, 1) * x - q(5, 1) * y + q(7, 1);
                let got: BigRational = region
                    .layout
                    .iter()
                    .zip(row)
                    .map(|(&p, w)| {
                        let (x, y) = plane(p);
                        w * f(q(x, 1), q(y, 1))
                    })
                    .sum();
                assert_eq!(
                    got,
                    f(q(j1, scale), q(j2, scale)),
                    "region {i} ({j1}, {j2})"
                );
            }
        }
    }

    #[test]
    fn documented_sizes() {
        // docs/algorithms/sqrt3.md's table: layout points per region at K = 3..=8.
        let mut lines = Vec::new();
        for k in 3..=8u32 {
            let r = Sqrt3Regions::new(&sqrt3(), k).expect("builds");
            let sizes: Vec<String> = r
                .regions
                .iter()
                .map(|g| format!("{}/{}/{}", g.size(), g.regular_points.len(), g.tiles.len()))
                .collect();
            lines.push(format!("K = {k}: {}", sizes.join(" ")));
        }
        // Pins the table in the module docs and docs/algorithms/sqrt3.md (a change of layout
        // or tiles must update both).
        let expected = [
            "K = 3: 18/115/72 23/46/9 21/46/9 23/46/9 27/46/9 26/46/9 26/46/9 26/46/9 27/46/9",
            "K = 4: 21/115/72 25/46/9 24/46/9 25/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9",
            "K = 5: 24/115/72 26/46/9 26/46/9 26/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9",
            "K = 6: 27/115/72 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9",
            "K = 7: 30/115/72 28/46/9 28/46/9 28/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9",
            "K = 8: 33/115/72 29/46/9 29/46/9 29/46/9 27/46/9 27/46/9 27/46/9 27/46/9 27/46/9",
        ];
        assert_eq!(lines, expected);
    }

    #[test]
    fn other_schemes_are_errors() {
        let loop_ = TriangleScheme::by_name("loop").expect("catalogued");
        assert!(Sqrt3Regions::new(&loop_, 5).is_err());
    }
}
