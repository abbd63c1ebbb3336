//! The merge strips between two fan blocks ([`super::fans`]), found by the scan with the
//! blocks: a run of triangles, each `[b_j, a_(i+1), a_i]` (the row `a` advances) or
//! `[b_j, b_(j+1), a_i]` (the row `b` does), from `(i, j) = (0, 0)` to the rows' ends: two rows
//! merged in order of their parameters, whatever their lengths (`kernel::merge_rows`). Its rung
//! `a_i b_j` between two consecutive triangles is used by both, once each way.
//!
//! The scan keeps a run whose row `a` has the points of a fan block's side as the block's border
//! runs it, and whose row `b` those of a side run backwards, recognised from the points alone
//! ([`side_of_points`]): which block that is, and whether the scan kept it, is settled once
//! every piece of the list is scanned ([`super::fan_grid`]).

use std::ops::Range;

use super::fans::{FanBlock, MAX_FAN_RATE};

/// A side of a fan block named by its points: the block's first vertex and rate, and the side
/// ([`FanBlock::side_point`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct FanSide {
    pub(super) first: u32,
    pub(super) n: u32,
    pub(super) side: u8,
}

/// A merge strip whose rows are fan blocks' sides: `sides[0]` its row `a`, `sides[1]` its row
/// `b` run backwards.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct MergeStrip {
    pub(super) triangles: Range<usize>,
    pub(super) sides: [FanSide; 2],
}

/// The two rows of a strip, reused from one strip to the next.
#[derive(Debug, Default)]
pub(super) struct Rows {
    pub(super) a: Vec<u32>,
    pub(super) b: Vec<u32>,
}

impl Rows {
    /// The sides of two fan blocks whose points the rows are (`a` as its border runs it, `b`
    /// the other way), if they are two different blocks' sides.
    pub(super) fn sides(&mut self) -> Option<[FanSide; 2]> {
        let a = side_of_points(&self.a)?;
        self.b.reverse();
        let b = side_of_points(&self.b)?;
        (a.first != b.first).then_some([a, b])
    }
}

/// The zigzag of triangles that starts at `triangles[0]`, each triangle advancing one of two
/// rows, read into `rows` but for its last triangle's middle vertex, which ends one row or the
/// other (the triangle alone does not say which): its length in triangles (1 when the second
/// triangle does not go on from the first) and that vertex.
fn zigzag_at(triangles: &[[u32; 3]], rows: &mut Rows) -> (usize, u32) {
    let Some(&[x, _, z]) = triangles.first() else {
        return (0, 0);
    };
    rows.a.clear();
    rows.b.clear();
    rows.a.push(z);
    rows.b.push(x);
    let mut length = 1;
    while let Some(&next) = triangles.get(length) {
        let this = triangles[length - 1];
        // The next triangle begins and ends with the pair `(b_j, a_i)` this one leaves.
        if (next[0], next[2]) == (this[0], this[1]) {
            rows.a.push(this[1]);
        } else if (next[0], next[2]) == (this[1], this[2]) {
            rows.b.push(this[1]);
        } else {
            break;
        }
        length += 1;
    }
    (length, triangles[length - 1][1])
}

/// The merge strip that starts at `triangles[0]` (its `triangles` from 0), or the length of the
/// zigzag there that is none (at least 1).
pub(super) fn merge_strip_at(triangles: &[[u32; 3]], rows: &mut Rows) -> Result<MergeStrip, usize> {
    let (length, last) = zigzag_at(triangles, rows);
    if length < 2 {
        return Err(1);
    }
    // Both rows have an odd length (a side's `2n - 1` points): the last point ends the row
    // that is one short.
    if rows.a.len() % 2 == 0 {
        rows.a.push(last);
    } else {
        rows.b.push(last);
    }
    match rows.sides() {
        Some(sides) => Ok(MergeStrip {
            triangles: 0..length,
            sides,
        }),
        None => Err(length),
    }
}

/// The fan block side whose points `row` holds, in the order the block's border runs them,
/// from the points alone: a side of `2n - 1` points is side 0 when its second point follows
/// its first, side 1 when it is one less, side 2 when two less (the numbering of
/// [`super::fans`]); then the block's first vertex is the first point's offset back, and every
/// point is compared (without a branch per point).
pub(super) fn side_of_points(row: &[u32]) -> Option<FanSide> {
    let [p0, p1, ..] = *row else {
        return None;
    };
    let n = u32::try_from(row.len().div_ceil(2)).ok()?;
    if row.len() % 2 == 0 || !(3..=MAX_FAN_RATE).contains(&n) {
        return None;
    }
    // Point 0 of each side: `first`, `up(n - 1, 0) = first + 2n - 2`, `up(0, n - 1) = first
    // + n^2 - 1`.
    let (side, offset) = match p0.wrapping_sub(p1) {
        u32::MAX => (0u8, 0),
        1 => (1, 2 * n - 2),
        2 => (2, n * n - 1),
        _ => return None,
    };
    let first = p0.checked_sub(offset)?;
    let block = FanBlock { start: 0, first, n };
    if block.vertices().end > 1 << 32 {
        return None;
    }
    // Each side compared with a literal side number, so that `side_point`'s choice of side
    // and of up or down point folds away out of the loop.
    let point = |side: u8| move |k: u32| block.side_point(side, k);
    let mismatch = match side {
        0 => differs(row, point(0)),
        1 => differs(row, point(1)),
        _ => differs(row, point(2)),
    };
    (mismatch == 0).then_some(FanSide { first, n, side })
}

