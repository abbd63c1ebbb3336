//! Whether a triangle mesh is closed: every directed edge used exactly once, and its reverse
//! exactly once (a closed, consistently oriented, edge-manifold surface).
//!
//! The general check looks at every directed edge, `3T` of them, and pairs each with its
//! reverse ([`DirectedEdges`] groups them by tail; few are sorted instead). A dual grid's output
//! is mostly its faces' grids (`(n-1)^2` quads of two triangles each) and the strips between
//! neighbouring grids (`n - 1` quads each at equal rates), whose inner edges pair up by
//! construction. So the check first looks for both in the triangle list itself,
//! trusting nothing the tessellator says:
//!
//! * a *grid block* is a run of triangles `[a, b, c], [a, c, d]` over quads
//!   `(a, b, c, d) = (r+i, r+i+1, r+w+i+1, r+w+i)`, `i` in `0..w-1`, for rows `r = first + j w`,
//!   `j` in `0..rows`: complete rows only;
//! * a *fan block* is a triangle face's grid in a triangle dual grid: the hexagons around the
//!   face's interior primal points, each fanned at its point, in the order and numbering of
//!   [`fans`]'s documentation, whole faces only;
//! * a *strip* is a run of triangles `[b_k, a_(k+1), a_k], [b_k, b_(k+1), a_(k+1)]` over two
//!   rows of vertices in arithmetic progression, `a_k = a_0 + k s`, `b_k = b_0 + k t`, `k` in
//!   `0..=m`, `m >= 2`, whose two sides are whole sides of two different blocks, run the
//!   other way (the sides' edges then pair with those blocks' border edges).
//!
//! Every inner edge of a block or strip (a block's edges off its border; a strip's rungs
//! `a_k b_k`, `0 < k < m`, and diagonals `b_k a_(k+1)`) is used once each way by its own
//! triangles, and a strip's sides pair with the blocks' sides it was matched with, and by
//! nothing else when
//!
//! * the blocks' vertex ranges are disjoint (a block's edges join its own vertices; a strip's
//!   inner edges join two blocks' vertices, one of them inside a side no other strip matched),
//! * no block side is matched by two strips, and
//! * no other triangle uses an inner edge of a block or strip or an edge of a matched side
//!   (checked edge by edge).
//!
//! Where the blocks kept are all fan blocks (a triangle dual grid), the strips between them are
//! merge strips of any two rates, which the scan finds too ([`merge_strips`]), and the other
//! triangles are tested by vertex, not by edge ([`fan_grid`]); where grid blocks were kept too,
//! a fan block's inner edges are tested like a grid block's, its border edges and the merge
//! strips take the general check.
//!
//! What is left, the unmatched sides' border edges, the strips' end rungs (`a_0 -> b_0`,
//! `b_m -> a_m`) and every edge of the other triangles, takes the general check. The answer is
//! the general check's on the whole mesh, exactly; only the cost differs: a block's or strip's
//! triangle costs a comparison with the pattern instead of three edges grouped and searched.
//!
//! The scan for blocks and strips runs in pieces of the triangle list in parallel (a block cut
//! between two pieces is two blocks, as valid as one; a strip cut there matches no side and goes
//! to the general check), and so does the test of the other triangles against the inner and
//! matched edges. The blocks' disjointness is checked on their ranges sorted by first vertex,
//! and a vertex's block is found from those ranges ([`BlockIndex`]): nothing is allocated per
//! vertex, since the first writes to such arrays (fresh pages) cost more than the rest of the
//! check at rate 16.

use std::cmp::Ordering;
use std::ops::Range;

use rayon::prelude::*;

mod directed_edges;
mod fan_grid;
mod fans;
mod grids;
mod merge_strips;
mod vertex_polygons;
mod vertex_set;

pub(crate) use directed_edges::DirectedEdges;
use fans::FanBlock;
use grids::{scan_grids_in_parallel, Found, GridBlock, GridStrip, MAX_BLOCK_SIDE, SCAN_CHUNK};

