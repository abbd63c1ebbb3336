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

impl FanSide {
    /// The block the side is named by (its first triangle unknown: `start` 0).
    fn block(&self) -> FanBlock {
        FanBlock {
            start: 0,
            first: self.first,
            n: self.n,
        }
    }
}

/// A merge strip whose rows are fan blocks' sides: `sides[0]` its row `a`, `sides[1]` its row
/// `b` run backwards.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct MergeStrip {
    pub(super) triangles: Range<usize>,
    pub(super) sides: [FanSide; 2],
    pub(super) advances: Advances,
}

/// How many triangles at either end of a strip [`Advances`] records.
pub(super) const END_TRIANGLES: usize = 32;

/// Which row the triangles at a strip's two ends advance, as the scan read them: bit `k` of
/// `head` is set when triangle `k` advances row `a`, bit `k` of `tail` when the `k`-th from the
/// last does (the first and last [`END_TRIANGLES`]). With the sides, they give those
/// triangles again without reading the list (where each strip's ends cost a cache miss, long
/// after the scan).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Advances {
    head: u32,
    tail: u32,
}

impl Advances {
    /// A strip of quads' (`[b_k, a_(k+1), a_k], [b_k, b_(k+1), a_(k+1)]`): the rows in turn,
    /// `a` first, so `b` last.
    pub(super) const QUADS: Advances = Advances {
        head: 0x5555_5555,
        tail: 0xaaaa_aaaa,
    };

    /// Record that triangle `k` (from the strip's first) advances row `a` or not.
    fn push(&mut self, k: usize, row_a: bool) {
        if k < END_TRIANGLES {
            self.head |= u32::from(row_a) << k;
        }
        self.tail = self.tail << 1 | u32::from(row_a);
    }
}

/// A point of a strip's rows: the row (0 for `a`, 1 for `b`) and its place along the strip
/// (`a_i`, `b_j`: `b` counted from the strip's first triangle, against its side's order).
pub(super) type RowPoint = (usize, u32);

impl MergeStrip {
    /// The vertex at a point of the rows.
    pub(super) fn vertex(&self, (row, k): RowPoint) -> u32 {
        let side = self.sides[row & 1];
        let along = if row == 0 {
            k
        } else {
            self.row_length(1) - 1 - k
        };
        side.block().side_point(side.side, along)
    }

    /// The points in a row: a side's `2n - 1`.
    pub(super) fn row_length(&self, row: usize) -> u32 {
        2 * self.sides[row & 1].n - 1
    }

    /// The strip's first triangles (at most [`END_TRIANGLES`]) as points of its rows, from its
    /// advances: those of the list, which the scan compared.
    pub(super) fn head(&self) -> impl Iterator<Item = [RowPoint; 3]> {
        let bits = self.advances.head;
        let (mut i, mut j) = (0, 0);
        (0..self.triangles.len().min(END_TRIANGLES)).map(move |k| {
            if bits >> k & 1 == 1 {
                i += 1;
                [(1, j), (0, i), (0, i - 1)]
            } else {
                j += 1;
                [(1, j - 1), (1, j), (0, i)]
            }
        })
    }

    /// The strip's last triangles (at most [`END_TRIANGLES`]), the last first, as
    /// [`MergeStrip::head`] makes the first.
    pub(super) fn tail(&self) -> impl Iterator<Item = [RowPoint; 3]> {
        let bits = self.advances.tail;
        // Each row's last point; a triangle that advances a row steps back along it.
        let (mut i, mut j) = (self.row_length(0) - 1, self.row_length(1) - 1);
        (0..self.triangles.len().min(END_TRIANGLES)).map(move |k| {
            if bits >> k & 1 == 1 {
                i = i.saturating_sub(1);
                [(1, j), (0, i + 1), (0, i)]
            } else {
                j = j.saturating_sub(1);
                [(1, j), (1, j + 1), (0, i)]
            }
        })
    }
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
/// triangle does not go on from the first), that vertex, and the rows advanced but the last
/// triangle's.
fn zigzag_at(triangles: &[[u32; 3]], rows: &mut Rows) -> (usize, u32, Advances) {
    let mut advances = Advances::default();
    let Some(&[x, _, z]) = triangles.first() else {
        return (0, 0, advances);
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
            advances.push(length - 1, true);
        } else if (next[0], next[2]) == (this[1], this[2]) {
            rows.b.push(this[1]);
            advances.push(length - 1, false);
        } else {
            break;
        }
        length += 1;
    }
    (length, triangles[length - 1][1], advances)
}

