//! Whether a triangle mesh is closed: every directed edge used exactly once, and its reverse
//! exactly once (a closed, consistently oriented, edge-manifold surface).
//!
//! The general check ([`DirectedEdges`]) groups every directed edge by its tail, `3T` of them.
//! A dual grid's output is mostly its faces' grids (`(n-1)^2` quads of two triangles each),
//! whose inner edges pair up by construction. So the check first looks for such grids
//! in the triangle list itself, trusting nothing the tessellator says: a *grid block* is a run
//! of triangles `[a, b, c], [a, c, d]` over quads `(a, b, c, d) = (r+i, r+i+1, r+w+i+1, r+w+i)`,
//! `i` in `0..w-1`, for rows `r = first + j w`, `j` in `0..rows`: complete rows only. Every
//! inner edge of a block (not on its border) is used once each way by the block's own
//! triangles, and by nothing else when
//!
//! * the blocks' vertex ranges are disjoint (a block's edges join its own vertices), and
//! * no other triangle uses an inner edge of a block (checked edge by edge).
//!
//! What is left, the blocks' border edges and every edge of the other triangles, takes the
//! general check. The answer is the general check's on the whole mesh, exactly; only the cost
//! differs: a block's triangle costs a comparison with the pattern instead of three edges
//! grouped and searched.
//!
//! The scan for blocks runs in pieces of the triangle list in parallel (a block cut between two
//! pieces is two blocks, as valid as one), and so does the test of the other triangles against
//! the blocks' inner edges; the blocks' disjointness is checked on their ranges sorted by first
//! vertex, and the general check numbers the vertices its edges touch densely (at rate 16 about
//! a quarter of all), so its passes over vertices skip the blocks' interiors.

use std::ops::Range;

use rayon::prelude::*;

/// A run of grid quads found in the triangle list: `rows` rows of `width - 1` quads over the
/// vertices `first..first + (rows + 1) * width`, row-major.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct GridBlock {
    /// The block's first triangle.
    start: usize,
    first: u32,
    width: u32,
    rows: u32,
}

impl GridBlock {
    fn triangles(&self) -> Range<usize> {
        self.start..self.start + 2 * (self.width as usize - 1) * self.rows as usize
    }

    fn vertices(&self) -> Range<u64> {
        let first = u64::from(self.first);
        first..first + (u64::from(self.rows) + 1) * u64::from(self.width)
    }

    /// The border's directed edges, as the block's triangles run them: the first row's
    /// bottoms, the last row's tops, the first quads' left sides, the last quads' right sides.
    fn border_edges(&self, out: &mut Vec<(u32, u32)>) {
        let (w, first) = (self.width, self.first);
        let top = first + (self.rows - 1) * w;
        for i in 0..w - 1 {
            out.push((first + i, first + i + 1));
            out.push((top + w + i + 1, top + w + i));
        }
        for j in 0..self.rows {
            let r = first + j * w;
            out.push((r + w, r));
            out.push((r + w - 1, r + 2 * w - 1));
        }
    }
}

/// How many complete rows of `w - 1` grid quads start at `triangles[0]`, the first over
/// vertices from `first` (at most `u32::MAX` rows; 0 when the first row is incomplete).
fn complete_rows(triangles: &[[u32; 3]], first: u32, w: u32) -> u32 {
    let per_row = 2 * (w as usize - 1);
    let mut rows = 0u32;
    for row in triangles.chunks_exact(per_row) {
        let r = u64::from(first) + u64::from(rows) * u64::from(w);
        // The row's largest index is `r + 2w - 1`: when it fits, no quad's index overflows.
        let Ok(r) = u32::try_from(r) else { break };
        if u64::from(r) + 2 * u64::from(w) - 1 > u64::from(u32::MAX)
            || !is_grid_row(row, r, w)
            || rows == u32::MAX
        {
            break;
        }
        rows += 1;
    }
    rows
}