/// No strip matched the side.
const NO_STRIP: u32 = u32::MAX;

/// A block whose inner edges pair in place: a quad face's grid, or a triangle face's hexagon
/// fans (which no strip is matched with: all their border edges take the general check).
#[derive(Clone, Copy, Debug)]
enum Block {
    Grid(GridBlock),
    Fans(FanBlock),
}

impl Block {
    fn first(&self) -> u32 {
        match self {
            Block::Grid(b) => b.first,
            Block::Fans(b) => b.first,
        }
    }

    fn vertices(&self) -> Range<u64> {
        match self {
            Block::Grid(b) => b.vertices(),
            Block::Fans(b) => b.vertices(),
        }
    }

    fn triangles(&self) -> Range<usize> {
        match self {
            Block::Grid(b) => b.triangles(),
            Block::Fans(b) => b.triangles(),
        }
    }

    /// Whether its index arithmetic stays within `u32` (a fan block's scan checks its rate).
    fn fits(&self) -> bool {
        match self {
            Block::Grid(b) => b.width <= MAX_BLOCK_SIDE && b.rows < MAX_BLOCK_SIDE,
            Block::Fans(_) => true,
        }
    }

    fn grid(&self) -> Option<&GridBlock> {
        match self {
            Block::Grid(b) => Some(b),
            Block::Fans(_) => None,
        }
    }

    fn inner_edge(&self, p: u32, q: u32) -> bool {
        match self {
            Block::Grid(b) => b.inner_edge(p, q),
            Block::Fans(b) => b.inner_edge(p, q),
        }
    }

    /// The border edges that no strip pairs (`matched`: the strip on each grid side).
    fn unpaired_border(&self, matched: &[u32], out: &mut Vec<(u32, u32)>) {
        match self {
            Block::Grid(b) => {
                for side in 0..4u8 {
                    if matched[usize::from(side)] == NO_STRIP {
                        b.side_edges(side, out);
                    }
                }
            }
            Block::Fans(b) => b.border_edges(out),
        }
    }
}

/// Which block holds a vertex, for blocks with sorted, disjoint vertex ranges: the vertices in
/// buckets of `2^shift`, about one block each, a bucket's candidates found by their first
/// index.
struct BlockIndex<'a> {
    blocks: &'a [Block],
    shift: u32,
    /// `starts[c]`: the first block whose range ends after bucket `c` begins.
    starts: Vec<usize>,
}

impl<'a> BlockIndex<'a> {
    fn new(blocks: &'a [Block], vertices: usize) -> BlockIndex<'a> {
        let shift = (vertices / blocks.len().max(1)).max(1).ilog2();
        let buckets = (vertices >> shift) + 1;
        let mut starts = Vec::with_capacity(buckets + 1);
        let mut k = 0;
        for c in 0..=buckets as u64 {
            while blocks
                .get(k)
                .is_some_and(|b| b.vertices().end <= c << shift)
            {
                k += 1;
            }
            starts.push(k);
        }
        BlockIndex {
            blocks,
            shift,
            starts,
        }
    }

    /// The block that holds vertex `v`, by its number.
    fn holding(&self, v: u32) -> Option<usize> {
        // A block that holds `v` ends after its bucket begins, and begins before the next one
        // does: it is the last candidate at most.
        let c = (v >> self.shift) as usize;
        let (low, high) = (*self.starts.get(c)?, *self.starts.get(c + 1)?);
        let candidates = &self.blocks[low..(high + 1).min(self.blocks.len())];
        let k = low
            + candidates
                .partition_point(|b| b.first() <= v)
                .checked_sub(1)?;
        (u64::from(v) < self.blocks[k].vertices().end).then_some(k)
    }
}

/// Seam copies and their originals: vertex `copy` stands for the position vertex `original`.
#[derive(Debug, Default)]
struct Seams {
    /// `(copy, original)` by copy, one each, no copy its own original.
    copies: Vec<(u32, u32)>,
}

impl Seams {
    /// The pairs `[copy, original]` as a mesh lists them, a later pair for the same copy
    /// replacing an earlier one; a copy not below `vertices` is no vertex and ignored. `None`
    /// when an original is not below `vertices`.
    fn new(pairs: &[[u32; 2]], vertices: usize) -> Option<Seams> {
        let mut copies: Vec<(u32, usize, u32)> = pairs
            .iter()
            .enumerate()
            .filter(|(_, &[copy, _])| (copy as usize) < vertices)
            .map(|(k, &[copy, original])| (copy, k, original))
            .collect();
        copies.sort_unstable();
        // The last pair of each copy.
        let mut last: Vec<(u32, u32)> = Vec::with_capacity(copies.len());
        for (copy, _, original) in copies {
            match last.last_mut() {
                Some(entry) if entry.0 == copy => entry.1 = original,
                _ => last.push((copy, original)),
            }
        }
        if last
            .iter()
            .any(|&(_, original)| original as usize >= vertices)
        {
            return None;
        }
        last.retain(|&(copy, original)| copy != original);
        Some(Seams { copies: last })
    }

