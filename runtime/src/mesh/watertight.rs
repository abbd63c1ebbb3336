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

use std::ops::Range;

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

/// The quad triangles `[a, b, c], [a, c, d]` at quad `i` of row `r` of width `w`.
fn grid_quad(r: u32, w: u32, i: u32) -> Option<[[u32; 3]; 2]> {
    let a = r.checked_add(i)?;
    let c = a.checked_add(w)?.checked_add(1)?;
    Some([[a, a + 1, c], [a, c, c - 1]])
}

/// How many complete rows of `w - 1` grid quads start at `triangles[0]`, the first over
/// vertices from `first` (at most `u32::MAX` rows; 0 when the first row is incomplete).
fn complete_rows(triangles: &[[u32; 3]], first: u32, w: u32) -> u32 {
    let per_row = 2 * (w as usize - 1);
    let mut rows = 0u32;
    for row in triangles.chunks_exact(per_row) {
        let Some(r) = u32::try_from(u64::from(first) + u64::from(rows) * u64::from(w)).ok() else {
            break;
        };
        let matches = (0..w - 1).all(|i| {
            let i2 = 2 * i as usize;
            grid_quad(r, w, i).is_some_and(|q| row[i2] == q[0] && row[i2 + 1] == q[1])
        });
        if !matches || rows == u32::MAX {
            break;
        }
        rows += 1;
    }
    rows
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

/// The largest grid side a block may have: its vertices' grid coordinates fit a `u16`.
const MAX_BLOCK_SIDE: u32 = u16::MAX as u32;

/// Where a vertex sits in the grid block holding it: the block and the grid coordinates.
#[derive(Clone, Copy)]
struct Cell {
    block: u32,
    i: u16,
    j: u16,
}

const NO_CELL: Cell = Cell {
    block: u32::MAX,
    i: 0,
    j: 0,
};

impl Cell {
    /// Whether the edge between the vertices at `self` and `other`, both of `block`, is a
    /// quad edge or diagonal of the block not on its border: one its triangles use both ways.
    fn inner_edge(self, other: Cell, block: &GridBlock) -> bool {
        let (p, q) = if (self.j, self.i) <= (other.j, other.i) {
            (self, other)
        } else {
            (other, self)
        };
        let (ip, jp, iq, jq) = (
            u32::from(p.i),
            u32::from(p.j),
            u32::from(q.i),
            u32::from(q.j),
        );
        let horizontal = jp == jq && iq == ip + 1 && jp > 0 && jp < block.rows;
        let vertical = ip == iq && jq == jp + 1 && ip > 0 && ip + 1 < block.width;
        let diagonal = iq == ip + 1 && jq == jp + 1;
        horizontal || vertical || diagonal
    }
}

/// Whether `triangles`, over `vertices` vertices where vertex `v` stands for `of[v]` (a seam
/// copy for its original; `of` empty for the identity), use every directed edge once and its
/// reverse once. `false` also when a triangle names a vertex beyond `vertices`.
pub(crate) fn is_closed(triangles: &[[u32; 3]], vertices: usize, of: &[u32]) -> bool {
    if triangles.iter().flatten().any(|&i| i as usize >= vertices)
        || of.iter().any(|&o| o as usize >= vertices)
    {
        return false;
    }
    let (mut blocks, mut others) = find_blocks(triangles);
    // A block over a seam copy or its original would pair edges by index where the positions
    // pair them differently: its triangles go to the general check.
    let mut merged = vec![false; if of.is_empty() { 0 } else { vertices }];
    for (v, &o) in of.iter().enumerate() {
        if o as usize != v {
            merged[v] = true;
            merged[o as usize] = true;
        }
    }
    let mut cells = vec![NO_CELL; vertices];
    let mut kept = Vec::with_capacity(blocks.len());
    for b in blocks.drain(..) {
        let range = b.vertices();
        let usable = b.width <= MAX_BLOCK_SIDE
            && b.rows < MAX_BLOCK_SIDE
            && range.end <= vertices as u64
            && !range.clone().any(|v| merged.get(v as usize) == Some(&true));
        // Disjoint vertex ranges: a block's edges join its own vertices only.
        if !usable || range.clone().any(|v| cells[v as usize].block != u32::MAX) {
            others.extend(b.triangles());
            continue;
        }
        let block = kept.len() as u32;
        for (k, v) in range.enumerate() {
            cells[v as usize] = Cell {
                block,
                i: (k as u32 % b.width) as u16,
                j: (k as u32 / b.width) as u16,
            };
        }
        kept.push(b);
    }
    let blocks = kept;
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * others.len());
    for &t in &others {
        let tri = triangles[t];
        for k in 0..3 {
            edges.push((tri[k], tri[(k + 1) % 3]));
        }
    }
    // No other triangle may use a block's inner edge, which the block already uses both ways.
    let uses_inner_edge = edges.iter().any(|&(p, q)| {
        let (a, b) = (cells[p as usize], cells[q as usize]);
        a.block != u32::MAX && a.block == b.block && a.inner_edge(b, &blocks[a.block as usize])
    });
    if uses_inner_edge {
        return false;
    }
    for b in &blocks {
        b.border_edges(&mut edges);
    }
    if !of.is_empty() {
        for e in &mut edges {
            *e = (of[e.0 as usize], of[e.1 as usize]);
        }
    }
    DirectedEdges::new(vertices, || edges.iter().copied()).is_some_and(|d| d.all_paired())
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

    fn leaving(&self, a: u32) -> &[u32] {
        let a = a as usize;
        &self.heads[self.start[a] as usize..self.start[a + 1] as usize]
    }

    pub(crate) fn contains(&self, a: u32, b: u32) -> bool {
        let leaving = self.leaving(a);
        if leaving.len() > SHORT {
            leaving.binary_search(&b).is_ok()
        } else {
            leaving.contains(&b)
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
