//! The local subdivision matrices around an interior extraordinary vertex of valence `K` that
//! the modified butterfly ([`crate::butterfly_local`]) and √3 ([`crate::sqrt3_local`]) share:
//! the patch layout, the local subdivision matrix `A` and the regular tiles of the patch's
//! outer part with their control points as rows of level-0 weights (Schaefer–Warren sections
//! 5.1–5.3). Data only: `stencilgen` solves with them.
//!
//! The two schemes differ in their rules and in the **dilation** `λ` of one step: `λ = 2` for
//! the butterfly (one dyadic step), `λ = 3` for √3 (two √3 steps, one ternary step aligned
//! with the original lattice). Everything else follows from `λ`:
//!
//! * the scaling relation `phi(x) = phi(λx) A` covers `u + v <= 1/λ`;
//! * the regular basis `psi` is supported on the fixed set of `S = (S + H)/λ`, `H` the hull of
//!   the regular mask's indices, i.e. `S = H/(λ - 1)` (`H` for the butterfly, `H/2` for √3);
//! * a level-`L` triangle `T` (level-`L` coordinates, `λ^L` per level-0 unit) of the outer part
//!   `1/λ <= u + v <= 1` is **regular** — the surface on it is `sum_j psi(y - j) p^L_j` over the
//!   unfolded lattice — when `V` is outside `T + int S`: the points influencing `T` at deeper
//!   levels then stay in `T + int S` (their parents lie in `c + H/λ`), so no rule there reads `V`.
//!   In integers: `(λ - 1) T` does not meet `int H`. The tile level `L` is the smallest for which
//!   every level-`L` triangle of the outer part passes (butterfly `L = 3`, 48 tiles; √3 `L = 2`,
//!   72 tiles), and each tile's control points are the level-`L` lattice points `j` with
//!   `T ∩ (j + int S)` nonempty, rows of level-0 layout weights after `L` steps of the true
//!   rules.
//!
//! The rows are built by one memoized implementation (`RowMemo`) over the scheme's rules
//! (`ConeRules`, kept with the family enum [`ConeFamily`]); reading a level-0 point outside
//! the layout is an error, which is how every
//! layout is checked. Every matrix is kept in f64 and, when every weight is rational
//! (`K = 3, 4, 6` for both schemes), also exactly as [`BigRational`].

use std::collections::{BTreeMap, BTreeSet, HashMap};

use num_rational::BigRational;

use crate::cone::{interiors_meet, layout_ball, point_name, Weight, LAYOUT_RADIUS};
use crate::cone_rules::ConeRules;
// The family enum lives with the rules it tells apart (`cone_rules`); this is its public path.
pub use crate::cone_rules::ConeFamily;
use crate::local_matrices::UnsupportedNeighbourhood;
use crate::triangle_local::{canonical_triangle_point, TrianglePoint};
use crate::TriangleScheme;

/// One regular tile of a region at level `L` (the corner's: [`ConeLocalMatrices::tile_level`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegularTile {
    /// Its corners, level-`L` sector-0 skew coordinates, counter-clockwise.
    pub corners: [(i64, i64); 3],
    /// Its control points: indices into the owner's `regular_points`, every level-`L` lattice
    /// point `j` with `T ∩ (j + int S)` nonempty.
    pub points: Vec<usize>,
}

impl RegularTile {
    /// Whether `(y_1/d, y_2/d)` (level-`L` coordinates) lies in the closed tile.
    pub fn contains(&self, y: (i64, i64), d: i64) -> bool {
        (0..3).all(|e| {
            let (p, q) = (self.corners[e], self.corners[(e + 1) % 3]);
            let cross = (q.0 - p.0) * (y.1 - d * p.1) - (q.1 - p.1) * (y.0 - d * p.0);
            cross >= 0
        })
    }
}

