//! The coarse tessellation of a patch and its displacement map (Espino et al., section 2.1).
//!
//! The coarse tessellation is the paper's 18 triangles per patch: the surface points at
//! `(u, v) = (j/3, i/3)`, `i, j = 0..=3`, joined as 3×3 quads, each cut by its `(i, j)–(i+1, j+1)`
//! diagonal. The displacement map samples the surface at `M × N` points
//! `(u, v) = (i/(M-1), j/(N-1))` and stores, for each, a signed distance to that coarse mesh:
//!
//! * general case (`S1` in Fig. 2): the point lies over exactly one triangle (its projection
//!   along the triangle's normal falls inside the triangle): the signed distance to that
//!   triangle's plane;
//! * the point lies over several triangles (`S3`): the nearest of them is chosen;
//! * the point lies over no triangle (`S2`, outside a convex fold): the distance to the
//!   nearest edge (or corner) of the coarse mesh, signed by the side of the triangles there.
//!
//! The sign is positive on the side the triangles' normals point to (`S_u × S_v`, the
//! counter-clockwise `(u, v)` order).

use super::bicubic::{cross, dot, norm, scale, sub, BicubicPatch, Point3};
use super::mesh_error::closest_point_on_triangle;
use crate::RuntimeError;

/// Segments of the coarse tessellation per patch side (the paper's 18 triangles = 2 · 3 · 3).
pub const COARSE_SEGMENTS: usize = 3;

/// The 18 coarse triangles as `(j, i)` = `(u, v)` indices on the 4×4 grid of thirds,
/// counter-clockwise in `(u, v)`.
pub fn coarse_triangles() -> [[[usize; 2]; 3]; 18] {
    let mut out = [[[0usize; 2]; 3]; 18];
    let mut k = 0;
    for i in 0..COARSE_SEGMENTS {
        for j in 0..COARSE_SEGMENTS {
            let (a, b, c, d) = ([j, i], [j + 1, i], [j + 1, i + 1], [j, i + 1]);
            out[k] = [a, b, c];
            out[k + 1] = [a, c, d];
            k += 2;
        }
    }
    out
}

/// A patch's coarse tessellation: 16 surface points and 18 triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct CoarseMesh {
    /// `S(j/3, i/3)` at index `4 * i + j`.
    pub positions: [Point3; 16],
}

impl CoarseMesh {
    /// The coarse tessellation of `patch`.
    pub fn new(patch: &BicubicPatch) -> CoarseMesh {
        let mut positions = [[0.0; 3]; 16];
        let s = COARSE_SEGMENTS as f64;
        for i in 0..=COARSE_SEGMENTS {
            for j in 0..=COARSE_SEGMENTS {
                positions[4 * i + j] = patch.position(j as f64 / s, i as f64 / s);
            }
        }
        CoarseMesh { positions }
    }

    /// The 18 triangles as corner positions (some have zero area on a collapsed row).
    pub fn triangles(&self) -> Vec<[Point3; 3]> {
        coarse_triangles()
            .iter()
            .map(|t| t.map(|[j, i]| self.positions[4 * i + j]))
            .collect()
    }
}

/// Which case of section 2.1 (Fig. 2) gave a map value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DistanceCase {
    /// `S1`: over exactly one triangle; distance to its plane.
    OneTriangle,
    /// `S3`: over several triangles; the nearest one's plane.
    SeveralTriangles,
    /// `S2`: over no triangle; distance to the nearest edge.
    NearestEdge,
}

