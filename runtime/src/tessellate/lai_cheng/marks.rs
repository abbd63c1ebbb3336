//! A face's leaves and marked points (Lai–Cheng section 5's `MarkBlack`), numbered as the
//! marking pass makes them.
//!
//! Each leaf marks its four corners. A face's marks fall on far fewer points (a point is the
//! corner of up to four leaves), and only the first mark of a point counts: its evaluation is
//! the point's position and normal ("first evaluation wins"). The marking pass numbers each
//! place when first met, through a hash table of places, and keeps per point its `(u, v)`, its
//! position and normal, and per mark only the point's number; the globalization
//! (`global_ids.rs`) reads these. Keeping every mark with its evaluation (64 bytes) and
//! numbering them afterwards read 64 bytes a mark again in a pass that did not scale on two
//! threads (docs/benchmarks.md).

use super::bezier_net::Point;
use super::Leaf;
use crate::mesh::topology::NONE;
use crate::RuntimeError;

/// A face's leaves and its marked points, each point once, in the order first marked.
#[derive(Debug, Default)]
pub(super) struct FaceMarks {
    pub(super) leaves: Vec<Leaf>,
    /// Per mark (four a leaf, its corners in the patch's order), its point.
    pub(super) point_of_mark: Vec<u32>,
    /// Per point, its `(u, v)` on the face's grid.
    pub(super) places: Vec<(u32, u32)>,
    /// Per point, the position its first mark gave it.
    pub(super) positions: Vec<Point>,
    /// Per point, the unit normal its first mark gave it.
    pub(super) normals: Vec<Point>,
    /// The points whose first mark left them to be evaluated after the marking (the corners of
    /// a hull square at a feature, `feature.rs`), ascending.
    pub(super) pending: Vec<u32>,
}

impl FaceMarks {
    /// Empty lists with the capacities of `other`'s lengths: a face's buffers sized by the face
    /// before, so that a face grows its vectors rarely (they grew by doubling from empty, and a
    /// tenth of the marking pass's instructions went to `realloc` and its copies).
    pub(super) fn sized_like(other: &FaceMarks) -> Self {
        FaceMarks {
            leaves: Vec::with_capacity(other.leaves.len()),
            point_of_mark: Vec::with_capacity(other.point_of_mark.len()),
            places: Vec::with_capacity(other.places.len()),
            positions: Vec::with_capacity(other.positions.len()),
            normals: Vec::with_capacity(other.normals.len()),
            pending: Vec::new(),
        }
    }

    /// Every list emptied, capacities kept.
    pub(super) fn clear(&mut self) {
        self.leaves.clear();
        self.point_of_mark.clear();
        self.places.clear();
        self.positions.clear();
        self.normals.clear();
        self.pending.clear();
    }

    /// Every list shrunk to its length (in place: the allocator keeps the block where it can).
    pub(super) fn shrink_to_fit(&mut self) {
        self.leaves.shrink_to_fit();
        self.point_of_mark.shrink_to_fit();
        self.places.shrink_to_fit();
        self.positions.shrink_to_fit();
        self.normals.shrink_to_fit();
    }

    /// Mark the place `(u, v)`; where it is new, its position is `position` and its normal
    /// `normal()` (evaluated only then), or both are left to be evaluated when `position` is
    /// `None`.
    pub(super) fn mark(
        &mut self,
        table: &mut PlaceTable,
        (u, v): (u32, u32),
        position: Option<Point>,
        normal: impl FnOnce() -> Point,
    ) -> Result<(), RuntimeError> {
        let next = u32::try_from(self.places.len())
            .ok()
            .filter(|&n| n != NONE)
            .ok_or_else(|| RuntimeError::Unsupported("more than 2^32 points in a face".into()))?;
        let point = table.get_or_insert(pack(u, v), next, &self.places);
        if point == next {
            self.places.push((u, v));
            match position {
                Some(p) => {
                    self.positions.push(p);
                    self.normals.push(normal());
                }
                None => {
                    self.positions.push([0.0; 3]);
                    self.normals.push([0.0; 3]);
                    self.pending.push(next);
                }
            }
        }
        self.point_of_mark.push(point);
        Ok(())
    }
}

