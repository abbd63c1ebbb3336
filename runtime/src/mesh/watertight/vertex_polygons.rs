//! The vertex polygons of a triangle dual grid among the triangles that no block or strip
//! pairs: a *closed fan* `[c, x_r, x_(r+1)]`, `r` in `0..m`, `x_m = x_0`, `m >= 3`, its ring
//! `x_0 .. x_(m-1)` all different and different from `c` (the tessellator fans a polygon at the
//! primal vertex's limit point, `kernel::Connectivity::connect`).
//!
//! Why its spokes pair in place: triangle `r` uses `c -> x_r` and `x_(r+1) -> c`, so each spoke
//! is used once each way, by two consecutive triangles, and no other spoke repeats one (the
//! ring's points differ). Where no other triangle uses `c` (*private*: in no kept block, whose
//! triangles and strips use the blocks' vertices only, the centre of no other fan, on no other
//! triangle among these), the edges at `c` are those spokes: the mesh is closed exactly when the
//! rest is, the rims `x_r -> x_(r+1)` and every other triangle's edges. Everything is by
//! position (a seam copy stands for its original), as the general check counts.

use std::ops::Range;

use super::vertex_set::VertexSet;
use super::Seams;

/// The closed fan at `triangles[0]` (corners by position): its centre and number of
/// triangles, its ring into `ring`; else the number of triangles that go on as a fan would
/// (at least one), which the caller passes over so that it stays linear (a closed fan that
/// starts among them is left to the general check: a cost, not an answer).
fn closed_fan_at(triangles: &[[u32; 3]], ring: &mut Vec<u32>) -> Result<(u32, usize), usize> {
    let Some(&[c, x0, _]) = triangles.first() else {
        return Err(1);
    };
    ring.clear();
    let mut expected = x0;
    for &[centre, x, next] in triangles {
        if centre != c || x != expected {
            break;
        }
        ring.push(x);
        if next == x0 {
            let m = ring.len();
            // The ring's points differ from each other and from the centre.
            ring.push(c);
            ring.sort_unstable();
            let simple = ring.windows(2).all(|w| w[0] != w[1]);
            return if m >= 3 && simple { Ok((c, m)) } else { Err(m) };
        }
        expected = next;
    }
    Err(ring.len().max(1))
}

/// The directed edges of `triangles` over `runs`, by position, into `out`, but the spokes of
/// closed fans around private points (the module's documentation); `in_block(v)`: whether the
/// position `v` is a kept block's vertex. `None` when a triangle names a vertex beyond
/// `vertices`; else whether one of its corners is in `avoid`.
pub(super) fn edges_off_polygons(
    triangles: &[[u32; 3]],
    runs: &[Range<usize>],
    vertices: usize,
    seams: &Seams,
    in_block: impl Fn(u32) -> bool,
    avoid: &VertexSet,
    out: &mut Vec<(u32, u32)>,
) -> Option<bool> {
    // The fans found, by first triangle, with their centres; the triangles as positions.
    let mut fans: Vec<(usize, u32, usize)> = Vec::new();
    let (mut centres, mut twice, mut used) = (
        VertexSet::new(vertices),
        VertexSet::new(vertices),
        VertexSet::new(vertices),
    );
    let mut positions: Vec<[u32; 3]> = Vec::new();
    let mut ring = Vec::new();
    let mut touched = false;
    for run in runs {
        positions.clear();
        for &corners in &triangles[run.clone()] {
            if corners.iter().any(|&v| v as usize >= vertices) {
                return None;
            }
            let corners = corners.map(|v| seams.position(v));
            touched |= corners.iter().any(|&v| avoid.contains(v));
            positions.push(corners);
        }
        let mut t = 0;
        while t < positions.len() {
            let passed = match closed_fan_at(&positions[t..], &mut ring) {
                Ok((c, m)) if !in_block(c) => {
                    if centres.insert(c) {
                        twice.insert(c);
                    }
                    for &[_, x, _] in &positions[t..t + m] {
                        used.insert(x);
                    }
                    fans.push((run.start + t, c, m));
                    t += m;
                    continue;
                }
                Ok((_, m)) | Err(m) => m,
            };
            for &[a, b, c] in &positions[t..t + passed] {
                for v in [a, b, c] {
                    used.insert(v);
                }
                out.extend([(a, b), (b, c), (c, a)]);
            }
            t += passed;
        }
    }
    for (start, c, m) in fans {
        let private = !twice.contains(c) && !used.contains(c);
        for &corners in &triangles[start..start + m] {
            let [a, b, x] = corners.map(|v| seams.position(v));
            if private {
                out.push((b, x));
            } else {
                out.extend([(a, b), (b, x), (x, a)]);
            }
        }
    }
    Some(touched)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fan `[c, x_r, x_(r+1)]` around `c` over `ring`, closed.
    fn fan(c: u32, ring: &[u32]) -> Vec<[u32; 3]> {
        (0..ring.len())
            .map(|r| [c, ring[r], ring[(r + 1) % ring.len()]])
            .collect()
    }

    fn edges(triangles: &[[u32; 3]], in_block: impl Fn(u32) -> bool) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        let whole = 0..triangles.len();
        let none = VertexSet::new(0);
        let touched = edges_off_polygons(
            triangles,
            std::slice::from_ref(&whole),
            100,
            &Seams::default(),
            in_block,
            &none,
            &mut out,
        );
        assert_eq!(touched, Some(false));
        out.sort_unstable();
        out
    }

    fn all(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
        let mut out: Vec<_> = triangles
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .collect();
        out.sort_unstable();
        out
    }

    /// A closed fan around a private point leaves its rims; a fan that is open, whose ring
    /// repeats a point, whose centre is a block's, is another fan's centre, or is on another
    /// triangle leaves every edge.
    #[test]
    fn private_fans_leave_their_rims() {
        let pentagon = fan(0, &[1, 2, 3, 4, 5]);
        let rims = vec![(1, 2), (2, 3), (3, 4), (4, 5), (5, 1)];
        assert_eq!(edges(&pentagon, |_| false), rims);
        let keep_all = [
            pentagon[..4].to_vec(),
            fan(0, &[1, 2, 3, 1, 5]),
            fan(0, &[1, 0, 3, 4]),
            [fan(0, &[1, 2, 3]), fan(0, &[4, 5, 6])].concat(),
            [pentagon.clone(), vec![[0, 7, 8]]].concat(),
        ];
        for triangles in keep_all {
            assert_eq!(
                edges(&triangles, |_| false),
                all(&triangles),
                "{triangles:?}"
            );
        }
        assert_eq!(edges(&pentagon, |v| v == 0), all(&pentagon));
        // On another fan's ring: that fan, private, leaves its rims; this one every edge.
        let triangles = [pentagon.clone(), fan(9, &[0, 7, 8])].concat();
        let mut expected = [all(&pentagon), vec![(0, 7), (7, 8), (8, 0)]].concat();
        expected.sort_unstable();
        assert_eq!(edges(&triangles, |_| false), expected);
        // Two private fans side by side, after a stray triangle: both leave their rims.
        let triangles = [vec![[20, 21, 22]], pentagon, fan(10, &[11, 12, 13])].concat();
        let mut expected = [rims, vec![(11, 12), (12, 13), (13, 11)]].concat();
        expected.extend([(20, 21), (21, 22), (22, 20)]);
        expected.sort_unstable();
        assert_eq!(edges(&triangles, |_| false), expected);
    }
}