/// The merge strip that starts at `triangles[0]` (its `triangles` from 0), or the length of the
/// zigzag there that is none (at least 1).
pub(super) fn merge_strip_at(triangles: &[[u32; 3]], rows: &mut Rows) -> Result<MergeStrip, usize> {
    let (length, last, mut advances) = zigzag_at(triangles, rows);
    if length < 2 {
        return Err(1);
    }
    // Both rows have an odd length (a side's `2n - 1` points): the last point ends the row
    // that is one short.
    let row_a = rows.a.len() % 2 == 0;
    if row_a {
        rows.a.push(last);
    } else {
        rows.b.push(last);
    }
    advances.push(length - 1, row_a);
    match rows.sides() {
        Some(sides) => Ok(MergeStrip {
            triangles: 0..length,
            sides,
            advances,
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
    let found = FanSide {
        first: p0.checked_sub(offset)?,
        n,
        side,
    };
    let block = found.block();
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
    (mismatch == 0).then_some(found)
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
pub(super) mod tests {
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

    /// The triangles of the strip merging row `a` (`a.len()` points at `i / (len - 1)`) with
    /// row `b`, in order of their parameters, as the tessellator merges two rows
    /// (`kernel::merge_rows`), into `out`.
    pub(in crate::mesh::watertight) fn merged(a: &[u32], b: &[u32], out: &mut Vec<[u32; 3]>) {
        let (last_a, last_b) = (a.len() - 1, b.len() - 1);
        let (mut i, mut j) = (0, 0);
        while i < last_a || j < last_b {
            if j == last_b || (i < last_a && (i + 1) * last_b <= (j + 1) * last_a) {
                out.push([b[j], a[i + 1], a[i]]);
                i += 1;
            } else {
                out.push([b[j], b[j + 1], a[i]]);
                j += 1;
            }
        }
    }

    /// Two fan blocks of rates `n` and `m`, apart (at vertices 0 and 10,000).
    pub(in crate::mesh::watertight) fn two_blocks(n: u32, m: u32) -> (FanBlock, FanBlock) {
        let block = |first, n| FanBlock { start: 0, first, n };
        (block(0, n), block(10_000, m))
    }

    /// A side of a fan block, as its border runs it (`backwards`: the other way).
    pub(in crate::mesh::watertight) fn side(
        block: &FanBlock,
        side: u8,
        backwards: bool,
    ) -> Vec<u32> {
        let mut row: Vec<u32> = (0..2 * block.n - 1)
            .map(|k| block.side_point(side, k))
            .collect();
        if backwards {
            row.reverse();
        }
        row
    }

    /// The triangles a strip's advances make at its two ends are the list's, as the scan found
    /// the strip, for rows of equal and of very different lengths (the first and last 32
    /// triangles, of strips of 8 to 84); a strip of quads' advances are the rows in turn.
    #[test]
    fn advances_make_the_strips_ends_again() {
        let mut rows = Rows::default();
        for (n, m) in [(3, 3), (5, 7), (7, 5), (8, 8), (17, 19), (3, 40), (40, 3)] {
            let (one, other) = two_blocks(n, m);
            for (sa, sb) in [(0, 2), (1, 0), (2, 1)] {
                let mut triangles = Vec::new();
                merged(
                    &side(&one, sa, false),
                    &side(&other, sb, true),
                    &mut triangles,
                );
                let strip = merge_strip_at(&triangles, &mut rows).expect("a strip");
                assert_eq!(strip.triangles, 0..triangles.len(), "{n} {m}");
                let vertices = |t: [RowPoint; 3]| t.map(|p| strip.vertex(p));
                let head: Vec<[u32; 3]> = strip.head().map(vertices).collect();
                let tail: Vec<[u32; 3]> = strip.tail().map(vertices).collect();
                let ends = triangles.len().min(END_TRIANGLES);
                assert_eq!(head, triangles[..ends], "{n} {m} {sa} {sb}");
                assert!(tail.iter().eq(triangles.iter().rev().take(ends)), "{n} {m}");
            }
        }
        // Two rows of equal length merged: the rows in turn, `a` first.
        let (a, b): (Vec<u32>, Vec<u32>) = ((0..40).collect(), (100..140).collect());
        let mut triangles = Vec::new();
        merged(&a, &b, &mut triangles);
        let (_, _, advances) = zigzag_at(&triangles, &mut rows);
        let mut quads = Advances::QUADS;
        // The zigzag leaves the last triangle's advance open; it is `b`'s.
        quads.tail >>= 1;
        assert_eq!(advances, quads);
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
        let mut triangles = vec![[900, 901, 902]];
        merged(
            &side(&one, 1, false),
            &side(&other, 0, true),
            &mut triangles,
        );
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
