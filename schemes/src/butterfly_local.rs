//! The modified butterfly (Zorin, Schröder and Sweldens 1996) around an interior extraordinary
//! vertex of valence `K`: the patch layout, the local subdivision matrix `A` and the regular
//! tiles of the patch's outer half with their control points as rows of level-0 weights
//! (Schaefer–Warren sections 5.2–5.3 on the triangular lattice of section 5.1). Data only:
//! `stencilgen::butterfly_patch` solves with them.
//!
//! **Sectors and the patch** are those of [`crate::triangle_local`]: sector `s` holds the points
//! `(a, b)`, `a >= 1`, `b >= 0`, of its own skew chart, named by [`canonical_triangle_point`];
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
//! [`canonical_triangle_point`] names the true vertices even at `K = 3`, where both wings of the
//! edge `E_0 E_1` are `E_2`.
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
//! rule there reads `V`. [`ButterflyLocalMatrices::tile_level`] is the smallest `L` for which
//! every level-`L` triangle of the outer half passes (`L = 3`: 48 tiles, since `H` reaches
//! `(2, 0)` in its interior but no point of hex norm 4). Each tile's control points, the
//! level-`L` lattice points `j` with `T ∩ (j + int H)` nonempty, are rows of level-0 layout
//! weights after `L` steps of the true rules.
//!
//! **Numbers.** Every matrix is kept in f64 (the weights' f64 values) and, when all weights are
//! rational (`K = 3, 4, 6`), also exactly as [`BigRational`].

use std::collections::{BTreeMap, BTreeSet, HashMap};

use num_rational::BigRational;

pub(crate) use crate::cone::{interiors_meet, layout_ball, Weight};
pub use crate::cone::{layout_key, point_name};

use crate::local_matrices::UnsupportedNeighbourhood;
use crate::triangle::{apply_map, lattice_symmetries, TriangleRefinement};
use crate::triangle_local::{canonical_triangle_point, TrianglePoint};
use crate::{TriangleScheme, TriangleVertexRule, TriangleWeight};

/// The graph distance from `{V, E_0, E_1}` that the layout reaches (the smallest that works,
/// see the module docs).
pub const LAYOUT_RADIUS: u32 = 2;

/// The number of 60-degree chart sectors, counter-clockwise from `(1, 0)`, between the chart's
/// first sector and the lattice point `(a, b) != (0, 0)`: `0` for `a >= 1, b >= 0`, `1` for the
/// next wedge, `-1` for the one clockwise, ... in `-2..=3` (the chart's cut is the ray at 180
/// degrees, sector 3). The rotation is the one [`canonical_triangle_point`] applies.
pub fn chart_sector(a: i64, b: i64) -> i64 {
    let (mut a, mut b, mut s) = (a, b, 0);
    while !(a >= 1 && b >= 0) {
        if a == 0 && b == 0 {
            return 0;
        }
        if b < 0 {
            (s, a, b) = (s - 1, -b, a + b);
        } else {
            (s, a, b) = (s + 1, a + b, -a);
        }
    }
    s
}

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

/// The level-0 edge `(p, p + R^k (1, 0))` whose new point is the odd level-1 point `(a, b)`.
fn edge_of(a: i64, b: i64) -> Option<((i64, i64), usize)> {
    match (a.rem_euclid(2), b.rem_euclid(2)) {
        (0, 0) => None,
        (1, 0) => Some((((a - 1) / 2, b / 2), 0)),
        (0, 1) => Some(((a / 2, (b - 1) / 2), 1)),
        _ => Some((((a - 1) / 2, (b + 1) / 2), 5)),
    }
}

/// The layout of valence `valence` in table order (see the module docs): the ball of graph
/// radius [`LAYOUT_RADIUS`] around the patch.
pub fn butterfly_layout(valence: u32) -> Vec<TrianglePoint> {
    layout_ball(valence, LAYOUT_RADIUS)
}

/// A linear combination of level-`(k-1)` points making a level-`k` point.
type Combination<T> = Vec<(TrianglePoint, T)>;

/// The modified butterfly's rules at one valence, in one number field.
#[derive(Clone, Debug)]
pub(crate) struct ButterflyRules<T> {
    valence: u32,
    /// `(3/4, [s_0, .., s_{K-1}])` at an edge of `V`; `None` at `K = 6` (regular rule).
    extraordinary: Option<(T, Vec<T>)>,
    /// The regular edge rule of the edge `(0,0)-(1,0)`.
    edge: Vec<((i64, i64), T)>,
}

