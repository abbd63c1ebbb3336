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

    /// Side `side` of the border (0: the first row, 1: the last column, 2: the last row, 3: the
    /// first column) as the block's triangles run it: the directed edges `x_k -> x_k + d`,
    /// `x_k = x_0 + k d`, `k` in `0..m`, as `(x_0, d, m)`. Every side runs counterclockwise
    /// around the block (`x_0` a corner), so a neighbour's matching edges run `(x_m, -d, m)`.
    fn side_run(&self, side: u8) -> (u32, i64, u32) {
        let (w, first, rows) = (self.width, self.first, self.rows);
        let top = first + rows * w;
        match side {
            0 => (first, 1, w - 1),
            1 => (first + w - 1, i64::from(w), rows),
            2 => (top + w - 1, -1, w - 1),
            _ => (top, -i64::from(w), rows),
        }
    }

    /// The side whose run is `run` ([`GridBlock::side_run`]), if any.
    fn side_of_run(&self, run: (u32, i64, u32)) -> Option<u8> {
        (0..4).find(|&side| self.side_run(side) == run)
    }

    /// The directed edges of side `side`, as the block's triangles run them.
    fn side_edges(&self, side: u8, out: &mut Vec<(u32, u32)>) {
        let (x, d, m) = self.side_run(side);
        // Inside the block's vertex range: every `x + k d` fits.
        let at = |k: u32| (i64::from(x) + i64::from(k) * d) as u32;
        out.extend((0..m).map(|k| (at(k), at(k + 1))));
    }

    /// The block coordinates `(i, j)` of its vertex `v`.
    fn cell(&self, v: u32) -> (u32, u32) {
        let local = v - self.first;
        (local % self.width, local / self.width)
    }

    /// The side that holds the block's vertex `v` strictly between the side's two corners, if
    /// any (a corner or an inner vertex has none).
    fn side_inside(&self, v: u32) -> Option<u8> {
        let (i, j) = self.cell(v);
        let along_row = i > 0 && i + 1 < self.width;
        let along_column = j > 0 && j < self.rows;
        match (i, j) {
            (_, 0) if along_row => Some(0),
            (i, _) if i + 1 == self.width && along_column => Some(1),
            (_, j) if j == self.rows && along_row => Some(2),
            (0, _) if along_column => Some(3),
            _ => None,
        }
    }

    /// The side that the edge between the block's vertices `p` and `q` lies on, if any.
    fn side_of_edge(&self, p: u32, q: u32) -> Option<u8> {
        let (low, high) = (p.min(q), p.max(q));
        let (i, j) = self.cell(low);
        match high - low {
            1 if i + 1 < self.width && j == 0 => Some(0),
            1 if i + 1 < self.width && j == self.rows => Some(2),
            s if s == self.width && i + 1 == self.width => Some(1),
            s if s == self.width && i == 0 => Some(3),
            _ => None,
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

/// A strip found in the triangle list: `quads` quads `(a_k, a_(k+1), b_(k+1), b_k)` over
/// `a_k = a + k s`, `b_k = b + k t` (the module's pattern).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct GridStrip {
    /// The strip's first triangle.
    start: usize,
    a: u32,
    s: i64,
    b: u32,
    t: i64,
    quads: u32,
}

impl GridStrip {
    fn triangles(&self) -> Range<usize> {
        self.start..self.start + 2 * self.quads as usize
    }

    fn a_at(&self, k: u32) -> i64 {
        i64::from(self.a) + i64::from(k) * self.s
    }

    fn b_at(&self, k: u32) -> i64 {
        i64::from(self.b) + i64::from(k) * self.t
    }

    /// The side `a_(k+1) -> a_k` reversed, `a_0 -> a_m`, and the side `b_k -> b_(k+1)`
    /// reversed, `b_m -> b_0`, as runs `(x_0, d, m)`: what a block's side must run for the
    /// strip's sides to pair with it.
    fn matching_runs(&self) -> [(i64, i64, u32); 2] {
        let m = self.quads;
        [(self.a_at(0), self.s, m), (self.b_at(m), -self.t, m)]
    }

    /// Whether `{v, w}` is one of the strip's inner edges, `v` being `a_k` (`on_a`) or `b_k`
    /// for some `0 < k < m`: the rung `a_k b_k` and the diagonals `b_(k-1) a_k`, `b_k a_(k+1)`.
    fn inner_edge_at(&self, v: u32, on_a: bool, w: u32) -> bool {
        let w = i64::from(w);
        if on_a {
            let k = ((i64::from(v) - i64::from(self.a)) / self.s) as u32;
            w == self.b_at(k) || w == self.b_at(k - 1)
        } else {
            let k = ((i64::from(v) - i64::from(self.b)) / self.t) as u32;
            w == self.a_at(k) || w == self.a_at(k + 1)
        }
    }

    /// The end rungs `a_0 -> b_0` and `b_m -> a_m`, the strip's edges that pair outside it.
    fn end_rungs(&self) -> [(u32, u32); 2] {
        let m = self.quads;
        // A matched strip's vertices are blocks' vertices: they fit.
        let v = |x: i64| x as u32;
        [
            (v(self.a_at(0)), v(self.b_at(0))),
            (v(self.b_at(m)), v(self.a_at(m))),
        ]
    }
}

/// The strip that starts at `triangles[0]`, if its pattern holds for at least two quads.
fn strip_at(triangles: &[[u32; 3]]) -> Option<GridStrip> {
    let [[b0, a1, a0], [b0_, b1, a1_], ..] = *triangles else {
        return None;
    };
    if b0_ != b0 || a1_ != a1 {
        return None;
    }
    let (s, t) = (i64::from(a1) - i64::from(a0), i64::from(b1) - i64::from(b0));
    // `a_k`, `b_k` for `k = quads`: within `u32` after every match, so `+ s` cannot overflow.
    let (mut a, mut b) = (i64::from(a1), i64::from(b1));
    let mut quads = 1u32;
    for quad in triangles[2..].chunks_exact(2) {
        let (next_a, next_b) = (a + s, b + t);
        let wide = |triangle: [u32; 3]| triangle.map(i64::from);
        if quads == u32::MAX
            || wide(quad[0]) != [b, next_a, a]
            || wide(quad[1]) != [b, next_b, next_a]
        {
            break;
        }
        (a, b) = (next_a, next_b);
        quads += 1;
    }
    (quads >= 2).then_some(GridStrip {
        start: 0,
        a: a0,
        s,
        b: b0,
        t,
        quads,
    })
}

/// What the scan finds: grid blocks, strips, and the triangles outside both.
#[derive(Debug, Default)]
struct Found {
    blocks: Vec<GridBlock>,
    strips: Vec<GridStrip>,
    others: Others,
}

/// Triangles left to the general check, as runs of consecutive indices (a mesh without grids
/// is one run, not an index per triangle).
#[derive(Debug, Default)]
struct Others {
    runs: Vec<Range<usize>>,
}

impl Others {
    /// Add the triangles `run`, after every other.
    fn push(&mut self, run: Range<usize>) {
        match self.runs.last_mut() {
            Some(last) if last.end == run.start => last.end = run.end,
            _ => self.runs.push(run),
        }
    }

    fn len(&self) -> usize {
        self.runs.iter().map(|r| r.len()).sum()
    }

    /// The runs cut into pieces of at most `size` triangles, for the threads.
    fn pieces(&self, size: usize) -> Vec<Range<usize>> {
        let cut = |run: &Range<usize>| {
            let end = run.end;
            run.clone()
                .step_by(size)
                .map(move |start| start..end.min(start + size))
        };
        self.runs.iter().flat_map(cut).collect()
    }
}

/// The grid blocks and strips of `triangles` and the triangles outside them. A block starts at
/// a triangle `[a, a + 1, a + w + 1]` (`w >= 2`) and runs for as many complete rows as follow;
/// where none starts, a strip may, for as many quads as follow its pattern; a triangle that
/// starts neither is left to the general check. Linear: a failed start is passed over, never
/// rescanned.
fn scan_grids(triangles: &[[u32; 3]]) -> Found {
    let mut found = Found::default();
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
                found.blocks.push(block);
            }
            _ => match strip_at(&triangles[t..]) {
                Some(strip) => {
                    let strip = GridStrip { start: t, ..strip };
                    t = strip.triangles().end;
                    found.strips.push(strip);
                }
                None => {
                    found.others.push(t..t + 1);
                    t += 1;
                }
            },
        }
    }
    found
}