/// The bits in which a row of odd length differs from the points `point(k)`, compared a pair
/// `2t`, `2t + 1` at a time (an up and a down point: each pair's formula is known without a
/// branch), branch-free per point.
fn differs(row: &[u32], point: impl Fn(u32) -> u32) -> u32 {
    let Some((&last, pairs)) = row.split_last() else {
        return 0;
    };
    let last_place = pairs.len() as u32;
    (0u32..)
        .zip(pairs.chunks_exact(2))
        .fold(last ^ point(last_place), |d, (t, pair)| {
            d | (pair[0] ^ point(2 * t)) | (pair[1] ^ point(2 * t + 1))
        })
}

#[cfg(test)]
mod tests {
    use super::super::fans::tests::fans;
    use super::*;

    /// Every side of fan blocks of rates 3 to 11 is recognised from its points, as
    /// `side_point` numbers them (itself tested against the hexagons' geometry), and a side
    /// with one point changed, or cut to an even length, is not.
    #[test]
    fn sides_are_recognised_from_their_points() {
        for n in 3..12 {
            let block = FanBlock {
                start: 0,
                first: 1_000,
                n,
            };
            for side in 0..3u8 {
                let row: Vec<u32> = (0..2 * n - 1).map(|k| block.side_point(side, k)).collect();
                let expected = FanSide {
                    first: 1_000,
                    n,
                    side,
                };
                assert_eq!(
                    side_of_points(&row),
                    Some(expected),
                    "rate {n}, side {side}"
                );
                for k in 0..row.len() {
                    let mut changed = row.clone();
                    changed[k] += 1;
                    assert_ne!(side_of_points(&changed), Some(expected), "{n} {side} {k}");
                }
                // An even number of points, or fewer than a rate 3 side's five, is no side.
                assert_eq!(side_of_points(&row[..row.len() - 1]), None);
                assert_eq!(side_of_points(&row[..4.min(row.len())]), None);
            }
        }
    }

    /// The strip between side 1 of one block (rate 5) and side 0 of another (rate 7), merged
    /// as the tessellator merges two rows: found whole, with both sides; a stray triangle
    /// ahead of it is a zigzag of one.
    #[test]
    fn a_merge_strip_is_found_with_its_sides() {
        let (one, other) = (
            FanBlock {
                start: 0,
                first: 0,
                n: 5,
            },
            FanBlock {
                start: 0,
                first: 500,
                n: 7,
            },
        );
        let a: Vec<u32> = (0..9).map(|k| one.side_point(1, k)).collect();
        let mut b: Vec<u32> = (0..13).map(|k| other.side_point(0, k)).collect();
        b.reverse();
        // Merged by parameter: `a_i` at `i / 8`, `b_j` at `j / 12`.
        let mut triangles = vec![[900, 901, 902]];
        let (mut i, mut j) = (0, 0);
        while i + 1 < a.len() || j + 1 < b.len() {
            let advance_a = j + 1 == b.len() || (i + 1 < a.len() && (i + 1) * 12 <= (j + 1) * 8);
            if advance_a {
                triangles.push([b[j], a[i + 1], a[i]]);
                i += 1;
            } else {
                triangles.push([b[j], b[j + 1], a[i]]);
                j += 1;
            }
        }
        let mut rows = Rows::default();
        assert_eq!(merge_strip_at(&triangles, &mut rows), Err(1));
        let strip = merge_strip_at(&triangles[1..], &mut rows).expect("a strip");
        assert_eq!(strip.triangles, 0..20);
        assert_eq!(
            strip.sides,
            [
                FanSide {
                    first: 0,
                    n: 5,
                    side: 1
                },
                FanSide {
                    first: 500,
                    n: 7,
                    side: 0
                }
            ]
        );
        // The blocks' triangles themselves are no strip.
        let mut block = Vec::new();
        fans(0, 5, &mut block);
        assert!(merge_strip_at(&block, &mut rows).is_err());
    }
}