/// The local subdivision matrices of the butterfly or √3 around an interior vertex of valence
/// `K` (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ConeLocalMatrices {
    /// The scheme's name.
    pub scheme: String,
    /// Whose rules built the matrices (and so the dilation `λ`).
    pub family: ConeFamily,
    /// The valence `K`.
    pub valence: u32,
    /// The control points, in table order (the cone ball of [`crate::cone`]).
    pub layout: Vec<TrianglePoint>,
    /// `A` (`N x N`, `N` = layout size), f64: row `i` is the level-1 layout point `i` in
    /// level-0 layout weights, so `P_1 = A P_0` and `phi(x) = phi(λx) A`.
    pub a: Vec<Vec<f64>>,
    /// `A` exactly, when every weight is rational (`K = 3, 4, 6`).
    pub a_exact: Option<Vec<Vec<BigRational>>>,
    /// The hull `H` of the regular mask's indices, counter-clockwise; the regular basis
    /// function `psi` is supported on `S = H/(λ - 1)`.
    pub hull: Vec<(i64, i64)>,
    /// The level `L` of the regular tiles (butterfly 3, √3 2).
    pub tile_level: u32,
    /// Every level-`L` lattice point some tile needs, unfolded in sector 0's chart.
    pub regular_points: Vec<(i64, i64)>,
    /// For each of `regular_points`, its level-0 weights over the layout (`L` steps), f64.
    pub regular_rows: Vec<Vec<f64>>,
    /// The same rows exactly, when every weight is rational.
    pub regular_rows_exact: Option<Vec<Vec<BigRational>>>,
    /// The regular tiles covering `1/λ <= u + v <= 1`: up triangles `(a,b),(a+1,b),(a,b+1)`
    /// then down triangles `(a+1,b),(a+1,b+1),(a,b+1)`, each by `b`, then `a`.
    pub tiles: Vec<RegularTile>,
}

/// The level-`level` triangles of `1/λ <= u + v <= 1` (`level >= 1`), in
/// [`ConeLocalMatrices::tiles`] order, by corners.
pub(crate) fn outer_tiles(family: ConeFamily, level: u32) -> Vec<[(i64, i64); 3]> {
    let m = family.scale(level);
    let l = i64::from(family.dilation());
    let mut up = Vec::new();
    let mut down = Vec::new();
    for b in 0..m {
        for a in 0..m - b {
            if l * (a + b) >= m {
                up.push([(a, b), (a + 1, b), (a, b + 1)]);
            }
            if l * (a + b + 1) >= m && a + b + 2 <= m {
                down.push([(a + 1, b), (a + 1, b + 1), (a, b + 1)]);
            }
        }
    }
    up.extend(down);
    up
}

/// `T` scaled by `λ - 1`: the test `T ∩ (j + int H/(λ-1)) != ∅` is
/// `(λ-1)T ∩ ((λ-1)j + int H) != ∅`.
pub(crate) fn support_scaled(family: ConeFamily, t: &[(i64, i64); 3]) -> [(i64, i64); 3] {
    let f = i64::from(family.dilation()) - 1;
    t.map(|(a, b)| (f * a, f * b))
}

/// What one build of the matrices needs: the rows of `A`, the tiles and their rows.
struct Built<T> {
    a: Vec<Vec<T>>,
    regular_points: Vec<(i64, i64)>,
    rows: Vec<Vec<T>>,
    tiles: Vec<RegularTile>,
}

/// Rows of level-`k` points in level-0 layout weights, memoized per level: the one
/// implementation of "apply the true rules `k` times" that the EV patch and every region
/// ([`crate::cone_regions`]) use. Reading a level-0 point outside the layout is an error,
/// which is how every layout is checked; rule weights that are exactly zero (the butterfly's
/// `s_1`, `s_3` at `K = 4`) read nothing.
pub(crate) struct RowMemo<'a, T> {
    rules: &'a ConeRules<T>,
    index: HashMap<TrianglePoint, usize>,
    size: usize,
    /// `memo[k][p]`: the level-`k` point `p` in level-0 layout weights.
    memo: Vec<HashMap<TrianglePoint, Vec<T>>>,
}

impl<'a, T: Weight> RowMemo<'a, T> {
    /// Rows over `layout`, for points of levels `0..=max_level`.
    pub(crate) fn new(rules: &'a ConeRules<T>, layout: &[TrianglePoint], max_level: u32) -> Self {
        RowMemo {
            rules,
            index: layout.iter().enumerate().map(|(i, &p)| (p, i)).collect(),
            size: layout.len(),
            memo: vec![HashMap::new(); max_level as usize + 1],
        }
    }

    /// The level-`k` point `p` in level-0 layout weights, or the first unlisted point read.
    pub(crate) fn row(&mut self, k: usize, p: TrianglePoint) -> Result<Vec<T>, String> {
        if let Some(r) = self.memo.get(k).and_then(|m| m.get(&p)) {
            return Ok(r.clone());
        }
        if k >= self.memo.len() {
            return Err(format!("level {k} is past the memo's deepest level"));
        }
        let mut r = vec![T::zero(); self.size];
        if k == 0 {
            let i = *self
                .index
                .get(&p)
                .ok_or_else(|| format!("level-0 point {} is not in the layout", point_name(p)))?;
            r[i] = T::one_weight();
        } else {
            for (parent, w) in self.rules.refine(p)? {
                if w.is_zero() {
                    continue;
                }
                let pr = self.row(k - 1, parent)?;
                for (x, y) in r.iter_mut().zip(pr) {
                    if !y.is_zero() {
                        *x = x.clone() + w.clone() * y;
                    }
                }
            }
        }
        self.memo[k].insert(p, r.clone());
        Ok(r)
    }

