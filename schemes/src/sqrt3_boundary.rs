//! √3 subdivision (Kobbelt 2000) next to a boundary: two √3 steps, one ternary step, with
//! Kobbelt's boundary rules, on the fan of `K` triangles around a boundary vertex `V` (every
//! other vertex regular) and on the half-plane beside a straight boundary, which is the fan of
//! three. Data only: the rows of every level-`L` point over the level-0 points, the material of
//! the boundary patches (docs/algorithms/sqrt3.md, "The plan for boundary patches").
//!
//! **The fan.** Sector `s = 0..K` is the triangle `V, E_s, E_{s+1}` and the `60°` wedge beyond
//! it; in its skew chart `(a, b)` (`V` at the origin, `E_s = (1, 0)`, `E_{s+1} = (0, 1)`) it holds
//! the points `a >= 1, b >= 0`. The boundary is the ray of `E_0` (sector 0's `b = 0`) and the ray
//! of `E_K`, named as sector `K`'s `b = 0` (a sector `K` holds nothing else). Sector `s + 1`'s
//! chart is sector `s`'s turned by `60°`: its point `(a, b)` is sector `s`'s `(-b, a + b)`
//! ([`BoundaryFan::canonical`] names any chart point). Level-`L` points have level-`L` integer
//! coordinates (level-0 coordinates times `3^L`) in the same charts.
//!
//! **Half-level points.** In level-1 coordinates of a chart, the points after one √3 step are
//! the old vertices (both coordinates `0 mod 3`) and the centroids of the chart's up triangles
//! `(a,b), (a+1,b), (a,b+1)` (`1 mod 3`) and down triangles `(a+1,b), (a+1,b+1), (a,b+1)`
//! (`2 mod 3`); turning a chart swaps the two kinds.
//!
//! **Rules** (Kobbelt 2000, section 4; the whole-mesh version is the runtime's
//! `scheme::sqrt3::refine`, compared with this one in its tests). First step: a boundary
//! vertex stays (`h = p`), an interior vertex (valence 6) moves to `h = 2/3 p + 1/18 sum` of its
//! six neighbours; every triangle gets its centroid `c`. Second step, per level-1 point:
//!
//! * a boundary vertex: `(4 p_prev + 19 p + 4 p_next) / 27` over its boundary neighbours; an
//!   interior vertex: `2/3 h + 1/18 sum` of the six centroids around it;
//! * a centroid: `(1 - alpha_k) c + (alpha_k / k) (sum of its corners' h + sum of the centroids
//!   across its inner edges)`, `k = 3 +` the number of inner edges,
//!   `alpha_k = (4 - 2 cos(2π/k)) / 9`;
//! * a boundary third: `(p_prev + 16 p + 10 p_next) / 27` nearer `p`, `p_prev` the boundary
//!   neighbour of `p` away from `p_next`;
//! * every other point (the thirds of inner edges): the average of the three half-level points
//!   among its six unit neighbours.
//!
//! The centre of a triangle with one boundary edge has valence 5, and `alpha_5` has
//! `cos(2π/5)`, so the rows are f64.

use std::collections::{BTreeMap, HashMap};

use crate::TriangleVertexRule;

/// A point of a fan: `(sector, a, b)` in that sector's chart with `a >= 1, b >= 0` (sector `K`
/// only with `b = 0`: the ray of `E_K`), or `V = (0, 0, 0)`.
pub type FanPoint = (u32, i64, i64);

/// The vertex `V`.
pub const V: FanPoint = (0, 0, 0);

/// Weights over level-0 points.
pub type FanRow = BTreeMap<FanPoint, f64>;

/// The six unit steps of the lattice, counter-clockwise from `(1, 0)`.
const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// The offsets, in level-1 coordinates, from a vertex to the centroids of its six triangles.
const CENTROIDS_AROUND_VERTEX: [(i64, i64); 6] =
    [(1, 1), (-2, 1), (1, -2), (-1, -1), (2, -1), (-1, 2)];