/// The signed distance from `p` to a triangle soup by the rules of section 2.1 (Fig. 2),
/// with the case that applied.
///
/// We read the three cases as one rule, "the distance to the nearest point of the coarse
/// mesh": where that point is inside a triangle, it is the distance to that triangle's plane
/// along its normal (`S1`, or `S3` when the point lies over several triangles: the nearest
/// one is chosen); where it is on an edge or corner, the point lies over no triangle near it
/// and the distance is to that edge (`S2`). A literal "any triangle whose normal passes
/// through the point" would, on strongly curved patches (spout, handle, knob), pick the plane
/// of a far triangle over a near edge and make the map jump; the nearest-point reading keeps
/// the map continuous except where the side changes. The sign is that of `(p − q) · n` for the
/// nearest point `q` (normals summed over the triangles that share it). Zero-area triangles
/// have no plane and count only as edges.
pub fn signed_distance(triangles: &[[Point3; 3]], p: Point3) -> (f64, DistanceCase) {
    let normals: Vec<Option<Point3>> = triangles
        .iter()
        .map(|&[a, b, c]| {
            let n = cross(sub(b, a), sub(c, a));
            let longest = dot(sub(b, a), sub(b, a))
                .max(dot(sub(c, a), sub(c, a)))
                .max(dot(sub(c, b), sub(c, b)));
            (dot(n, n) > 1e-28 * longest * longest).then(|| scale(1.0 / norm(n), n))
        })
        .collect();
    let closest: Vec<(f64, Point3)> = triangles
        .iter()
        .map(|&[a, b, c]| {
            let q = closest_point_on_triangle(p, a, b, c);
            (norm(sub(p, q)), q)
        })
        .collect();
    let best = closest.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
    if !best.is_finite() {
        return (0.0, DistanceCase::NearestEdge);
    }
    // The point is "over" triangle t when its projection along t's normal is inside t, i.e.
    // when t's closest point is the foot of the perpendicular.
    let over = |t: usize| -> bool {
        match normals[t] {
            Some(n) => {
                let (d, q) = closest[t];
                let h = dot(sub(p, q), n).abs();
                (h - d).abs() <= 1e-12 * (1.0 + d)
            }
            None => false,
        }
    };
    let nearest: Vec<usize> = (0..triangles.len())
        .filter(|&t| closest[t].0 <= best * (1.0 + 1e-9) + 1e-300)
        .collect();
    let mut side = 0.0;
    for &t in &nearest {
        if let Some(n) = normals[t] {
            side += dot(sub(p, closest[t].1), n);
        }
    }
    let sign = if side < 0.0 { -1.0 } else { 1.0 };
    let case = if nearest.iter().any(|&t| over(t)) {
        if (0..triangles.len()).filter(|&t| over(t)).count() > 1 {
            DistanceCase::SeveralTriangles
        } else {
            DistanceCase::OneTriangle
        }
    } else {
        DistanceCase::NearestEdge
    };
    (sign * best, case)
}

/// A patch's displacement map: `M × N` signed distances between the surface and its coarse
/// tessellation (section 2.1), read by bilinear interpolation (section 2.2).
#[derive(Clone, Debug, PartialEq)]
pub struct DisplacementMap {
    /// Samples along `u` (`M ≥ 2`).
    pub m: usize,
    /// Samples along `v` (`N ≥ 2`).
    pub n: usize,
    /// `values[j * m + i]` at `(u, v) = (i/(M-1), j/(N-1))`.
    pub values: Vec<f64>,
    /// How many samples fell in each case: `[S1, S3, S2]` ([`DistanceCase`]).
    pub cases: [usize; 3],
}

impl DisplacementMap {
    /// The map of `patch` at resolution `m × n` (each at least 2).
    pub fn build(
        patch: &BicubicPatch,
        m: usize,
        n: usize,
    ) -> Result<DisplacementMap, RuntimeError> {
        if m < 2 || n < 2 {
            return Err(RuntimeError::invalid_option(format!(
                "displacement map resolution {m}x{n}: both must be at least 2"
            )));
        }
        let triangles = CoarseMesh::new(patch).triangles();
        let mut values = Vec::with_capacity(m * n);
        let mut cases = [0usize; 3];
        for j in 0..n {
            for i in 0..m {
                let p = patch.position(i as f64 / (m - 1) as f64, j as f64 / (n - 1) as f64);
                let (d, case) = signed_distance(&triangles, p);
                cases[case as usize] += 1;
                values.push(d);
            }
        }
        Ok(DisplacementMap {
            m,
            n,
            values,
            cases,
        })
    }

    /// The map at `(u, v)` (clamped to the unit square), bilinearly interpolated between the
    /// four nearest samples ("the distances are linearly interpolated", section 2.2).
    pub fn sample(&self, u: f64, v: f64) -> f64 {
        let x = u.clamp(0.0, 1.0) * (self.m - 1) as f64;
        let y = v.clamp(0.0, 1.0) * (self.n - 1) as f64;
        let i = (x.floor() as usize).min(self.m - 2);
        let j = (y.floor() as usize).min(self.n - 2);
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |i: usize, j: usize| self.values[j * self.m + i];
        let bottom = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let top = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        bottom * (1.0 - fy) + top * fy
    }
}
