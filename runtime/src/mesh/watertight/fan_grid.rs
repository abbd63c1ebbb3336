//! The pairing of a triangle dual grid's output: fan blocks (the faces' hexagon fans,
//! [`super::fans`]) and the *merge strips* between two of them, where no quad grid was found.
//!
//! A merge strip is a run of triangles, each `[b_j, a_(i+1), a_i]` (the row `a` advances) or
//! `[b_j, b_(j+1), a_i]` (the row `b` does), from `(i, j) = (0, 0)` to the rows' ends: two rows
//! merged in order of their parameters, whatever their lengths (`kernel::merge_rows`). Its rung
//! `a_i b_j` between two consecutive triangles is used by both, once each way. It is kept when
//! its row `a` is a whole side of a fan block as the block's border runs it and its row `b`
//! one of another block's run backwards ([`super::fans::FanBlock::side_point`]), each side matched once.
//!
//! Why the answer is the general check's: call a vertex *claimed* when it is deep in its block
//! (an interior point, or a dual point with three interior corners), one of a matched side's
//! points `2..=2n-4`, which lie on that side alone, or the point next to a block's corner (point
//! 1 of one side, `2n - 3` of the one before) when both sides are matched, by strips from two
//! different blocks. An edge and its reverse have the same ends, so the mesh is closed exactly
//! when both the edges with a claimed end and the others are. The edges at a claimed vertex
//! come from its block and the strips along its sides (a strip's triangles use its rows only,
//! and no other strip's rows hold such a point): the fans pair theirs, a strip's rungs pair
//! inside it (its end rungs join unclaimed corner points), the sides' border edges pair with the
//! strips' row edges, and the segment from a corner to the point next to it is run once by each
//! of the two strips that meet there; the rungs of those two strips at that point end in two
//! different blocks, so none is used by both. So where no other triangle touches a claimed vertex (checked,
//! a bit per vertex) the edges with a claimed end pair, and the rest go to the general check:
//! the other triangles', and the blocks' and strips' edges without a claimed end (the strips'
//! end rungs, what is next to a side no strip matched, that side's border). Where
//! another triangle does touch one, every edge goes to the general check.

use std::ops::{Range, RangeInclusive};

use rayon::prelude::*;

use super::grids::{Others, SCAN_CHUNK};
use super::{Block, BlockIndex, Seams};

/// A merge strip kept: its triangles, and the block and side of its rows `a` and `b`.
struct MergeStrip {
    triangles: Range<usize>,
    sides: [(usize, u8); 2],
}

/// The rows of the merge strip that starts at `triangles[0]` (at least two triangles), into
/// `a` and `b`, but for its last triangle's middle vertex, which ends one row or the other
/// (the triangle alone does not say which): returns the strip's length and that vertex.
fn zigzag_at(triangles: &[[u32; 3]], a: &mut Vec<u32>, b: &mut Vec<u32>) -> Option<(usize, u32)> {
    let [[x, y, z], second, ..] = *triangles else {
        return None;
    };
    a.clear();
    b.clear();
    a.push(z);
    b.push(x);
    // The pairs `(b_j, a_i)` that the next triangle must begin and end with.
    let advance = |[x, y, z]: [u32; 3], next: [u32; 3]| {
        if (next[0], next[2]) == (x, y) {
            Some(true)
        } else if (next[0], next[2]) == (y, z) {
            Some(false)
        } else {
            None
        }
    };
    advance([x, y, z], second)?;
    let mut length = 1;
    while let Some(&next) = triangles.get(length) {
        let this = triangles[length - 1];
        match advance(this, next) {
            Some(true) => a.push(this[1]),
            Some(false) => b.push(this[1]),
            None => break,
        }
        length += 1;
    }
    Some((length, triangles[length - 1][1]))
}

