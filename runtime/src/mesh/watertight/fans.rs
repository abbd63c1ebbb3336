//! The pattern of a triangle face's grid in a triangle dual grid (Loop, the butterfly, √3):
//! hexagons fanned at the face's interior primal points, found in the triangle list by the
//! scan ([`fan_block_at`]) and paired in place as the quad grids' blocks are.
//!
//! A *fan block* of rate `n >= 3` over the vertices from `first` numbers
//!
//! * the dual points (the centroids of the face's `n^2` small triangles) row by row: row `j`
//!   (`0..n`) holds `2(n - j) - 1` of them, `up(i, j) = first + j (2n - j) + 2i` (the triangle
//!   with corners `(i, j), (i + 1, j), (i, j + 1)`) and `down(i, j) = up(i, j) + 1` (corners
//!   `(i + 1, j), (i, j + 1), (i + 1, j + 1)`);
//! * then the interior primal points `(i, j)`, `i, j >= 1`, `i + j <= n - 1`, row by row:
//!   `centre(i, j) = first + n^2 + (j - 1)(n - 1) - (j - 1) j / 2 + i - 1`;
//!
//! and its triangles are, for `j` in `1..n` and `i` in `1..n - j`, the six `[c, x_r, x_(r+1)]`
//! (`r` in `0..6`, `x_6 = x_0`) around `c = centre(i, j)` over its hexagon, counterclockwise:
//! `up(i, j), down(i - 1, j), up(i - 1, j), down(i - 1, j - 1), up(i, j - 1), down(i, j - 1)`:
//! `3(n - 1)(n - 2)` triangles.
//!
//! Why its inner edges pair inside it: a spoke `c x_r` is used by the fan's triangles `r - 1`
//! and `r`, one each way; a rim `x_r x_(r+1)` joins the two small triangles on the primal edge
//! from `c` to a neighbour `q`, and where `q` is an interior point too its fan runs the same two
//! dual points the other way (both fans turn counterclockwise). The rims whose `q` is not
//! interior are the block's border, used once: they pair outside it.

use std::ops::Range;

/// The largest rate of a fan block: its index arithmetic (`j (2n - j)`, `n^2`) then stays far
/// from `u32`'s end.
pub(super) const MAX_FAN_RATE: u32 = 1 << 12;

/// A triangle face's grid found in the triangle list: the module's pattern at rate `n`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct FanBlock {
    /// The block's first triangle.
    pub(super) start: usize,
    pub(super) first: u32,
    pub(super) n: u32,
}

/// A vertex of a fan block: a dual point (its small triangle, `down` or up) or an interior
/// primal point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FanVertex {
    Dual { i: u32, j: u32, down: bool },
    Centre { i: u32, j: u32 },
}

/// The last row `j` in `0..rows` whose start `start(j)` (increasing) is at most `x`.
fn row_holding(x: u32, rows: u32, start: impl Fn(u32) -> u32) -> u32 {
    let (mut low, mut high) = (0, rows);
    while high - low > 1 {
        let middle = (low + high) / 2;
        if start(middle) <= x {
            low = middle;
        } else {
            high = middle;
        }
    }
    low
}

impl FanBlock {
    pub(super) fn triangles(&self) -> Range<usize> {
        let n = self.n as usize;
        self.start..self.start + 3 * (n - 1) * (n - 2)
    }

    pub(super) fn vertices(&self) -> Range<u64> {
        let (first, n) = (u64::from(self.first), u64::from(self.n));
        first..first + n * n + (n - 1) * (n - 2) / 2
    }

    fn up(&self, i: u32, j: u32) -> u32 {
        self.first + j * (2 * self.n - j) + 2 * i
    }

    fn centre(&self, i: u32, j: u32) -> u32 {
        let n = self.n;
        self.first + n * n + (j - 1) * (n - 1) - (j - 1) * j / 2 + i - 1
    }

    /// The hexagon around the interior point `(i, j)`, counterclockwise (the module's order).
    fn ring(&self, i: u32, j: u32) -> [u32; 6] {
        [
            self.up(i, j),
            self.up(i - 1, j) + 1,
            self.up(i - 1, j),
            self.up(i - 1, j - 1) + 1,
            self.up(i, j - 1),
            self.up(i, j - 1) + 1,
        ]
    }

    fn interior(&self, (i, j): (u32, u32)) -> bool {
        i >= 1 && j >= 1 && u64::from(i) + u64::from(j) < u64::from(self.n)
    }