/// The largest grid side a block may have: a block's index arithmetic (`first + j w + i`,
/// `w + 1`) then stays far from `u32`'s end.
const MAX_BLOCK_SIDE: u32 = u16::MAX as u32;

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

/// [`scan_grids`] over pieces of `triangles` in parallel, in the order of the triangles.
fn scan_grids_in_parallel(triangles: &[[u32; 3]]) -> Found {
    let pieces = rayon::current_num_threads().max(1) * 4;
    let chunk = triangles.len().div_ceil(pieces).max(SCAN_CHUNK);
    let found: Vec<_> = triangles
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, piece)| {
            let mut found = scan_grids(piece);
            let offset = c * chunk;
            for b in &mut found.blocks {
                b.start += offset;
            }
            for s in &mut found.strips {
                s.start += offset;
            }
            for run in &mut found.others.runs {
                *run = run.start + offset..run.end + offset;
            }
            found
        })
        .collect();
    let mut all = Found::default();
    for piece in found {
        all.blocks.extend(piece.blocks);
        all.strips.extend(piece.strips);
        for run in piece.others.runs {
            all.others.push(run);
        }
    }
    all
}

/// No strip matched the side.
const NO_STRIP: u32 = u32::MAX;

/// Which block holds a vertex, for blocks with sorted, disjoint vertex ranges: the vertices in
/// buckets of `2^shift`, about one block each, a bucket's candidates found by their first
/// index.
struct BlockIndex<'a> {
    blocks: &'a [GridBlock],
    shift: u32,
    /// `starts[c]`: the first block whose range ends after bucket `c` begins.
    starts: Vec<u32>,
}

