//! The twelve symmetries of the triangular lattice in skew coordinates, and the canonical
//! grid points a compact region table stores a regular basis on (docs/table-format.md,
//! "Compact region tables").
//!
//! Skew coordinates `(x_1, x_2)` are the point `x_1 e_1 + x_2 e_2`, `e_1 = (1, 0)`,
//! `e_2 = (1/2, sqrt(3)/2)`. The rotation by 60 degrees is `rho(x) = (-x_2, x_1 + x_2)`
//! (`e_1 -> e_2`, `e_2 -> e_2 - e_1`), the reflection in the `e_1` axis
//! `sigma(x) = (x_1 + x_2, -x_2)`; together they generate the dihedral group `D_6` of order 12,
//! which maps the lattice `(1/d) Z^2` onto itself.
//!
//! A regular basis function `psi` whose mask has this symmetry (the butterfly's, √3's) has it
//! too: `psi(g x) = psi(x)` for all twelve `g`, so its values on the wedge `W`:
//! `0 <= x_2 <= x_1` (between the rays of angle 0 and 30 degrees) give it everywhere. Its
//! derivative along `e_1`, `psi_1 = d psi / d x_1` at fixed `x_2`, satisfies
//! `psi_1(x) = (D_{g e_1} psi)(g x)` (differentiate `psi(g x) = psi(x)`): the two symmetries
//! fixing `e_1` (the identity and `sigma`) leave it unchanged and the two sending `e_1` to
//! `-e_1` (`-1`, `-sigma`) change its sign, so its values on the half-plane quarter
//! `Q`: `x_2 > 0, 2 x_1 + x_2 >= 0`, or `x_2 = 0, x_1 >= 0`, give it everywhere (on the ray
//! `2 x_1 + x_2 = 0`, which `-sigma` fixes, `psi_1` is its own negative, so zero). With
//! `g = rho`, `psi_1(x) = psi_2(rho x)`: the derivative along `e_2` is
//! `psi_2(y) = psi_1(rho^-1 y)`, `rho^-1(y) = (y_1 + y_2, -y_1)`. Each identity is a sign
//! change or a permutation of values, exact in any arithmetic.

/// `rho`: the rotation by 60 degrees (`e_1 -> e_2`).
#[inline]
pub fn rotate(x: (i64, i64)) -> (i64, i64) {
    (-x.1, x.0 + x.1)
}

/// `rho^-1`: the rotation by -60 degrees (`e_2 -> e_1`).
#[inline]
pub fn rotate_back(x: (i64, i64)) -> (i64, i64) {
    (x.0 + x.1, -x.0)
}

/// `sigma`: the reflection in the `e_1` axis.
#[inline]
pub fn reflect(x: (i64, i64)) -> (i64, i64) {
    (x.0 + x.1, -x.1)
}

/// Whether `x` is in the wedge `W` (`0 <= x_2 <= x_1`).
#[inline]
pub fn in_wedge(x: (i64, i64)) -> bool {
    0 <= x.1 && x.1 <= x.0
}

/// Whether `x` is in the quarter `Q` (`x_2 > 0` and `2 x_1 + x_2 >= 0`, or `x_2 = 0` and
/// `x_1 >= 0`).
#[inline]
pub fn in_quarter(x: (i64, i64)) -> bool {
    (x.1 > 0 && 2 * x.0 + x.1 >= 0) || (x.1 == 0 && x.0 >= 0)
}

/// The image of `x` in the wedge `W` under the twelve symmetries (`psi(x)` is `psi` there).
pub fn to_wedge(x: (i64, i64)) -> (i64, i64) {
    let mut y = x;
    for _ in 0..6 {
        if in_wedge(y) {
            return y;
        }
        let m = reflect(y);
        if in_wedge(m) {
            return m;
        }
        y = rotate(y);
    }
    // The twelve images cover every direction: one of them is in W (the tests check every
    // point of a box). The origin is in W, so this is not reached for any input.
    x
}

