//! The pairing of a triangle dual grid's output: fan blocks (the faces' hexagon fans,
//! [`super::fans`]) and the merge strips between two of them ([`super::merge_strips`]), where
//! no quad grid was found.
//!
//! A merge strip's rung `a_i b_j` between two consecutive triangles is used by both, once each
//! way. It is kept when its row `a` is a whole side of a kept fan block as the block's border
//! runs it and its row `b` one of another kept block's run backwards, each side matched once.
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
//! different blocks, so none is used by both. So where no other triangle touches a claimed
//! vertex (checked, a bit per vertex) the edges with a claimed end pair, and the rest go to the
//! general check: the other triangles', and the blocks' and strips' edges without a claimed end
//! (the strips' end rungs, what is next to a side no strip matched, that side's border). Where
//! another triangle does touch one, every edge does.
//!
//! Where those edges are: a block's vertices are its deep ones and its sides' points (a dual
//! point off the deep ones has a corner on the face's border), so the unclaimed ones are its
//! three corners, the points of the sides no strip matched, and the corners' neighbours that
//! the rule above leaves out. Along a strip's row, a matched side, the claimed points are
//! therefore one run (`1` or `2` to `2n - 4` or `2n - 3`), and the triangles of a strip go along
//! both rows in order: between two triangles of a strip whose three corners are claimed, every
//! triangle's are. So a strip's edges without a claimed end are in its first triangles, up to
//! the first with three claimed corners, and its last ones, back to the last such.
//!
//! Those first and last triangles are made again from the strip's sides and the rows they
//! advance, which the scan recorded ([`super::merge_strips::Advances`]), and their corners
//! tested against each row's run: the list is not read again (each strip's two ends were two
//! cache misses, a fifth of the check on the triangulated Spot).

use rayon::prelude::*;

use super::fans::FanBlock;
use super::grids::{GridStrip, Others};
use super::merge_strips::{Advances, FanSide, MergeStrip, RowPoint, Rows, END_TRIANGLES};
use super::vertex_polygons::edges_off_polygons;
use super::vertex_set::VertexSet;
use super::{Block, BlockIndex, Seams};

/// The strips the scan found: merge strips, and strips of quads (merge strips of two rows of
/// equal length whose rows are arithmetic, which the scan takes for quads' strips first).
pub(super) struct Strips {
    pub(super) merges: Vec<MergeStrip>,
    pub(super) quads: Vec<GridStrip>,
}

/// The kept block that a side names (its first vertex and rate), and the side.
fn block_side(side: FanSide, blocks: &[Block], index: &BlockIndex) -> Option<(usize, u8)> {
    let k = index.holding(side.first)?;
    let Block::Fans(block) = &blocks[k] else {
        return None;
    };
    ((block.first, block.n) == (side.first, side.n)).then_some((k, side.side))
}

/// Claim a fan block's vertices (the module's documentation), `across[side]` the block across
/// each of its sides where a strip matched it: every vertex, but its corners, the points of the
/// sides no strip matched, and a corner's neighbour unless both sides there are matched by
/// strips from two different blocks.
fn claim(block: &FanBlock, across: [Option<u32>; 3], claimed: &mut VertexSet) {
    // The block's range is below the vertex count.
    claimed.insert_range(block.first..=(block.vertices().end - 1) as u32);
    let last = 2 * block.n - 2;
    for side in 0..3u8 {
        if across[usize::from(side)].is_none() {
            for p in 0..=last {
                claimed.remove(block.side_point(side, p));
            }
            continue;
        }
        claimed.remove(block.side_point(side, 0));
        let (this, that) = (
            across[usize::from(side)],
            across[usize::from((side + 2) % 3)],
        );
        if that.is_none() || this == that {
            claimed.remove(block.side_point(side, 1));
        }
    }
}

/// The edges without a claimed end of the triangles `order` walks (each with its index, its
/// corners named as `vertex` numbers them), into `out`; stops at the first triangle with three
/// claimed corners and returns its index (`None` when none has).
fn unclaimed_edges<T: Copy>(
    order: impl Iterator<Item = (usize, [T; 3])>,
    claimed: impl Fn(T) -> bool,
    vertex: impl Fn(T) -> u32,
    out: &mut Vec<(u32, u32)>,
) -> Option<usize> {
    for (t, [a, b, c]) in order {
        let [x, y, z] = [a, b, c].map(&claimed);
        if x && y && z {
            return Some(t);
        }
        if !(x || y) {
            out.push((vertex(a), vertex(b)));
        }
        if !(y || z) {
            out.push((vertex(b), vertex(c)));
        }
        if !(z || x) {
            out.push((vertex(c), vertex(a)));
        }
    }
    None
}

