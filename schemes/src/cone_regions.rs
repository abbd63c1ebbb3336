//! Every triangle of one sector whose surface the extraordinary vertex `V` affects — the
//! **regions** of a valence-`K` vertex — for the schemes of [`crate::cone_local`] (the
//! butterfly, √3), each with its layout, its regular tiles and their control points as rows of
//! level-0 weights (Schaefer–Warren sections 5.1–5.3). Data only: `stencilgen` evaluates them.
//! The numbers of each scheme (tile levels, sizes) are in [`crate::butterfly_regions`] and
//! [`crate::sqrt3_regions`].
//!
//! **Why more than the corner.** The regular basis `psi` is supported on `S = H/(λ - 1)`
//! ([`crate::cone_local`]). A triangle `T` is regular at level 0 only if `V ∉ T + int S`, so
//! every sector-0 triangle with `V ∈ T + int S` — `(λ-1)T ∩ int(-H) ≠ ∅` — is a region and needs
//! its own stencils; region 0 is the corner `V, E_0, E_1`, the EV patch of
//! [`ConeLocalMatrices`].
//!
//! **Triangles of sector 0** in sector-0 skew coordinates (`a, b >= 0`):
//! `up(a,b)` = corners `(a,b), (a+1,b), (a,b+1)`; `down(a,b)` = `(a+1,b), (a+1,b+1), (a,b+1)`.
//! A region's barycentric frame `(u, v)` puts its first corner at `(0,0)`, the second at
//! `(1,0)`, the third at `(0,1)`: the chart point of `(u, v)` is `c0 + u (c1 - c0) + v (c2 -
//! c0)` ([`RegionTriangle::chart_point`]). Regions are ordered by band (the ring of the corner
//! nearest `V`), then counter-clockwise from `E_0`'s side ([`region_triangles`]).
//!
//! **Tile level.** A non-corner region is cut into its `λ^2L` level-`L` triangles, `L` the
//! smallest level at which every one keeps `V` outside `T' + int S` (level-`L` units). Each
//! tile's control points are the level-`L` lattice points `j` with `T' ∩ (j + int S)` nonempty,
//! unfolded in sector 0's chart (checked to stay within chart sectors `-1..=2`), as rows of
//! level-0 weights after `L` steps of the true rules — [`crate::cone_local`]'s row machinery.
//!
//! **Layouts.** Region 0's is the corner's cone ball. Every other region's is the closure of
//! what its rows read (nonzero rule weights only), ordered by [`layout_key`] (`V` first if
//! present, then ring `a + b`, sector, `b`); the rows are built over exactly that layout, so a
//! point the rules read but the layout lacks is an error.
//!
//! **Rotation contract (how the runtime gathers).** The same region in sector `s` of a mesh —
//! the triangle whose corners are those of region `r` rotated by `s` sectors around `V` — is
//! region `r` with every layout point `(a, b)_t` read as `(a, b)_{(t + s) mod K}` and `V` as
//! `V`. The rules are invariant under rotation by a sector, so the weights are the same.
//!
//! **Numbers.** f64 always; exactly ([`BigRational`]) when every weight is rational
//! (`K = 3, 4, 6`).

use num_rational::BigRational;

use crate::cone::{chart_sector, interiors_meet, layout_key, Weight};
use crate::cone_local::{
    level0_reads, support_scaled, tile_set, ConeFamily, ConeLocalMatrices, RegularTile, RowMemo,
    TileSet,
};
use crate::cone_rules::ConeRules;
use crate::local_matrices::UnsupportedNeighbourhood;
use crate::triangle_local::TrianglePoint;
use crate::TriangleScheme;

/// The finest sub-triangle scale `λ^L` the tile-level search tries (the regions need 4 for the
/// butterfly, 3 for √3).
const MAX_TILE_SCALE: i64 = 256;

/// The two orientations of a triangle of the skew lattice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RegionShape {
    /// `(a,b), (a+1,b), (a,b+1)`.
    Up,
    /// `(a+1,b), (a+1,b+1), (a,b+1)`.
    Down,
}

/// A triangle of sector 0 by shape and lower-left cell `(a, b)`, `a, b >= 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RegionTriangle {
    /// Up or down.
    pub shape: RegionShape,
    /// The cell's first skew coordinate.
    pub a: i64,
    /// The cell's second skew coordinate.
    pub b: i64,
}

impl RegionTriangle {
    /// The corners in frame order: `c0` at `(u,v) = (0,0)`, `c1` at `(1,0)`, `c2` at `(0,1)`
    /// (counter-clockwise), sector-0 chart coordinates.
    pub fn corners(&self) -> [(i64, i64); 3] {
        let (a, b) = (self.a, self.b);
        match self.shape {
            RegionShape::Up => [(a, b), (a + 1, b), (a, b + 1)],
            RegionShape::Down => [(a + 1, b), (a + 1, b + 1), (a, b + 1)],
        }
    }