/// The image of `x` in the quarter `Q` under the symmetries fixing the axis `e_1` up to sign,
/// and that sign: `psi_1(x) = sign psi_1(image)`.
pub fn to_quarter(x: (i64, i64)) -> ((i64, i64), f64) {
    let m = reflect(x);
    let candidates = [
        (x, 1.0),
        (m, 1.0),
        ((-x.0, -x.1), -1.0),
        ((-m.0, -m.1), -1.0),
    ];
    candidates
        .into_iter()
        .find(|(y, _)| in_quarter(*y))
        // As for the wedge: the four images cover both half-planes; unreached.
        .unwrap_or((x, 1.0))
}

/// The box of numerators `([lo_1, hi_1], [lo_2, hi_2])` holding the support `hull/(dilation -
/// 1)` of a basis on the grid `(1/d) Z^2` (`stencilgen::triangle_system`'s box).
pub fn support_box(hull: &[(i64, i64)], dilation: u32, d: u32) -> ((i64, i64), (i64, i64)) {
    let (n, s) = (i64::from(d), i64::from(dilation) - 1);
    let lo = |c: fn(&(i64, i64)) -> i64| {
        hull.iter()
            .map(c)
            .min()
            .map_or(0, |m| (m * n).div_euclid(s))
    };
    let hi = |c: fn(&(i64, i64)) -> i64| {
        hull.iter()
            .map(c)
            .max()
            .map_or(0, |m| -(-m * n).div_euclid(s))
    };
    ((lo(|p| p.0), hi(|p| p.0)), (lo(|p| p.1), hi(|p| p.1)))
}

/// Whether `k/d` is strictly inside the support `hull/(dilation - 1)` (`hull`
/// counter-clockwise): where a continuous basis function may be nonzero.
pub fn in_open_support(hull: &[(i64, i64)], dilation: u32, d: u32, k: (i64, i64)) -> bool {
    let (n, s) = (i64::from(d), i64::from(dilation) - 1);
    let q = (s * k.0, s * k.1);
    (0..hull.len()).all(|e| {
        let (a, b) = (hull[e], hull[(e + 1) % hull.len()]);
        (n * (b.0 - a.0)) * (q.1 - n * a.1) - (n * (b.1 - a.1)) * (q.0 - n * a.0) > 0
    })
}

/// The numerators `k_1` of the row `k_2` of the grid `(1/d) Z^2` strictly inside the support
/// ([`in_open_support`]), as the run `(first, last)`, `None` if there are none: each edge's
/// test is linear in `k_1` along the row, `A k_1 + B > 0`, a bound on `k_1` (none and no point
/// at all where `A = 0` and `B <= 0`).
fn open_support_row(hull: &[(i64, i64)], dilation: u32, d: u32, k2: i64) -> Option<(i64, i64)> {
    let (n, s) = (i64::from(d), i64::from(dilation) - 1);
    let (mut first, mut last) = (i64::MIN, i64::MAX);
    for e in 0..hull.len() {
        let (a, b) = (hull[e], hull[(e + 1) % hull.len()]);
        let (p, q) = (n * (b.0 - a.0), n * (b.1 - a.1));
        // p (s k_2 - n a_2) - q (s k_1 - n a_1) > 0.
        let (slope, rest) = (-q * s, p * (s * k2 - n * a.1) + q * n * a.0);
        match slope.signum() {
            // k_1 > -B/A.
            1 => first = first.max((-rest).div_euclid(slope) + 1),
            // k_1 < B/|A|.
            -1 => last = last.min(-(-rest).div_euclid(-slope) - 1),
            _ if rest <= 0 => return None,
            _ => {}
        }
    }
    (first <= last).then_some((first, last))
}

/// The numerators `k` of the grid `(1/d) Z^2` strictly inside the support whose `k_1` is at
/// least `start(k_2)` (the wedge, the quarter: `None` for a row without such points), `k_2`
/// outer, `k_1` inner, both ascending: the order a compact table stores values in.
fn canonical(
    hull: &[(i64, i64)],
    dilation: u32,
    d: u32,
    start: fn(i64) -> Option<i64>,
) -> Vec<(i64, i64)> {
    let ((_, _), (l2, h2)) = support_box(hull, dilation, d);
    let mut points = Vec::new();
    for k2 in l2..=h2 {
        if let (Some(from), Some((first, last))) =
            (start(k2), open_support_row(hull, dilation, d, k2))
        {
            points.extend((first.max(from)..=last).map(|k1| (k1, k2)));
        }
    }
    points
}

