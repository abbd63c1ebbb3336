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
//! closure of what its rows read, ordered by [`layout_key`] (`V` first, then ring `a + b`,
//! sector, `b`); the rows are built over exactly that layout.
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
//! **Numbers.** f64 always; exactly ([`BigRational`]) when `alpha_K` is rational (`K = 3, 4, 6`).

use num_rational::BigRational;

use crate::butterfly_local::chart_sector;
pub use crate::butterfly_regions::{RegionShape, RegionTriangle};
use crate::cone::{interiors_meet, layout_key, Weight};
use crate::local_matrices::UnsupportedNeighbourhood;
use crate::sqrt3_local::{
    doubled, level0_reads, sqrt3_layout, sqrt3_tile_set, Rows, Sqrt3LocalMatrices, Sqrt3Rules,
    Sqrt3Tile,
};
use crate::triangle_local::TrianglePoint;
use crate::TriangleScheme;

/// The deepest ternary tile level searched (the regions need 1).
const MAX_TILE_LEVEL: u32 = 4;

/// `-H`, counter-clockwise (a point reflection keeps the orientation).
fn minus(hull: &[(i64, i64)]) -> Vec<(i64, i64)> {
    hull.iter().map(|&(a, b)| (-a, -b)).collect()
}

/// The regions of the two-step mask hull `hull` in region order (module docs): the sector-0
/// triangles `T` with `V ∈ T + int S`, `S = H/2`, i.e. `2T ∩ int(-H) ≠ ∅`; region 0 the corner.
pub fn region_triangles(hull: &[(i64, i64)]) -> Vec<RegionTriangle> {
    let minus = minus(hull);
    let reach = hull
        .iter()
        .map(|&(a, b)| a.abs().max(b.abs()).max((a + b).abs()))
        .max()
        .unwrap_or(0)
        / 2
        + 1;
    let mut out = Vec::new();
    for b in 0..=reach {
        for a in 0..=reach {
            for shape in [RegionShape::Up, RegionShape::Down] {
                let t = RegionTriangle { shape, a, b };
                if interiors_meet(&doubled(&t.corners()), &minus) {
                    out.push(t);
                }
            }
        }
    }
    out.sort_by_key(|t| (t.band(), 2 * t.b + i64::from(t.shape == RegionShape::Down)));
    out
}

/// The smallest ternary level `L >= 1` at which every level-`L` sub-triangle `T'` of
/// `triangle` keeps `V` outside `T' + int S` (`2T' ∩ int(-H)` empty); `None` when `V` is a
/// corner or no level up to 4 does.
pub fn region_tile_level(triangle: &RegionTriangle, hull: &[(i64, i64)]) -> Option<u32> {
    if triangle.corners().contains(&(0, 0)) {
        return None;
    }
    let minus = minus(hull);
    (1..=MAX_TILE_LEVEL).find(|&level| {
        triangle
            .sub_triangles_scaled(3i64.pow(level))
            .iter()
            .all(|t| !interiors_meet(&doubled(t), &minus))
    })
}

/// One region of √3: a triangle of sector 0 whose surface `V` affects, with what evaluating it
/// needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Region {
    /// The triangle, which fixes the barycentric frame ([`RegionTriangle::corners`]).
    pub triangle: RegionTriangle,
    /// The level-0 control points, [`layout_key`] order. Region 0: `sqrt3_layout`.
    pub layout: Vec<TrianglePoint>,
    /// The tiles' ternary level `L` (region 0: the corner's outer-part level, 2).
    pub tile_level: u32,
    /// The regular level-`L` tiles, corners in level-`L` sector-0 chart coordinates. They cover
    /// the whole triangle, except for region 0, where they cover `1/3 <= u + v <= 1` and
    /// `phi(x) = phi(3x) A` holds inside.
    pub tiles: Vec<Sqrt3Tile>,
    /// Every level-`L` lattice point a tile needs, sector-0 chart.
    pub regular_points: Vec<(i64, i64)>,
    /// Per `regular_points`, its level-0 weights over `layout`, f64.
    pub regular_rows: Vec<Vec<f64>>,
    /// The same exactly, when every weight is rational (`K = 3, 4, 6`).
    pub regular_rows_exact: Option<Vec<Vec<BigRational>>>,
}

impl Sqrt3Region {
    /// The number of control points.
    pub fn size(&self) -> usize {
        self.layout.len()
    }

    /// Whether this is the corner region (`V` a corner; `A` needed inside `u + v <= 1/3`).
    pub fn is_corner(&self) -> bool {
        self.triangle.band() == 0
    }

    /// The first tile holding the chart point `(y_1/d, y_2/d)` (level-`L` coordinates).
    pub fn tile_containing(&self, y: (i64, i64), d: i64) -> Option<usize> {
        self.tiles.iter().position(|t| t.contains(y, d))
    }
}