/// The fan block and side whose border runs `row` (`backwards`: runs it reversed), if any.
fn side_of_row(
    row: &[u32],
    backwards: bool,
    blocks: &[Block],
    index: &BlockIndex,
) -> Option<(usize, u8)> {
    // A fan block's side has `2n - 1 >= 5` points.
    if row.len() < 5 {
        return None;
    }
    let at = |k: usize| {
        if backwards {
            row[row.len() - 1 - k]
        } else {
            row[k]
        }
    };
    let v = at(2);
    let k = index.holding(v)?;
    let Block::Fans(block) = &blocks[k] else {
        return None;
    };
    let (side, place) = block.side_inside(v)?;
    let length = 2 * block.n as usize - 1;
    (place == 2
        && row.len() == length
        && (0..length).all(|p| at(p) == block.side_point(side, p as u32)))
    .then_some((k, side))
}

/// The merge strips in the runs of `others` whose rows are two different fan blocks' sides
/// (not yet each side once), and the triangles left.
fn find_strips(
    triangles: &[[u32; 3]],
    others: &Others,
    blocks: &[Block],
    index: &BlockIndex,
) -> (Vec<MergeStrip>, Vec<Range<usize>>) {
    let found: Vec<_> = others
        .pieces(SCAN_CHUNK)
        .into_par_iter()
        .map(|piece| {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let (mut strips, mut left) = (Vec::new(), Vec::new());
            let mut t = piece.start;
            while t < piece.end {
                let strip = zigzag_at(&triangles[t..piece.end], &mut a, &mut b).and_then(
                    |(length, last)| {
                        let sides = |a: &[u32], b: &[u32]| {
                            let sa = side_of_row(a, false, blocks, index)?;
                            let sb = side_of_row(b, true, blocks, index)?;
                            (sa.0 != sb.0).then_some([sa, sb])
                        };
                        // Both rows have an odd length (a side's `2n - 1` points): the last
                        // point ends the row that is one short.
                        if a.len() % 2 == 0 {
                            a.push(last);
                        } else {
                            b.push(last);
                        }
                        let sides = sides(&a, &b)?;
                        Some(MergeStrip {
                            triangles: t..t + length,
                            sides,
                        })
                    },
                );
                match strip {
                    Some(strip) => {
                        t = strip.triangles.end;
                        strips.push(strip);
                    }
                    None => {
                        left.push(t..t + 1);
                        t += 1;
                    }
                }
            }
            (strips, left)
        })
        .collect();
    let mut strips = Vec::new();
    let mut left = Others::default();
    for (s, l) in found {
        strips.extend(s);
        for run in l {
            left.push(run);
        }
    }
    (strips, left.runs)
}

/// The fan blocks' claimed vertices (the module's documentation), a bit each.
struct Claimed {
    bits: Vec<u64>,
}

impl Claimed {
    fn set(&mut self, v: u32) {
        self.bits[(v / 64) as usize] |= 1 << (v % 64);
    }

    /// Every vertex of `range` (a block's, below the vertex count), a word at a time.
    fn set_range(&mut self, range: RangeInclusive<u32>) {
        let (first, last) = (*range.start() as usize, *range.end() as usize);
        if first > last {
            return;
        }
        let (low, high) = (first / 64, last / 64);
        let head = !0u64 << (first % 64);
        let tail = !0u64 >> (63 - last % 64);
        if low == high {
            self.bits[low] |= head & tail;
        } else {
            self.bits[low] |= head;
            self.bits[low + 1..high].fill(!0);
            self.bits[high] |= tail;
        }
    }

    fn holds(&self, v: u32) -> bool {
        self.bits
            .get((v / 64) as usize)
            .is_some_and(|word| word & 1 << (v % 64) != 0)
    }
}

