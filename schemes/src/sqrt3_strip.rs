//! √3 subdivision (Kobbelt 2000) beside a straight boundary: two √3 steps, one ternary step, on
//! the half-plane of the triangular lattice, with Kobbelt's boundary rules. Data only: the
//! rows of every level-`L` point over the level-0 points, the material of the strip patches
//! that border a boundary (docs/algorithms/sqrt3.md, "The plan for boundary patches").
//!
//! **Coordinates.** Skew lattice coordinates `(a, b)`, the boundary the line `b = 0`, the
//! surface on `b >= 0`; triangles `(a,b), (a+1,b), (a,b+1)` (up) and
//! `(a+1,b), (a+1,b+1), (a,b+1)` (down), counter-clockwise. Level-`L` points have level-`L`
//! integer coordinates (level-0 coordinates times `3^L`). In level-1 coordinates the half-level
//! points (after one √3 step) are the old vertices (both coordinates `0 mod 3`) and the
//! centroids of up triangles (`1 mod 3`) and down triangles (`2 mod 3`).
//!
//! **Rules** (Kobbelt 2000, section 4; the whole-mesh version is the runtime's
//! `scheme::sqrt3::refine`, and the two are compared in the tests crate). First step: a
//! boundary vertex stays (`h = p`), an interior vertex moves by the valence-6 rule
//! `h = 2/3 p + 1/18 sum` of its six neighbours; every triangle gets its centroid `c`. Second
//! step, per level-1 point:
//!
//! * a boundary vertex: `(4 p_{a-1} + 19 p_a + 4 p_{a+1}) / 27`; an interior vertex:
//!   `2/3 h + 1/18 sum` of the six centroids around it;
//! * a centroid: `(1 - alpha_k) c + (alpha_k / k) (sum of its corners' h + sum of the centroids
//!   across its inner edges)`, `k = 3 +` the number of inner edges (5 for an up triangle on the
//!   boundary, 6 otherwise), `alpha_k = (4 - 2 cos(2π/k)) / 9`;
//! * a boundary third: `(p_{a-1} + 16 p_a + 10 p_{a+1}) / 27` nearer `p_a`, and its mirror;
//! * every other point (the thirds of inner edges): the average of the three half-level points
//!   among its six unit neighbours.
//!
//! `alpha_5` has `cos(2π/5)`, so the rows are f64.

use std::collections::{BTreeMap, HashMap};

use crate::TriangleVertexRule;

/// A lattice point `(a, b)`, `b >= 0`.
pub type StripPoint = (i64, i64);

/// Weights over lattice points.
pub type StripRow = BTreeMap<StripPoint, f64>;

/// The six unit steps of the lattice, counter-clockwise from `(1, 0)`.
const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// The offsets, in level-1 coordinates, from a vertex to the centroids of its six triangles.
const CENTROIDS_AROUND_VERTEX: [(i64, i64); 6] =
    [(1, 1), (-2, 1), (1, -2), (-1, -1), (2, -1), (-1, 2)];

/// The offsets, in level-1 coordinates, from an up triangle's centroid to the centroids across
/// its edges (bottom edge first) and to its corners.
const UP_ACROSS: [(i64, i64); 3] = [(1, -2), (1, 1), (-2, 1)];
const UP_CORNERS: [(i64, i64); 3] = [(-1, -1), (2, -1), (-1, 2)];

/// The same for a down triangle's centroid.
const DOWN_ACROSS: [(i64, i64); 3] = [(-1, -1), (2, -1), (-1, 2)];
const DOWN_CORNERS: [(i64, i64); 3] = [(1, -2), (1, 1), (-2, 1)];

/// `alpha_k` of √3 (Kobbelt 2000), f64.
fn alpha(valence: u32) -> f64 {
    let (_, beta) = TriangleVertexRule::Sqrt3.weights(valence);
    beta.value * f64::from(valence)
}

fn add_scaled(row: &mut StripRow, terms: &StripRow, w: f64) {
    for (&p, &x) in terms {
        *row.entry(p).or_insert(0.0) += w * x;
    }
}

/// The first step's value at the half-level point `q` (level-1 coordinates), over level-0
/// points; `None` when `q` is not a half-level point of the half-plane.
fn half_level(q: (i64, i64)) -> Option<StripRow> {
    let (x, y) = q;
    let (i, j) = (x.rem_euclid(3), y.rem_euclid(3));
    if i != j || y < 0 {
        return None;
    }
    let (a, b) = ((x - i) / 3, (y - j) / 3);
    let mut row = StripRow::new();
    match i {
        0 if b == 0 => {
            row.insert((a, 0), 1.0);
        }
        0 => {
            row.insert((a, b), 2.0 / 3.0);
            for (da, db) in NEIGHBOURS {
                row.insert((a + da, b + db), 1.0 / 18.0);
            }
        }
        1 => {
            for p in [(a, b), (a + 1, b), (a, b + 1)] {
                row.insert(p, 1.0 / 3.0);
            }
        }
        _ => {
            for p in [(a + 1, b), (a + 1, b + 1), (a, b + 1)] {
                row.insert(p, 1.0 / 3.0);
            }
        }
    }
    Some(row)
}

