//! A set of a mesh's vertices, a bit each: what the triangle dual grid's check marks (claimed
//! vertices, the vertex polygons' points) and asks of every triangle it does not pair in place.

use std::ops::RangeInclusive;

/// Vertices below a count, a bit each (256 KB for two million vertices, which stays in the
/// cache where the triangles stream past).
#[derive(Debug)]
pub(super) struct VertexSet {
    bits: Vec<u64>,
}

impl VertexSet {
    /// The empty set of vertices below `vertices`.
    pub(super) fn new(vertices: usize) -> VertexSet {
        VertexSet {
            bits: vec![0; vertices.div_ceil(64)],
        }
    }

    /// Add `v` (below the count); whether it was in the set already.
    pub(super) fn insert(&mut self, v: u32) -> bool {
        let (word, bit) = ((v / 64) as usize, 1 << (v % 64));
        let was = self.bits[word] & bit != 0;
        self.bits[word] |= bit;
        was
    }

    /// Remove `v` (below the count).
    pub(super) fn remove(&mut self, v: u32) {
        self.bits[(v / 64) as usize] &= !(1 << (v % 64));
    }

    /// Add every vertex of `range` (below the count), a word at a time.
    pub(super) fn insert_range(&mut self, range: RangeInclusive<u32>) {
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

    /// Whether `v` is in the set (`false` past the count).
    pub(super) fn contains(&self, v: u32) -> bool {
        self.bits
            .get((v / 64) as usize)
            .is_some_and(|word| word & 1 << (v % 64) != 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ranges added a word at a time are the vertices added one by one, and removing takes
    /// one vertex out.
    #[test]
    fn ranges_are_vertices_one_by_one() {
        for (first, last) in [
            (0, 0),
            (3, 70),
            (64, 127),
            (63, 64),
            (5, 4),
            (100, 300),
            (0, 255),
        ] {
            let mut words = VertexSet::new(320);
            words.insert_range(first..=last);
            let mut single = VertexSet::new(320);
            for v in first..=last {
                assert!(!single.insert(v));
            }
            assert_eq!(words.bits, single.bits, "{first}..={last}");
            if first <= last {
                assert!(words.insert(first));
                words.remove(first);
                assert!(!words.contains(first) && !words.insert(first));
            }
        }
        assert!(!VertexSet::new(64).contains(64));
    }
}