    /// The position vertex that `v` stands for.
    fn position(&self, v: u32) -> u32 {
        // Copies follow the vertices they copy in a tessellation: most vertices are below all.
        if self.copies.first().map_or(true, |&(first, _)| v < first) {
            return v;
        }
        match self.copies.binary_search_by_key(&v, |&(copy, _)| copy) {
            Ok(k) => self.copies[k].1,
            Err(_) => v,
        }
    }

    /// Whether a seam copy lies in `range`.
    fn any_copy_in(&self, range: &Range<u64>) -> bool {
        let k = self
            .copies
            .partition_point(|&(c, _)| u64::from(c) < range.start);
        self.copies
            .get(k)
            .is_some_and(|&(c, _)| u64::from(c) < range.end)
    }
}

/// Whether `triangles`, over `vertices` vertices of which the seam copies `seams` (pairs
/// `[copy, original]`) stand for their originals, use every directed edge between position
/// vertices once and its reverse once. `false` also when a triangle names a vertex beyond
/// `vertices`.
pub(crate) fn is_closed(triangles: &[[u32; 3]], vertices: usize, seams: &[[u32; 2]]) -> bool {
    let Some(seams) = Seams::new(seams, vertices) else {
        return false;
    };
    let Some(edges) = general_edges(triangles, vertices, &seams) else {
        return false;
    };
    // A dual grid leaves few edges (1–2% of Spot's quads at rate 16, 6% of Loop's triangles at
    // rate 8): those are sorted; many are grouped by tail, in linear time.
    if edges.len() < vertices / 2 {
        sorted_in_pairs(&edges, vertices)
    } else {
        DirectedEdges::new(vertices, || edges.iter().copied()).is_some_and(|d| d.all_paired())
    }
}

/// Whether every directed edge of `edges` (between vertices below `vertices`) is listed once
/// and its reverse once, by sorting: the edges `a -> b` with `a < b` as `(a, b)`, those with
/// `a > b` reversed, as `(b, a)`; closed exactly when the two sorted lists are equal and neither
/// repeats a pair. An edge from a vertex to itself is its own reverse, as in [`DirectedEdges`]:
/// it may be listed once.
///
/// For few edges: nothing is allocated per vertex, where the first writes to arrays over every
/// vertex (fresh pages) cost more than the sorts.
fn sorted_in_pairs(edges: &[(u32, u32)], vertices: usize) -> bool {
    // `a V + b` is below `V^2`: four passes of a radix sort for two million vertices.
    let v = vertices as u64;
    let key = |a: u32, b: u32| u64::from(a) * v + u64::from(b);
    let (mut forward, mut backward, mut loops) = (Vec::new(), Vec::new(), Vec::new());
    for &(a, b) in edges {
        match a.cmp(&b) {
            Ordering::Less => forward.push(key(a, b)),
            Ordering::Greater => backward.push(key(b, a)),
            Ordering::Equal => loops.push(a),
        }
    }
    // At most 64 bits: `a V + b < V^2 <= 2^64` for indices below `V <= 2^32`.
    let bits = 128 - (u128::from(v) * u128::from(v)).leading_zeros();
    rayon::join(
        || sort_keys(&mut forward, bits),
        || sort_keys(&mut backward, bits),
    );
    loops.sort_unstable();
    forward == backward
        && forward.windows(2).all(|w| w[0] != w[1])
        && loops.windows(2).all(|w| w[0] != w[1])
}

/// Radix digits of this many bits.
const DIGIT: u32 = 11;

/// Sort `keys` (below `2^bits`): by radix where they are many (a triangle dual grid leaves
/// 280,000 edges at rate 8, which a comparison sort took 8 ms to order), else by comparison.
fn sort_keys(keys: &mut Vec<u64>, bits: u32) {
    if keys.len() < 1 << 14 {
        keys.sort_unstable();
        return;
    }
    let mut other = vec![0u64; keys.len()];
    let mut shift = 0;
    while shift < bits {
        let digit = |k: u64| ((k >> shift) & ((1 << DIGIT) - 1)) as usize;
        let mut start = vec![0usize; 1 << DIGIT];
        for &k in keys.iter() {
            start[digit(k)] += 1;
        }
        let mut total = 0;
        for s in &mut start {
            (*s, total) = (total, total + *s);
        }
        for &k in keys.iter() {
            let d = digit(k);
            other[start[d]] = k;
            start[d] += 1;
        }
        std::mem::swap(keys, &mut other);
        shift += DIGIT;
    }
}

/// The directed edges between position vertices left to the general check once the blocks and
/// strips have paired theirs (the module's conditions), or `None` when the mesh is already
/// known not to be closed: an index beyond `vertices`, or another triangle on an edge a block
/// or strip pairs.
fn general_edges(
    triangles: &[[u32; 3]],
    vertices: usize,
    seams: &Seams,
) -> Option<Vec<(u32, u32)>> {
    let Found {
        blocks: grids,
        fans,
        strips,
        merges,
        mut others,
    } = scan_grids_in_parallel(triangles);
    let mut found: Vec<Block> = grids.into_iter().map(Block::Grid).collect();
    found.extend(fans.into_iter().map(Block::Fans));
    // Disjoint vertex ranges, a block's edges joining its own vertices only: by first vertex,
    // a block that starts before the last kept one ends goes to the general check. So does a
    // block over a seam copy, which would pair edges by index where the positions pair them
    // differently: the blocks kept hold position vertices only, and the other triangles are
    // tested by position.
    found.sort_unstable_by_key(Block::first);
    let mut blocks = Vec::with_capacity(found.len());
    let mut kept_end = 0;
    for b in found {
        let range = b.vertices();
        let usable = b.fits()
            && range.start >= kept_end
            && range.end <= vertices as u64
            && !seams.any_copy_in(&range);
        if !usable {
            others.push(b.triangles());
            continue;
        }
        kept_end = range.end;
        blocks.push(b);
    }
    let index = BlockIndex::new(&blocks, vertices);
    if !blocks.is_empty() && blocks.iter().all(|b| b.grid().is_none()) {
        // A triangle dual grid: its strips are merge strips (a strip of quads is one whose
        // rows advance in turn), its other triangles tested by vertex.
        return fan_grid::fan_grid_edges(
            triangles,
            vertices,
            seams,
            &blocks,
            &index,
            fan_grid::Strips {
                merges,
                quads: strips,
            },
            others,
        );
    }
    // With grid blocks kept, merge strips take the general check (they pair with fan blocks in
    // a triangle dual grid only).
    for merge in merges {
        others.push(merge.triangles);
    }
    let block_of = |v: u32| index.holding(v);
    // A strip pairs its sides with two sides of two different blocks, each side with one strip
    // only; `matched[4 k + side]` is the strip (twice its number, plus one on its side `b`).
    let mut matched = vec![NO_STRIP; 4 * blocks.len()];
    let mut kept: Vec<GridStrip> = Vec::new();
    let side_of = |(x, d, m): (i64, i64, u32)| {
        let x = u32::try_from(x).ok()?;
        let k = block_of(x)?;
        let side = blocks[k].grid()?.side_of_run((x, d, m))?;
        Some((k, 4 * k + usize::from(side)))
    };
    for strip in strips {
        let [a, b] = strip.matching_runs();
        // Numbers below `NO_STRIP` only: past them a strip takes the general check.
        let number = u32::try_from(2 * kept.len())
            .ok()
            .filter(|&n| n < NO_STRIP - 1);
        match (side_of(a), side_of(b), number) {
            (Some((ka, sa)), Some((kb, sb)), Some(number))
                if ka != kb && matched[sa] == NO_STRIP && matched[sb] == NO_STRIP =>
            {
                (matched[sa], matched[sb]) = (number, number + 1);
                kept.push(strip);
            }
            _ => others.push(strip.triangles()),
        }
    }
    // Whether the edge `v w`, `v` inside a side of block `k` that a strip matched, is an inner
    // edge of that strip.
    let strip_edge = |k: Option<usize>, v: u32, w: u32| {
        let Some((k, side)) = k.and_then(|k| Some((k, blocks[k].grid()?.side_inside(v)?))) else {
            return false;
        };
        let m = matched[4 * k + usize::from(side)];
        m != NO_STRIP && kept[(m / 2) as usize].inner_edge_at(v, m % 2 == 0, w)
    };
    // Whether a block or strip pairs the edge `p q` already, `k` and `l` their blocks.
    let paired = |(p, k): (u32, Option<usize>), (q, l): (u32, Option<usize>)| match (k, l) {
        (Some(k), Some(l)) if k == l => {
            let block = &blocks[k];
            block.inner_edge(p, q)
                || block
                    .grid()
                    .and_then(|grid| grid.side_of_edge(p, q))
                    .is_some_and(|side| matched[4 * k + usize::from(side)] != NO_STRIP)
        }
        (k, l) => strip_edge(k, p, q) || strip_edge(l, q, p),
    };
    // The other triangles name vertices that exist, and none uses an edge (between positions)
    // that a block or strip pairs already (none does when there are no blocks: a grid of
    // triangles).
    // The other triangles' edges between positions, written in place by pieces in parallel.
    let pieces = others.pieces(SCAN_CHUNK);
    let count = others.len();
    let mut edges = vec![(0, 0); 3 * count];
    let mut outputs = Vec::with_capacity(pieces.len());
    let mut rest = edges.as_mut_slice();
    for piece in &pieces {
        let (output, after) = rest.split_at_mut(3 * piece.len());
        outputs.push(output);
        rest = after;
    }
    let valid = pieces.into_par_iter().zip(outputs).all(|(piece, output)| {
        piece.zip(output.chunks_exact_mut(3)).all(|(t, out)| {
            let corners = triangles[t];
            if corners.iter().any(|&v| v as usize >= vertices) {
                return false;
            }
            let [a, b, c] = corners.map(|v| seams.position(v));
            out.copy_from_slice(&[(a, b), (b, c), (c, a)]);
            if blocks.is_empty() {
                return true;
            }
            let [a, b, c] = [a, b, c].map(|v| (v, block_of(v)));
            !(paired(a, b) || paired(b, c) || paired(c, a))
        })
    });
    if !valid {
        return None;
    }
    // The blocks and strips kept hold position vertices only.
    for (k, b) in blocks.iter().enumerate() {
        b.unpaired_border(&matched[4 * k..4 * k + 4], &mut edges);
    }
    for strip in &kept {
        edges.extend(strip.end_rungs());
    }
    Some(edges)
}

#[cfg(test)]
mod tests {
    use super::grids::tests::{grid, strip};
    use super::*;