/// The composed step's row of the level-1 point `q` (level-1 coordinates, `q.1 >= 0`) over
/// level-0 points (module docs).
pub fn level1_row(q: (i64, i64)) -> StripRow {
    let (x, y) = q;
    assert!(y >= 0, "the point {q:?} is outside the half-plane");
    let half = |p: (i64, i64)| half_level(p).expect("a half-level point of the half-plane");
    let (i, j) = (x.rem_euclid(3), y.rem_euclid(3));
    let mut row = StripRow::new();
    if y == 0 {
        let a = (x - i) / 3;
        let weights: &[(i64, f64)] = match i {
            0 => &[(-1, 4.0), (0, 19.0), (1, 4.0)],
            1 => &[(-1, 1.0), (0, 16.0), (1, 10.0)],
            _ => &[(0, 10.0), (1, 16.0), (2, 1.0)],
        };
        for &(da, w) in weights {
            row.insert((a + da, 0), w / 27.0);
        }
        return row;
    }
    let offset = |d: (i64, i64)| (x + d.0, y + d.1);
    match (i, j) {
        (0, 0) => {
            add_scaled(&mut row, &half(q), 2.0 / 3.0);
            for d in CENTROIDS_AROUND_VERTEX {
                add_scaled(&mut row, &half(offset(d)), 1.0 / 18.0);
            }
        }
        (1, 1) | (2, 2) => {
            let (across, corners) = if i == 1 {
                (UP_ACROSS, UP_CORNERS)
            } else {
                (DOWN_ACROSS, DOWN_CORNERS)
            };
            let neighbours: Vec<(i64, i64)> = across
                .iter()
                .chain(&corners)
                .map(|&d| offset(d))
                .filter(|p| p.1 >= 0)
                .collect();
            let k = neighbours.len() as u32;
            let a = alpha(k);
            add_scaled(&mut row, &half(q), 1.0 - a);
            for p in neighbours {
                add_scaled(&mut row, &half(p), a / f64::from(k));
            }
        }
        _ => {
            for d in NEIGHBOURS {
                if let Some(h) = half_level(offset(d)) {
                    add_scaled(&mut row, &h, 1.0 / 3.0);
                }
            }
        }
    }
    row.retain(|_, w| *w != 0.0);
    row
}

/// Rows of level-`L` points over level-0 points, memoized: level `L` is the composed step
/// applied to level `L - 1`, whose points are level-0 points of the same rules one level down.
#[derive(Clone, Debug, Default)]
pub struct StripRows {
    memo: HashMap<(u32, StripPoint), StripRow>,
}

impl StripRows {
    /// An empty memo.
    pub fn new() -> Self {
        Self::default()
    }

    /// The row of the level-`level` point `q` (level-`level` coordinates) over level-0 points.
    pub fn row(&mut self, level: u32, q: StripPoint) -> StripRow {
        if level == 0 {
            return StripRow::from([(q, 1.0)]);
        }
        if let Some(row) = self.memo.get(&(level, q)) {
            return row.clone();
        }
        let mut row = StripRow::new();
        for (p, w) in level1_row(q) {
            let inner = self.row(level - 1, p);
            add_scaled(&mut row, &inner, w);
        }
        row.retain(|_, w| *w != 0.0);
        self.memo.insert((level, q), row.clone());
        row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every row is an affine combination (weights sum to 1), reads only the half-plane, and
    /// stays within two level-0 units of the point (the reach the layout will rely on).
    #[test]
    fn rows_are_affine_and_local() {
        for y in 0..9 {
            for x in -4..5 {
                let row = level1_row((x, y));
                let sum: f64 = row.values().sum();
                assert!((sum - 1.0).abs() < 1e-14, "({x}, {y}): {sum}");
                for &(a, b) in row.keys() {
                    assert!(b >= 0, "({x}, {y}) reads ({a}, {b})");
                    let (da, db) = (3 * a - x, 3 * b - y);
                    let hex = da.abs().max(db.abs()).max((da + db).abs());
                    assert!(hex <= 6, "({x}, {y}) reads ({a}, {b})");
                }
            }
        }
    }

    /// Far from the boundary the rules are the interior ones, so a row moved by whole level-0
    /// units is the moved point's row; next to the boundary a centroid's rule changes.
    #[test]
    fn rows_are_translation_invariant_away_from_the_boundary() {
        for q in [(0, 9), (1, 10), (2, 11), (1, 9), (0, 10)] {
            let here = level1_row(q);
            let shifted = level1_row((q.0 + 3, q.1 + 3));
            let moved: StripRow = here
                .iter()
                .map(|(&(a, b), &w)| ((a + 1, b + 1), w))
                .collect();
            assert_eq!(moved.len(), shifted.len(), "{q:?}");
            for (p, w) in &moved {
                assert!((shifted[p] - w).abs() < 1e-15, "{q:?}");
            }
        }
        let near = level1_row((1, 1));
        let far = level1_row((1, 10));
        assert_ne!(
            near.len(),
            far.len(),
            "the boundary changes the centroid's rule"
        );
    }
}
