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
//!
//! Once the face is marked, each leaf also lists the face's points strictly inside those of its
//! sides that lie inside the face, from the same table: the marked points of the polygon that
//! replaces it there (section 5), found by halving the side ([`PlaceTable::push_between`]).
//! Only the points on the face's own sides, which the face across shares, are left to the
//! globalization.

use super::bezier_net::Point;
use super::Leaf;
use crate::mesh::topology::NONE;
use crate::RuntimeError;

/// A face's leaves and its marked points, each point once, in the order first marked.
#[derive(Debug, Default)]
pub(super) struct FaceMarks {
    pub(super) leaves: Vec<Leaf>,
    /// Per leaf, its corners' points counter-clockwise from its `(u0, v0)`.
    pub(super) corners: Vec<[u32; 4]>,
    /// Per leaf, where the points inside each of its sides end in `side_points` (those of
    /// side `s`, from corner `s` to corner `s + 1`, start where side `s - 1`'s end, or the leaf
    /// before's side 3's); a side on the face's boundary has none there.
    pub(super) side_ends: Vec<[u32; 4]>,
    /// The points strictly inside the leaves' sides, counter-clockwise ([`FaceMarks::sides`]).
    pub(super) side_points: Vec<u32>,
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
    /// Every list emptied, capacities kept.
    pub(super) fn clear(&mut self) {
        self.leaves.clear();
        self.corners.clear();
        self.side_ends.clear();
        self.side_points.clear();
        self.places.clear();
        self.positions.clear();
        self.normals.clear();
        self.pending.clear();
    }

    /// Mark the place `(u, v)`, its point's number returned; where it is new, its position is
    /// `position` and its normal `normal()` (evaluated only then), or both are left to be
    /// evaluated when `position` is `None`.
    pub(super) fn mark(
        &mut self,
        table: &mut PlaceTable,
        (u, v): (u32, u32),
        position: Option<Point>,
        normal: impl FnOnce() -> Point,
    ) -> Result<u32, RuntimeError> {
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
        Ok(point)
    }

    /// List every leaf's side points (`side_ends`, `side_points`) from `table`, which holds
    /// this face's points: on each side of a leaf that lies inside the face, the marked points
    /// strictly between its corners, counter-clockwise.
    pub(super) fn sides(&mut self, table: &PlaceTable) -> Result<(), RuntimeError> {
        let too_many = || RuntimeError::Unsupported("more than 2^32 side points in a face".into());
        self.side_ends.clear();
        self.side_points.clear();
        // The parent square of the four sibling leaves being listed, if any.
        let mut siblings: Option<(u32, u32, usize)> = None;
        for (i, leaf) in self.leaves.iter().enumerate() {
            if siblings.is_some_and(|(_, _, end)| i >= end) {
                siblings = None;
            }
            if siblings.is_none() {
                siblings = sibling_leaves(&self.leaves[i..]).map(|(pu, pv)| (pu, pv, i + 4));
            }
            let corners = leaf.corners();
            let mut inside = leaf.on_face_side().map(|on| on.is_none());
            // A side facing a sibling that is a leaf too has no point inside.
            if let Some((pu, pv, _)) = siblings {
                let (left, bottom) = (leaf.u0 == pu, leaf.v0 == pv);
                inside[if bottom { 2 } else { 0 }] = false;
                inside[if left { 1 } else { 3 }] = false;
            }
            let mut ends = [0; 4];
            for s in 0..4 {
                if inside[s] {
                    table.push_between(corners[s], corners[(s + 1) % 4], &mut self.side_points);
                }
                ends[s] = u32::try_from(self.side_points.len()).map_err(|_| too_many())?;
            }
            self.side_ends.push(ends);
        }
        Ok(())
    }
}

/// The lower-left corner of the parent square of the first four `leaves` where they are its
/// four children (the same size, tiling a square of twice it on the dyadic grid), in any order.
fn sibling_leaves(leaves: &[Leaf]) -> Option<(u32, u32)> {
    let four = leaves.get(..4)?;
    let size = four[0].size;
    let (pu, pv) = (four[0].u0 & !size, four[0].v0 & !size);
    let mut seen = [false; 4];
    for leaf in four {
        let (du, dv) = (leaf.u0.wrapping_sub(pu), leaf.v0.wrapping_sub(pv));
        let slot = match (du == size, dv == size) {
            _ if leaf.size != size || (du != 0 && du != size) || (dv != 0 && dv != size) => None,
            (right, up) => Some(usize::from(right) + 2 * usize::from(up)),
        }?;
        if std::mem::replace(&mut seen[slot], true) {
            return None;
        }
    }
    Some((pu, pv))
}

