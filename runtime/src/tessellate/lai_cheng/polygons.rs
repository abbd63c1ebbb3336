//! Triangulating the polygons that replace base quadrilaterals (Lai–Cheng section 4.2), and
//! writing them as OBJ n-gons.

use std::io::Write;
use std::path::Path;

use super::bezier_net::{norm, sub, Point};
use super::AdaptiveMesh;
use crate::io::atomic::write_atomically;
use crate::RuntimeError;

/// Twice the signed area of the parameter triangle `(a, b, c)` (exact on the integer grid).
fn area2(a: (i64, i64), b: (i64, i64), c: (i64, i64)) -> i64 {
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

/// Whether all the points are on one line (tested against the line through the first two).
fn collinear(mut points: impl Iterator<Item = (i64, i64)>) -> bool {
    match (points.next(), points.next()) {
        (Some(a), Some(b)) => points.all(|c| area2(a, b, c) == 0),
        _ => true,
    }
}

/// Triangulate a polygon whose vertices `params` are points of the boundary of a square in
/// parameter space, counter-clockwise, corners included (so it is convex, with collinear runs
/// along the sides). Ear clipping in parameter space with exact integer orientation tests:
/// only ears of positive area are cut, and never one that leaves the rest collinear, so every
/// triangle has positive parameter area and the triangles tile the square. Among the
/// admissible ears the one with the shortest new diagonal in space (`positions`) is cut first.
///
/// Writes index triples into `params` to `out` (cleared first), counter-clockwise in parameter
/// space; `ring` is scratch (both are kept by the caller from polygon to polygon, so that a
/// polygon allocates nothing here).
pub(crate) fn triangulate(
    params: &[(i64, i64)],
    positions: &[Point],
    ring: &mut Vec<usize>,
    out: &mut Vec<[usize; 3]>,
) {
    match quad(params, positions) {
        Some(pair) => {
            out.clear();
            out.extend_from_slice(&pair);
        }
        None => clip_ears(params, positions, ring, out),
    }
}

/// [`triangulate`]'s ear clipping, for any polygon of its shape (`out` cleared).
fn clip_ears(
    params: &[(i64, i64)],
    positions: &[Point],
    ring: &mut Vec<usize>,
    out: &mut Vec<[usize; 3]>,
) {
    out.clear();
    ring.clear();
    ring.extend(0..params.len());
    while ring.len() > 3 {
        let m = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for k in 0..m {
            let (a, b, c) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
            if area2(params[a], params[b], params[c]) <= 0 {
                continue;
            }
            let length = norm(sub(positions[a], positions[c]));
            if matches!(best, Some((l, _)) if l <= length) {
                // Not cut whether admissible or not: the earlier ear is at least as short.
                continue;
            }
            // The ring without `b`, walked in place (no copy per candidate ear); only for an
            // ear that would be cut.
            if collinear(ring.iter().filter(|&&i| i != b).map(|&i| params[i])) {
                continue;
            }
            best = Some((length, k));
        }
        let Some((_, k)) = best else {
            // Not reachable for a polygon of the documented shape; fan what is left.
            for w in 1..m - 1 {
                out.push([ring[0], ring[w], ring[w + 1]]);
            }
            return;
        };
        out.push([ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]]);
        ring.remove(k);
    }
    if ring.len() == 3 {
        out.push([ring[0], ring[1], ring[2]]);
    }
}

/// [`triangulate`]'s two triangles for a strictly convex quadrilateral (most polygons: a leaf
/// with no marked point inside its sides), without its loop: every ear is admissible, the ears
/// at corners 2 and 3 have the new diagonals of those at 1 and 0 (the same lengths to the bit),
/// so the ear at corner 0 is cut where its diagonal `3-1` is at most the other, `0-2`, else the
/// ear at corner 1. `None` for any other polygon, or a diagonal's length that is NaN (where
/// the loop's comparisons order the ears otherwise).
fn quad(params: &[(i64, i64)], positions: &[Point]) -> Option<[[usize; 3]; 2]> {
    let &[a, b, c, d] = params else {
        return None;
    };
    let &[p0, p1, p2, p3] = positions else {
        return None;
    };
    let ears = [
        area2(d, a, b),
        area2(a, b, c),
        area2(b, c, d),
        area2(c, d, a),
    ];
    if ears.iter().any(|&area| area <= 0) {
        return None;
    }
    let (l31, l02) = (norm(sub(p3, p1)), norm(sub(p0, p2)));
    if l31.is_nan() || l02.is_nan() {
        return None;
    }
    Some(if l31 <= l02 {
        [[3, 0, 1], [1, 2, 3]]
    } else {
        [[0, 1, 2], [0, 2, 3]]
    })
}