impl<T: Weight> ButterflyRules<T> {
    /// `None` when a weight is irrational in an exact field.
    pub(crate) fn new(scheme: &TriangleScheme, valence: u32) -> Option<Self> {
        let TriangleRefinement::Dyadic {
            edge,
            edge_denominator,
        } = scheme.refinement
        else {
            return None;
        };
        let extraordinary = if valence == 6 {
            None
        } else {
            let (q, s) = scheme.butterfly_extraordinary(valence)?;
            let s: Option<Vec<T>> = s.into_iter().map(T::from_weight).collect();
            Some((T::from_weight(q)?, s?))
        };
        let edge = edge
            .iter()
            .map(|&(o, w)| {
                Some((
                    o,
                    T::from_weight(TriangleWeight::ratio(w, edge_denominator))?,
                ))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(ButterflyRules {
            valence,
            extraordinary,
            edge,
        })
    }

    /// The level-`(k-1)` combination of the level-`k` point `point`, or the reason the chart
    /// cannot name the stencil.
    pub(crate) fn refine(&self, point: TrianglePoint) -> Result<Combination<T>, String> {
        let TrianglePoint::Sector { s, a, b } = point else {
            return Ok(vec![(TrianglePoint::Centre, T::one_weight())]);
        };
        let si = i64::from(s);
        let Some((p, k)) = edge_of(a, b) else {
            return Ok(vec![(
                canonical_triangle_point(self.valence, si, a / 2, b / 2),
                T::one_weight(),
            )]);
        };
        if let (Some((q, weights)), true) = (&self.extraordinary, p == (0, 0) && k == 0) {
            let mut out = vec![(TrianglePoint::Centre, q.clone())];
            out.extend(weights.iter().enumerate().map(|(j, w)| {
                (
                    TrianglePoint::Sector {
                        s: (s + j as u32) % self.valence,
                        a: 1,
                        b: 0,
                    },
                    w.clone(),
                )
            }));
            return Ok(out);
        }
        let map = lattice_symmetries()[k];
        self.edge
            .iter()
            .map(|(o, w)| {
                let o = apply_map(map, *o);
                let q = (p.0 + o.0, p.1 + o.1);
                let sector = chart_sector(q.0, q.1);
                // At K = 6 the cone is the plane and every chart position is right.
                if self.valence != 6 && q != (0, 0) && !(-1..=2).contains(&sector) {
                    return Err(format!(
                        "the stencil of {} reaches chart sector {sector}, past the cut",
                        point_name(point)
                    ));
                }
                Ok((
                    canonical_triangle_point(self.valence, si, q.0, q.1),
                    w.clone(),
                ))
            })
            .collect()
    }
}

/// One regular tile of the patch's outer half at level [`ButterflyLocalMatrices::tile_level`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ButterflyTile {
    /// Its corners, level-`L` sector-0 skew coordinates, counter-clockwise.
    pub corners: [(i64, i64); 3],
    /// Its control points: indices into [`ButterflyLocalMatrices::regular_points`], every
    /// level-`L` lattice point `j` with `T ∩ (j + int H)` nonempty.
    pub points: Vec<usize>,
}

impl ButterflyTile {
    /// Whether `(y_1/d, y_2/d)` (level-`L` coordinates) lies in the closed tile.
    pub fn contains(&self, y: (i64, i64), d: i64) -> bool {
        (0..3).all(|e| {
            let (p, q) = (self.corners[e], self.corners[(e + 1) % 3]);
            let cross = (q.0 - p.0) * (y.1 - d * p.1) - (q.1 - p.1) * (y.0 - d * p.0);
            cross >= 0
        })
    }
}

/// The local subdivision matrices of the modified butterfly around an interior vertex of
/// valence `K` (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ButterflyLocalMatrices {
    /// The scheme's name.
    pub scheme: String,
    /// The valence `K`.
    pub valence: u32,
    /// The control points, in table order ([`butterfly_layout`]).
    pub layout: Vec<TrianglePoint>,
    /// `A` (`N x N`, `N` = layout size), f64: row `i` is the level-1 layout point `i` in
    /// level-0 layout weights, so `P_1 = A P_0`.
    pub a: Vec<Vec<f64>>,
    /// `A` exactly, when every weight is rational (`K = 3, 4, 6`).
    pub a_exact: Option<Vec<Vec<BigRational>>>,
    /// The hull `H` of the regular mask's indices, counter-clockwise: the support of the
    /// regular basis function `psi`.
    pub hull: Vec<(i64, i64)>,
    /// The level `L` of the regular tiles (3).
    pub tile_level: u32,
    /// Every level-`L` lattice point some tile needs, unfolded in sector 0's chart.
    pub regular_points: Vec<(i64, i64)>,
    /// For each of `regular_points`, its level-0 weights over the layout (`L` steps), f64.
    pub regular_rows: Vec<Vec<f64>>,
    /// The same rows exactly, when every weight is rational.
    pub regular_rows_exact: Option<Vec<Vec<BigRational>>>,
    /// The regular tiles covering `1/2 <= u + v <= 1`: up triangles `(a,b),(a+1,b),(a,b+1)`
    /// then down triangles `(a+1,b),(a+1,b+1),(a,b+1)`, each by `b`, then `a`.
    pub tiles: Vec<ButterflyTile>,
}