/// The slot of the corner `(u, v)` of a square with lower-left corner `(u0, v0)`
/// counter-clockwise from it: `(u0, v0)`, `(u1, v0)`, `(u1, v1)`, `(u0, v1)`.
pub(super) fn counter_clockwise((u, v): (u32, u32), (u0, v0): (u32, u32)) -> usize {
    let (right, up) = (u != u0, v != v0);
    usize::from(right ^ up) + 2 * usize::from(up)
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
        if let Some(point) = self.get(key) {
            return point;
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

    /// The point at `key`, if there is one.
    fn get(&self, key: u64) -> Option<u32> {
        let mask = self.slots.len() - 1;
        let mut i = self.slot(key);
        loop {
            let slot = self.slots[i];
            if slot.0 == key {
                return Some(slot.1);
            }
            if slot.0 == EMPTY {
                return None;
            }
            i = (i + 1) & mask;
        }
    }

    /// Append the points strictly between the places `a` and `b`, from `a` to `b`, where `a`
    /// and `b` are the ends of a side of a leaf of this face's quadtree and the side lies
    /// inside the face.
    ///
    /// Why halving finds them all: a point inside the side is a corner of a smaller leaf across
    /// it, inside the square of the side's size across it; that square was then split, and its
    /// child at the side's midpoint `m` is a leaf or split again, so some leaf has `m` as a
    /// corner: `m` is marked. The same holds for each half, with the children across them.
    /// A side without points costs one lookup.
    pub(super) fn push_between(&self, a: (u32, u32), b: (u32, u32), out: &mut Vec<u32>) {
        let m = ((a.0 + b.0) / 2, (a.1 + b.1) / 2);
        // A side one grid step long has no midpoint on the grid.
        if m == a || m == b {
            return;
        }
        if let Some(point) = self.get(pack(m.0, m.1)) {
            self.push_between(a, m, out);
            out.push(point);
            self.push_between(m, b, out);
        }
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
    use super::super::GRID;
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
                        let marked = marks
                            .mark(&mut table, c, position, || [n as f64, 0.0, 1.0])
                            .expect("few points");
                        assert_eq!(marked, point);
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

    /// Random quadtrees over a face (split with probability falling with depth, down to
    /// depth 7), their leaves in depth-first order and reversed: each leaf's side points
    /// ([`FaceMarks::sides`]) against every marked place strictly inside each of its sides that
    /// lies inside the face, found by scanning all of them, in counter-clockwise order.
    #[test]
    fn side_points_are_the_marked_points_inside_each_side() {
        fn grow(state: &mut u64, (u0, v0, depth): (u32, u32, u32), leaves: &mut Vec<Leaf>) {
            *state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let chance = (*state >> 33) % 8;
            let size = GRID >> depth;
            if depth < 7 && (depth == 0 || chance + u64::from(depth) < 8) {
                let half = size / 2;
                for (du, dv) in [(0, 0), (half, 0), (half, half), (0, half)] {
                    grow(state, (u0 + du, v0 + dv, depth + 1), leaves);
                }
                return;
            }
            leaves.push(Leaf {
                u0,
                v0,
                size,
                depth,
                bound: 0.0,
                tolerance: 0.0,
                diagonal: 0.0,
                extraordinary: false,
            });
        }
        let mut state = 7;
        let mut sides_seen = [0usize; 2];
        for tree in 0..40 {
            let mut leaves = Vec::new();
            grow(&mut state, (0, 0, 0), &mut leaves);
            if tree % 2 == 1 {
                leaves.reverse();
            }
            let mut table = PlaceTable::default();
            let mut marks = FaceMarks::default();
            for leaf in &leaves {
                let (u1, v1) = (leaf.u0 + leaf.size, leaf.v0 + leaf.size);
                for c in [(leaf.u0, leaf.v0), (u1, leaf.v0), (u1, v1), (leaf.u0, v1)] {
                    marks
                        .mark(&mut table, c, Some([0.0; 3]), || [0.0; 3])
                        .expect("few");
                }
            }
            marks.leaves = leaves;
            marks.sides(&table).expect("few side points");
            let mut from = 0;
            for (leaf, ends) in marks.leaves.iter().zip(&marks.side_ends) {
                let (u0, v0, u1, v1) = (leaf.u0, leaf.v0, leaf.u0 + leaf.size, leaf.v0 + leaf.size);
                let corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1)];
                for s in 0..4 {
                    let (a, b) = (corners[s], corners[(s + 1) % 4]);
                    let on_face_side = match s {
                        0 => v0 == 0,
                        1 => u1 == GRID,
                        2 => v1 == GRID,
                        _ => u0 == 0,
                    };
                    // Every marked place strictly between `a` and `b`, by distance from `a`.
                    let mut expected: Vec<(u32, u32)> = Vec::new();
                    if !on_face_side {
                        expected = marks
                            .places
                            .iter()
                            .copied()
                            .filter(|&(u, v)| {
                                let within = |x: u32, p: u32, q: u32| p.min(q) < x && x < p.max(q);
                                (a.0 == b.0 && u == a.0 && within(v, a.1, b.1))
                                    || (a.1 == b.1 && v == a.1 && within(u, a.0, b.0))
                            })
                            .collect();
                        expected.sort_by_key(|&(u, v)| u.abs_diff(a.0) + v.abs_diff(a.1));
                    }
                    let found: Vec<(u32, u32)> = marks.side_points[from..ends[s] as usize]
                        .iter()
                        .map(|&p| marks.places[p as usize])
                        .collect();
                    assert_eq!(found, expected, "tree {tree}, leaf {leaf:?}, side {s}");
                    sides_seen[usize::from(!expected.is_empty())] += 1;
                    from = ends[s] as usize;
                }
            }
        }
        // Both kinds of side were met, many times.
        assert!(sides_seen.iter().all(|&n| n > 100), "{sides_seen:?}");
    }
}