/// Whether `row` is the quads `[a, a + 1, c], [a, c, c - 1]`, `a = r + i`, `c = a + w + 1`, in
/// order (`r + 2w - 1` must not overflow).
///
/// Why in runs of eight quads: a run compares without a branch per index (about 11
/// instructions a quad, where one comparison at a time took more than twice that), and a
/// mismatch still ends the scan within a run of it (a failed start costs what it did).
fn is_grid_row(row: &[[u32; 3]], r: u32, w: u32) -> bool {
    row.chunks(16).enumerate().all(|(run, triangles)| {
        let first = r + 8 * run as u32;
        let differs = (first..)
            .zip(triangles.chunks_exact(2))
            .fold(0, |differs, (a, quad)| {
                let c = a + w + 1;
                let ([p, q, s], [t, x, y]) = (quad[0], quad[1]);
                differs | (p ^ a) | (q ^ (a + 1)) | (s ^ c) | (t ^ a) | (x ^ c) | (y ^ (c - 1))
            });
        differs == 0
    })
}

/// The grid blocks of `triangles` and the triangles outside them. A block starts at a
/// triangle `[a, a + 1, a + w + 1]` (`w >= 2`) and runs for as many complete rows as follow; a
/// triangle that starts no complete row is left to the general check. Linear: a failed start
/// is passed over, never rescanned.
fn find_blocks(triangles: &[[u32; 3]]) -> (Vec<GridBlock>, Vec<usize>) {
    let mut blocks = Vec::new();
    let mut others = Vec::new();
    let mut t = 0;
    while t < triangles.len() {
        let [a, b, c] = triangles[t];
        let width = c.checked_sub(a).and_then(|d| d.checked_sub(1));
        let rows = match width {
            Some(w) if b == a.wrapping_add(1) && w >= 2 => complete_rows(&triangles[t..], a, w),
            _ => 0,
        };
        match (width, rows) {
            (Some(width), rows) if rows > 0 => {
                let block = GridBlock {
                    start: t,
                    first: a,
                    width,
                    rows,
                };
                t = block.triangles().end;
                blocks.push(block);
            }
            _ => {
                others.push(t);
                t += 1;
            }
        }
    }
    (blocks, others)
}

/// The largest grid side a block may have: a block's index arithmetic (`first + j w + i`,
/// `w + 1`) then stays far from `u32`'s end.
const MAX_BLOCK_SIDE: u32 = u16::MAX as u32;

/// No block holds the vertex.
const NO_BLOCK: u32 = u32::MAX;

impl GridBlock {
    /// Whether the edge between the block's vertices `p` and `q` is a quad edge or diagonal of
    /// the block not on its border: one its triangles use both ways.
    fn inner_edge(&self, p: u32, q: u32) -> bool {
        let (low, high) = (p.min(q) - self.first, p.max(q) - self.first);
        let w = self.width;
        let step = high - low;
        if step != 1 && step != w && step != w + 1 {
            return false;
        }
        let (i, j) = (low % w, low / w);
        match step {
            // Along a row, not across its end, not on the first or last row.
            1 => i + 1 < w && j > 0 && j < self.rows,
            // Along a column, not the first or last.
            s if s == w => i > 0 && i + 1 < w,
            // A quad's diagonal.
            _ => i + 1 < w,
        }
    }
}

/// Triangles a worker scans for blocks at least (a block split between two workers becomes
/// two blocks, which the check takes as well).
const SCAN_CHUNK: usize = 1 << 16;

/// [`find_blocks`] over pieces of `triangles` in parallel, in the order of the triangles.
fn find_blocks_in_parallel(triangles: &[[u32; 3]]) -> (Vec<GridBlock>, Vec<usize>) {
    let pieces = rayon::current_num_threads().max(1) * 4;
    let chunk = triangles.len().div_ceil(pieces).max(SCAN_CHUNK);
    let found: Vec<_> = triangles
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, piece)| {
            let (mut blocks, mut others) = find_blocks(piece);
            let offset = c * chunk;
            for b in &mut blocks {
                b.start += offset;
            }
            for t in &mut others {
                *t += offset;
            }
            (blocks, others)
        })
        .collect();
    let mut blocks = Vec::new();
    let mut others = Vec::new();
    for (b, o) in found {
        blocks.extend(b);
        others.extend(o);
    }
    (blocks, others)
}