/// Write the polygons (not triangulated) as OBJ: `v`, `vn`, then one `f a//a b//b ...` line
/// per polygon, counter-clockwise for counter-clockwise input faces.
pub fn write_obj_polygons(mesh: &AdaptiveMesh, path: &Path) -> Result<(), RuntimeError> {
    let io = |source: std::io::Error| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    };
    write_atomically(path, |w| {
        writeln!(
            w,
            "# subtess Lai-Cheng adaptive tessellation: {} vertices, {} polygons",
            mesh.positions.len(),
            mesh.polygon_count()
        )
        .map_err(io)?;
        for p in &mesh.positions {
            writeln!(w, "v {} {} {}", p[0], p[1], p[2]).map_err(io)?;
        }
        for n in &mesh.normals {
            writeln!(w, "vn {} {} {}", n[0], n[1], n[2]).map_err(io)?;
        }
        for polygon in mesh.polygons() {
            write!(w, "f").map_err(io)?;
            for &i in polygon.vertices {
                write!(w, " {0}//{0}", i + 1).map_err(io)?;
            }
            writeln!(w).map_err(io)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_with_points_on_every_side_get_positive_triangles() {
        // A square of side 4 with extra points on every side, and one with points on one side.
        let shapes: [&[(i64, i64)]; 3] = [
            &[
                (0, 0),
                (1, 0),
                (2, 0),
                (4, 0),
                (4, 2),
                (4, 4),
                (2, 4),
                (0, 4),
                (0, 3),
                (0, 1),
            ],
            &[(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 4), (0, 4)],
            &[(0, 0), (4, 0), (4, 4), (0, 4)],
        ];
        for params in shapes {
            let positions: Vec<Point> = params
                .iter()
                .map(|&(u, v)| [u as f64, v as f64, 0.0])
                .collect();
            let mut triangles = Vec::new();
            triangulate(params, &positions, &mut Vec::new(), &mut triangles);
            assert_eq!(triangles.len(), params.len() - 2);
            let mut area = 0;
            for t in &triangles {
                let a = area2(params[t[0]], params[t[1]], params[t[2]]);
                assert!(a > 0, "{t:?} in {params:?}");
                area += a;
            }
            assert_eq!(area, 2 * 16);
        }
    }

    #[test]
    fn a_quadrilateral_gets_the_ear_clipping_triangles() {
        // Squares of the grid with their corners moved off the plane (and one diagonal pair
        // exactly as long as the other): the shortcut must cut the ears the loop cuts.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let square = [(0, 0), (8, 0), (8, 8), (0, 8)];
        let (mut ring, mut by_loop) = (Vec::new(), Vec::new());
        let mut cuts = [0; 2];
        for case in 0..2000 {
            let mut positions: Vec<Point> = square
                .iter()
                .map(|&(u, v)| [u as f64 + next(), v as f64 + next(), 4.0 * next()])
                .collect();
            if case % 10 == 0 {
                positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
            }
            let shortcut = quad(&square, &positions).expect("a square is strictly convex");
            clip_ears(&square, &positions, &mut ring, &mut by_loop);
            assert_eq!(by_loop, shortcut, "{positions:?}");
            cuts[usize::from(shortcut[0][0] == 0)] += 1;
        }
        // Both ears were cut: at corner 0 (its diagonal shorter, or as long) and at corner 1.
        assert!(cuts[0] > 100 && cuts[1] > 100, "{cuts:?}");
        // Not a strictly convex quadrilateral: a corner on a side, or a NaN position.
        let flat = [(0, 0), (8, 0), (8, 8), (8, 16)];
        assert!(quad(&flat, &[[0.0; 3]; 4]).is_none());
        let nan = [
            [f64::NAN; 3],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert!(quad(&square, &nan).is_none());
    }
}