    /// A block of 4 rows of 5 vertices (`0..20`), one of 3 rows from 100, and the strip from
    /// the first one's last row to the second one's first row, both walked from their right
    /// ends; a vertex 200 for fins.
    fn two_blocks_and_a_strip() -> Vec<[u32; 3]> {
        let mut triangles = Vec::new();
        grid(0, 5, 3, &mut triangles);
        strip(19, -1, 104, -1, 4, &mut triangles);
        grid(100, 5, 2, &mut triangles);
        triangles
    }

    /// The strip's sides pair with the blocks' sides it runs along: what is left to the
    /// general check is the blocks' other sides and the strip's two end rungs.
    #[test]
    fn a_strip_pairs_its_sides_with_the_blocks() {
        let triangles = two_blocks_and_a_strip();
        let mut edges =
            general_edges(&triangles, 201, &Seams::default()).expect("no edge used twice");
        edges.sort_unstable();
        let mut expected = Vec::new();
        let path = |vertices: &[u32], out: &mut Vec<(u32, u32)>| {
            out.extend(vertices.windows(2).map(|e| (e[0], e[1])));
        };
        // The first block: its first row, last column and first column.
        path(&[0, 1, 2, 3, 4], &mut expected);
        path(&[4, 9, 14, 19], &mut expected);
        path(&[15, 10, 5, 0], &mut expected);
        // The second block: its last column, last row and first column.
        path(&[104, 109, 114], &mut expected);
        path(&[114, 113, 112, 111, 110], &mut expected);
        path(&[110, 105, 100], &mut expected);
        // The strip's end rungs: a_0 -> b_0, b_m -> a_m.
        expected.extend([(19, 104), (100, 15)]);
        expected.sort_unstable();
        assert_eq!(edges, expected);
    }