    /// Which vertex of the block `v` is.
    fn vertex(&self, v: u32) -> FanVertex {
        let n = self.n;
        let x = v - self.first;
        if x < n * n {
            let j = row_holding(x, n, |j| j * (2 * n - j));
            let along = x - j * (2 * n - j);
            FanVertex::Dual {
                i: along / 2,
                j,
                down: along % 2 == 1,
            }
        } else {
            let y = x - n * n;
            let start = |k: u32| k * (n - 2) - k * k.saturating_sub(1) / 2;
            let k = row_holding(y, n - 2, start);
            FanVertex::Centre {
                i: y - start(k) + 1,
                j: k + 1,
            }
        }
    }

    /// The corners of a dual point's small triangle.
    fn corners(i: u32, j: u32, down: bool) -> [(u32, u32); 3] {
        if down {
            [(i + 1, j), (i, j + 1), (i + 1, j + 1)]
        } else {
            [(i, j), (i + 1, j), (i, j + 1)]
        }
    }

    /// Whether the edge between the block's vertices `p` and `q` is one its triangles use both
    /// ways: a spoke (an interior point and a corner of its hexagon), or a rim between two
    /// small triangles on a primal edge whose two ends are both interior.
    pub(super) fn inner_edge(&self, p: u32, q: u32) -> bool {
        match (self.vertex(p), self.vertex(q)) {
            (FanVertex::Centre { i, j }, FanVertex::Dual { i: k, j: l, down })
            | (FanVertex::Dual { i: k, j: l, down }, FanVertex::Centre { i, j }) => {
                Self::corners(k, l, down).contains(&(i, j))
            }
            (
                FanVertex::Dual { i, j, down },
                FanVertex::Dual {
                    i: k,
                    j: l,
                    down: other,
                },
            ) => {
                let theirs = Self::corners(k, l, other);
                let (shared, interior) = Self::corners(i, j, down)
                    .into_iter()
                    .filter(|c| theirs.contains(c))
                    .fold((0, true), |(shared, interior), c| {
                        (shared + 1, interior && self.interior(c))
                    });
                shared == 2 && interior
            }
            _ => false,
        }
    }

    /// Whether the block's vertex `v` is *deep*: an interior point, or a dual point whose three
    /// corners are interior points (the claims of [`super::fan_grid`] rest on it).
    ///
    /// Every inner edge has a deep end: a spoke its interior point; a rim lies on a primal
    /// edge between two interior points, an edge of the triangle the interior points fill
    /// (side `n - 3 >= 1`), which bounds at least one of that triangle's small triangles, a
    /// dual point with three interior corners. A vertex that is not deep is a side's point
    /// ([`FanBlock::side_point`]): a dual point with a corner on the face's border.
    #[cfg(test)]
    pub(super) fn deep(&self, v: u32) -> bool {
        match self.vertex(v) {
            FanVertex::Centre { .. } => true,
            FanVertex::Dual { i, j, down } => {
                Self::corners(i, j, down).iter().all(|&c| self.interior(c))
            }
        }
    }

    /// Side `side`'s dual points in the order the block's border runs them (counterclockwise
    /// around the face): the `2n - 1` dual points of the small triangles on that side of the
    /// face, from the corner point before it to the one after. Side 0 is `j = 0`, side 1
    /// `i + j = n`, side 2 `i = 0`. The border edges along the side join its points `1..=2n-3`
    /// (the corner points' segments `0 1` and `2n-3 2n-2` are no block edges); a strip along
    /// the side runs all of them the other way.
    pub(super) fn side_point(&self, side: u8, k: u32) -> u32 {
        let (n, t) = (self.n, k / 2);
        let down = k % 2 == 1;
        let (i, j) = match side {
            0 => return self.first + k,
            1 if down => (n - 2 - t, t),
            1 => (n - 1 - t, t),
            _ if down => (0, n - 2 - t),
            _ => (0, n - 1 - t),
        };
        self.up(i, j) + u32::from(down)
    }