/// The level-`level` triangles of `1/2 <= u + v <= 1`, in [`ButterflyLocalMatrices::tiles`]
/// order, by corners.
fn outer_half_tiles(level: u32) -> Vec<[(i64, i64); 3]> {
    let m = 1i64 << level;
    let mut up = Vec::new();
    let mut down = Vec::new();
    for b in 0..m {
        for a in 0..m - b {
            if a + b >= m / 2 {
                up.push([(a, b), (a + 1, b), (a, b + 1)]);
            }
            if a + b + 1 >= m / 2 && a + b + 2 <= m {
                down.push([(a + 1, b), (a + 1, b + 1), (a, b + 1)]);
            }
        }
    }
    up.extend(down);
    up
}

/// What one build of the matrices needs: the rows of `A`, the tiles and their rows.
struct Built<T> {
    a: Vec<Vec<T>>,
    regular_points: Vec<(i64, i64)>,
    rows: Vec<Vec<T>>,
    tiles: Vec<ButterflyTile>,
}

/// Rows of level-`k` points in level-0 layout weights, memoized per level: the one
/// implementation of "apply the true rules `k` times" that the EV patch and every region
/// ([`crate::butterfly_regions`]) use. Reading a level-0 point outside the layout is an error,
/// which is how every layout is checked; rule weights that are exactly zero (`s_1`, `s_3` at
/// `K = 4`) read nothing.
pub(crate) struct RowMemo<'a, T> {
    rules: &'a ButterflyRules<T>,
    index: HashMap<TrianglePoint, usize>,
    size: usize,
    /// `memo[k][p]`: the level-`k` point `p` in level-0 layout weights.
    memo: Vec<HashMap<TrianglePoint, Vec<T>>>,
}

impl<'a, T: Weight> RowMemo<'a, T> {
    /// Rows over `layout`, for points of levels `0..=max_level`.
    pub(crate) fn new(
        rules: &'a ButterflyRules<T>,
        layout: &[TrianglePoint],
        max_level: u32,
    ) -> Self {
        RowMemo {
            rules,
            index: layout.iter().enumerate().map(|(i, &p)| (p, i)).collect(),
            size: layout.len(),
            memo: vec![HashMap::new(); max_level as usize + 1],
        }
    }

    /// The level-`k` point `p` in level-0 layout weights.
    pub(crate) fn row(&mut self, k: usize, p: TrianglePoint) -> Result<Vec<T>, String> {
        if let Some(r) = self.memo.get(k).and_then(|m| m.get(&p)) {
            return Ok(r.clone());
        }
        if k >= self.memo.len() {
            return Err(format!("level {k} is past the memo's deepest level"));
        }
        let row = if k == 0 {
            let i = *self
                .index
                .get(&p)
                .ok_or_else(|| format!("level-0 point {} is not in the layout", point_name(p)))?;
            let mut r = vec![T::zero(); self.size];
            r[i] = T::one_weight();
            r
        } else {
            let mut r = vec![T::zero(); self.size];
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
            r
        };
        self.memo[k].insert(p, row.clone());
        Ok(row)
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
                let p = canonical_triangle_point(self.rules.valence, 0, j1, j2);
                self.row(k as usize, p)
            })
            .collect()
    }
}