impl<'a> BlockIndex<'a> {
    fn new(blocks: &'a [GridBlock], vertices: usize) -> BlockIndex<'a> {
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
            starts.push(k as u32);
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
        let (low, high) = (
            *self.starts.get(c)? as usize,
            *self.starts.get(c + 1)? as usize,
        );
        let candidates = &self.blocks[low..(high + 1).min(self.blocks.len())];
        let k = low
            + candidates
                .partition_point(|b| b.first <= v)
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
    // A dual grid of quads leaves few edges (1–2% of Spot's at rate 16), one of triangles most
    // of them (its grids are not paired by pattern): those are grouped by tail, in linear time.
    if edges.len() < vertices / 4 {
        sorted_in_pairs(&edges)
    } else {
        DirectedEdges::new(vertices, || edges.iter().copied()).is_some_and(|d| d.all_paired())
    }
}

/// Whether every directed edge of `edges` is listed once and its reverse once, by sorting: the
/// edges `a -> b` with `a < b` as `(a, b)`, those with `a > b` reversed, as `(b, a)`; closed
/// exactly when the two sorted lists are equal and neither repeats a pair. An edge from a vertex
/// to itself is its own reverse, as in [`DirectedEdges`]: it may be listed once.
///
/// For few edges: nothing is allocated per vertex, where the first writes to arrays over every
/// vertex (fresh pages) cost more than the sorts.
fn sorted_in_pairs(edges: &[(u32, u32)]) -> bool {
    let key = |a: u32, b: u32| u64::from(a) << 32 | u64::from(b);
    let (mut forward, mut backward, mut loops) = (Vec::new(), Vec::new(), Vec::new());
    for &(a, b) in edges {
        match a.cmp(&b) {
            Ordering::Less => forward.push(key(a, b)),
            Ordering::Greater => backward.push(key(b, a)),
            Ordering::Equal => loops.push(a),
        }
    }
    forward.sort_unstable();
    backward.sort_unstable();
    loops.sort_unstable();
    forward == backward
        && forward.windows(2).all(|w| w[0] != w[1])
        && loops.windows(2).all(|w| w[0] != w[1])
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
        blocks: mut found,
        strips,
        mut others,
    } = scan_grids_in_parallel(triangles);
    // Disjoint vertex ranges, a block's edges joining its own vertices only: by first vertex,
    // a block that starts before the last kept one ends goes to the general check. So does a
    // block over a seam copy, which would pair edges by index where the positions pair them
    // differently: the blocks kept hold position vertices only, and the other triangles are
    // tested by position.
    found.sort_unstable_by_key(|b| b.first);
    let mut blocks = Vec::with_capacity(found.len());
    let mut kept_end = 0;
    for b in found {
        let range = b.vertices();
        let usable = b.width <= MAX_BLOCK_SIDE
            && b.rows < MAX_BLOCK_SIDE
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
    let block_of = |v: u32| index.holding(v);
    // A strip pairs its sides with two sides of two different blocks, each side with one strip
    // only; `matched[4 k + side]` is the strip (twice its number, plus one on its side `b`).
    let mut matched = vec![NO_STRIP; 4 * blocks.len()];
    let mut kept: Vec<GridStrip> = Vec::new();
    let side_of = |(x, d, m): (i64, i64, u32)| {
        let x = u32::try_from(x).ok()?;
        let k = block_of(x)?;
        let side = blocks[k].side_of_run((x, d, m))?;
        Some((k, 4 * k + usize::from(side)))
    };
    for strip in strips {
        let [a, b] = strip.matching_runs();
        match (side_of(a), side_of(b)) {
            (Some((ka, sa)), Some((kb, sb)))
                if ka != kb && matched[sa] == NO_STRIP && matched[sb] == NO_STRIP =>
            {
                let number = 2 * kept.len() as u32;
                (matched[sa], matched[sb]) = (number, number + 1);
                kept.push(strip);
            }
            _ => others.push(strip.triangles()),
        }
    }
    // Whether the edge `v w`, `v` inside a side of block `k` that a strip matched, is an inner
    // edge of that strip.
    let strip_edge = |k: Option<usize>, v: u32, w: u32| {
        let Some((k, side)) = k.and_then(|k| Some((k, blocks[k].side_inside(v)?))) else {
            return false;
        };
        let m = matched[4 * k + usize::from(side)];
        m != NO_STRIP && kept[(m / 2) as usize].inner_edge_at(v, m % 2 == 0, w)
    };
    // Whether a block or strip pairs the edge `p q` already.
    let paired = |p: u32, q: u32| match (block_of(p), block_of(q)) {
        (Some(k), Some(l)) if k == l => {
            let block = &blocks[k];
            block.inner_edge(p, q)
                || block
                    .side_of_edge(p, q)
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
            blocks.is_empty() || !(paired(a, b) || paired(b, c) || paired(c, a))
        })
    });
    if !valid {
        return None;
    }
    // The blocks and strips kept hold position vertices only.
    for (k, b) in blocks.iter().enumerate() {
        for side in 0..4u8 {
            if matched[4 * k + usize::from(side)] == NO_STRIP {
                b.side_edges(side, &mut edges);
            }
        }
    }
    for strip in &kept {
        edges.extend(strip.end_rungs());
    }
    Some(edges)
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