/// The offsets, in level-1 coordinates, from an up triangle's centroid to the centroids across
/// its edges and to its corners; a down triangle's are the opposites.
const UP_ACROSS: [(i64, i64); 3] = [(1, -2), (1, 1), (-2, 1)];
const UP_CORNERS: [(i64, i64); 3] = [(-1, -1), (2, -1), (-1, 2)];

/// `alpha_k` of √3 (Kobbelt 2000), f64.
fn alpha(valence: u32) -> f64 {
    let (_, beta) = TriangleVertexRule::Sqrt3.weights(valence);
    beta.value * f64::from(valence)
}

fn add_scaled(row: &mut FanRow, terms: &FanRow, w: f64) {
    for (&p, &x) in terms {
        *row.entry(p).or_insert(0.0) += w * x;
    }
}

fn offset(q: (i64, i64), d: (i64, i64)) -> (i64, i64) {
    (q.0 + d.0, q.1 + d.1)
}

/// The fan of `faces` triangles around a boundary vertex (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryFan {
    /// `K`, the number of triangles at `V` (3: the regular boundary, the half-plane).
    pub faces: u32,
}

impl BoundaryFan {
    /// The fan of `faces` triangles (at least 1).
    pub fn new(faces: u32) -> Self {
        assert!(faces >= 1, "a boundary vertex has a triangle");
        BoundaryFan { faces }
    }

    /// The point at coordinates `q` of sector `sector`'s chart (any level), or `None` when it
    /// lies outside the fan (beyond the boundary rays).
    pub fn canonical(&self, sector: i64, q: (i64, i64)) -> Option<FanPoint> {
        let (mut s, mut q) = (sector, q);
        for _ in 0..8 {
            if q == (0, 0) {
                return Some(V);
            }
            if q.1 < 0 {
                // Sector s - 1's chart holds it turned back by 60 degrees.
                q = (-q.1, q.0 + q.1);
                s -= 1;
            } else if q.0 <= 0 {
                q = (q.0 + q.1, -q.0);
                s += 1;
            } else {
                let k = i64::from(self.faces);
                return ((0..k).contains(&s) || (s == k && q.1 == 0))
                    .then_some((s as u32, q.0, q.1));
            }
        }
        None
    }

    /// Whether level-0 point `p` is on the boundary.
    pub fn on_boundary(&self, p: FanPoint) -> bool {
        p == V || (p.2 == 0 && (p.0 == 0 || p.0 == self.faces))
    }

    /// The boundary neighbours `(prev, next)` of boundary point `p` (faces counter-clockwise:
    /// the fan lies to the left of `prev -> p -> next`).
    fn boundary_neighbours(&self, p: FanPoint) -> (FanPoint, FanPoint) {
        let k = self.faces;
        let step = |s: u32, a: i64| if a == 0 { V } else { (s, a, 0) };
        match p {
            V => ((k, 1, 0), (0, 1, 0)),
            (0, a, _) => (step(0, a - 1), (0, a + 1, 0)),
            (_, a, _) => ((k, a + 1, 0), step(k, a - 1)),
        }
    }

    /// The chart coordinates of `p` in sector 0's chart (for the half-plane, `K = 3`).
    pub fn in_sector_zero(p: FanPoint) -> (i64, i64) {
        (0..p.0).fold((p.1, p.2), |(a, b), _| (-b, a + b))
    }

