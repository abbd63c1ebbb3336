//! The one set of 3D vector helpers (generic over f32 and f64: the evaluators work in f32, the
//! error measures in f64) and exact point–triangle distances, shared by the error measures of
//! the tessellators (`rates`, `bezier`).

use num_traits::Float;

/// A point or vector in 3D.
pub type Point3 = [f64; 3];

/// Difference `a - b`.
pub fn sub<T: Float>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Sum `a + b`.
pub fn add<T: Float>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s * a`.
pub fn scale<T: Float>(s: T, a: [T; 3]) -> [T; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// Dot product.
pub fn dot<T: Float>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross<T: Float>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v` scaled to unit length, or zero where it has none (a degenerate tangent pair gives a
/// zero normal rather than NaN, and so does a non-finite `v`). Every output normal goes through
/// here. The squared length is used directly only when it is a normal float; otherwise (a
/// cross product of tangents of a surface of size 2e10 or 1e-11 overflows or underflows `f32`
/// when squared) `v` is first divided by its largest component, so any finite `v` other than
/// zero gets a unit result.
pub fn normalize<T: Float>(v: [T; 3]) -> [T; 3] {
    let squared = dot(v, v);
    if squared.is_normal() {
        let length = squared.sqrt();
        return v.map(|x| x / length);
    }
    let largest = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if !(largest > T::zero() && v.iter().all(|x| x.is_finite())) {
        return [T::zero(); 3];
    }
    let w = v.map(|x| x / largest);
    let length = norm(w);
    w.map(|x| x / length)
}

/// Euclidean distance between two points.
pub fn distance(a: Point3, b: Point3) -> f64 {
    norm(sub(a, b))
}

/// Euclidean length.
pub fn norm<T: Float>(a: [T; 3]) -> T {
    dot(a, a).sqrt()
}

/// The closest point to `p` on segment `ab`.
pub fn closest_point_on_segment(p: Point3, a: Point3, b: Point3) -> Point3 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    if len2 == 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0);
    add(a, scale(t, ab))
}

/// The closest point to `p` on the (closed, solid) triangle `abc`, exactly in the sense of
/// the Voronoi-region classification (Ericson, *Real-Time Collision Detection*, 5.1.5).
/// A degenerate triangle (zero area: coincident or collinear corners) is treated as the
/// union of its three sides.
pub fn closest_point_on_triangle(p: Point3, a: Point3, b: Point3, c: Point3) -> Point3 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let n = cross(ab, ac);
    let longest = dot(ab, ab).max(dot(ac, ac)).max(dot(sub(c, b), sub(c, b)));
    if dot(n, n) <= 1e-28 * longest * longest {
        let candidates = [
            closest_point_on_segment(p, a, b),
            closest_point_on_segment(p, b, c),
            closest_point_on_segment(p, c, a),
        ];
        let mut best = candidates[0];
        for q in candidates {
            if norm(sub(p, q)) < norm(sub(p, best)) {
                best = q;
            }
        }
        return best;
    }
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return add(a, scale(d1 / (d1 - d3), ab));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return add(a, scale(d2 / (d2 - d6), ac));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return add(b, scale((d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b)));
    }
    let denom = 1.0 / (va + vb + vc);
    add(a, add(scale(vb * denom, ab), scale(vc * denom, ac)))
}

/// The distance from `p` to the triangle `t` ([`closest_point_on_triangle`]).
pub fn point_triangle_distance(p: Point3, t: &[Point3; 3]) -> f64 {
    norm(sub(p, closest_point_on_triangle(p, t[0], t[1], t[2])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_unit(n: [f32; 3], expected: [f32; 3]) {
        for k in 0..3 {
            assert!((n[k] - expected[k]).abs() < 1e-6, "{n:?} != {expected:?}");
        }
    }

    /// Issue 20: the normals of a cube of side 2e10 or 1e-11 were `0 0 0`, the squared length
    /// overflowing or underflowing `f32`. Every finite nonzero vector normalizes to unit length.
    #[test]
    fn normalize_any_finite_scale() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        for s in [1.0f32, 4e20, 3e38, 1e-22, 1e-40, f32::MIN_POSITIVE] {
            assert_unit(normalize([s, 0.0, -s]), [h, 0.0, -h]);
            assert_unit(normalize([0.0, s, 0.0]), [0.0, 1.0, 0.0]);
            let tangents = cross([s.sqrt(), 0.0, 0.0], [0.0, s.sqrt(), 0.0]);
            if tangents[2] > 0.0 && tangents[2].is_finite() {
                assert_unit(normalize(tangents), [0.0, 0.0, 1.0]);
            }
        }
        let n = normalize([1e300f64, 1e300, 0.0]);
        assert!(
            (n[0] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15,
            "{n:?}"
        );
        for v in [[0.0f32; 3], [f32::INFINITY, 0.0, 0.0], [f32::NAN, 1.0, 0.0]] {
            assert_eq!(normalize(v), [0.0; 3], "{v:?}");
        }
    }
}