/// The edges without a claimed end of a kept strip, into `out`: those of its first triangles,
/// up to the first with three claimed corners, and of its last ones, back to the last such.
///
/// The claimed points of a row (a matched side) are one run: never its two ends (a block's
/// corners), always `2..=2n-4` (on that side alone), and points 1 and `2n - 3` as [`claim`]
/// left them. So the triangles at the ends are made from the strip's advances and their corners
/// tested against the two runs; the list is read only beyond the [`END_TRIANGLES`] the
/// advances record.
fn strip_end_edges(
    strip: &MergeStrip,
    triangles: &[[u32; 3]],
    claimed: &VertexSet,
    out: &mut Vec<(u32, u32)>,
) {
    let runs = [0, 1].map(|row| {
        let last = strip.row_length(row) - 1;
        let at = |k: u32| claimed.contains(strip.vertex((row, k)));
        (if at(1) { 1 } else { 2 })..=(if at(last - 1) { last - 1 } else { last - 2 })
    });
    let in_run = |(row, k): RowPoint| runs[row & 1].contains(&k);
    let on_list = |v: u32| claimed.contains(v);
    let listed = |t: usize| (t, triangles[t]);
    let all = strip.triangles.clone();
    let made = all.len().min(END_TRIANGLES);
    let first = unclaimed_edges(
        all.clone().zip(strip.head()),
        in_run,
        |p| strip.vertex(p),
        out,
    )
    .or_else(|| unclaimed_edges((all.start + made..all.end).map(listed), on_list, |v| v, out));
    let Some(end) = first.map(|t| t + 1) else {
        return;
    };
    let from_end = all.clone().rev().zip(strip.tail());
    if unclaimed_edges(
        from_end.take_while(|&(t, _)| t >= end),
        in_run,
        |p| strip.vertex(p),
        out,
    )
    .is_none()
    {
        unclaimed_edges((end..all.end - made).rev().map(listed), on_list, |v| v, out);
    }
}