    /// The rows of the level-`k` points `points`, unfolded in sector 0's chart.
    pub(crate) fn chart_rows(
        &mut self,
        k: u32,
        points: &[(i64, i64)],
    ) -> Result<Vec<Vec<T>>, String> {
        points
            .iter()
            .map(|&(j1, j2)| {
                let p = canonical_triangle_point(self.rules.valence(), 0, j1, j2);
                self.row(k as usize, p)
            })
            .collect()
    }
}

/// Every level-0 point that the level-`level` points `points` (sector-0 chart) read through
/// the rules, counting only nonzero rule weights: the closure a layout must hold.
pub(crate) fn level0_reads<T: Weight>(
    rules: &ConeRules<T>,
    level: u32,
    points: &[(i64, i64)],
) -> Result<BTreeSet<TrianglePoint>, String> {
    let mut current: BTreeSet<TrianglePoint> = points
        .iter()
        .map(|&(j1, j2)| canonical_triangle_point(rules.valence(), 0, j1, j2))
        .collect();
    for _ in 0..level {
        let mut parents = BTreeSet::new();
        for &p in &current {
            for (parent, w) in rules.refine(p)? {
                if !w.is_zero() {
                    parents.insert(parent);
                }
            }
        }
        current = parents;
    }
    Ok(current)
}

/// Regular tiles and the level-`L` lattice points they need.
pub(crate) struct TileSet {
    /// Every control point of some tile, sector-0 chart, in first-use order.
    pub(crate) regular_points: Vec<(i64, i64)>,
    /// The tiles, control points as indices into `regular_points`.
    pub(crate) tiles: Vec<RegularTile>,
}

/// The tiles with corners `tile_corners` (level-`L` chart coordinates) and, for each, the
/// level-`L` lattice points `j` with `T ∩ (j + int S)` nonempty, `S = H/(λ - 1)` (tested as
/// `(λ-1)T ∩ ((λ-1)j + int H)`): the only `j` whose `psi(. - j)` does not vanish on `T`.
pub(crate) fn tile_set(
    family: ConeFamily,
    hull: &[(i64, i64)],
    tile_corners: Vec<[(i64, i64); 3]>,
) -> TileSet {
    let f = i64::from(family.dilation()) - 1;
    let mut regular_points: Vec<(i64, i64)> = Vec::new();
    let mut point_index: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    let mut tiles = Vec::new();
    // Lattice points j with T ∩ (j + int S) nonempty are within S's hex radius of T.
    let radius = hull
        .iter()
        .map(|&(a, b)| a.abs().max(b.abs()).max((a + b).abs()))
        .max()
        .unwrap_or(0)
        / f
        + 1;
    for corners in tile_corners {
        let scaled = support_scaled(family, &corners);
        let mut points = Vec::new();
        let range = |c: fn(&(i64, i64)) -> i64| {
            let lo = corners.iter().map(c).min().unwrap_or(0) - radius;
            let hi = corners.iter().map(c).max().unwrap_or(0) + radius;
            lo..=hi
        };
        for j2 in range(|c| c.1) {
            for j1 in range(|c| c.0) {
                let shifted: Vec<(i64, i64)> = hull
                    .iter()
                    .map(|&(a, b)| (a + f * j1, b + f * j2))
                    .collect();
                if !interiors_meet(&scaled, &shifted) {
                    continue;
                }
                let next = regular_points.len();
                let u = *point_index.entry((j1, j2)).or_insert(next);
                if u == next {
                    regular_points.push((j1, j2));
                }
                points.push(u);
            }
        }
        tiles.push(RegularTile { corners, points });
    }
    TileSet {
        regular_points,
        tiles,
    }
}

/// Build `A` and the tile rows over `layout` in the field `T`; `Err` names the first point
/// whose rule reads a point outside the layout (or past the chart's cut).
fn build<T: Weight>(
    family: ConeFamily,
    rules: &ConeRules<T>,
    layout: &[TrianglePoint],
    hull: &[(i64, i64)],
    level: u32,
) -> Result<Built<T>, String> {
    let mut memo = RowMemo::new(rules, layout, level.max(1));
    let a = layout
        .iter()
        .map(|&p| memo.row(1, p))
        .collect::<Result<Vec<_>, _>>()?;
    let TileSet {
        regular_points,
        tiles,
    } = tile_set(family, hull, outer_tiles(family, level));
    let rows = memo.chart_rows(level, &regular_points)?;
    Ok(Built {
        a,
        regular_points,
        rows,
        tiles,
    })
}