/// The directed edges left to the general check of a mesh whose kept blocks are all fan blocks
/// (`blocks`, sorted, disjoint, below `vertices`, no seam copies), `others` the triangles
/// outside them; `None` when a triangle names a vertex beyond `vertices`.
pub(super) fn fan_grid_edges(
    triangles: &[[u32; 3]],
    vertices: usize,
    seams: &Seams,
    blocks: &[Block],
    index: &BlockIndex,
    others: &Others,
) -> Option<Vec<(u32, u32)>> {
    let fans = |k: usize| match &blocks[k] {
        Block::Fans(block) => Some(block),
        Block::Grid(_) => None,
    };
    let (found, mut left) = find_strips(triangles, others, blocks, index);
    // Each side with one strip at most.
    // `across[3 k + side]`: the block across a matched side.
    let mut across: Vec<Option<usize>> = vec![None; 3 * blocks.len()];
    let mut strips = Vec::with_capacity(found.len());
    for strip in found {
        let [(ka, sa), (kb, sb)] = strip.sides;
        let (a, b) = (3 * ka + usize::from(sa), 3 * kb + usize::from(sb));
        if across[a].is_some() || across[b].is_some() {
            left.push(strip.triangles);
            continue;
        }
        (across[a], across[b]) = (Some(kb), Some(ka));
        strips.push(strip);
    }
    let matched = |k: usize, side: u8| across[3 * k + usize::from(side)].is_some();
    let mut claimed = Claimed {
        bits: vec![0; vertices.div_ceil(64)],
    };
    for (k, block) in (0..blocks.len()).filter_map(|k| Some((k, fans(k)?))) {
        for range in block.deep_ranges() {
            claimed.set_range(range);
        }
        for side in 0..3u8 {
            if matched(k, side) {
                for p in 2..=2 * block.n - 4 {
                    claimed.set(block.side_point(side, p));
                }
            }
            // The point next to the corner before the side, on this side and the one before:
            // claimed when both strips are there, from two different blocks.
            let before = (side + 2) % 3;
            let (this, that) = (
                across[3 * k + usize::from(side)],
                across[3 * k + usize::from(before)],
            );
            if this.is_some() && that.is_some() && this != that {
                claimed.set(block.side_point(side, 1));
            }
        }
    }
    // The other triangles: every edge, by position; none may touch a claimed vertex.
    let count = left.iter().map(|run| run.len()).sum::<usize>();
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * count);
    let mut touched = false;
    for run in &left {
        for &corners in &triangles[run.clone()] {
            if corners.iter().any(|&v| v as usize >= vertices) {
                return None;
            }
            let [a, b, c] = corners.map(|v| seams.position(v));
            touched |= claimed.holds(a) || claimed.holds(b) || claimed.holds(c);
            edges.extend([(a, b), (b, c), (c, a)]);
        }
    }
    if touched {
        return all_edges(triangles, vertices, seams);
    }
    // The strips' edges without a claimed end (near the strips' ends), by pieces in parallel.
    let pieces: Vec<Vec<(u32, u32)>> = strips
        .par_chunks(1024)
        .map(|strips| {
            let mut out = Vec::new();
            for strip in strips {
                for &[a, b, c] in &triangles[strip.triangles.clone()] {
                    let [x, y, z] = [a, b, c].map(|v| claimed.holds(v));
                    if !(x || y) {
                        out.push((a, b));
                    }
                    if !(y || z) {
                        out.push((b, c));
                    }
                    if !(z || x) {
                        out.push((c, a));
                    }
                }
            }
            out
        })
        .collect();
    for piece in pieces {
        edges.extend(piece);
    }
    // The border of the sides no strip matched.
    for (k, block) in (0..blocks.len()).filter_map(|k| Some((k, fans(k)?))) {
        for side in 0..3u8 {
            if !matched(k, side) {
                block.side_edges(side, &mut edges);
            }
        }
    }
    Some(edges)
}

/// Every triangle's edges, by position (`None` for a vertex beyond `vertices`).
fn all_edges(triangles: &[[u32; 3]], vertices: usize, seams: &Seams) -> Option<Vec<(u32, u32)>> {
    triangles
        .par_iter()
        .flat_map_iter(|&corners| {
            let valid = corners.iter().all(|&v| (v as usize) < vertices);
            let [a, b, c] = corners.map(|v| seams.position(v));
            [(a, b), (b, c), (c, a)].map(|e| valid.then_some(e))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ranges set a word at a time are the vertices set one by one.
    #[test]
    fn ranges_are_claimed_vertex_by_vertex() {
        for (first, last) in [
            (0, 0),
            (3, 70),
            (64, 127),
            (63, 64),
            (5, 4),
            (100, 300),
            (0, 255),
        ] {
            let mut words = Claimed { bits: vec![0; 5] };
            words.set_range(first..=last);
            let mut single = Claimed { bits: vec![0; 5] };
            for v in first..=last {
                single.set(v);
            }
            assert_eq!(words.bits, single.bits, "{first}..={last}");
        }
    }
}