/// The wedge points of the grid `1/d` inside the support, in storage order (`psi`).
pub fn wedge_points(hull: &[(i64, i64)], dilation: u32, d: u32) -> Vec<(i64, i64)> {
    // W: 0 <= k_2 <= k_1.
    canonical(hull, dilation, d, |k2| (k2 >= 0).then_some(k2))
}

/// The quarter points of the grid `1/d` inside the support, in storage order (`psi_1`).
pub fn quarter_points(hull: &[(i64, i64)], dilation: u32, d: u32) -> Vec<(i64, i64)> {
    // Q: 2 k_1 + k_2 >= 0 where k_2 > 0, k_1 >= 0 where k_2 = 0.
    canonical(hull, dilation, d, |k2| (k2 >= 0).then_some(-(k2 / 2)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point of a box has an image in `W` and in `Q`, reached by a symmetry (the image
    /// has the same hexagonal norm), and the images of a point's orbit agree.
    /// The row runs of [`canonical`] are the filter over the whole support box, for both
    /// region schemes' hulls at every grid `1/3n` of the tables' rates and the odd grids
    /// between.
    #[test]
    fn canonical_points_are_the_box_filtered() {
        for name in ["butterfly", "sqrt3"] {
            let mask = crate::TriangleScheme::by_name(name)
                .expect("catalogued")
                .regular_mask();
            let hull = mask.hull();
            for d in 1..=72 {
                let ((l1, h1), (l2, h2)) = support_box(&hull, mask.dilation, d);
                let all: Vec<(i64, i64)> = (l2..=h2)
                    .flat_map(|k2| (l1..=h1).map(move |k1| (k1, k2)))
                    .filter(|&k| in_open_support(&hull, mask.dilation, d, k))
                    .collect();
                for (keep, fast) in [
                    (
                        in_wedge as fn((i64, i64)) -> bool,
                        wedge_points(&hull, mask.dilation, d),
                    ),
                    (in_quarter, quarter_points(&hull, mask.dilation, d)),
                ] {
                    let want: Vec<_> = all.iter().copied().filter(|&k| keep(k)).collect();
                    assert!(!want.is_empty(), "{name} at 1/{d}");
                    assert_eq!(fast, want, "{name} at 1/{d}");
                }
            }
        }
    }

    #[test]
    fn every_point_has_its_canonical_images() {
        // The hexagonal norm squared: |x_1 e_1 + x_2 e_2|^2 = x_1^2 + x_1 x_2 + x_2^2.
        let norm = |x: (i64, i64)| x.0 * x.0 + x.0 * x.1 + x.1 * x.1;
        for a in -20..=20 {
            for b in -20..=20 {
                let x = (a, b);
                let w = to_wedge(x);
                assert!(in_wedge(w), "{x:?} -> {w:?}");
                assert_eq!(norm(w), norm(x));
                assert_eq!(to_wedge(rotate(x)), w);
                assert_eq!(to_wedge(reflect(x)), w);
                let (q, sign) = to_quarter(x);
                assert!(in_quarter(q), "{x:?} -> {q:?}");
                assert_eq!(norm(q), norm(x));
                let (qr, sr) = to_quarter(reflect(x));
                assert_eq!((qr, sr), (q, sign));
                let (qn, sn) = to_quarter((-a, -b));
                // On the ray 2 x_1 + x_2 = 0 (x_2 > 0), which -sigma fixes, psi_1 vanishes
                // (it is its own negative) and either sign names it.
                if x != (0, 0) && 2 * a + b != 0 {
                    assert_eq!((qn, sn), (q, -sign), "{x:?}");
                } else {
                    assert_eq!(qn, q, "{x:?}");
                }
                assert_eq!(rotate_back(rotate(x)), x);
            }
        }
    }
}