    /// Points `2..=2n-4` of a side belong to that side alone (the others are its corner
    /// points and their neighbours, on two sides each): the side and the place of the block's
    /// vertex `v` when it is one of them.
    #[cfg(test)]
    pub(super) fn side_inside(&self, v: u32) -> Option<(u8, u32)> {
        let n = self.n;
        let FanVertex::Dual { i, j, down } = self.vertex(v) else {
            return None;
        };
        let d = u32::from(down);
        let place = if j == 0 {
            (0, 2 * i + d)
        } else if i == 0 {
            (2, 2 * (n - 1 - j) - d)
        } else if i + j + 1 + d == n {
            (1, 2 * j + d)
        } else {
            return None;
        };
        (2..=2 * n - 4).contains(&place.1).then_some(place)
    }

    /// The border edges along side `side`, as the block's triangles run them: between its
    /// points `1..=2n-3` ([`FanBlock::side_point`]).
    pub(super) fn side_edges(&self, side: u8, out: &mut Vec<(u32, u32)>) {
        let point = |k| self.side_point(side, k);
        out.extend((1..2 * self.n - 3).map(|k| (point(k), point(k + 1))));
    }

    /// The block's border edges, as its triangles run them.
    pub(super) fn border_edges(&self, out: &mut Vec<(u32, u32)>) {
        for side in 0..3 {
            self.side_edges(side, out);
        }
    }
}

/// The fan block that starts at `triangles[0]`, if all of its triangles follow: its rate and
/// first vertex come from its first fan, `[c, first + 2n + 1, first + 2n], [c, first + 2n,
/// first + 2n - 1], [c, first + 2n - 1, first + 1]`, `c = first + n^2`.
pub(super) fn fan_block_at(triangles: &[[u32; 3]]) -> Option<FanBlock> {
    let [[c, x0, x1], [c1, x1_, x2], [c2, x2_, x3], ..] = *triangles else {
        return None;
    };
    if c1 != c || c2 != c || x1_ != x1 || x2_ != x2 || x1.checked_add(1) != Some(x0) {
        return None;
    }
    let first = x3.checked_sub(1)?;
    let twice = x0.checked_sub(first)?.checked_sub(1)?;
    let n = twice / 2;
    if twice % 2 != 0 || !(3..=MAX_FAN_RATE).contains(&n) {
        return None;
    }
    let block = FanBlock { start: 0, first, n };
    if block.vertices().end > 1 << 32
        || c != first + n * n
        || triangles.len() < block.triangles().len()
    {
        return None;
    }
    let mut at = 0;
    for j in 1..n - 1 {
        let fans = (n - 1 - j) as usize;
        let row = &triangles[at..at + 6 * fans];
        if !is_fan_row(row, block.centre(1, j), block.ring(1, j)) {
            return None;
        }
        at += 6 * fans;
    }
    Some(block)
}