    /// The chart vectors `c1 - c0` (the direction of `d/du`) and `c2 - c0` (`d/dv`).
    pub fn axes(&self) -> [(i64, i64); 2] {
        let [c0, c1, c2] = self.corners();
        [(c1.0 - c0.0, c1.1 - c0.1), (c2.0 - c0.0, c2.1 - c0.1)]
    }

    /// The numerators over `d` of the chart point `c0 + u (c1 - c0) + v (c2 - c0)` at
    /// `(u, v) = (i/d, j/d)`.
    pub fn chart_point(&self, i: i64, j: i64, d: i64) -> (i64, i64) {
        let [c0, _, _] = self.corners();
        let [e1, e2] = self.axes();
        (
            d * c0.0 + i * e1.0 + j * e2.0,
            d * c0.1 + i * e1.1 + j * e2.1,
        )
    }

    /// The band: the ring `a + b` of the corner nearest `V` (0 for the corner triangle).
    pub fn band(&self) -> i64 {
        match self.shape {
            RegionShape::Up => self.a + self.b,
            RegionShape::Down => self.a + self.b + 1,
        }
    }

    /// The level-`level` triangles covering this one, corners in level-`level` chart
    /// coordinates: up triangles (by `b`, then `a`), then down triangles (same order).
    pub fn sub_triangles(&self, level: u32) -> Vec<[(i64, i64); 3]> {
        self.sub_triangles_scaled(1i64 << level)
    }

    /// The triangles of the lattice scaled by `1/m` covering this one (`m = λ^L` for a level
    /// `L` of dilation `λ`: `2^L` for the butterfly, `3^L` for √3), corners in those units, in
    /// [`Self::sub_triangles`] order.
    pub fn sub_triangles_scaled(&self, m: i64) -> Vec<[(i64, i64); 3]> {
        let big = self.corners().map(|(x, y)| (m * x, m * y));
        let inside = |p: (i64, i64), three: i64| {
            // The centroid `p / 3` is inside `big` (strictly: tiles do not overlap).
            (0..3).all(|e| {
                let (s, t) = (big[e], big[(e + 1) % 3]);
                (t.0 - s.0) * (p.1 - three * s.1) - (t.1 - s.1) * (p.0 - three * s.0) > 0
            })
        };
        let lo = (
            big.iter().map(|c| c.0).min().unwrap_or(0),
            big.iter().map(|c| c.1).min().unwrap_or(0),
        );
        let hi = (
            big.iter().map(|c| c.0).max().unwrap_or(0),
            big.iter().map(|c| c.1).max().unwrap_or(0),
        );
        let mut up = Vec::new();
        let mut down = Vec::new();
        for y in lo.1..hi.1 {
            for x in lo.0..hi.0 {
                if inside((3 * x + 1, 3 * y + 1), 3) {
                    up.push([(x, y), (x + 1, y), (x, y + 1)]);
                }
                if inside((3 * x + 2, 3 * y + 2), 3) {
                    down.push([(x + 1, y), (x + 1, y + 1), (x, y + 1)]);
                }
            }
        }
        up.extend(down);
        up
    }
}

/// `-H`, counter-clockwise (a point reflection keeps the orientation).
fn minus(hull: &[(i64, i64)]) -> Vec<(i64, i64)> {
    hull.iter().map(|&(a, b)| (-a, -b)).collect()
}

/// The regions of `family` with mask hull `hull`, in region order (module docs): the sector-0
/// triangles `T` with `V ∈ T + int S`, `S = H/(λ - 1)`, i.e. `(λ-1)T ∩ int(-H) ≠ ∅`; region 0
/// the corner `up(0,0)`.
pub fn region_triangles(family: ConeFamily, hull: &[(i64, i64)]) -> Vec<RegionTriangle> {
    let minus = minus(hull);
    let reach = hull
        .iter()
        .map(|&(a, b)| a.abs().max(b.abs()).max((a + b).abs()))
        .max()
        .unwrap_or(0)
        / (i64::from(family.dilation()) - 1)
        + 1;
    let mut out = Vec::new();
    for b in 0..=reach {
        for a in 0..=reach {
            for shape in [RegionShape::Up, RegionShape::Down] {
                let t = RegionTriangle { shape, a, b };
                if interiors_meet(&support_scaled(family, &t.corners()), &minus) {
                    out.push(t);
                }
            }
        }
    }
    // Band, then counter-clockwise: along a band, up(a,b) sits at 2b and down(a,b) at 2b + 1.
    out.sort_by_key(|t| (t.band(), 2 * t.b + i64::from(t.shape == RegionShape::Down)));
    out
}

/// The smallest level `L >= 1` at which every level-`L` sub-triangle `T'` of `triangle` keeps
/// `V` outside `T' + int S` (`(λ-1)T' ∩ int(-H)` empty); `None` when `V` is a corner (the
/// sub-triangle at `V` always meets `int S`) or no level with `λ^L <= 256` does.
pub fn region_tile_level(
    family: ConeFamily,
    triangle: &RegionTriangle,
    hull: &[(i64, i64)],
) -> Option<u32> {
    if triangle.corners().contains(&(0, 0)) {
        return None;
    }
    let minus = minus(hull);
    (1..)
        .take_while(|&level| family.scale(level) <= MAX_TILE_SCALE)
        .find(|&level| {
            triangle
                .sub_triangles_scaled(family.scale(level))
                .iter()
                .all(|t| !interiors_meet(&support_scaled(family, t), &minus))
        })
}