/// Every level-0 point that the level-`level` points `points` (sector-0 chart) read through
/// the rules, counting only nonzero rule weights: the closure a layout must hold.
pub(crate) fn level0_reads<T: Weight>(
    rules: &ButterflyRules<T>,
    level: u32,
    points: &[(i64, i64)],
) -> Result<BTreeSet<TrianglePoint>, String> {
    let mut current: BTreeSet<TrianglePoint> = points
        .iter()
        .map(|&(j1, j2)| canonical_triangle_point(rules.valence, 0, j1, j2))
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
    pub(crate) tiles: Vec<ButterflyTile>,
}

/// The tiles with corners `tile_corners` (level-`L` chart coordinates) and, for each, the
/// level-`L` lattice points `j` with `T ∩ (j + int H)` nonempty: the only ones whose `psi`
/// does not vanish on `T`.
pub(crate) fn tile_set(hull: &[(i64, i64)], tile_corners: Vec<[(i64, i64); 3]>) -> TileSet {
    let mut regular_points: Vec<(i64, i64)> = Vec::new();
    let mut point_index: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    let mut tiles = Vec::new();
    let radius = hull
        .iter()
        .map(|&(a, b)| a.abs().max(b.abs()).max((a + b).abs()))
        .max()
        .unwrap_or(0);
    for corners in tile_corners {
        let mut points = Vec::new();
        let (lo1, hi1) = (
            corners.iter().map(|c| c.0).min().unwrap_or(0) - radius,
            corners.iter().map(|c| c.0).max().unwrap_or(0) + radius,
        );
        let (lo2, hi2) = (
            corners.iter().map(|c| c.1).min().unwrap_or(0) - radius,
            corners.iter().map(|c| c.1).max().unwrap_or(0) + radius,
        );
        for j2 in lo2..=hi2 {
            for j1 in lo1..=hi1 {
                let shifted: Vec<(i64, i64)> =
                    hull.iter().map(|&(a, b)| (a + j1, b + j2)).collect();
                if !interiors_meet(&corners, &shifted) {
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
        tiles.push(ButterflyTile { corners, points });
    }
    TileSet {
        regular_points,
        tiles,
    }
}

/// Build `A` and the tile rows over `layout` in the field `T`; `Err` names the first point
/// whose rule reads a point outside the layout (or past the chart's cut).
fn build<T: Weight>(
    rules: &ButterflyRules<T>,
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
    } = tile_set(hull, outer_half_tiles(level));
    let rows = memo.chart_rows(level, &regular_points)?;
    Ok(Built {
        a,
        regular_points,
        rows,
        tiles,
    })
}

/// The smallest level `L >= 1` at which every triangle of the outer half `1/2 <= u + v <= 1`
/// keeps `V` outside `T + int H` (module docs), i.e. `T ∩ int H` is empty.
pub fn regular_tile_level(hull: &[(i64, i64)]) -> u32 {
    (1..)
        .find(|&level| {
            outer_half_tiles(level)
                .iter()
                .all(|t| !interiors_meet(t, hull))
        })
        .unwrap_or(1)
}

impl ButterflyLocalMatrices {
    /// Build the layout, `A` and the regular tiles of the modified butterfly (`butterfly`)
    /// around an interior vertex of valence `valence >= 3`.
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
        if scheme.vertex != TriangleVertexRule::Interpolatory {
            return Err(unsupported(
                "these local matrices are the modified butterfly's (interpolatory rules)"
                    .to_owned(),
            ));
        }
        if valence < 3 {
            return Err(unsupported(format!(
                "an interior vertex needs valence >= 3, not {valence}"
            )));
        }
        let layout = layout_ball(valence, radius);
        let hull = scheme.regular_mask().hull();
        let level = regular_tile_level(&hull);
        let rules = ButterflyRules::<f64>::new(scheme, valence)
            .ok_or_else(|| unsupported("the scheme is not a dyadic butterfly".to_owned()))?;
        let fail = |e: String| unsupported(format!("valence {valence}, radius {radius}: {e}"));
        let built = build(&rules, &layout, &hull, level).map_err(fail)?;
        let exact = match ButterflyRules::<BigRational>::new(scheme, valence) {
            Some(rules) => Some(build(&rules, &layout, &hull, level).map_err(fail)?),
            None => None,
        };
        let (a_exact, regular_rows_exact) = match exact {
            Some(e) => (Some(e.a), Some(e.rows)),
            None => (None, None),
        };
        Ok(ButterflyLocalMatrices {
            scheme: scheme.name.to_owned(),
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

    /// The tile holding `(y_1/d, y_2/d)` in level-`L` coordinates (`1/2 <= u + v <= 1`), the
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

#[cfg(test)]
mod tests {
    use super::*;
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