    /// The first step's value at the half-level point at level-1 coordinates `q` of sector
    /// `s`'s chart, over level-0 points.
    fn half_level(&self, s: i64, q: (i64, i64)) -> FanRow {
        let (i, j) = (q.0.rem_euclid(3), q.1.rem_euclid(3));
        debug_assert_eq!(i, j, "{q:?} is not a half-level point");
        let (a, b) = ((q.0 - i) / 3, (q.1 - j) / 3);
        let at = |c: (i64, i64)| self.canonical(s, c).expect("a point of the fan");
        let mut row = FanRow::new();
        match i {
            0 => {
                let p = at((a, b));
                if self.on_boundary(p) {
                    row.insert(p, 1.0);
                } else {
                    row.insert(p, 2.0 / 3.0);
                    for d in NEIGHBOURS {
                        *row.entry(at(offset((a, b), d))).or_insert(0.0) += 1.0 / 18.0;
                    }
                }
            }
            1 => {
                for c in [(a, b), (a + 1, b), (a, b + 1)] {
                    row.insert(at(c), 1.0 / 3.0);
                }
            }
            _ => {
                for c in [(a + 1, b), (a + 1, b + 1), (a, b + 1)] {
                    row.insert(at(c), 1.0 / 3.0);
                }
            }
        }
        row
    }

    /// The composed step's row of the level-1 point `q` (level-1 coordinates) over level-0
    /// points (module docs).
    pub fn level1_row(&self, q: FanPoint) -> FanRow {
        let (s, x, y) = (i64::from(q.0), q.1, q.2);
        let (i, j) = (x.rem_euclid(3), y.rem_euclid(3));
        let mut row = FanRow::new();
        if self.on_boundary(q) {
            let along = |a: i64| if a == 0 { V } else { (q.0, a, 0) };
            let (base, third) = ((x - i) / 3, i);
            let here = along(base);
            let weights: Vec<(FanPoint, f64)> = if third == 0 {
                let (prev, next) = self.boundary_neighbours(here);
                vec![(prev, 4.0), (here, 19.0), (next, 4.0)]
            } else {
                // The boundary edge from `here` outward along this ray to `there`.
                let there = along(base + 1);
                let beyond = |p: FanPoint, other: FanPoint| {
                    let (prev, next) = self.boundary_neighbours(p);
                    if prev == other {
                        next
                    } else {
                        prev
                    }
                };
                let (near, far) = if third == 1 {
                    (here, there)
                } else {
                    (there, here)
                };
                vec![(beyond(near, far), 1.0), (near, 16.0), (far, 10.0)]
            };
            for (p, w) in weights {
                *row.entry(p).or_insert(0.0) += w / 27.0;
            }
            return row;
        }
        let point = (x, y);
        let half = |d: (i64, i64)| self.half_level(s, offset(point, d));
        let exists = |d: (i64, i64)| self.canonical(s, offset(point, d)).is_some();
        match (i, j) {
            (0, 0) => {
                add_scaled(&mut row, &half((0, 0)), 2.0 / 3.0);
                for d in CENTROIDS_AROUND_VERTEX {
                    add_scaled(&mut row, &half(d), 1.0 / 18.0);
                }
            }
            (1, 1) | (2, 2) => {
                let sign = if i == 1 { 1 } else { -1 };
                let turn = |d: &(i64, i64)| (sign * d.0, sign * d.1);
                let neighbours: Vec<(i64, i64)> = UP_CORNERS
                    .iter()
                    .map(turn)
                    .chain(UP_ACROSS.iter().map(turn).filter(|&d| exists(d)))
                    .collect();
                let k = neighbours.len() as u32;
                let a = alpha(k);
                add_scaled(&mut row, &half((0, 0)), 1.0 - a);
                for d in neighbours {
                    add_scaled(&mut row, &half(d), a / f64::from(k));
                }
            }
            _ => {
                for d in NEIGHBOURS {
                    let (u, v) = offset(point, d);
                    if u.rem_euclid(3) == v.rem_euclid(3) {
                        add_scaled(&mut row, &half(d), 1.0 / 3.0);
                    }
                }
            }
        }
        row.retain(|_, w| *w != 0.0);
        row
    }
}

/// Rows of a fan's level-`L` points over its level-0 points, memoized: level `L` is the
/// composed step applied to level `L - 1`, whose points are level-0 points of the same rules
/// one level down.
#[derive(Clone, Debug)]
pub struct BoundaryRows {
    fan: BoundaryFan,
    memo: HashMap<(u32, FanPoint), FanRow>,
}