    /// Whether every edge's reverse is an edge too (the tails in parallel).
    pub(crate) fn all_paired(&self) -> bool {
        self.start.par_windows(2).enumerate().all(|(a, range)| {
            self.heads[range[0] as usize..range[1] as usize]
                .iter()
                .all(|&b| self.contains(b, a as u32))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangles of a grid block of `rows` rows of `w` vertices from `first`.
    fn grid(first: u32, w: u32, rows: u32, out: &mut Vec<[u32; 3]>) {
        for j in 0..rows {
            for i in 0..w - 1 {
                let a = first + j * w + i;
                out.push([a, a + 1, a + w + 1]);
                out.push([a, a + w + 1, a + w]);
            }
        }
    }

    /// The triangles of the strip over `a_k = a + k s`, `b_k = b + k t`, `k` in `0..=m`.
    fn strip(a: i64, s: i64, b: i64, t: i64, m: i64, out: &mut Vec<[u32; 3]>) {
        for k in 0..m {
            let v = |x: i64| x as u32;
            let (a0, a1, b0, b1) = (a + k * s, a + (k + 1) * s, b + k * t, b + (k + 1) * t);
            out.push([v(b0), v(a1), v(a0)]);
            out.push([v(b0), v(b1), v(a1)]);
        }
    }

    /// Two grids of quads, long enough to be scanned in several pieces, a strip and stray
    /// triangles between them: every triangle is in exactly one block or strip or among the
    /// others, and every block's and strip's triangles are its pattern, whichever piece found
    /// it.
    #[test]
    fn pieces_cover_every_triangle_once() {
        let mut triangles = Vec::new();
        grid(0, 300, 250, &mut triangles);
        triangles.extend([[7, 3, 5], [1, 1, 1], [90_000, 4, 2]]);
        strip(75_299, -1, 100_096, -1, 96, &mut triangles);
        grid(100_000, 97, 400, &mut triangles);
        assert!(triangles.len() > 3 * SCAN_CHUNK);
        let Found {
            blocks,
            strips,
            others,
        } = scan_grids_in_parallel(&triangles);
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
        assert_eq!(strips.len(), 1);
        let found = strips[0];
        let mut expected = Vec::new();
        strip(
            found.a.into(),
            found.s,
            found.b.into(),
            found.t,
            found.quads.into(),
            &mut expected,
        );
        assert_eq!(&triangles[found.triangles()], &expected[..]);
        assert_eq!(
            (found.a, found.s, found.b, found.t, found.quads),
            (75_299, -1, 100_096, -1, 96)
        );
        for t in found.triangles() {
            seen[t] += 1;
        }
        for t in others.runs.iter().flat_map(|r| r.clone()) {
            seen[t] += 1;
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert!(blocks.len() >= 4, "{} blocks", blocks.len());
    }

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
                sorted_in_pairs(&edges),
                DirectedEdges::new(6, || edges.iter().copied()).is_some_and(|d| d.all_paired())
            );
        }
    }
}