/// `(a, b)` as one `u64` key, `a` in the high half: keys order as the pairs do.
pub(super) fn pack(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

/// A face's points by place: open addressing, linear probing, from a point's [`pack`]ed
/// `(u, v)` to its number, a slot's key and point side by side so that a probe reads one cache
/// line. At most half the slots are full (a power of two of them: a new place always finds an
/// empty slot); the table doubles past that, the places re-inserted from the face's list.
#[derive(Debug)]
pub(super) struct PlaceTable {
    slots: Vec<(u64, u32)>,
    /// Full slots.
    full: usize,
    /// `64 - log2(slots)`: a key's slot is the top bits of its product with an odd constant.
    shift: u32,
}

/// An empty slot's key: no place packs to it (`u, v <= GRID < 2^32 - 1`).
const EMPTY: u64 = u64::MAX;

/// The fewest slots a table has.
const MIN_SLOTS: usize = 16;

impl Default for PlaceTable {
    fn default() -> Self {
        PlaceTable {
            slots: vec![(EMPTY, NONE); MIN_SLOTS],
            full: 0,
            shift: 64 - MIN_SLOTS.trailing_zeros(),
        }
    }
}

impl PlaceTable {
    /// Empty the table, with room for about `points` places before it grows (the face before's
    /// count: clearing costs a write per slot, so a small face after a large one gets a small
    /// table).
    pub(super) fn reset(&mut self, points: usize) {
        let slots = points
            .saturating_mul(2)
            .max(MIN_SLOTS)
            .checked_next_power_of_two()
            .unwrap_or(MIN_SLOTS);
        self.slots.clear();
        self.slots.resize(slots, (EMPTY, NONE));
        self.full = 0;
        self.shift = 64 - slots.trailing_zeros();
    }

    /// The first slot to probe for `key` (Fibonacci hashing).
    fn slot(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> self.shift) as usize
    }

    /// The point at `key`, or `new` where there is none yet (then it is the point at `key`).
    /// `places` are the points numbered so far, by number (for the doubling).
    fn get_or_insert(&mut self, key: u64, new: u32, places: &[(u32, u32)]) -> u32 {
        let mask = self.slots.len() - 1;
        let mut i = self.slot(key);
        loop {
            let slot = &mut self.slots[i];
            if slot.0 == key {
                return slot.1;
            }
            if slot.0 == EMPTY {
                break;
            }
            i = (i + 1) & mask;
        }
        if 2 * (self.full + 1) > self.slots.len() {
            self.reset(self.slots.len());
            for (point, &(u, v)) in (0u32..).zip(places) {
                self.insert(pack(u, v), point);
            }
        }
        self.insert(key, new);
        new
    }

    /// Put `key`, absent, in its first empty slot.
    fn insert(&mut self, key: u64, point: u32) {
        let mask = self.slots.len() - 1;
        let mut i = self.slot(key);
        while self.slots[i].0 != EMPTY {
            i = (i + 1) & mask;
        }
        self.slots[i] = (key, point);
        self.full += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// The corners of the squares of dyadic quadtrees (every square of levels 1 to 5 of the
    /// unit square on a 64 x 64 grid, then one square alone) numbered in the order first met,
    /// against a `HashMap` doing the same, through tables that start small and double; the
    /// first mark's position and normal kept, pending points listed.
    #[test]
    fn places_are_numbered_in_the_order_first_met() {
        let mut squares = Vec::new();
        for depth in 1..6u32 {
            let size = 64 >> depth;
            for k in 0..(1u32 << depth) {
                for l in 0..(1u32 << depth) {
                    squares.push((k * size, l * size, size));
                }
            }
        }
        let mut table = PlaceTable::default();
        for squares in [&squares[..], &squares[..1]] {
            for hint in [0, 4, 10_000] {
                table.reset(hint);
                let mut marks = FaceMarks::default();
                let mut expected: HashMap<(u32, u32), u32> = HashMap::new();
                let mut order = Vec::new();
                for (n, &(u0, v0, size)) in squares.iter().enumerate() {
                    let corners = [
                        (u0, v0),
                        (u0 + size, v0),
                        (u0 + size, v0 + size),
                        (u0, v0 + size),
                    ];
                    for c in corners {
                        let next = expected.len() as u32;
                        let point = *expected.entry(c).or_insert(next);
                        if point == next {
                            order.push(c);
                        }
                        let at = [f64::from(c.0), f64::from(c.1), n as f64];
                        let position = (n % 3 != 0).then_some(at);
                        marks
                            .mark(&mut table, c, position, || [n as f64, 0.0, 1.0])
                            .expect("few points");
                        assert_eq!(marks.point_of_mark.last(), Some(&point));
                    }
                }
                assert_eq!(marks.places, order);
                // Each point's position is its first mark's (`n`, in the third coordinate).
                for (p, &(u, v)) in marks.places.iter().enumerate() {
                    let first = squares
                        .iter()
                        .position(|&(u0, v0, s)| {
                            [(u0, v0), (u0 + s, v0), (u0 + s, v0 + s), (u0, v0 + s)]
                                .contains(&(u, v))
                        })
                        .expect("a marked place is a square's corner");
                    let pending = marks.pending.binary_search(&(p as u32)).is_ok();
                    assert_eq!(pending, first % 3 == 0, "point {p}");
                    if !pending {
                        assert_eq!(
                            marks.positions[p],
                            [f64::from(u), f64::from(v), first as f64]
                        );
                        assert_eq!(marks.normals[p], [first as f64, 0.0, 1.0]);
                    }
                }
            }
        }
    }
}