/// The smallest level `L >= 1` at which every triangle `T` of the outer part
/// `1/λ <= u + v <= 1` keeps `V` outside `T + int S` (module docs): `(λ-1)T ∩ int H` is empty.
pub fn regular_tile_level(family: ConeFamily, hull: &[(i64, i64)]) -> u32 {
    (1..)
        .find(|&level| {
            outer_tiles(family, level)
                .iter()
                .all(|t| !interiors_meet(&support_scaled(family, t), hull))
        })
        .unwrap_or(1)
}

impl ConeLocalMatrices {
    /// Build the layout, `A` and the regular tiles of the modified butterfly (`butterfly`) or
    /// √3 (`sqrt3`), by the scheme's rules ([`ConeFamily::of`]), around an interior vertex of
    /// valence `valence >= 3`.
    pub fn new(scheme: &TriangleScheme, valence: u32) -> Result<Self, UnsupportedNeighbourhood> {
        Self::with_radius(scheme, valence, LAYOUT_RADIUS)
    }

    /// [`Self::new`] over the ball of graph radius `radius` (for checking that
    /// [`LAYOUT_RADIUS`] is the smallest that works: smaller balls are errors).
    pub fn with_radius(
        scheme: &TriangleScheme,
        valence: u32,
        radius: u32,
    ) -> Result<Self, UnsupportedNeighbourhood> {
        let unsupported = |reason: String| UnsupportedNeighbourhood {
            scheme: scheme.name.to_owned(),
            reason,
        };
        let family = ConeFamily::of(scheme).map_err(unsupported)?;
        if valence < 3 {
            return Err(unsupported(format!(
                "an interior vertex needs valence >= 3, not {valence}"
            )));
        }
        let layout = layout_ball(valence, radius);
        let hull = scheme.regular_mask().hull();
        let level = regular_tile_level(family, &hull);
        let rules = ConeRules::<f64>::new(family, scheme, valence)
            .ok_or_else(|| unsupported("the scheme is not a dyadic butterfly".to_owned()))?;
        let fail = |e: String| unsupported(format!("valence {valence}, radius {radius}: {e}"));
        let built = build(family, &rules, &layout, &hull, level).map_err(fail)?;
        let exact = match ConeRules::<BigRational>::new(family, scheme, valence) {
            Some(rules) => Some(build(family, &rules, &layout, &hull, level).map_err(fail)?),
            None => None,
        };
        let (a_exact, regular_rows_exact) = match exact {
            Some(e) => (Some(e.a), Some(e.rows)),
            None => (None, None),
        };
        Ok(ConeLocalMatrices {
            scheme: scheme.name.to_owned(),
            family,
            valence,
            layout,
            a: built.a,
            a_exact,
            hull,
            tile_level: level,
            regular_points: built.regular_points,
            regular_rows: built.rows,
            regular_rows_exact,
            tiles: built.tiles,
        })
    }

    /// The dilation `λ` of one step ([`ConeFamily::dilation`]).
    pub fn dilation(&self) -> u32 {
        self.family.dilation()
    }

    /// The number of control points `N = 3K + 9`.
    pub fn size(&self) -> usize {
        self.layout.len()
    }

    /// Whether every weight is rational (`a_exact` and `regular_rows_exact` are present).
    pub fn is_rational(&self) -> bool {
        self.a_exact.is_some()
    }

    /// Names of the layout's points ([`point_name`]).
    pub fn names(&self) -> Vec<String> {
        self.layout.iter().map(|&p| point_name(p)).collect()
    }

    /// The tile holding `(y_1/d, y_2/d)` in level-`L` coordinates (`1/λ <= u + v <= 1`), the
    /// first in [`Self::tiles`] order.
    pub fn tile_containing(&self, y: (i64, i64), d: i64) -> Option<usize> {
        self.tiles.iter().position(|t| t.contains(y, d))
    }

    /// The layout index of the reflection `(a, b) -> (b, a)` of sector 0 (the patch's
    /// `u <-> v` mirror) applied to layout point `i`: sector `s` goes to sector `1 - s` read
    /// with its axes swapped, `(a, b)_s -> (b, a)_{-s}`.
    pub fn mirror(&self, i: usize) -> Option<usize> {
        let k = i64::from(self.valence);
        let image = match self.layout.get(i)? {
            TrianglePoint::Centre => TrianglePoint::Centre,
            &TrianglePoint::Sector { s, a, b } => {
                canonical_triangle_point(self.valence, (-i64::from(s)).rem_euclid(k), b, a)
            }
        };
        self.layout.iter().position(|&p| p == image)
    }
}