/// The directed edges left to the general check of a mesh whose kept blocks are all fan blocks
/// (`blocks`, sorted, disjoint, below `vertices`, no seam copies), `strips` the strips the scan
/// found and `left` the triangles outside blocks and strips; `None` when a triangle names a
/// vertex beyond `vertices`.
pub(super) fn fan_grid_edges(
    triangles: &[[u32; 3]],
    vertices: usize,
    seams: &Seams,
    blocks: &[Block],
    index: &BlockIndex,
    strips: Strips,
    mut left: Others,
) -> Option<Vec<(u32, u32)>> {
    // The strips of quads read as merge strips.
    let mut rows = Rows::default();
    let mut found = strips.merges;
    found.reserve(strips.quads.len());
    for strip in strips.quads {
        strip.rows(&mut rows);
        match rows.sides() {
            Some(sides) => found.push(MergeStrip {
                triangles: strip.triangles(),
                sides,
                advances: Advances::QUADS,
            }),
            None => left.push(strip.triangles()),
        }
    }
    // Each side with one strip at most; `across[3 k + side]`: the block across a matched side
    // (blocks hold three vertices at least, `u32` numbers them).
    let mut across: Vec<Option<u32>> = vec![None; 3 * blocks.len()];
    // The strips kept stay in place (a copy's fresh pages cost more than the loop).
    found.retain(|strip| {
        let [a, b] = strip
            .sides
            .map(|side| block_side(side, blocks, index).map(|(k, s)| (k, 3 * k + usize::from(s))));
        match (a, b) {
            (Some((ka, a)), Some((kb, b)))
                if ka != kb && across[a].is_none() && across[b].is_none() =>
            {
                (across[a], across[b]) = (Some(kb as u32), Some(ka as u32));
                true
            }
            _ => {
                left.push(strip.triangles.clone());
                false
            }
        }
    });
    let kept = found;
    let mut claimed = VertexSet::new(vertices);
    let fans = || {
        blocks.iter().enumerate().filter_map(|(k, b)| match b {
            Block::Fans(block) => Some((k, block)),
            Block::Grid(_) => None,
        })
    };
    for (k, block) in fans() {
        claim(
            block,
            [0, 1, 2].map(|side| across[3 * k + side]),
            &mut claimed,
        );
    }
    // The other triangles: every edge by position but the vertex polygons' spokes; none may
    // touch a claimed vertex.
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * left.len());
    let touched = edges_off_polygons(
        triangles,
        &left.runs,
        vertices,
        seams,
        |v| index.holding(v).is_some(),
        &claimed,
        &mut edges,
    )?;
    if touched {
        return all_edges(triangles, vertices, seams);
    }
    // The strips' edges without a claimed end, at their two ends.
    for strip in &kept {
        strip_end_edges(strip, triangles, &claimed, &mut edges);
    }
    // The border of the sides no strip matched.
    for (k, block) in fans() {
        for side in 0..3u8 {
            if across[3 * k + usize::from(side)].is_none() {
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

    /// A block's claims, for every way strips may match its sides (none, or from one of two
    /// blocks), are the vertices the module's definition names one by one: the deep ones, a
    /// matched side's points `2..=2n-4`, and a corner's neighbour where both sides there are
    /// matched from two different blocks; nothing outside the block.
    #[test]
    fn claims_are_the_definition_vertex_by_vertex() {
        let choices = [None, Some(1), Some(2)];
        for n in 3..9 {
            let block = FanBlock {
                start: 0,
                first: 70,
                n,
            };
            let end = block.vertices().end as u32;
            for pick in 0..27 {
                let across = [pick % 3, pick / 3 % 3, pick / 9].map(|c| choices[c]);
                let mut claimed = VertexSet::new(64 * 64);
                claim(&block, across, &mut claimed);
                for v in 0..end + 70 {
                    let matched = |side: u8| across[usize::from(side)];
                    let corner_rule = (0..3u8).any(|side| {
                        let before = (side + 2) % 3;
                        block.side_point(side, 1) == v
                            && matched(side).is_some()
                            && matched(before).is_some()
                            && matched(side) != matched(before)
                    });
                    let expected = (70..end).contains(&v)
                        && (block.deep(v)
                            || block
                                .side_inside(v)
                                .is_some_and(|(side, _)| matched(side).is_some())
                            || corner_rule);
                    assert_eq!(claimed.contains(v), expected, "rate {n}, {across:?}, {v}");
                }
            }
        }
    }

    /// The edges a strip's ends leave are those of its listed triangles, walked from both ends
    /// to the first with three claimed corners, for claims made as [`claim`] makes them (every
    /// way the sides next to the strip may be matched) and strips whose first such triangle
    /// lies beyond the advances recorded (rates 3 and 40, 3 and 64).
    #[test]
    fn strip_ends_are_the_listed_triangles_edges() {
        use super::super::merge_strips::merge_strip_at;
        use super::super::merge_strips::tests::{merged, side, two_blocks};
        let mut rows = Rows::default();
        let choices = [None, Some(1), Some(2)];
        for (n, m) in [(3, 3), (5, 7), (8, 8), (17, 19), (3, 40), (40, 3), (3, 64)] {
            let (one, other) = two_blocks(n, m);
            let mut triangles = Vec::new();
            merged(
                &side(&one, 1, false),
                &side(&other, 0, true),
                &mut triangles,
            );
            let strip = merge_strip_at(&triangles, &mut rows).expect("a strip");
            for pick in 0..81 {
                // Side 1 of `one` and side 0 of `other` face each other; the sides around them
                // are matched from nothing, from a third block, or from the other one.
                let [p0, p2, q1, q2] =
                    [pick % 3, pick / 3 % 3, pick / 9 % 3, pick / 27].map(|c| choices[c]);
                let mut claimed = VertexSet::new(20_000);
                claim(&one, [p0, Some(1), p2], &mut claimed);
                claim(&other, [Some(0), q1, q2], &mut claimed);
                let mut made = Vec::new();
                strip_end_edges(&strip, &triangles, &claimed, &mut made);
                let mut listed = Vec::new();
                let on_list = |v: u32| claimed.contains(v);
                let all = 0..triangles.len();
                let order = |t: usize| (t, triangles[t]);
                if let Some(t) =
                    unclaimed_edges(all.clone().map(order), on_list, |v| v, &mut listed)
                {
                    unclaimed_edges(
                        (t + 1..all.end).rev().map(order),
                        on_list,
                        |v| v,
                        &mut listed,
                    );
                }
                assert_eq!(made, listed, "rates {n} {m}, pick {pick}");
                assert!(!made.is_empty());
            }
        }
    }
}