/// Whether `row` is the fans around `c + k` over the hexagons `ring + 2k`, `k = 0, 1, ..`, in
/// order (every index fits: the block's range is checked first). Without a branch per index,
/// as the quad rows are compared.
fn is_fan_row(row: &[[u32; 3]], c: u32, ring: [u32; 6]) -> bool {
    let differs = (0u32..)
        .zip(row.chunks_exact(6))
        .fold(0, |differs, (k, fan)| {
            let x = ring.map(|x| x + 2 * k);
            (0..6).fold(differs, |differs, r| {
                let [p, q, s] = fan[r];
                differs | (p ^ (c + k)) | (q ^ x[r]) | (s ^ x[(r + 1) % 6])
            })
        });
    differs == 0
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The triangles of a fan block of rate `n` from `first`, fan by fan from the hexagon's
    /// geometry (the small triangles around each interior point, sorted by angle), not from the
    /// index formulas the scan uses.
    pub(in crate::mesh::watertight) fn fans(first: u32, n: u32, out: &mut Vec<[u32; 3]>) {
        // Dual points numbered row by row, up then down, as the module states.
        let mut index = std::collections::HashMap::new();
        let mut next = first;
        for j in 0..n {
            for i in 0..n - j {
                index.insert((i, j, false), next);
                next += 1;
                if i + j + 1 < n {
                    index.insert((i, j, true), next);
                    next += 1;
                }
            }
        }
        let centroid = |(i, j, down): (u32, u32, bool)| {
            let (i, j) = (f64::from(i), f64::from(j));
            if down {
                (i + 2.0 / 3.0, j + 2.0 / 3.0)
            } else {
                (i + 1.0 / 3.0, j + 1.0 / 3.0)
            }
        };
        for j in 1..n {
            for i in 1..n - j {
                // The six small triangles with corner (i, j).
                let mut around: Vec<(u32, u32, bool)> = index
                    .keys()
                    .copied()
                    .filter(|&(k, l, down)| FanBlock::corners(k, l, down).contains(&(i, j)))
                    .collect();
                assert_eq!(around.len(), 6);
                // Counterclockwise in the skewed plane (u + v/2, v sqrt(3)/2), from the
                // triangle between +u and +v.
                let angle = |d| {
                    let (u, v) = centroid(d);
                    let (x, y) = (u - f64::from(i), v - f64::from(j));
                    let a = (y * 3f64.sqrt() / 2.0).atan2(x + y / 2.0);
                    a.rem_euclid(std::f64::consts::TAU)
                };
                around.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)));
                let c = next;
                next += 1;
                for r in 0..6 {
                    out.push([c, index[&around[r]], index[&around[(r + 1) % 6]]]);
                }
            }
        }
    }

    /// The blocks the geometry makes are the ones the scan finds, with their vertex counts,
    /// and every vertex decodes to what the numbering states.
    #[test]
    fn the_scan_finds_blocks_made_from_the_geometry() {
        for n in 3..12 {
            let mut triangles = Vec::new();
            fans(40, n, &mut triangles);
            let block = fan_block_at(&triangles).expect("a block");
            assert_eq!(
                block,
                FanBlock {
                    start: 0,
                    first: 40,
                    n
                }
            );
            assert_eq!(block.triangles().len(), triangles.len());
            let used = triangles.iter().flatten().copied().max().unwrap_or(0);
            assert_eq!(block.vertices().end, u64::from(used) + 1, "rate {n}");
            // Cut short or with one index changed, it is no block.
            assert_eq!(fan_block_at(&triangles[..triangles.len() - 1]), None);
            let mut changed = triangles.clone();
            let last = changed.len() - 1;
            changed[last][2] += 1;
            assert_eq!(fan_block_at(&changed), None);
        }
    }

    /// Every edge the block's triangles use both ways is inner and has a deep end, every one
    /// used once is a border edge as the triangles run it (so the sides' points `1..=2n-3` are
    /// right), nothing else is an edge, the sides close around the face, and every vertex off
    /// them is deep.
    #[test]
    fn inner_and_border_edges_are_the_triangles() {
        for n in 3..10 {
            let mut triangles = Vec::new();
            fans(0, n, &mut triangles);
            let block = fan_block_at(&triangles).expect("a block");
            let directed: std::collections::HashSet<(u32, u32)> = triangles
                .iter()
                .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
                .collect();
            assert_eq!(directed.len(), 3 * triangles.len(), "an edge twice");
            let mut border = Vec::new();
            block.border_edges(&mut border);
            let mut expected: Vec<_> = directed
                .iter()
                .copied()
                .filter(|&(p, q)| !directed.contains(&(q, p)))
                .collect();
            expected.sort_unstable();
            border.sort_unstable();
            assert_eq!(border, expected, "rate {n}");
            let count = block.vertices().end as u32;
            for p in 0..count {
                for q in 0..count {
                    let both = directed.contains(&(p, q)) && directed.contains(&(q, p));
                    assert_eq!(block.inner_edge(p, q), both, "rate {n}, {p} {q}");
                    assert!(!both || block.deep(p) || block.deep(q), "rate {n}, {p} {q}");
                }
            }
            // The sides run around the face: each ends at the next one's first point, and
            // their points 2..=2n-4 are theirs alone, as `side_inside` finds them.
            for side in 0..3u8 {
                let last = block.side_point(side, 2 * n - 2);
                assert_eq!(last, block.side_point((side + 1) % 3, 0), "rate {n}");
            }
            for v in 0..count {
                let places: Vec<(u8, u32)> = (0..3u8)
                    .flat_map(|side| (2..=2 * n - 4).map(move |k| (side, k)))
                    .filter(|&(side, k)| block.side_point(side, k) == v)
                    .collect();
                assert!(places.len() <= 1, "rate {n}, vertex {v}: {places:?}");
                assert_eq!(
                    block.side_inside(v),
                    places.first().copied(),
                    "rate {n}, {v}"
                );
            }
            // Every vertex is deep or on a side.
            for v in 0..count {
                let on_side =
                    (0..3u8).any(|side| (0..2 * n - 1).any(|k| block.side_point(side, k) == v));
                assert!(block.deep(v) || on_side, "rate {n}, {v}");
            }
        }
    }
}