/// Every region of √3 around an interior vertex of valence `K`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Regions {
    /// The scheme's name.
    pub scheme: String,
    /// The valence `K`.
    pub valence: u32,
    /// The two-step mask's hull `H` (`psi` is supported on `H/2`).
    pub hull: Vec<(i64, i64)>,
    /// The corner's local matrices (`A`, its outer part's tiles): region 0.
    pub corner: Sqrt3LocalMatrices,
    /// The regions in region order; `regions[0]` is the corner.
    pub regions: Vec<Sqrt3Region>,
}

impl Sqrt3Regions {
    /// Build every region of √3 (`sqrt3`) at valence `valence >= 3`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, UnsupportedNeighbourhood> {
        let corner = Sqrt3LocalMatrices::new(scheme, valence)?;
        let unsupported = |reason: String| UnsupportedNeighbourhood {
            scheme: scheme.name.to_owned(),
            reason: format!("sqrt3 regions at valence {valence}: {reason}"),
        };
        let hull = corner.hull.clone();
        let triangles = region_triangles(&hull);
        if triangles.first().map(|t| t.band()) != Some(0) {
            return Err(unsupported(
                "the corner triangle is not a region".to_owned(),
            ));
        }
        let rules = Sqrt3Rules::<f64>::new(valence)
            .ok_or_else(|| unsupported("f64 weights always exist".to_owned()))?;
        let exact_rules = Sqrt3Rules::<BigRational>::new(valence);
        let mut regions = vec![Sqrt3Region {
            triangle: triangles[0],
            layout: sqrt3_layout(valence),
            tile_level: corner.tile_level,
            tiles: corner.tiles.clone(),
            regular_points: corner.regular_points.clone(),
            regular_rows: corner.regular_rows.clone(),
            regular_rows_exact: corner.regular_rows_exact.clone(),
        }];
        for &triangle in &triangles[1..] {
            let level = region_tile_level(&triangle, &hull)
                .ok_or_else(|| unsupported(format!("{triangle:?} has no regular level")))?;
            let (regular_points, tiles) =
                sqrt3_tile_set(&hull, triangle.sub_triangles_scaled(3i64.pow(level)));
            // The unfolding argument (module docs), checked: no tile point near the chart's cut.
            if let Some(&(j1, j2)) = regular_points
                .iter()
                .find(|&&(j1, j2)| (j1, j2) != (0, 0) && !(-1..=2).contains(&chart_sector(j1, j2)))
            {
                return Err(unsupported(format!(
                    "{triangle:?}: the level-{level} tile point ({j1}, {j2}) lies past chart \
                     sector 2"
                )));
            }
            let mut layout: Vec<TrianglePoint> = level0_reads(&rules, level, &regular_points)
                .map_err(&unsupported)?
                .into_iter()
                .collect();
            layout.sort_by_key(|&p| layout_key(p));
            let regular_rows =
                region_rows(&rules, &layout, level, &regular_points).map_err(&unsupported)?;
            let regular_rows_exact = match &exact_rules {
                Some(r) => {
                    Some(region_rows(r, &layout, level, &regular_points).map_err(&unsupported)?)
                }
                None => None,
            };
            regions.push(Sqrt3Region {
                triangle,
                layout,
                tile_level: level,
                tiles,
                regular_points,
                regular_rows,
                regular_rows_exact,
            });
        }
        Ok(Sqrt3Regions {
            scheme: scheme.name.to_owned(),
            valence,
            hull,
            corner,
            regions,
        })
    }

    /// Whether every weight is rational (every region has exact rows).
    pub fn is_rational(&self) -> bool {
        self.corner.is_rational()
    }
}

/// The level-`level` chart points `points` in level-0 weights over `layout` (an unlisted
/// level-0 point is an error).
fn region_rows<T: Weight>(
    rules: &Sqrt3Rules<T>,
    layout: &[TrianglePoint],
    level: u32,
    points: &[(i64, i64)],
) -> Result<Vec<Vec<T>>, String> {
    Rows::new(rules, layout, level).chart_rows(level, points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle::{apply_map, lattice_symmetries};
    use crate::triangle_local::canonical_triangle_point;
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
        assert_eq!(region_triangles(&hull), expected);
        // Brute force over a larger sector: T meets int S iff 2T meets int H (H = -H here).
        let mut found = 0;
        for b in 0..12 {
            for a in 0..12 {
                for t in [up(a, b), down(a, b)] {
                    if interiors_meet(&doubled(&t.corners()), &hull) {
                        assert!(expected.contains(&t), "{t:?}");
                        found += 1;
                    }
                }
            }
        }
        assert_eq!(found, expected.len());
        let levels: Vec<Option<u32>> = expected
            .iter()
            .map(|t| region_tile_level(t, &hull))
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