/// Whether `triangles`, over `vertices` vertices where vertex `v` stands for `of[v]` (a seam
/// copy for its original; `of` empty for the identity), use every directed edge once and its
/// reverse once. `false` also when a triangle names a vertex beyond `vertices`.
pub(crate) fn is_closed(triangles: &[[u32; 3]], vertices: usize, of: &[u32]) -> bool {
    if of.iter().any(|&o| o as usize >= vertices) {
        return false;
    }
    let (mut found, mut others) = find_blocks_in_parallel(triangles);
    // A block over a seam copy or its original would pair edges by index where the positions
    // pair them differently: its triangles go to the general check.
    let mut merged: Vec<u64> = of
        .iter()
        .enumerate()
        .filter(|&(v, &o)| o as usize != v)
        .flat_map(|(v, &o)| [v as u64, u64::from(o)])
        .collect();
    merged.sort_unstable();
    let holds_merged = |range: &Range<u64>| {
        let k = merged.partition_point(|&m| m < range.start);
        merged.get(k).is_some_and(|&m| m < range.end)
    };
    // Disjoint vertex ranges, a block's edges joining its own vertices only: by first vertex,
    // a block that starts before the last kept one ends goes to the general check.
    found.sort_unstable_by_key(|b| b.first);
    let mut blocks = Vec::with_capacity(found.len());
    let mut block_of = vec![NO_BLOCK; vertices];
    let mut kept_end = 0;
    for b in found {
        let range = b.vertices();
        let usable = b.width <= MAX_BLOCK_SIDE
            && b.rows < MAX_BLOCK_SIDE
            && range.start >= kept_end
            && range.end <= vertices as u64
            && !holds_merged(&range);
        if !usable {
            others.extend(b.triangles());
            continue;
        }
        kept_end = range.end;
        block_of[range.start as usize..range.end as usize].fill(blocks.len() as u32);
        blocks.push(b);
    }
    // The other triangles name vertices that exist, and none uses a block's inner edge, which
    // the block already uses both ways.
    let inner = |p: u32, q: u32| {
        let b = block_of[p as usize];
        b != NO_BLOCK && b == block_of[q as usize] && blocks[b as usize].inner_edge(p, q)
    };
    let others_valid = others.par_iter().all(|&t| {
        let [a, b, c] = triangles[t];
        [a, b, c].iter().all(|&v| (v as usize) < vertices)
            && !inner(a, b)
            && !inner(b, c)
            && !inner(c, a)
    });
    if !others_valid {
        return false;
    }
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * others.len());
    for &t in &others {
        let [a, b, c] = triangles[t];
        edges.extend([(a, b), (b, c), (c, a)]);
    }
    for b in &blocks {
        b.border_edges(&mut edges);
    }
    // Position vertices, then numbered densely in the order met: the grouping's arrays then
    // span the vertices these edges touch (a quarter of all at rate 16), not every vertex.
    // Every number stays below `vertices`, so below `u32::MAX`, the unnumbered mark (more
    // vertices than that are taken by position as they are).
    let position = |v: u32| if of.is_empty() { v } else { of[v as usize] };
    if u32::try_from(vertices).map_or(true, |n| n == u32::MAX) {
        let edges = || edges.iter().map(|&(a, b)| (position(a), position(b)));
        return DirectedEdges::new(vertices, edges).is_some_and(|d| d.all_paired());
    }
    let mut dense = vec![u32::MAX; vertices];
    let mut touched = 0u32;
    for e in &mut edges {
        for v in [&mut e.0, &mut e.1] {
            let slot = &mut dense[position(*v) as usize];
            if *slot == u32::MAX {
                *slot = touched;
                touched += 1;
            }
            *v = *slot;
        }
    }
    DirectedEdges::new(touched as usize, || edges.iter().copied()).is_some_and(|d| d.all_paired())
}

/// Up to this many edges leaving a vertex (a tessellation's vertices have about six) are
/// searched one by one; more are sorted and searched by halves.
const SHORT: usize = 16;

/// Directed edges grouped by tail: the heads of the edges leaving `a` are
/// `heads[start[a]..start[a + 1]]`, sorted where there are more than [`SHORT`].
pub(crate) struct DirectedEdges {
    start: Vec<u32>,
    heads: Vec<u32>,
}

