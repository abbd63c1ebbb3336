//! Directed edges grouped by tail (a counting sort), the general watertightness check on every
//! edge: the reference the pattern pairing is tested against (`TriangleMesh::boundary_edges`),
//! what many edges left by it are grouped with, and the adaptive output's check.

use rayon::prelude::*;

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