    /// Another triangle on an edge the strip pairs (a rung, a diagonal at either end, a side),
    /// or a second copy of the strip: not closed, whatever the general check would say of the
    /// rest.
    #[test]
    fn edges_a_strip_pairs_are_not_used_again() {
        // a_k = 19 - k, b_k = 104 - k.
        for (p, q) in [(17, 102), (104, 18), (101, 15), (101, 16), (16, 17)] {
            let mut triangles = two_blocks_and_a_strip();
            triangles.extend([[p, q, 200], [q, p, 200]]);
            let left = general_edges(&triangles, 201, &Seams::default());
            assert!(left.is_none(), "a fin on {p} {q}");
        }
        let mut twice = two_blocks_and_a_strip();
        strip(19, -1, 104, -1, 4, &mut twice);
        // The second copy matches no side (the first took both), so its triangles are others,
        // on the first copy's rungs.
        assert!(general_edges(&twice, 201, &Seams::default()).is_none());
        assert!(!is_closed(&twice, 201, &[]));
    }

    proptest::proptest! {
        /// The radix sort orders keys as the comparison sort does (lists long enough to take
        /// it, with repeats).
        #[test]
        fn radix_and_comparison_sorts_agree(
            keys in proptest::collection::vec(0u64..1 << 12, 0..40_000),
        ) {
            // Spread over all 40 bits, repeats kept.
            let keys: Vec<u64> = keys.iter().map(|k| k * 0x9E37_79B1 % (1 << 40)).collect();
            let mut radix = keys.clone();
            sort_keys(&mut radix, 40);
            let mut expected = keys;
            expected.sort_unstable();
            proptest::prop_assert_eq!(radix, expected);
        }

        /// The two general checks agree on edge lists with repeats, loops and missing
        /// reverses, and on the same lists closed by their reverses.
        #[test]
        fn sorting_and_grouping_agree(
            edges in proptest::collection::vec((0u32..6, 0u32..6), 0..12),
            close in proptest::bool::ANY,
        ) {
            let mut edges = edges;
            if close {
                let reverses: Vec<_> = edges.iter().map(|&(a, b)| (b, a)).collect();
                edges.extend(reverses);
            }
            proptest::prop_assert_eq!(
                sorted_in_pairs(&edges, 6),
                DirectedEdges::new(6, || edges.iter().copied()).is_some_and(|d| d.all_paired())
            );
        }
    }
}
