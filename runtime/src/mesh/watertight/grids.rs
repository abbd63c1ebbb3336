//! The patterns the watertightness check pairs in place: the faces' grids (blocks) and the
//! strips between them, found by a scan of the triangle list ([`scan_grids_in_parallel`]); the
//! conditions under which their edges pair are in the parent module's documentation.

use std::ops::Range;

use rayon::prelude::*;

use super::fans::{fan_block_at, FanBlock};
use super::merge_strips::{merge_strip_at, MergeStrip, Rows};

/// A run of grid quads found in the triangle list: `rows` rows of `width - 1` quads over the
/// vertices `first..first + (rows + 1) * width`, row-major.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct GridBlock {
    /// The block's first triangle.
    pub(super) start: usize,
    pub(super) first: u32,
    pub(super) width: u32,
    pub(super) rows: u32,
}

impl GridBlock {
    pub(super) fn triangles(&self) -> Range<usize> {
        self.start..self.start + 2 * (self.width as usize - 1) * self.rows as usize
    }

    pub(super) fn vertices(&self) -> Range<u64> {
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
    pub(super) fn side_of_run(&self, run: (u32, i64, u32)) -> Option<u8> {
        (0..4).find(|&side| self.side_run(side) == run)
    }

    /// The directed edges of side `side`, as the block's triangles run them.
    pub(super) fn side_edges(&self, side: u8, out: &mut Vec<(u32, u32)>) {
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
    pub(super) fn side_inside(&self, v: u32) -> Option<u8> {
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
    pub(super) fn side_of_edge(&self, p: u32, q: u32) -> Option<u8> {
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
pub(super) struct GridStrip {
    /// The strip's first triangle.
    start: usize,
    a: u32,
    s: i64,
    b: u32,
    t: i64,
    quads: u32,
}

impl GridStrip {
    pub(super) fn triangles(&self) -> Range<usize> {
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
    pub(super) fn matching_runs(&self) -> [(i64, i64, u32); 2] {
        let m = self.quads;
        [(self.a_at(0), self.s, m), (self.b_at(m), -self.t, m)]
    }

    /// Whether `{v, w}` is one of the strip's inner edges, `v` being `a_k` (`on_a`) or `b_k`
    /// for some `0 < k < m`: the rung `a_k b_k` and the diagonals `b_(k-1) a_k`, `b_k a_(k+1)`.
    pub(super) fn inner_edge_at(&self, v: u32, on_a: bool, w: u32) -> bool {
        let w = i64::from(w);
        if on_a {
            let k = ((i64::from(v) - i64::from(self.a)) / self.s) as u32;
            w == self.b_at(k) || w == self.b_at(k - 1)
        } else {
            let k = ((i64::from(v) - i64::from(self.b)) / self.t) as u32;
            w == self.a_at(k) || w == self.a_at(k + 1)
        }
    }

    /// The strip's rows `a_0..=a_m` and `b_0..=b_m`, into `rows`: the same triangles read as a
    /// merge strip whose rows advance in turn ([`super::merge_strips`]).
    pub(super) fn rows(&self, rows: &mut Rows) {
        // A strip's vertices are the triangles' indices: they fit.
        let v = |x: i64| x as u32;
        rows.a.clear();
        rows.b.clear();
        rows.a.extend((0..=self.quads).map(|k| v(self.a_at(k))));
        rows.b.extend((0..=self.quads).map(|k| v(self.b_at(k))));
    }

    /// The end rungs `a_0 -> b_0` and `b_m -> a_m`, the strip's edges that pair outside it.
    pub(super) fn end_rungs(&self) -> [(u32, u32); 2] {
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

/// What the scan finds: grid blocks, fan blocks, strips, merge strips, and the triangles
/// outside them.
#[derive(Debug, Default)]
pub(super) struct Found {
    pub(super) blocks: Vec<GridBlock>,
    pub(super) fans: Vec<FanBlock>,
    pub(super) strips: Vec<GridStrip>,
    pub(super) merges: Vec<MergeStrip>,
    pub(super) others: Others,
}

/// Triangles left to the general check, as runs of consecutive indices (a mesh without grids
/// is one run, not an index per triangle).
#[derive(Debug, Default)]
pub(super) struct Others {
    pub(super) runs: Vec<Range<usize>>,
}

impl Others {
    /// Add the triangles `run`, after every other.
    pub(super) fn push(&mut self, run: Range<usize>) {
        match self.runs.last_mut() {
            Some(last) if last.end == run.start => last.end = run.end,
            _ => self.runs.push(run),
        }
    }

    pub(super) fn len(&self) -> usize {
        self.runs.iter().map(|r| r.len()).sum()
    }

    /// The runs cut into pieces of at most `size` triangles, for the threads.
    pub(super) fn pieces(&self, size: usize) -> Vec<Range<usize>> {
        let cut = |run: &Range<usize>| {
            let end = run.end;
            run.clone()
                .step_by(size)
                .map(move |start| start..end.min(start + size))
        };
        self.runs.iter().flat_map(cut).collect()
    }
}

/// The grid blocks, fan blocks, strips and merge strips of `triangles` and the triangles
/// outside them. A block starts at a triangle `[a, a + 1, a + w + 1]` (`w >= 2`) and runs for
/// as many complete rows as follow; where none starts, a whole fan block may ([`fan_block_at`]),
/// else a strip, for as many quads as follow its pattern, else a merge strip between two fan
/// blocks' sides ([`merge_strip_at`]); a triangle that starts none is left to the general
/// check. Linear: a failed start is passed over, never rescanned, and a zigzag that is no
/// merge strip is tried once more from its second triangle (a stray triangle may go on into a
/// strip), then passed over whole.
fn scan_grids(triangles: &[[u32; 3]]) -> Found {
    let mut found = Found::default();
    let mut rows = Rows::default();
    // Whether the triangle before failed as a merge strip's start.
    let mut retrying = false;
    let mut t = 0;
    while t < triangles.len() {
        let [a, b, c] = triangles[t];
        let width = c.checked_sub(a).and_then(|d| d.checked_sub(1));
        let rows_of_grid = match width {
            Some(w) if b == a.wrapping_add(1) && w >= 2 => complete_rows(&triangles[t..], a, w),
            _ => 0,
        };
        let passed = match (width, rows_of_grid) {
            (Some(width), rows) if rows > 0 => {
                let block = GridBlock {
                    start: t,
                    first: a,
                    width,
                    rows,
                };
                found.blocks.push(block);
                block.triangles().len()
            }
            _ => {
                if let Some(fans) = fan_block_at(&triangles[t..]) {
                    let fans = FanBlock { start: t, ..fans };
                    found.fans.push(fans);
                    fans.triangles().len()
                } else if let Some(strip) = strip_at(&triangles[t..]) {
                    let strip = GridStrip { start: t, ..strip };
                    found.strips.push(strip);
                    strip.triangles().len()
                } else {
                    match merge_strip_at(&triangles[t..], &mut rows) {
                        Ok(merge) => {
                            let length = merge.triangles.len();
                            found.merges.push(MergeStrip {
                                triangles: t..t + length,
                                ..merge
                            });
                            length
                        }
                        Err(zigzag) => {
                            let passed = if retrying { zigzag } else { 1 };
                            retrying = !retrying && zigzag > 1;
                            found.others.push(t..t + passed);
                            t += passed;
                            continue;
                        }
                    }
                }
            }
        };
        retrying = false;
        t += passed;
    }
    found
}

/// The largest grid side a block may have: a block's index arithmetic (`first + j w + i`,
/// `w + 1`) then stays far from `u32`'s end.
pub(super) const MAX_BLOCK_SIDE: u32 = u16::MAX as u32;

impl GridBlock {
    /// Whether the edge between the block's vertices `p` and `q` is a quad edge or diagonal of
    /// the block not on its border: one its triangles use both ways.
    pub(super) fn inner_edge(&self, p: u32, q: u32) -> bool {
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
pub(super) const SCAN_CHUNK: usize = 1 << 16;

/// [`scan_grids`] over pieces of `triangles` in parallel, in the order of the triangles.
pub(super) fn scan_grids_in_parallel(triangles: &[[u32; 3]]) -> Found {
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
            for f in &mut found.fans {
                f.start += offset;
            }
            for s in &mut found.strips {
                s.start += offset;
            }
            for m in &mut found.merges {
                m.triangles = m.triangles.start + offset..m.triangles.end + offset;
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
        all.fans.extend(piece.fans);
        all.strips.extend(piece.strips);
        all.merges.extend(piece.merges);
        for run in piece.others.runs {
            all.others.push(run);
        }
    }
    all
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::fans::tests::fans;
    use super::*;

    /// The triangles of a grid block of `rows` rows of `w` vertices from `first`.
    pub(in crate::mesh::watertight) fn grid(
        first: u32,
        w: u32,
        rows: u32,
        out: &mut Vec<[u32; 3]>,
    ) {
        for j in 0..rows {
            for i in 0..w - 1 {
                let a = first + j * w + i;
                out.push([a, a + 1, a + w + 1]);
                out.push([a, a + w + 1, a + w]);
            }
        }
    }

    /// The triangles of the strip over `a_k = a + k s`, `b_k = b + k t`, `k` in `0..=m`.
    pub(in crate::mesh::watertight) fn strip(
        a: i64,
        s: i64,
        b: i64,
        t: i64,
        m: i64,
        out: &mut Vec<[u32; 3]>,
    ) {
        for k in 0..m {
            let v = |x: i64| x as u32;
            let (a0, a1, b0, b1) = (a + k * s, a + (k + 1) * s, b + k * t, b + (k + 1) * t);
            out.push([v(b0), v(a1), v(a0)]);
            out.push([v(b0), v(b1), v(a1)]);
        }
    }

    /// Two grids of quads, long enough to be scanned in several pieces, a strip and stray
    /// triangles between them, three fan blocks after them: every triangle is in exactly one block or strip or among the
    /// others, and every block's and strip's triangles are its pattern, whichever piece found
    /// it.
    #[test]
    fn pieces_cover_every_triangle_once() {
        let mut triangles = Vec::new();
        grid(0, 300, 250, &mut triangles);
        triangles.extend([[7, 3, 5], [1, 1, 1], [90_000, 4, 2]]);
        strip(75_299, -1, 100_096, -1, 96, &mut triangles);
        grid(100_000, 97, 400, &mut triangles);
        let before_fans = triangles.len();
        for k in 0..3 {
            fans(200_000 + 1_000 * k, 7 + k, &mut triangles);
        }
        let fan_triangles = triangles[before_fans..].to_vec();
        assert!(triangles.len() > 3 * SCAN_CHUNK);
        let Found {
            blocks,
            fans: fan_blocks,
            strips,
            merges,
            others,
        } = scan_grids_in_parallel(&triangles);
        assert_eq!(merges, []);
        let mut seen = vec![0u8; triangles.len()];
        assert_eq!(fan_blocks.len(), 3);
        let mut scanned = Vec::new();
        for f in &fan_blocks {
            scanned.extend_from_slice(&triangles[f.triangles()]);
            for t in f.triangles() {
                seen[t] += 1;
            }
        }
        assert_eq!(scanned, fan_triangles);
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
}