impl DirectedEdges {
    /// Group `edges` by tail, by a counting sort: linear, where hashing took seconds for
    /// millions of edges. `None` when an edge is listed twice or names a vertex not below
    /// `vertices`. `edges` is called twice (count, then place), for the same edges each time.
    pub(crate) fn new<I: Iterator<Item = (u32, u32)>>(
        vertices: usize,
        edges: impl Fn() -> I,
    ) -> Option<DirectedEdges> {
        let mut start = vec![0u32; vertices + 1];
        for (a, b) in edges() {
            if a as usize >= vertices || b as usize >= vertices {
                return None;
            }
            start[a as usize + 1] += 1;
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut heads = vec![0u32; start[vertices] as usize];
        for (a, b) in edges() {
            heads[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
        }
        for v in 0..vertices {
            let around = &mut heads[start[v] as usize..start[v + 1] as usize];
            let repeated = if around.len() > SHORT {
                around.sort_unstable();
                around.windows(2).any(|w| w[0] == w[1])
            } else {
                (1..around.len()).any(|k| around[..k].contains(&around[k]))
            };
            if repeated {
                return None;
            }
        }
        Some(DirectedEdges { start, heads })
    }

    #[inline]
    fn leaving(&self, a: u32) -> &[u32] {
        let a = a as usize;
        &self.heads[self.start[a] as usize..self.start[a + 1] as usize]
    }

    #[inline]
    #[allow(clippy::manual_contains)]
    pub(crate) fn contains(&self, a: u32, b: u32) -> bool {
        let leaving = self.leaving(a);
        if leaving.len() > SHORT {
            leaving.binary_search(&b).is_ok()
        } else {
            // A loop of its own: `slice::contains` cost three times the instructions here
            // (callgrind, the general check of a rate-16 tessellation).
            leaving.iter().any(|&h| h == b)
        }
    }

    /// Every edge, by tail.
    pub(crate) fn edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..self.start.len() as u32 - 1)
            .flat_map(move |a| self.leaving(a).iter().map(move |&b| (a, b)))
    }

    /// Whether every edge's reverse is an edge too.
    pub(crate) fn all_paired(&self) -> bool {
        self.start.windows(2).enumerate().all(|(a, range)| {
            self.heads[range[0] as usize..range[1] as usize]
                .iter()
                .all(|&b| self.contains(b, a as u32))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two grids of quads, long enough to be scanned in several pieces, and stray triangles
    /// between them: every triangle is in exactly one block or among the others, and every
    /// block's triangles are its pattern, whichever piece found it.
    #[test]
    fn pieces_cover_every_triangle_once() {
        let mut triangles = Vec::new();
        let grid = |first: u32, w: u32, rows: u32, out: &mut Vec<[u32; 3]>| {
            for j in 0..rows {
                for i in 0..w - 1 {
                    let a = first + j * w + i;
                    out.push([a, a + 1, a + w + 1]);
                    out.push([a, a + w + 1, a + w]);
                }
            }
        };
        grid(0, 300, 250, &mut triangles);
        triangles.extend([[7, 3, 5], [1, 1, 1], [90_000, 4, 2]]);
        grid(100_000, 97, 400, &mut triangles);
        assert!(triangles.len() > 3 * SCAN_CHUNK);
        let (blocks, others) = find_blocks_in_parallel(&triangles);
        let mut seen = vec![0u8; triangles.len()];
        for b in &blocks {
            for (k, t) in b.triangles().enumerate() {
                seen[t] += 1;
                let (quad, second) = (k / 2, k % 2);
                let (row, i) = (quad as u32 / (b.width - 1), quad as u32 % (b.width - 1));
                let a = b.first + row * b.width + i;
                let c = a + b.width + 1;
                let expected = if second == 0 {
                    [a, a + 1, c]
                } else {
                    [a, c, c - 1]
                };
                assert_eq!(triangles[t], expected, "block {b:?}, triangle {t}");
            }
        }
        for &t in &others {
            seen[t] += 1;
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert!(blocks.len() >= 4, "{} blocks", blocks.len());
    }
}