impl BoundaryRows {
    /// An empty memo for `fan`.
    pub fn new(fan: BoundaryFan) -> Self {
        BoundaryRows {
            fan,
            memo: HashMap::new(),
        }
    }

    /// The row of the level-`level` point `q` (level-`level` coordinates) over level-0 points.
    pub fn row(&mut self, level: u32, q: FanPoint) -> &FanRow {
        if !self.memo.contains_key(&(level, q)) {
            let row = if level == 0 {
                FanRow::from([(q, 1.0)])
            } else {
                let mut row = FanRow::new();
                for (p, w) in self.fan.level1_row(q) {
                    let inner = self.row(level - 1, p);
                    add_scaled(&mut row, inner, w);
                }
                row.retain(|_, w| *w != 0.0);
                row
            };
            self.memo.insert((level, q), row);
        }
        &self.memo[&(level, q)]
    }
}

/// The half-plane beside a straight boundary, `b >= 0`, in sector 0's chart of the fan of
/// three (whose `V` is a regular boundary vertex like every other on the line): the row of
/// the level-1 point at half-plane coordinates `q` over level-0 half-plane points.
pub fn half_plane_row(q: (i64, i64)) -> BTreeMap<(i64, i64), f64> {
    let fan = BoundaryFan::new(3);
    let name = fan.canonical(0, q).expect("a point of the half-plane");
    fan.level1_row(name)
        .into_iter()
        .map(|(p, w)| (BoundaryFan::in_sector_zero(p), w))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every level-1 point of every fan within three units of `V` has an affine row (weights
    /// sum to 1) within two level-0 units (hex norm in its chart) of the point.
    #[test]
    fn rows_are_affine_and_local() {
        for k in 1..=8 {
            let fan = BoundaryFan::new(k);
            for s in 0..=k {
                for b in 0..9 {
                    for a in 0..9 {
                        let Some(q) = fan.canonical(i64::from(s), (a, b)) else {
                            continue;
                        };
                        let row = fan.level1_row(q);
                        let sum: f64 = row.values().sum();
                        assert!((sum - 1.0).abs() < 1e-14, "K = {k}, {q:?}: {sum}");
                        assert!(row.len() >= 3, "K = {k}, {q:?}");
                    }
                }
            }
        }
    }

    /// The charts agree: a point named from a neighbouring sector's chart is the same point,
    /// and the ray of `E_{s+1}` is sector `s + 1`'s `b = 0`.
    #[test]
    fn charts_name_points_consistently() {
        let fan = BoundaryFan::new(5);
        assert_eq!(fan.canonical(0, (0, 2)), Some((1, 2, 0)));
        assert_eq!(fan.canonical(1, (3, -1)), Some((0, 1, 2)));
        assert_eq!(fan.canonical(4, (-1, 2)), None);
        assert_eq!(fan.canonical(4, (0, 2)), Some((5, 2, 0)));
        assert_eq!(fan.canonical(0, (1, -1)), None);
        assert_eq!(BoundaryFan::in_sector_zero((3, 2, 0)), (-2, 0));
    }

    /// Far from the boundary the rules are the interior ones, so on the half-plane a row moved
    /// by whole level-0 units is the moved point's row; next to the boundary a centroid's rule
    /// changes.
    #[test]
    fn half_plane_rows_are_translation_invariant_away_from_the_boundary() {
        for q in [(0, 9), (1, 10), (2, 11), (1, 9), (0, 10), (-4, 12)] {
            let here = half_plane_row(q);
            let shifted = half_plane_row((q.0 + 3, q.1 + 3));
            assert_eq!(here.len(), shifted.len(), "{q:?}");
            for (&(a, b), w) in &here {
                assert!((shifted[&(a + 1, b + 1)] - w).abs() < 1e-15, "{q:?}");
            }
        }
        assert_ne!(half_plane_row((1, 1)).len(), half_plane_row((1, 10)).len());
    }
}