/// One region: a triangle of sector 0 whose surface `V` affects, with what evaluating it needs.
#[derive(Clone, Debug, PartialEq)]
pub struct ConeRegion {
    /// The triangle, which fixes the barycentric frame ([`RegionTriangle::corners`]).
    pub triangle: RegionTriangle,
    /// The level-0 control points, [`layout_key`] order. Region 0: the corner's cone ball.
    pub layout: Vec<TrianglePoint>,
    /// The tiles' level `L` (region 0: the corner's outer-part level).
    pub tile_level: u32,
    /// The regular level-`L` tiles, corners in level-`L` sector-0 chart coordinates. They cover
    /// the whole triangle, except for region 0, where they cover its outer part
    /// `1/λ <= u + v <= 1` and `phi(x) = phi(λx) A` holds inside.
    pub tiles: Vec<RegularTile>,
    /// Every level-`L` lattice point a tile needs, sector-0 chart.
    pub regular_points: Vec<(i64, i64)>,
    /// Per `regular_points`, its level-0 weights over `layout`, f64.
    pub regular_rows: Vec<Vec<f64>>,
    /// The same exactly, when every weight is rational (`K = 3, 4, 6`).
    pub regular_rows_exact: Option<Vec<Vec<BigRational>>>,
}

impl ConeRegion {
    /// The number of control points.
    pub fn size(&self) -> usize {
        self.layout.len()
    }

    /// Whether this is the corner region (`V` a corner; `A` needed inside `u + v <= 1/λ`).
    pub fn is_corner(&self) -> bool {
        self.triangle.band() == 0
    }

    /// The first tile holding the chart point `(y_1/d, y_2/d)` (level-`L` coordinates).
    pub fn tile_containing(&self, y: (i64, i64), d: i64) -> Option<usize> {
        self.tiles.iter().position(|t| t.contains(y, d))
    }
}

/// Every region of the butterfly or √3 around an interior vertex of valence `K`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConeRegions {
    /// The scheme's name.
    pub scheme: String,
    /// The valence `K`.
    pub valence: u32,
    /// The regular mask's hull `H` (`psi` is supported on `H/(λ - 1)`).
    pub hull: Vec<(i64, i64)>,
    /// The corner's local matrices (`A`, its outer part's tiles): region 0.
    pub corner: ConeLocalMatrices,
    /// The regions in region order; `regions[0]` is the corner.
    pub regions: Vec<ConeRegion>,
}

impl ConeRegions {
    /// Build every region of the modified butterfly (`butterfly`) or √3 (`sqrt3`) at valence
    /// `valence >= 3`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, UnsupportedNeighbourhood> {
        let corner = ConeLocalMatrices::new(scheme, valence)?;
        let family = corner.family;
        let unsupported = |reason: String| UnsupportedNeighbourhood {
            scheme: scheme.name.to_owned(),
            reason: format!("{} regions at valence {valence}: {reason}", scheme.name),
        };
        let hull = corner.hull.clone();
        let triangles = region_triangles(family, &hull);
        if triangles.first().map(|t| t.band()) != Some(0) {
            return Err(unsupported(
                "the corner triangle is not a region".to_owned(),
            ));
        }
        let rules = ConeRules::<f64>::new(family, scheme, valence)
            .ok_or_else(|| unsupported("the scheme is not a dyadic butterfly".to_owned()))?;
        let exact_rules = ConeRules::<BigRational>::new(family, scheme, valence);
        let mut regions = vec![ConeRegion {
            triangle: triangles[0],
            layout: corner.layout.clone(),
            tile_level: corner.tile_level,
            tiles: corner.tiles.clone(),
            regular_points: corner.regular_points.clone(),
            regular_rows: corner.regular_rows.clone(),
            regular_rows_exact: corner.regular_rows_exact.clone(),
        }];
        for &triangle in &triangles[1..] {
            let level = region_tile_level(family, &triangle, &hull)
                .ok_or_else(|| unsupported(format!("{triangle:?} has no regular level")))?;
            let TileSet {
                regular_points,
                tiles,
            } = tile_set(
                family,
                &hull,
                triangle.sub_triangles_scaled(family.scale(level)),
            );
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
            regions.push(ConeRegion {
                triangle,
                layout,
                tile_level: level,
                tiles,
                regular_points,
                regular_rows,
                regular_rows_exact,
            });
        }
        Ok(ConeRegions {
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
    rules: &ConeRules<T>,
    layout: &[TrianglePoint],
    level: u32,
    points: &[(i64, i64)],
) -> Result<Vec<Vec<T>>, String> {
    RowMemo::new(rules, layout, level).chart_rows(level, points)
}
