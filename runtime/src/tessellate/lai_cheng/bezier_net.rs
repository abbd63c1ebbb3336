//! Bicubic Bézier nets of regular (sub-)patches: conversion from the 4 x 4 B-spline net,
//! midpoint subdivision (de Casteljau at 1/2), and the guaranteed flatness bound that replaces
//! Lai–Cheng eq. (4)–(8).
//!
//! A net is 16 points `b[4 j + i]`, `i` along `u`, `j` along `v` (the layout order of
//! [`schemes::local_matrices::LocalMatrices`]: `q` outer).

/// A point in space.
pub type Point = [f64; 3];

pub(crate) use crate::mesh::geometry::{cross, dot, norm, sub};
use wide::f64x2;

/// A bicubic net, `b[4 j + i]`.
pub type Net = [Point; 16];

/// `a` scaled to unit length, or zero when it has none (the one normalization, at any scale).
pub(crate) use crate::mesh::geometry::normalize as unit;

fn lerp(a: Point, b: Point, t: f64) -> Point {
    std::array::from_fn(|c| a[c] + t * (b[c] - a[c]))
}

/// The Bézier net of the uniform bicubic B-spline patch with B-spline net `spline` (control
/// points at `-1..=2` in both directions): per direction `b_0 = (p_0 + 4 p_1 + p_2)/6`,
/// `b_1 = (2 p_1 + p_2)/3`, `b_2 = (p_1 + 2 p_2)/3`, `b_3 = (p_1 + 4 p_2 + p_3)/6`.
///
/// The rows first, then the columns of that, each entry written once, in plain loops (the rows
/// and columns mapped as whole nets were a tenth of the extraordinary descent; mapped as
/// arrays of points, `core::array::try_map` underneath, still 12% of the cage's frame
/// at `4e-4`, twice this).
pub fn bspline_to_bezier(spline: &Net) -> Net {
    const WEIGHTS: [[f64; 4]; 4] = [
        [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
        [0.0, 2.0 / 3.0, 1.0 / 3.0, 0.0],
        [0.0, 1.0 / 3.0, 2.0 / 3.0, 0.0],
        [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
    ];
    // `out[at(i)] = sum_m WEIGHTS[i][m] p[from(m)]`, in the order of `m`.
    fn convert(p: &Net, from: impl Fn(usize) -> usize, out: &mut Net, at: impl Fn(usize) -> usize) {
        for (i, [a, b, c, d]) in WEIGHTS.into_iter().enumerate() {
            let (p0, p1, p2, p3) = (p[from(0)], p[from(1)], p[from(2)], p[from(3)]);
            let o = &mut out[at(i)];
            for k in 0..3 {
                o[k] = a * p0[k] + b * p1[k] + c * p2[k] + d * p3[k];
            }
        }
    }
    let mut rows = [[0.0; 3]; 16];
    for j in 0..4 {
        convert(spline, |m| 4 * j + m, &mut rows, |i| 4 * j + i);
    }
    let mut out = [[0.0; 3]; 16];
    for i in 0..4 {
        convert(&rows, |m| 4 * m + i, &mut out, |j| 4 * j + i);
    }
    out
}

/// de Casteljau at `t = 1/2`: the two halves of a cubic Bézier segment, as seven points (the
/// first half's four and the second's, sharing the middle point).
fn halve(p: [Point; 4]) -> [Point; 7] {
    let a = lerp(p[0], p[1], 0.5);
    let b = lerp(p[1], p[2], 0.5);
    let c = lerp(p[2], p[3], 0.5);
    let ab = lerp(a, b, 0.5);
    let bc = lerp(b, c, 0.5);
    let m = lerp(ab, bc, 0.5);
    [p[0], a, ab, m, bc, c, p[3]]
}

/// The four quarter nets of a midpoint subdivision of the parameter square (Lai–Cheng
/// section 2), in the order `[0,1/2]^2`, `[1/2,1] x [0,1/2]`, `[1/2,1]^2`, `[0,1/2] x [1/2,1]`.
/// Exact subdivision of the polynomial (up to f64 rounding).
///
/// De Casteljau at `1/2` on each row gives seven points a row (the two halves share their
/// middle), then on each of those seven columns seven points: the quarters are the four
/// corner blocks of that 7 x 7 grid, each entry written once (the halves made as whole nets
/// and then halved again were ten copies of a net a split, a tenth of the adaptive pass's
/// instructions in `memcpy`). The arithmetic is the halves': rows first, the same `lerp`s.
pub fn split(net: &Net) -> [Net; 4] {
    let mut rows = [[[0.0; 3]; 7]; 4];
    for (j, row) in rows.iter_mut().enumerate() {
        *row = halve(std::array::from_fn(|i| net[4 * j + i]));
    }
    let mut grid = [[[0.0; 3]; 7]; 7];
    for i in 0..7 {
        let column = halve(std::array::from_fn(|j| rows[j][i]));
        for (j, p) in column.into_iter().enumerate() {
            grid[j][i] = p;
        }
    }
    let block =
        |i0: usize, j0: usize| -> Net { std::array::from_fn(|n| grid[j0 + n / 4][i0 + n % 4]) };
    [block(0, 0), block(3, 0), block(3, 3), block(0, 3)]
}

/// The corners `V_1 = S(0,0)`, `V_2 = S(1,0)`, `V_3 = S(1,1)`, `V_4 = S(0,1)` of the patch
/// (Lai–Cheng section 2), which are limit points.
pub fn corners(net: &Net) -> [Point; 4] {
    [net[0], net[3], net[15], net[12]]
}

/// Unit normals at the four corners, from the net's first differences (zero where degenerate).
pub fn corner_normals(net: &Net) -> [Point; 4] {
    std::array::from_fn(|k| corner_normal(net, k))
}

/// The unit normal at corner `k` (modulo 4) of [`corners`] ([`corner_normals`]), alone: a
/// corner that an earlier square already gave a normal needs none.
pub fn corner_normal(net: &Net, k: usize) -> Point {
    let d = |a: usize, b: usize| sub(net[b], net[a]);
    match k % 4 {
        0 => unit(cross(d(0, 1), d(0, 4))),
        1 => unit(cross(d(2, 3), d(3, 7))),
        2 => unit(cross(d(14, 15), d(11, 15))),
        _ => unit(cross(d(12, 13), d(8, 12))),
    }
}

/// The longer diagonal `max{D_1, D_2}` of the base quadrilateral (Lai–Cheng section 6).
pub fn longer_diagonal(v: &[Point; 4]) -> f64 {
    norm(sub(v[0], v[2])).max(norm(sub(v[1], v[3])))
}

/// A guaranteed bound on `|S(x) - L(x)|` over the square, where `S` is the patch and `L` is any
/// interpolant of `S` that is linear on the triangles of a triangulation of the square whose
/// vertices are points of the square's boundary (the base quadrilateral, or the polygon that
/// replaces it, Lai–Cheng section 4.2, triangulated in parameter space).
///
/// With `Q` the bilinear base quadrilateral (eq. 4) and `d = S - Q`, a bicubic whose Bézier
/// coefficients are `c_ij = b_ij - Q(i/3, j/3)` (the bilinear's degree-raised coefficients),
/// `L(x) - S(x) = (sum_k l_k Q(p_k) - Q(x)) + (sum_k l_k d(p_k) - d(x))` (`l_k` barycentric).
/// The second term is a difference of two points of the convex hull `H` of the `c_ij`. The
/// first is `w e(x)`, `w = V_1 - V_2 + V_3 - V_4` the twist, `e` the linear interpolation error
/// of `uv` on the triangle, which is at most `|du dv| / 4 <= 1/4` along the triangle's edges
/// and has no interior extremum (indefinite Hessian). So
/// `|S - L| <= max_{i,j, s = +-1} |c_i - c_j + s w / 4|` (a Minkowski sum's extreme points).
///
/// This is Lai–Cheng's two-sided test, eq. (8), made direction-free: eq. (8) adds the largest
/// deviations on the two sides of `Q` along its normal, the width of `H` in one direction; the
/// bound here is the width of `H` (plus the interpolation term) in the worst direction, so it
/// bounds the parametric distance and needs no planarity of `Q`.
pub fn flatness_bound(net: &Net) -> f64 {
    Deviation::new(net).bound()
}

/// The net's entries other than its four corners, after its first corner: the points whose
/// pairs [`Deviation`] visits (`DISTINCT` of them), then the first corner once more to make an
/// even number of lanes.
const ENTRIES: [usize; 14] = [0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14, 0];

/// The coefficients that differ: the first corner's (zero) and the twelve others'.
const DISTINCT: usize = 13;

/// The coefficients `c_ij` of `d = S - Q` by coordinate and the quarter twist `w / 4` of
/// [`flatness_bound`], from which both its bound and the cheaper lower bound
/// [`Deviation::corner_bound`] are read.
///
/// `Q` interpolates the net's corners, so the four corner coefficients are zero to the bit
/// (`V_k - V_k`, the bilinear's other terms multiplied by an exact `0`): a pair through any
/// corner has the value of the same pair through the first, and only the first corner is kept
/// ([`ENTRIES`]): the bound visits 13 x 14 pairs instead of 16 x 16, and every value it drops
/// is one that it computes.
#[derive(Clone, Copy)]
pub(crate) struct Deviation {
    x: [f64; 14],
    y: [f64; 14],
    z: [f64; 14],
    w: Point,
}

impl Deviation {
    /// The coefficients of the patch with Bézier net `net`.
    pub(crate) fn new(net: &Net) -> Self {
        let [v1, v2, v3, v4] = corners(net);
        let bilinear = |s: f64, t: f64| -> Point {
            std::array::from_fn(|k| {
                (1.0 - s) * (1.0 - t) * v1[k]
                    + s * (1.0 - t) * v2[k]
                    + s * t * v3[k]
                    + (1.0 - s) * t * v4[k]
            })
        };
        let c: [Point; 16] = std::array::from_fn(|n| {
            let (i, j) = (n % 4, n / 4);
            sub(net[n], bilinear(i as f64 / 3.0, j as f64 / 3.0))
        });
        let coordinate = |k: usize| -> [f64; 14] { ENTRIES.map(|n| c[n][k]) };
        Deviation {
            x: coordinate(0),
            y: coordinate(1),
            z: coordinate(2),
            w: std::array::from_fn(|k| (v1[k] - v2[k] + v3[k] - v4[k]) / 4.0),
        }
    }

    /// The squared length of `(c_i - c_j) + w`, in this order (the rounding of the unordered
    /// pairs' form), `i` and `j` indices of [`ENTRIES`].
    #[inline(always)]
    fn squared(&self, i: usize, j: usize) -> f64 {
        let w = self.w;
        let d = [
            self.x[i] - self.x[j] + w[0],
            self.y[i] - self.y[j] + w[1],
            self.z[i] - self.z[j] + w[2],
        ];
        dot(d, d)
    }

    /// [`flatness_bound`].
    pub(crate) fn bound(&self) -> f64 {
        // Squared lengths (`norm` is the square root of `dot`), one square root at the end:
        // `sqrt` is correctly rounded, hence monotone, so the square root of the largest square
        // is the largest length to the last bit. Every ordered pair with `+w` covers the
        // unordered pairs with both signs (`c_j - c_i + w = -(c_i - c_j - w)`, exactly in
        // floating point), and a branch-free loop over the pairs vectorizes: the largest
        // square per `j` (lane-wise maxima), then over `j`.
        // Two `j` a vector; `fast_max(sq, largest)` is `maxpd`, which keeps `largest` when `sq`
        // is NaN, as `f64::max` does (`largest` never is).
        let pairs = |c: &[f64; 14]| -> [f64x2; 7] {
            std::array::from_fn(|k| f64x2::new([c[2 * k], c[2 * k + 1]]))
        };
        let (xs, ys, zs) = (pairs(&self.x), pairs(&self.y), pairs(&self.z));
        let w = self.w.map(f64x2::splat);
        let mut largest = [f64x2::ZERO; 7];
        for i in 0..DISTINCT {
            let (xi, yi, zi) = (
                f64x2::splat(self.x[i]),
                f64x2::splat(self.y[i]),
                f64x2::splat(self.z[i]),
            );
            for k in 0..7 {
                let d = [xi - xs[k] + w[0], yi - ys[k] + w[1], zi - zs[k] + w[2]];
                let squared = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                largest[k] = squared.fast_max(largest[k]);
            }
        }
        largest
            .iter()
            .flat_map(|l| l.to_array())
            .fold(0.0f64, f64::max)
            .sqrt()
    }

    /// An upper bound of [`Deviation::bound`] (the computed value, rounding included) from 28
    /// lengths instead of 182 pairs.
    ///
    /// With `w` the quarter twist, `a_i = c_i - m + w/2` and `b_j = c_j - m - w/2` for any
    /// centre `m`, `c_i - c_j + w = a_i - b_j`, so by the triangle inequality
    /// `max_{i,j} |c_i - c_j + w| <= max_i |a_i| + max_j |b_j|`. The centre is the middle of the
    /// coefficients' bounding box, where both maxima are nearly the half-diameters along the
    /// direction that sets the bound: on Spot and the cage the result is within 1% of
    /// the bound for 99% of the leaves (at most 18% above it, docs/benchmarks.md), where a
    /// centroid gave up to 23%. The margin `1e-12` times the coefficients' largest magnitude
    /// plus the twist's covers the rounding of both computations (each a few `f64` steps
    /// from numbers of that size, errors near `1e-15` of it), so a square found flat by this
    /// bound is flat by [`Deviation::bound`] too, and takes the same decision.
    ///
    /// Why: most squares tested in full are leaves (their parents were split by
    /// [`Deviation::corner_bound`]), and on them this bound is almost always within the
    /// tolerance; the full bound is then needed only where it is not.
    pub(crate) fn upper_bound(&self) -> f64 {
        // Two entries a vector, as in `bound`; `fast_min` and `fast_max` (`minpd`, `maxpd`)
        // may drop a NaN, so a coefficient that is not finite sends the square to the full
        // bound (their sum is then not finite).
        let lanes = |c: &[f64; 14]| -> [f64x2; 7] {
            std::array::from_fn(|k| f64x2::new([c[2 * k], c[2 * k + 1]]))
        };
        let (xs, ys, zs) = (lanes(&self.x), lanes(&self.y), lanes(&self.z));
        let mut total = f64x2::ZERO;
        let mut middle = |c: &[f64x2; 7]| -> (f64x2, f64) {
            let (mut lo, mut hi) = (c[0], c[0]);
            for &v in c {
                lo = lo.fast_min(v);
                hi = hi.fast_max(v);
                total += v;
            }
            let ([l0, l1], [h0, h1]) = (lo.to_array(), hi.to_array());
            let (lo, hi) = (l0.min(l1), h0.max(h1));
            (f64x2::splat(0.5 * (lo + hi)), lo.abs().max(hi.abs()))
        };
        let ((mx, sx), (my, sy), (mz, sz)) = (middle(&xs), middle(&ys), middle(&zs));
        let w = self.w.map(|w| f64x2::splat(0.5 * w));
        let (mut a, mut b) = (f64x2::ZERO, f64x2::ZERO);
        for k in 0..7 {
            let d = [xs[k] - mx, ys[k] - my, zs[k] - mz];
            let plus = [d[0] + w[0], d[1] + w[1], d[2] + w[2]];
            let minus = [d[0] - w[0], d[1] - w[1], d[2] - w[2]];
            a = (plus[0] * plus[0] + plus[1] * plus[1] + plus[2] * plus[2]).fast_max(a);
            b = (minus[0] * minus[0] + minus[1] * minus[1] + minus[2] * minus[2]).fast_max(b);
        }
        let twist = self.w.iter().fold(0.0f64, |s, w| s + w.abs());
        if !(total.reduce_add() + twist).is_finite() {
            return f64::INFINITY;
        }
        let ([a0, a1], [b0, b1]) = (a.to_array(), b.to_array());
        let scale = sx.max(sy).max(sz) + twist;
        a0.max(a1).sqrt() + b0.max(b1).sqrt() + 1e-12 * scale
    }

    /// A lower bound of [`Deviation::bound`] from its pairs that contain a corner (`c = 0`:
    /// `|c_k + w|` and `|w - c_k|`), each computed as [`Deviation::bound`] computes it: the
    /// largest of a subset of the same numbers, so `corner_bound() > t` implies `bound() > t`
    /// to the bit.
    ///
    /// Why: a square that is split anyway needs no exact bound (only leaves record theirs), and
    /// on a curved square the largest pair usually has a corner in it (the control points bulge
    /// to one side of `Q`), so this decides most splits with 28 pairs instead of 182.
    pub(crate) fn corner_bound(&self) -> f64 {
        // Lane-wise maxima first (the pairs vectorize), then over the lanes.
        let mut largest = [0.0f64; 14];
        for (k, largest) in largest.iter_mut().enumerate() {
            *largest = self.squared(k, 0).max(self.squared(0, k));
        }
        largest.iter().fold(0.0f64, |a, &b| a.max(b)).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bicubic evaluated by de Casteljau, for the tests only.
    fn eval(net: &Net, u: f64, v: f64) -> Point {
        let curve = |p: [Point; 4], t: f64| {
            let a = [
                lerp(p[0], p[1], t),
                lerp(p[1], p[2], t),
                lerp(p[2], p[3], t),
            ];
            let b = [lerp(a[0], a[1], t), lerp(a[1], a[2], t)];
            lerp(b[0], b[1], t)
        };
        let rows: [Point; 4] =
            std::array::from_fn(|j| curve(std::array::from_fn(|i| net[4 * j + i]), u));
        curve(rows, v)
    }

    fn sample_net() -> Net {
        std::array::from_fn(|n| {
            let (i, j) = ((n % 4) as f64, (n / 4) as f64);
            [
                i + 0.1 * j * j,
                j - 0.05 * i * j,
                0.3 * (i * i - j) + 0.07 * i * j * j,
            ]
        })
    }

    #[test]
    fn split_reproduces_the_surface() {
        let net = sample_net();
        let parts = split(&net);
        let origins = [(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)];
        for (part, (u0, v0)) in parts.iter().zip(origins) {
            for (s, t) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.25), (0.6, 1.0)] {
                let a = eval(part, s, t);
                let b = eval(&net, u0 + s / 2.0, v0 + t / 2.0);
                assert!(norm(sub(a, b)) < 1e-12);
            }
        }
    }

    #[test]
    fn the_bound_holds_against_the_bilinear_and_its_triangles() {
        let net = sample_net();
        let bound = flatness_bound(&net);
        let [v1, v2, v3, v4] = corners(&net);
        // The two diagonal triangulations of the square, sampled.
        let n = 40;
        let mut worst: f64 = 0.0;
        for a in 0..=n {
            for b in 0..=n {
                let (u, v) = (a as f64 / n as f64, b as f64 / n as f64);
                let s = eval(&net, u, v);
                // Split along V1-V3: below the diagonal (V1, V2, V3), above (V1, V3, V4).
                let l1: Point = if v <= u {
                    std::array::from_fn(|k| v1[k] + u * (v2[k] - v1[k]) + v * (v3[k] - v2[k]))
                } else {
                    std::array::from_fn(|k| v1[k] + u * (v3[k] - v4[k]) + v * (v4[k] - v1[k]))
                };
                worst = worst.max(norm(sub(s, l1)));
            }
        }
        assert!(worst <= bound, "{worst} > {bound}");
        assert!(
            worst > 0.2 * bound,
            "the bound is not absurdly loose: {worst} vs {bound}"
        );
    }

    #[test]
    fn an_affine_patch_is_flat() {
        let net: Net = std::array::from_fn(|n| {
            let (i, j) = ((n % 4) as f64, (n / 4) as f64);
            [2.0 * i + j, j, 0.5 * i - j]
        });
        assert!(flatness_bound(&bspline_to_bezier(&net)) < 1e-12);
    }

    /// The bound over all 256 ordered pairs of the 16 coefficients, as the paper's form reads
    /// (the loop [`Deviation::bound`] shortens), and the largest over the pairs through a
    /// corner, from the coefficients computed here point by point.
    fn all_pairs(net: &Net) -> (f64, f64) {
        let [v1, v2, v3, v4] = corners(net);
        let c: [Point; 16] = std::array::from_fn(|n| {
            let (s, t) = ((n % 4) as f64 / 3.0, (n / 4) as f64 / 3.0);
            let q: Point = std::array::from_fn(|k| {
                (1.0 - s) * (1.0 - t) * v1[k]
                    + s * (1.0 - t) * v2[k]
                    + s * t * v3[k]
                    + (1.0 - s) * t * v4[k]
            });
            sub(net[n], q)
        });
        let w: Point = std::array::from_fn(|k| (v1[k] - v2[k] + v3[k] - v4[k]) / 4.0);
        let (mut all, mut cornered) = (0.0f64, 0.0f64);
        for i in 0..16 {
            for j in 0..16 {
                let d: Point = std::array::from_fn(|k| c[i][k] - c[j][k] + w[k]);
                all = all.max(dot(d, d));
                if [0, 3, 12, 15].contains(&i) || [0, 3, 12, 15].contains(&j) {
                    cornered = cornered.max(dot(d, d));
                }
            }
        }
        (all.sqrt(), cornered.sqrt())
    }

    /// The pairs left out (through the three other corners, whose coefficients are zero like
    /// the first's) change nothing, to the bit; the corner pairs' bound is theirs, and below
    /// the bound. Random nets at several scales and offsets, and twisted ones.
    #[test]
    fn the_bound_is_the_largest_of_all_pairs_to_the_bit() {
        let mut state = 0x2545_f491_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for case in 0..500 {
            let scale = [1e-6, 1.0, 1e3][case % 3];
            let offset = [0.0, 1e4, -37.5][case % 3];
            let net: Net = std::array::from_fn(|n| {
                let (i, j) = ((n % 4) as f64, (n / 4) as f64);
                [
                    offset + scale * (i + 0.3 * next()),
                    offset + scale * (j + 0.3 * next()),
                    scale * next() * if case % 2 == 0 { 1.0 } else { i * j },
                ]
            });
            let deviation = Deviation::new(&net);
            let (all, cornered) = all_pairs(&net);
            assert_eq!(deviation.bound().to_bits(), all.to_bits(), "case {case}");
            assert_eq!(flatness_bound(&net).to_bits(), all.to_bits(), "case {case}");
            assert_eq!(
                deviation.corner_bound().to_bits(),
                cornered.to_bits(),
                "case {case}"
            );
            assert!(deviation.corner_bound() <= deviation.bound());
            assert!(deviation.upper_bound() >= deviation.bound(), "case {case}");
        }
    }

    /// [`Deviation::upper_bound`] is never below the bound, also where the two are equal in
    /// exact arithmetic: coefficients on one line through the box's middle (`c = t e`,
    /// `t` in `[-1, 1]`, plus the corners' zero) with no twist, where both sides are the
    /// segment's length `2 |e|` (the bound the pair `t = 1`, `t = -1`); and it is that length
    /// up to its margin.
    #[test]
    fn the_upper_bound_is_above_the_bound_and_tight_on_a_segment() {
        for (case, e) in [
            [1.0, 0.0, 0.0],
            [0.3, -0.7, 0.2],
            [1e-7, 3e-7, -2e-7],
            [5e3, 1e3, 2e3],
        ]
        .into_iter()
        .enumerate()
        {
            // Bézier coefficients of a net whose corners are fixed and whose other entries
            // sit at `t e` from the bilinear (a flat square: the bilinear is the plane z = 0).
            let ts = [
                0.0, 1.0, -1.0, 0.0, 0.5, -0.5, 0.25, 1.0, -1.0, 0.75, -0.25, 0.0, 0.0, 0.1, -0.9,
                0.0,
            ];
            let net: Net = std::array::from_fn(|n| {
                let (i, j) = ((n % 4) as f64 / 3.0, (n / 4) as f64 / 3.0);
                [i + ts[n] * e[0], j + ts[n] * e[1], ts[n] * e[2]]
            });
            let deviation = Deviation::new(&net);
            let bound = deviation.bound();
            let upper = deviation.upper_bound();
            let length = 2.0 * norm(e);
            assert!(upper >= bound, "case {case}: {upper} < {bound}");
            assert!(
                (bound - length).abs() <= 1e-14 * length.max(1.0),
                "case {case}: {bound}"
            );
            assert!(
                upper - length <= 1e-11 * length.max(1.0),
                "case {case}: {upper}"
            );
        }
    }
}
